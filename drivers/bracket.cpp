// The bracketing search (contract and decisions in bracket.hpp).

#include "drivers/bracket.hpp"

#include <algorithm>

namespace voussoir {

std::vector<double> bracket_probes(const Bracket& b, int points, ProbePlacement placement) {
  if (placement == ProbePlacement::Midpoint) return {0.5 * (b.lo + b.hi)};
  std::vector<double> probes;
  for (int i = 1; i <= points; ++i) probes.push_back(b.lo + (b.hi - b.lo) * i / (points + 1));
  return probes;
}

bool narrow_bracket(Bracket& b, const std::vector<double>& probes,
                    const std::vector<bool>& crossed) {
  const Bracket before = b;
  for (std::size_t i = 0; i < probes.size(); ++i)
    if (crossed[i]) b.hi = std::min(b.hi, probes[i]);
  for (std::size_t i = 0; i < probes.size(); ++i)
    if (!crossed[i] && probes[i] < b.hi) b.lo = std::max(b.lo, probes[i]);
  return b.lo != before.lo || b.hi != before.hi;
}

}  // namespace voussoir

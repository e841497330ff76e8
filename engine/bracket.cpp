// The bracketing search (contract and decisions in bracket.hpp).

#include "engine/bracket.hpp"

#include <algorithm>
#include <cmath>

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

std::vector<double> probes_ahead(const Bracket& b, const std::vector<double>& probes,
                                 const std::vector<Outcome3>& known, double tolerance, int points,
                                 ProbePlacement placement, int depth, double estimate,
                                 const std::map<double, bool>& finished) {
  // What is known (lambda -> crossed): the trials that have ended and this round's outcomes.
  std::map<double, bool> facts = finished;
  for (std::size_t i = 0; i < probes.size(); ++i)
    if (known[i] != Outcome3::Unknown) facts[probes[i]] = known[i] == Outcome3::Crossed;
  std::vector<double> ahead;
  Bracket cur = b;
  std::vector<double> round = probes;
  for (int d = 0; d < depth; ++d) {
    const double middle = std::isnan(estimate) ? 0.5 * (cur.lo + cur.hi) : estimate;
    std::vector<bool> crossed(round.size());
    for (std::size_t i = 0; i < round.size(); ++i) {
      const double p = round[i];
      if (const auto it = facts.find(p); it != facts.end()) {
        crossed[i] = it->second;
        continue;
      }
      bool below_crossed = false, above_uncrossed = false;
      for (const auto& [l, c] : facts) {
        below_crossed |= c && l < p;
        above_uncrossed |= !c && l > p;
      }
      crossed[i] = below_crossed || (!above_uncrossed && p > middle);
    }
    if (!round.empty() && !narrow_bracket(cur, round, crossed)) break;
    if (!(cur.hi - cur.lo > tolerance * cur.hi)) break;  // shrink_bracket stops here
    round = bracket_probes(cur, points, placement);
    ahead.insert(ahead.end(), round.rbegin(), round.rend());
  }
  return ahead;
}

}  // namespace voussoir

// The bracketing search (contract and decisions in bracket.hpp).

#include "engine/bracket.hpp"

#include <algorithm>
#include <cmath>

#include "core/schema.hpp"

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

void check_stepping_options(const std::string& command, const std::string& quantity,
                            const std::string& step_example, bool start_given, double start,
                            double step, int steps_above, double tolerance) {
  if (start_given && !(start > 0.0 && std::isfinite(start)))
    throw DeckError(command + " --start " + option_number(start) + " g is not allowed: the first " +
                    quantity + " must be a positive number of g");
  if (!(step > 0.0 && std::isfinite(step)))
    throw DeckError(command + " --step " + option_number(step) + " is not allowed: the relative " +
                    quantity + " step must be positive (" + step_example + ")");
  if (steps_above < 0)
    throw DeckError(command + " --steps-above " + std::to_string(steps_above) +
                    " is not allowed: the number of steps past the first collapse must be 0 or "
                    "more");
  if (!(tolerance > 0.0 && tolerance < 1.0))
    throw DeckError(command + " --tolerance " + option_number(tolerance) +
                    " is not allowed: the relative bracket width must lie in (0, 1)");
}

}  // namespace voussoir

#pragma once
// The one bracketing search of the classified drivers: a bracket [lo, hi] on a load factor
// (capacity: lambda, commands/capacity.hpp; the pulse curve: the amplitude A, commands/pulse.hpp)
// with the structure not crossing the threshold at lo (stable, survived) and crossing it at hi
// (collapsed) is narrowed by rounds of interior probes until hi - lo <= tolerance x hi.
//
// A round places `points` probes (ProbePlacement), runs them all (the caller may run them in
// parallel: capacity's rounds are its parallel unit) and narrows the bracket: hi becomes the
// lowest crossed probe, lo the highest uncrossed probe below that new hi (an uncrossed probe
// above a crossed one, a non-monotone response near the threshold, is ignored). Each round
// therefore keeps a bracket with the threshold inside for a monotone response, and shrinks it
// by the factor points + 1. A round that cannot move either end (probes one rounding away
// from lo and hi: a tolerance below the resolution of doubles) ends the search.
//
// How the brackets are found first differs and stays with each driver: capacity grows lambda
// geometrically from 0.125 or from the limit-analysis seed, the pulse curve steps up or down
// by kBracketGrowth from lambda*.

#include <cstddef>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace voussoir {

struct Bracket {
  double lo = 0.0;  // not crossed here (or the start of the search)
  double hi = 0.0;  // crossed here
};

// Where a round's probes go.
//   KSection  lo + (hi - lo) i / (points + 1), i = 1 .. points (capacity, its trial count
//             estimate);
//   Midpoint  one probe at 0.5 (lo + hi) (the pulse curve). The same point as a one-probe
//             KSection up to the last bit; kept apart so that existing curves and capacities
//             stay bit for bit what they were.
enum class ProbePlacement { KSection, Midpoint };

// The probes of the next round (ascending).
std::vector<double> bracket_probes(const Bracket& b, int points, ProbePlacement placement);

// Narrows `b` by the outcome of one round: crossed[i] for probes[i] (header comment). Returns
// false when neither end moved.
bool narrow_bracket(Bracket& b, const std::vector<double>& probes,
                    const std::vector<bool>& crossed);

// What is known of a probe's outcome while its round runs.
enum class Outcome3 : signed char { Unknown = -1, NotCrossed = 0, Crossed = 1 };

// The probes of the rounds after this one, before its outcomes are all known: what idle cores
// can run ahead (engine/trial_pool.hpp). A probe's outcome is taken from `known` (this
// round's, in the order of `probes`), else from `finished` (every trial that has ended, run
// ahead or not: lambda -> crossed); one still unknown is guessed -- crossed when a known
// crossed probe or finished trial lies below it (it is then ignored by narrow_bracket anyway),
// not crossed when a known uncrossed one lies above it (a monotone response), else crossed
// exactly when it lies above `estimate` (a guess of the threshold; NaN: the middle of each
// bracket) -- the bracket is narrowed as narrow_bracket would, and the probes of the next round
// are listed, then those of the round after it with its own probes' outcomes found or guessed
// the same way, up to `depth` rounds ahead; nothing past the round after which shrink_bracket
// would stop. Within a round, the highest probe comes first (near the threshold a collapse
// starts slowly: the longest trial of its round). With every outcome known, the first `points`
// probes are exactly the next round's.
std::vector<double> probes_ahead(const Bracket& b, const std::vector<double>& probes,
                                 const std::vector<Outcome3>& known, double tolerance, int points,
                                 ProbePlacement placement, int depth,
                                 double estimate = std::numeric_limits<double>::quiet_NaN(),
                                 const std::map<double, bool>& finished = {});

// Rounds until hi - lo <= tolerance x hi. `run_round(probes)` returns the crossed flags of the
// probes; `after_round(b)` sees the bracket after each round (progress lines). Returns the
// number of probes run.
template <class RunRound, class AfterRound>
int shrink_bracket(Bracket& b, double tolerance, int points, ProbePlacement placement,
                   RunRound&& run_round, AfterRound&& after_round) {
  int probes_run = 0;
  while (b.hi - b.lo > tolerance * b.hi) {
    const std::vector<double> probes = bracket_probes(b, points, placement);
    const std::vector<bool> crossed = run_round(probes);
    probes_run += static_cast<int>(probes.size());
    const bool moved = narrow_bracket(b, probes, crossed);
    after_round(b);
    if (!moved) break;
  }
  return probes_run;
}

// The options of the stepping search of the classified drivers (pulse --curve, ida): --start
// (when given) and --step positive, --steps-above 0 or more, --tolerance in (0, 1). `command`
// and `quantity` ("amplitude", "intensity") name them in the messages, `step_example` shows a
// --step ("0.05: each step 5% above the last"). Throws DeckError with the offending value.
void check_stepping_options(const std::string& command, const std::string& quantity,
                            const std::string& step_example, bool start_given, double start,
                            double step, int steps_above, double tolerance);

}  // namespace voussoir

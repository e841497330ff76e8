#pragma once
// `voussoir capacity DECK` (docs/reference/commands.md): lambda* by bisection on the load
// factor, each trial a load trial of engine/load_trial.hpp from the settled state.
//
// Bisection: the bracket [lo, hi] (stable at lo, collapsed at hi) shrinks by k-section with
// `points` trial lambdas per round (run in parallel on the available cores); the number of
// points is fixed, not taken from the thread count, so results do not depend on it. Stops when
// hi - lo <= tolerance x hi; lambda* = (lo + hi) / 2.

#include <memory>
#include <string>
#include <vector>

#include "commands/common.hpp"
#include "core/schema.hpp"
#include "engine/load_trial.hpp"

namespace voussoir {

// How the search starts and what it remembers.
struct CapacitySearch {
  int points = 2;  // trial lambdas per round
  // Seed the bracket from rigid-block limit analysis (limit/limit_analysis.hpp) on the same
  // blocks: the k-section starts on [kSeedLow, kSeedHigh] x lambda_la with both ends presumed
  // (stable at the low end, collapsed at the high one), and an end is run only when the search
  // ends on it; one that contradicts the seed widens the bracket geometrically. Ignored when
  // the deck gives capacity.lambda_max.
  bool seed_from_limit = true;
  // Journal of finished trials (JSON lines); trials found there are not run again, so a killed
  // capacity run resumes where it stopped. Empty = none.
  std::string journal;
  bool quiet = false;
  // When set and a collapse is bracketed: the collapsed trial at the upper bound recorded by
  // record_trial to this HDF5 file (CapacityResult::movie).
  std::string movie;
  // A settle to start from instead of settling here: settle() of the same deck and criteria.
  // The settle under gravity does not read the load direction, so the two searches of
  // `--direction both` share one (the same trials, bit for bit, as each settling alone).
  std::shared_ptr<const SettledState> settled;
};

// Where the trials run ahead on idle cores guess lambda* when limit analysis seeds the search
// (engine/trial_pool.hpp; it decides only what runs ahead, never a result): lambda* / lambda_la
// lies between 0.981 (the churches) and 1.000 (the blocks) on the 22 regression cases
// (docs/regression.md), 0.992 on the semicircular arch. Replayed on those searches' trials,
// 0.99 guesses the next round wrong 4 times in 44, the bracket's middle 33 times
// (scripts/ahead_guess).
inline constexpr double kAheadGuess = 0.99;
inline constexpr double kSeedLow = 0.92;   // FDEM lambda* lies a few % below the rigid LA one
inline constexpr double kSeedHigh = 1.02;  // (deformable blocks, non-associative friction)
// A contradicted seed widens geometrically by these factors per trial (down when its low end
// collapsed, up when its high end stood).
inline constexpr double kWidenDown = 0.7;
inline constexpr double kWidenUp = 1.3;

struct SeedReport {
  bool used = false;
  double lambda_la = 0.0;
  std::string status;       // limit analysis status
  bool held = false;        // no seeded end run contradicted the seed
  int ends_run = 0;         // seeded ends run (0 when lambda* lies inside)
  int widenings = 0;        // rounds spent widening a contradicted bracket
  int unseeded_trials = 0;  // trials the unseeded search would run to this bracket
};

struct CapacityResult {
  double lambda_star = 0.0;
  double lo = 0.0, hi = 0.0;
  double tolerance = 0.0;
  std::vector<TrialResult> trials;  // in the order they were run
  std::vector<Hinge> hinges;        // of the collapsed trial closest to lambda*
  double wall_s = 0.0;
  Index triangles = 0;
  double dt = 0.0;  // [s]
  // The settle under gravity that every trial starts from: simulated time [s], steps, wall
  // time [s] (run once, before any trial: on one core).
  double settle_time = 0.0;
  long long settle_steps = 0;
  double settle_wall_s = 0.0;
  bool bracketed = false;  // false when no collapse was found up to the cap
  SeedReport seed;
  int resumed_trials = 0;  // trials taken from the journal
  // The model at the end of the collapsed trial closest to lambda* (the failure mode), when
  // that trial ran in this process (not taken from a journal).
  bool has_mode = false;
  Model mode;
  // Joint resultants (engine/thrust.hpp): of the settled state under gravity; of the last
  // stable trial, at lo (the settled state when lo = 0 was not tried); of the collapsed trial
  // at hi. has_stable / has_collapsed are false when that trial came from a journal or none
  // exists.
  std::vector<JointResultant> joints_settled, joints_stable, joints_collapsed;
  bool has_stable = false, has_collapsed = false;
  bool has_movie = false;  // CapacitySearch::movie was recorded
  MovieReport movie;
  // Trials run ahead on idle cores (engine/trial_pool.hpp); depends on timing, not on results.
  int workers = 1;
  int ahead = 0, ahead_used = 0, ahead_cancelled = 0;
  double ahead_unused_s = 0.0;
};

// Bisection for lambda*; progress lines on stderr unless quiet.
CapacityResult find_capacity(const Config& config, const TrialCriteria& criteria,
                             const CapacitySearch& search);
// Same with default search options except `points` and `quiet`.
CapacityResult find_capacity(const Config& config, const TrialCriteria& criteria, int points,
                             bool quiet);

// Number of trials the unseeded search (geometric growth from 0.125, then k-section) needs to
// bracket a threshold at `lambda_star` within `tolerance`: replays the search with an oracle.
int unseeded_trial_count(double lambda_star, double lambda_min, double tolerance, int points);

// A capacity search in which no trial collapsed has no lambda*: the commands say so in these
// words (text, JSON "result", sweep CSV "failure_mode"), with the highest lambda that stood.
inline constexpr const char* kNoCollapse = "no collapse up to lambda_max";

// The failure mode of a finished capacity search in words: "hinging", "sliding",
// "hinging and sliding", kNoCollapse, or "none found" (a collapse without an open or slid
// joint at the end of the trial).
std::string failure_mode_text(const CapacityResult& result);

struct CapacityOptions {
  int points = 2;                // trial lambdas per bisection round (k-section with k = points+1)
  bool no_seed = false;          // --no-seed: do not start from the limit-analysis bracket
  std::string resume;            // --resume FILE: journal of finished trials (created if absent)
  std::string mode_out;          // --mode-out FILE.json: deformed state of the collapse with hinges
  std::string picture;           // --picture FILE.png|svg: the same drawn by scripts/draw
  std::string movie;             // --movie FILE.gif|mp4: the collapsed trial at the upper bound
  TrialCriteria criteria;        // --ramp-time, --rest-speed, ... (docs/capacity.md)
  bool dynamic = false;          // --dynamic: no quasi-static damping (the physical trials)
  std::string direction = "+x";  // --direction +x | -x | both
};

int command_capacity(const Config& config, const CommonOptions& common,
                     const CapacityOptions& opts);

// Registers the options of `capacity` on `cmd` (commands/table.cpp).
CommandAction add_capacity_command(CLI::App& cmd, CommandLine& line);

}  // namespace voussoir

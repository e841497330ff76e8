#pragma once
// Base-excitation runs (docs/reference/commands.md, `voussoir pulse`; the signals:
// docs/reference/deck.md, [load.base]).
//
// A pulse run:
//   1. settle the structure under gravity (commands/capacity.hpp settle(); shared by all the
//      runs of a failure curve);
//   2. apply the base signal a_g(t) from t = 0 (signal time, counted from the settled state)
//      as the inertial body force in the frame of the supports:
//          body_ax = lambda g - a_g(t),  body_ay = -g           (seismic/base_motion.hpp)
//      (a non-zero deck load.lambda is ramped on over TrialCriteria::ramp_time before the
//      signal starts, as in a capacity trial);
//   3. run on after the signal ends, T = signal duration, and classify.
//
// Classification (motions of the free blocks measured from the settled state, by their
// best-fit rigid motion, engine/kinematics.hpp; L_ref = square root of the smallest free
// block area, 0.050 m for scaled_arch):
//   collapsed ("fall")  as soon as any block centroid has moved more than
//                       fall_displacement x L_ref, or any block has rotated more than
//                       fall_rotation, during or after the signal. These are beyond any motion
//                       a masonry block comes back from: a rocking block of width b and height
//                       h returns only while its rotation stays below atan(b/h) (0.46 rad at
//                       b/h = 0.5), and an arch mechanism's point of no return is smaller
//                       (hinge rotations of a few hundredths of a radian); a displacement of a
//                       block size means voussoirs falling through.
//   survived ("rest")   once the signal is over and the largest free-node speed has stayed
//                       below rest_speed x sqrt(g L_ref) for hold_time: the structure came to
//                       rest (possibly displaced; the residual motion is reported).
//   timeout             when neither fired within free_time after the signal: collapsed if the
//                       motion is still growing (the motion measure max(d / d_fall,
//                       |rot| / rot_fall) now exceeds by 10% its largest value over the first
//                       two thirds of the free motion), survived otherwise (rocking or
//                       creeping about a displaced state with bounded amplitude).
// Large rocking during the pulse is therefore allowed: nothing is decided from the pulse's
// peak response alone, only from falling or from what remains after it.
//
// Failure curve (`pulse --curve`): for each frequency f, the smallest amplitude A [g] of the
// deck's signal that collapses the structure. Rocking makes collapse non-monotonic in A (a
// larger pulse can leave a rocking structure standing where a smaller one felled it: a slender
// block overturns after one impact in a band of amplitudes, survives above it, and overturns
// without impact higher still; Zhang & Makris 2001), so "the smallest" depends on how A is
// searched. Two searches (AmplitudeSearch):
//   Step    (default; the shaking-table protocol): A_0 = start (default the quasi-static value
//           lambda* / peak factor: a pulse that peaks below lambda* g cannot tip a structure
//           whose tilting capacity is lambda*, up to dynamic effects), A_{k+1} = A_k (1 + step)
//           (step 0.05: each step 5% above the last) until the first collapse A_k (at most
//           kMaxAmplitude g; if A_0 already collapses, down by the same factor until a survival
//           or kMinAmplitude g: collapsing all the way down, the point says it collapses at
//           every amplitude tried, A_c the smallest, and nothing is bisected),
//           then bisection inside [A_{k-1}, A_k] until hi - lo <= tolerance x hi. Then
//           `steps_above` further steps above A_k, A_k (1 + step)^j, look for amplitudes that
//           survive above a collapsing one (reported, never used to move A_c).
//   Bisect  (the single bisection): from A_0 = start (default lambda*) growing by
//           kBracketGrowth until a collapse (down by it if A_0 collapses), then bisection.
//           Fewer runs, but a growth step can jump over a collapse band and report the upper
//           threshold (tests/unit/test_pulse_stepping.cpp shows it on a slender block).
// Both give A_c = hi, the smallest amplitude seen to collapse (conservative by at most the
// tolerance), and `stable_above`: every amplitude run that survived above A_c (empty for a
// response found monotone). Frequencies run in parallel (OpenMP, one frequency per thread,
// dynamic schedule), each from a copy of one settled state; the result for a frequency does
// not depend on the thread count.

#include <atomic>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "commands/capacity.hpp"
#include "commands/common.hpp"
#include "engine/journal.hpp"
#include "engine/runs_ahead.hpp"
#include "seismic/base_motion.hpp"

namespace voussoir {

struct PulseCriteria {
  TrialCriteria settle;            // settling under gravity and the lambda ramp
  double fall_displacement = 1.0;  // x L_ref
  double fall_rotation = 1.0;      // [rad]
  double rest_speed = 1e-3;        // x sqrt(g L_ref); 0.7 mm/s for scaled_arch
  double hold_time = 0.05;         // [s]
  double free_time = 1.5;          // [s] after the signal before the timeout decision
  double sample_time = 1e-3;       // [s] between classification samples
};

// The criteria of a command's pulse runs: the default ones with the engine's limits of the
// command line and its free time after the signal [s].
inline PulseCriteria pulse_criteria(const RunLimits& limits, double free_time) {
  PulseCriteria c;
  c.settle.limits = limits;
  c.free_time = free_time;
  return c;
}

// A named point whose displacement relative to the table is recorded: the node of `block`
// nearest to the reference position (x0, y0).
struct ControlPoint {
  std::string name;
  Index block = 0;
  Index node = 0;
  double x0 = 0.0, y0 = 0.0;  // [m]
};

// Control points of a model. Arches (blocks with role "voussoir", ordered from the left
// springing by centroid x): the extrados corners (the extrados ends of the two joints) of the
// k-th voussoir from each springing, k = min(6, ceil(n/2)), named
// "left6_springing_side", "left6_crown_side", "right6_springing_side", "right6_crown_side"
// (for k = 6). Other scenes: the highest node of every free block (at most 8), "block<b>_top".
std::vector<ControlPoint> find_control_points(const Model& model);

// Running summary of one control point [m]; displacements relative to the table, from the
// settled state.
struct ControlSummary {
  ControlPoint point;
  double max_abs_ux = 0.0, max_abs_uy = 0.0, max_displacement = 0.0;
  double final_ux = 0.0, final_uy = 0.0;
};

// What a recorder sees at each recording sample.
struct PulseSample {
  double time = 0.0;  // signal time [s] (0 at the start of the signal)
  double table_acceleration = 0.0, table_velocity = 0.0, table_displacement = 0.0;
  std::vector<double> control_ux, control_uy;  // per control point [m]
};
using PulseRecorder = std::function<void(const Simulation&, const PulseSample&)>;

struct PulseResult {
  double amplitude_g = 0.0;      // [g] (signal peak scale)
  double frequency = 0.0;        // [Hz]
  double signal_duration = 0.0;  // T [s]
  bool collapsed = false;
  std::string reason;       // "fall", "rest", "timeout"
  double decided_at = 0.0;  // signal time of the decision [s]
  long long steps = 0;
  double wall_s = 0.0;
  double max_kinetic_energy = 0.0;    // [J]
  double energy_balance_error = 0.0;  // at the end (EnergyLedger::balance_error)
  // Largest |W - K - U - C - D| over the samples / the run's peak energy (settling included).
  double max_energy_balance_error = 0.0;
  // Largest change of W - K - U - C - D since the signal start / the run's peak energy: the
  // balance of the base-motion phase alone.
  double pulse_energy_balance_error = 0.0;
  double peak_energy = 0.0;            // ledger max energy [J]
  double max_displacement = 0.0;       // largest block centroid displacement seen [m]
  double max_rotation = 0.0;           // [rad]
  double residual_displacement = 0.0;  // at the end [m]
  double residual_rotation = 0.0;      // [rad]
  std::vector<ControlSummary> control;
  std::vector<Hinge> hinges;  // joints open or slid at the end
};

// One pulse run from a copy of `settled`. `recorder` (optional) is called every
// `record_every` seconds of signal time (and at the start and the end); `at_end` (optional)
// once with the final state (pulse --picture). `cancel` (optional): when it becomes true the run
// stops at its next step with a RunError (a run ahead that its search no longer wants,
// engine/runs_ahead.hpp).
PulseResult run_pulse(const SettledState& settled, const BaseSignal& signal, double lambda,
                      const std::vector<ControlPoint>& points, const PulseCriteria& criteria,
                      const PulseRecorder& recorder = nullptr, double record_every = 1e-3,
                      const std::function<void(const Simulation&)>& at_end = nullptr,
                      const std::atomic<bool>* cancel = nullptr);

struct CurvePoint {
  double frequency = 0.0;     // [Hz]
  double amplitude = 0.0;     // [g] smallest collapsing amplitude found (hi)
  double lo = 0.0, hi = 0.0;  // bracket [g]: survived at lo, collapsed at hi
  bool bracketed = false;     // false: no collapse up to kMaxAmplitude
  // Every amplitude run collapsed, down to the smallest the search tries (kMinAmplitude):
  // lo = 0, hi = amplitude = that smallest amplitude, an upper bound (no bisection).
  bool collapses_everywhere = false;
  int trials = 0;
  double wall_s = 0.0;
  double max_energy_balance_error = 0.0;  // over the trials
  // Amplitudes [g] that survived above `amplitude` (ascending): a non-monotone response.
  std::vector<double> stable_above;
  std::vector<PulseResult> runs;
};

constexpr double kBracketGrowth = 1.5;
constexpr double kMaxAmplitude = 20.0;  // [g]
// The search steps down from a collapsing start no further than this [g]: a structure that
// collapses at every amplitude down to it collapses at every amplitude tried.
constexpr double kMinAmplitude = 1e-3;
// How a point's outcome reads when every amplitude tried collapsed (text, CSV and JSON).
inline constexpr const char* kCollapsesEverywhere = "collapses at every amplitude tried";

enum class AmplitudeSearch { Step, Bisect };

// How `find_collapse_amplitude` searches A (header comment).
struct AmplitudeSearchOptions {
  AmplitudeSearch search = AmplitudeSearch::Step;
  double start = 0.0;       // [g] first amplitude, > 0
  double step = 0.05;       // Step: relative increment, A_{k+1} = A_k (1 + step), > 0
  int steps_above = 2;      // Step: steps run above the first collapsing one, >= 0
  double tolerance = 0.02;  // relative bracket width of the final bisection, in (0, 1)
};

// What tells a search's runs apart in a journal beyond their frequency and amplitude: `fields`
// (an IDA's record: {"record": file, "record_hash": h}) are written into each run's record and
// must match when resuming; `label` names the search in the progress lines (empty:
// "f = 2.000 Hz").
struct SearchKey {
  nlohmann::json fields = nlohmann::json::object();
  std::string label;
};

// Whether a journal record `run` belongs to the search of `frequency` and `key`.
bool same_search(const nlohmann::json& run, double frequency, const SearchKey& key);

// The collapse amplitude at one frequency (header comment). With a `journal`
// (engine/journal.hpp; `pulse --curve --resume FILE`), a run of the same search (same_search)
// and amplitude found there is taken from it instead of being run (the searches recompute the
// same amplitudes bit for bit), and every run is appended as it finishes; safe to share between
// the searches run in parallel. With `ahead` (deal_searches), the search is `ahead_search` of
// that board: it runs through it and plans its next amplitudes there (engine/runs_ahead.hpp).
CurvePoint find_collapse_amplitude(const SettledState& settled, const BaseConfig& base,
                                   double frequency, const AmplitudeSearchOptions& search,
                                   const PulseCriteria& criteria, bool quiet,
                                   Journal* journal = nullptr, const SearchKey& key = {},
                                   RunsAhead<PulseResult>* ahead = nullptr,
                                   std::size_t ahead_search = 0);

// The tilting capacity lambda* that a study of base motions starts its searches from (and
// compares them with): `given` when it is >= 0 (--lambda-star), otherwise `voussoir capacity`'s
// search (commands/capacity.hpp, `points` trials a round, journalled in `resume` + ".capacity"
// when `resume` is not empty), run on rank 0 alone, its result shared with the other ranks.
// Under nscd the search runs at solver.tolerance's default when the study's is looser (a loose
// contact solve lets a stable trial creep instead of coming to rest). Rank 0 rethrows a failure,
// and a search without a collapse is one (RunError: no quasi-static limit; --lambda-star gives
// one); the other ranks then get nothing and stop without a word (rank 0 reports it).
struct TiltingCapacity {
  double lambda_star = 0.0;
  double wall_s = 0.0;  // of the search (0 when given)
  bool computed = false;
};
std::optional<TiltingCapacity> study_capacity(const Config& config, const TrialCriteria& settle,
                                              double given, int points, const std::string& resume,
                                              bool quiet);

// One search of a study: a failure curve's frequency, or an IDA's record (commands/ida.hpp).
struct SearchCell {
  BaseConfig base;
  double frequency = 0.0;  // [Hz] (0 for a record)
  AmplitudeSearchOptions search;
  SearchKey key;
};
struct SearchOutcome {
  CurvePoint point;
  std::string error;  // what went wrong in the search ("" when nothing did)
};

// Runs the searches `cells`, taken in the order `order` (the costliest first, for the dynamic
// schedule; the order changes no result), dealt to `threads` threads per rank and to the ranks
// of an MPI run (engine/dealer.hpp), from copies of `settled`. In one process, threads with no
// search left run the others' next runs ahead (engine/runs_ahead.hpp; no result changes). With a
// `journal` (rank 0's; null: none) every run is journalled: in one process as it finishes; under
// mpirun a search takes its runs already journalled with it, and rank 0 journals its new runs when
// the search comes back. Returns on rank 0 the outcome of each cell (by cell index), `done` being
// told of each as it arrives (progress); an empty vector on the other ranks.
std::vector<SearchOutcome> deal_searches(
    const SettledState& settled, const std::vector<SearchCell>& cells,
    const std::vector<std::size_t>& order, const PulseCriteria& criteria, int threads, bool quiet,
    Journal* journal, const std::function<void(std::size_t, const SearchOutcome&)>& done);

// The journal of a curve's runs: its fingerprint (the settled state, the signal's definition
// and the classification criteria: what a run at (frequency, amplitude) depends on), and a run
// as a record and back.
std::string pulse_fingerprint(const SettledState& settled, const BaseConfig& base,
                              const PulseCriteria& criteria);
nlohmann::json pulse_run_record(const PulseResult& run);
PulseResult pulse_run_from_record(const nlohmann::json& record);

// A frequency's point as a record and back (every field and its runs; `pulse --curve` under
// mpirun sends it from rank to rank, engine/dealer.hpp). Its runs are not journal records of
// their own: rank 0 journals them (pulse_run_record) as the point arrives.
nlohmann::json curve_point_record(const CurvePoint& point);
CurvePoint curve_point_from_record(const nlohmann::json& record);

// A point's outcome as the tables print it after its numbers: "" for a bisected collapse,
// "  (no collapse up to the cap: censored)" or "  (collapses at every amplitude tried, down to
// A g: an upper bound)", A the point's amplitude x `scale` (an IDA's IM per PGA).
std::string point_note(const CurvePoint& point, double scale = 1.0);

// The amplitudes of `runs` that survived above the smallest collapsing one, ascending.
std::vector<double> stable_above_collapse(const std::vector<PulseResult>& runs);

struct PulseOptions {
  std::string output;         // -o FILE: HDF5 of the single run
  std::string series;         // --series FILE.csv: time series of the single run
  std::string picture;        // --picture FILE.png|svg: the single run's final state
  bool curve = false;         // --curve
  std::vector<double> freqs;  // --freqs F1,F2,... [Hz]
  std::string csv;            // --csv FILE (curve; default curve.csv)
  std::string plot;           // --plot FILE.png (curve, by scripts/plot_curve)
  double lambda_star = -1.0;  // --lambda-star X: skip the capacity search (< 0: compute)
  bool lambda_star_given = false;
  double tolerance = 0.02;      // --tolerance: relative bracket width on A
  int points = 2;               // --points: capacity trials per round
  std::string search = "step";  // --search step|bisect (AmplitudeSearch)
  double start = 0.0;           // --start A [g] (not given: lambda*/peak factor; bisect: lambda*)
  bool start_given = false;
  double step = 0.05;           // --step: relative amplitude step of the stepping search
  int steps_above = 2;          // --steps-above N: steps past the first collapse
  double free_time = 1.5;       // --free-time S: PulseCriteria::free_time [s]
  double tilt_reference = 0.0;  // --tilt-reference X: a measured tilting capacity to compare
  bool tilt_reference_given = false;
  std::string resume;          // --resume FILE: journal of the curve's runs (and FILE.capacity)
  std::string spectrum;        // --spectrum FILE.csv: response spectrum of the base signal
  std::string spectrum_plot;   // --spectrum-plot FILE.png (scripts/plot_spectrum)
  bool spectrum_only = false;  // --spectrum-only: write the spectrum, run nothing
};

// Checks the options (the curve's search and frequencies with --curve): DeckError (exit 2)
// naming the option, the value and what is allowed.
void validate_pulse_options(const PulseOptions& opts);

// --lambda-star of `command` (pulse, ida), when given: a positive finite tilting capacity, else
// DeckError naming the option and value.
void check_lambda_star_option(const std::string& command, bool given, double lambda_star);

int command_pulse(const Config& config, const CommonOptions& common, const PulseOptions& opts);

// Registers the options of `pulse` on `cmd` (commands/table.cpp).
CommandAction add_pulse_command(CLI::App& cmd, CommandLine& line);

}  // namespace voussoir

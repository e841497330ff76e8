#pragma once
// The settled state under gravity and the trial at a load factor lambda: what the capacity
// search (commands/capacity.hpp), sweep, pushover, spread, pulse and stability start from
// (docs/reference/commands.md, `voussoir capacity`).
//
// A trial at load factor lambda:
//   1. start from the settled state (gravity ramped on over `ramp_time`, then held until the
//      structure is at rest by the stable criterion below; done once and shared by all trials);
//   2. ramp the horizontal body load from 0 to lambda g over `ramp_time` (a ramp, not a step:
//      a step load overshoots the static response by up to a factor of two in the contact
//      springs and would open joints that the static load keeps closed; 0.1 s is about ten
//      periods of the lowest mode of the shipped arches, so the ramp is quasi-static);
//   3. classify with early termination:
//      collapsed as soon as any free block's centroid has moved more than
//        `collapse_displacement` x L_ref or rotated more than `collapse_rotation` since the
//        settled state (L_ref: square root of the smallest free block area);
//      stable as soon as, after the ramp, the largest free-node speed has stayed below
//        `rest_speed` x sqrt(g L_ref) for `hold_time` without interruption and the kinetic
//        energy has not grown over that window (peak of its second half <= peak of its first:
//        a decaying oscillation, not a mechanism that has just started and is still slow);
//        in quasi-static trials, the motion measure has also grown by at most kCreepTolerance
//        over that window (below: a steady creep, however slow, is not rest);
//      when neither happens by `max_time`, the trial is collapsed if the block motion is still
//      growing (speed above the rest threshold), stable otherwise (reported as "timeout").
// The thresholds are studied in docs/capacity.md. With TrialCriteria::quasi_static (the
// default of `capacity` and `sweep`) the settle and the trials run with the local damping of
// the deck's capacity.local_damping (core/integrate.hpp LocalDamping; docs/capacity.md
// "Quasi-static decisions") and the kinetic damping of its capacity.kinetic_damping
// (core/integrate.hpp KineticDamping: a slow sway stopped at its equilibrium), rigid and
// elastic blocks alike; with rigid blocks the settle (whose state every trial starts from)
// also lowers the slow blocks' inertia to the model's step when capacity.mass_scaling is
// "equalize" (engine/step.hpp equalize_rigid_inertia; the loads keep the true masses); the step
// is the physical one (core/rigid.hpp kRigidStepFraction: why not longer).
// On a rigid sliding mechanism the damping does not arrest the slide, it slows it to a steady
// creep below the rest speed;
// before the creep check the rest rule took that creep for rest and lambda* of the sliding
// semicircular arch at beta = 120 came out 11% above the limit analysis that bounds it, so
// rigid blocks ran the physical trials until the check came in. TrialCriteria::direction
// points lambda g towards -x.
//

#include <functional>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "core/schema.hpp"
#include "engine/kinematics.hpp"
#include "engine/step.hpp"
#include "engine/thrust.hpp"
#include "engine/trial.hpp"
#include "limit/limit_analysis.hpp"

namespace voussoir {

// Creep tolerance of a quasi-static trial's rest rule (RestRule::refuse_creep): the growth of
// the motion measure max(d / (collapse_displacement L_ref), rotation / collapse_rotation)
// allowed over the hold window, 5e-5. At that rate the collapse criterion is 2000 s away; in
// displacement it is 2.5e-6 L_ref per 0.1 s, 4.9e-6 m/s on the beta = 120 arches (L_ref
// 0.195 m) against their rest speed of 1.38 mm/s. A trial refused rest goes on and is decided
// by the collapse criterion or by the trend rule at max_time. Studied on the rigid sliding
// arches, whose slide the local damping slows to a creep (docs/capacity.md "The rest rule
// refuses a creep"): circular b120 mu 0.6 gives 1.1738 / 1.1781 / 1.1825 at 2e-5 / 5e-5 /
// 1e-4, basket b120 mu 0.6 1.2055 / 1.2055 / 1.2145; limit analysis, an upper bound for these
// sliding mechanisms, gives 1.1830 and 1.2104: 5e-5 is the largest tolerance below both.
inline constexpr double kCreepTolerance = 5e-5;

struct TrialCriteria {
  double ramp_time = 0.1;               // [s] load ramp (gravity when settling, lambda g after)
  double collapse_displacement = 0.05;  // x L_ref
  double collapse_rotation = 0.05;      // [rad]
  double rest_speed = 1e-3;             // x sqrt(g L_ref)
  double hold_time = 0.1;               // [s]
  double max_time = 3.0;                // [s] of simulated time after settling
  double settle_max_time = 5.0;         // [s]; a collapse under gravity ends it sooner
  // Quasi-static settle and trials: Cundall's local damping with the deck's
  // capacity.local_damping and kinetic damping with its capacity.kinetic_damping
  // (docs/capacity.md). capacity and sweep set it unless --dynamic;
  // false (the physical settle) for the pulse curve's and the stability map's settles.
  bool quasi_static = false;
  double direction = 1.0;  // of lambda g: +1 towards +x, -1 towards -x
  RunLimits limits;        // guards and the user's limits (engine/trial.hpp)
};

// The load ramp of a settle or a trial [s]: crit.ramp_time, and none under non-smooth contact
// dynamics. On rigid contacts a load below the capacity moves nothing however fast it comes
// (nothing stores energy to give back), and the contact solver converges in fewer sweeps from
// one change of the load than from a hundred small ones (docs/nscd.md "Capacity").
double load_ramp(const TrialCriteria& crit, const Simulation& sim);

struct TrialResult {
  double lambda = 0.0;
  bool collapsed = false;
  std::string reason;     // "displacement", "rotation", "rest", "timeout"
  double sim_time = 0.0;  // [s] simulated after settling
  long long steps = 0;
  double wall_s = 0.0;
  double max_displacement = 0.0;  // largest block centroid displacement [m]
  double max_rotation = 0.0;      // largest block rotation [rad]
  double energy_balance_error = 0.0;
  long long kinetic_resets = 0;          // resets of the kinetic damping during the trial
  std::vector<Hinge> hinges;             // joints opened or slid at the end of the trial
  std::vector<double> final_x, final_y;  // node positions at the end (collapsed trials only)
  // Joint resultants at the end of the trial (engine/thrust.hpp); empty for a trial taken
  // from a journal.
  std::vector<JointResultant> joints;
};

struct SettledState {
  Simulation sim;
  double l_ref = 0.0;  // [m]
  double gravity = 9.81;
  double settle_time = 0.0;  // [s]
  long long steps = 0;
  double wall_s = 0.0;
  bool settled = false;
  bool collapsed = false;         // a block passed the collapse criterion while settling
  double max_displacement = 0.0;  // [m] largest block motion while settling
  double max_rotation = 0.0;      // [rad]
  // [supports]: the movement's run time [s] (settle_time includes it), and whether the
  // structure collapsed while the supports moved (then `collapsed` too)
  double supports_time = 0.0;
  bool supports_collapsed = false;
};

// Settles the model of `config` under gravity (lambda = 0): until rest (the trial criteria's
// rest rule), a collapse (their displacement or rotation rule: no gravity capacity), or
// `settle_max_time`. With [supports] moves, once at rest the supports move over
// supports.ramp and the structure is held until rest again (move_supports_settled): every
// analysis that starts from this state (capacity, sweep, pulse) runs on the moved structure.
SettledState settle(const Config& config, const TrialCriteria& criteria, bool quiet);

// What a support movement may move the free blocks by without a collapse: the moved blocks
// carry the structure with them, so the collapse limits of the phases in which supports move
// add the largest support displacement |d| times 3 (a three-hinge mechanism turns the
// movement of a support into a larger one of the crown) to the displacement limit [m], and
// 3 |d| / L_ref plus the largest prescribed rotation to the rotation limit [rad].
MotionExtent support_allowance(const SupportMotion& supports, double l_ref);

// A support movement already started on `sim` (core/supports.hpp start_support_motion or
// retarget_support_motion at sim.ctx.time) under gravity: the ramp over `ramp` seconds, with
// the quasi-static local and kinetic damping off (they act on absolute velocities and would
// hold back the blocks the supports carry: the blocks slid on their moving supports) and the
// collapse limits widened by `allowed` (support_allowance); then, the damping back on, held
// until rest (the settle's rest rule) or the settle's time limit, collapse limits as settled
// and motion measured from the end of the ramp. Outcome: decided and not collapsed = at rest.
Outcome run_support_movement(Simulation& sim, double gravity, double l_ref, double ramp,
                             const MotionExtent& allowed, const TrialCriteria& criteria,
                             bool quiet);

// The support movement of `settle` on a settled state (run_support_movement).
void move_supports_settled(SettledState& settled, const Config& config,
                           const TrialCriteria& criteria, bool quiet);

// The block outlines and joints of `model` mirrored about x = 0 (outlines counter-clockwise):
// what limit analysis reads, so that its lambda towards +x is the original's towards -x.
// Nodes and triangles are copied unchanged.
Model mirror_x(const Model& model);

// The blocks of a simulation where they are, for limit analysis of a structure whose supports
// moved: every outline (and joint) carried by its block's rigid motion (engine/kinematics.hpp
// block_motions), and the interfaces of the reference outlines, each end carried by the mean
// of its two blocks' motions and its normal turned by their mean rotation (an open hinge's
// faces no longer meet face to face, so find_interfaces would not find them; the joint gaps
// are a small fraction of the joint length). What the LP makes of the joints that opened
// (OpenJoints):
//   Closed  every joint is closed over its whole face: the LP sees a thicker arch than the
//           one that stands on its open hinges, and overestimates it;
//   Points  a joint open as the reports say (find_hinges, kHingeFraction L_ref: its largest gap
//           beyond that or a quarter of the model's largest) is a point contact at its pivot
//           (Interface::open_a / open_b on its other end): the LP sees the hinges that stand,
//           not that a hinge open by a millimetre closes under a small load, and
//           underestimates it. A symmetric spread opens both joints of the crown block, and the
//           semicircular arch is then a four-hinge chain: lambda_la near 0 (docs/supports.md).
// `mirror`: mirrored about x = 0 (mirror_x), for the load towards -x.
enum class OpenJoints { Closed, Points };
struct MovedBlocks {
  Model model;
  std::vector<Interface> interfaces;
  std::vector<Hinge> point_contacts;  // OpenJoints::Points: the open joints, each at its pivot
};
MovedBlocks moved_blocks(const Simulation& sim, bool mirror = false,
                         OpenJoints open = OpenJoints::Closed);

// Limit analysis (lambda_la towards +x, or towards -x when direction < 0) of the blocks of a
// settled state: of the reference outlines when no support moved (bit for bit the plain
// limit_analysis), else of moved_blocks.
LimitResult limit_of_settled(const SettledState& settled, double friction, double direction);

// Why a settle did not end at rest, for the error of the commands that need rest.
std::string unsettled_message(const SettledState& settled, const TrialCriteria& criteria);

// The journals' fingerprint (core/fnv.hpp, engine/journal.hpp) of a settled state and the
// trial criteria: what a trial's result depends on besides its load.
std::string settled_fingerprint(const SettledState& settled, const TrialCriteria& criteria);

// One trial from a copy of the settled state; unless quiet, a progress line on stderr every
// kProgressPeriod of wall time.
// `sample`, if any, is called at every sample with the simulated time reached [s]; false stops
// the trial there (its result is then meaningless).
TrialResult run_trial(const SettledState& settled, double lambda, const TrialCriteria& criteria,
                      bool quiet, const std::function<bool(double)>* sample = nullptr);

// A trial's record: a line of the `--resume` journal, and (without "hinges") an entry of the
// capacity JSON's "runs"; trial_from_json reads the journal's line back.
nlohmann::json trial_json(const TrialResult& r);
TrialResult trial_from_json(const nlohmann::json& j);

// The movie of a trial (`capacity --movie`, docs/thrust.md): the trial run again from the
// settled state (bit for bit the trial that was classified: same state, load and rules) with
// a snapshot every `frame_every` of trial time to the HDF5 file `h5_path` -- node positions,
// the joint resultants and the load factor acting (attribute "lambda", ramped); snapshot
// times count from the start of the lambda ramp. It goes on past the collapse criterion, so
// that the mechanism is seen moving, until a free block has rotated kMovieRotation or moved
// kMovieDisplacement x L_ref since the settled state, or kMovieFrames frames are written.
inline constexpr double kMovieRotation = 0.35;     // [rad], about 20 degrees
inline constexpr double kMovieDisplacement = 1.0;  // x L_ref
inline constexpr int kMovieFrames = 150;
inline constexpr double kMovieFramesToCollapse = 40.0;  // frames up to the collapse criterion

struct MovieReport {
  int frames = 0;
  double duration = 0.0;       // [s] trial time of the last frame
  bool collapsed = false;      // the collapse criterion fired
  double collapse_time = 0.0;  // [s] trial time when it did
  double wall_s = 0.0;
};

MovieReport record_trial(const SettledState& settled, double lambda, const TrialCriteria& crit,
                         double frame_every, const std::string& h5_path, bool quiet);

}  // namespace voussoir

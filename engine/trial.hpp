#pragma once
// The engine: the one time loop of every analysis (docs/engine.md). It advances a Simulation under
// a load program and a list of stop rules and returns the outcome with its reason. `voussoir run`
// (run_loop, engine/run_loop.hpp), the settle under gravity and the capacity trials
// (commands/capacity.cpp), the pulse runs (commands/pulse.cpp) and the stability cells
// (commands/stability.cpp) are configurations of it.
//
// One step of the engine:
//   1. end of the run?  the step limit `end_step` or the time limit `end_time` (checked before
//      every step, so a run ends at the first step that reaches them);
//   2. loads: the load program sets ctx.body_ax/ay from the simulation time (LoadProgram);
//   3. advance(sim) (engine/step.hpp), then the on_step hook (recorders, checkpoints);
//   4. at a sample (every `sample_every` of simulated time, counted in whole steps from
//      `sample_origin`): the guards (non-finite state, energy balance, the user's limits:
//      RunLimits), then the on_sample hook, then the stop rules in order until one decides.
//      A decided run ends there, unless `min_time` asks it to go on (sampled, not re-decided).
//
// Guards throw RunError (exit status 1) naming the run (RunSpec::label), the step, the time,
// the quantity and where (node, block, triangle). They are on in every run; tests may switch
// the energy guard off (RunLimits::drift_limit <= 0).
//
// Stop rules are small objects read at samples, never inside the step (a virtual call every
// millisecond of simulated time costs nothing against the step). The classification rules:
//   CollapseRule  collapsed when a free block's centroid moved more than d_limit or rotated
//                 more than rot_limit since the start of the run;
//   RestRule      stable when the largest free-node speed has stayed below v_rest for the hold
//                 window (RestDetector, engine/motion.hpp), from run time `from` on; with
//                 refuse_creep (the capacity trials), also when the motion measure has grown
//                 by at most a tolerance over that window (CreepDetector): a steady creep,
//                 however slow, is not rest; and a slow structure going back (no block's
//                 own motion measure has grown over the window) is rest, however its
//                 kinetic energy grows;
//   TrendRule     at run time `limit` (and not before `from`): collapsed when the motion
//                 measure max(d / d_scale, rot / rot_scale) now exceeds by 10% its largest
//                 value over the first two thirds of the samples since `measure_from`, stable
//                 otherwise (critical slowing down near a threshold: a mechanism that keeps
//                 opening against an oscillation about a displaced equilibrium).
// The guards and the user's limits (RunLimits) are built by the engine itself, so that every
// run has them and a new limit is one field and one rule here.

#include <deque>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/kinematics.hpp"
#include "engine/motion.hpp"
#include "engine/step.hpp"
#include "seismic/base_motion.hpp"

namespace CLI {
class App;
}

namespace voussoir {

// Largest balance error of the energy ledger a run may reach (dimensionless, relative to the
// peak energy; the study is in engine/run_loop.hpp).
inline constexpr double kEnergyDriftLimit = 0.05;
// Steps after which the energy guard is armed (engine/run_loop.hpp).
inline constexpr long long kEnergyDriftArmSteps = 1000;

// The loads of a run as functions of the simulation time t (docs/reference/deck.md, [load] and
// [load.base]):
//   body_ay = -g r_g(t),  body_ax = lambda r_l(t) g - a_g(t - signal_start)
// with the ramps r(t) = min(1, (t - start) / ramp) (1 when the ramp is 0) and a_g the base
// signal in m/s2 (none when `signal` is null). Evaluated once per step, before it.
struct LoadProgram {
  double gravity = 9.81;               // g [m/s2]
  double gravity_ramp = 0.0;           // [s]; 0 = full gravity from the start
  double lambda = 0.0;                 // horizontal load factor
  double lambda_ramp = 0.0;            // [s]; 0 = full lambda g from the start
  double start = 0.0;                  // simulation time at which the ramps start [s]
  const BaseSignal* signal = nullptr;  // base acceleration (owned by the caller), or none
  double signal_start = 0.0;           // simulation time of signal time 0 [s]

  // Sets ctx.body_ax and ctx.body_ay for the step that starts at ctx.time.
  void apply(Simulation& sim) const;
};

// Largest centroid displacement [m] and rotation [rad] of the free blocks since a reference.
struct MotionExtent {
  double displacement = 0.0, rotation = 0.0;
};

// Motion of each block of `model` since the block motions `base` (zero for fixed blocks).
std::vector<MotionExtent> motions_since(const Model& model, const std::vector<BlockMotion>& base);

// The largest displacement and the largest rotation among `blocks`.
MotionExtent largest_of(const std::vector<MotionExtent>& blocks);

// What the hooks and rules read at a sample.
struct Probe {
  explicit Probe(const Simulation& s) : sim(s) {}
  const Simulation& sim;
  double time = 0.0;    // run time: simulated time since the start of the run [s]
  long long steps = 0;  // steps since the start of the run
  MotionExtent motion;  // since the start of the run (when RunSpec::track_motion)
  double speed = 0.0;   // largest free-node speed [m/s]
  // Each block's motion since the start of the run, whose largest is `motion` (when
  // RunSpec::track_motion), else null.
  const std::vector<MotionExtent>* blocks = nullptr;
};

struct Verdict {
  bool collapsed = false;
  std::string reason;  // "displacement", "rotation", "fall", "rest", "timeout"
};

class StopRule {
 public:
  virtual ~StopRule() = default;
  // Reads one sample; a verdict ends the run (classified), a RunError fails it.
  virtual std::optional<Verdict> check(const Probe& p) = 0;
};

class CollapseRule : public StopRule {
 public:
  CollapseRule(double d_limit, double rot_limit, std::string d_reason = "displacement",
               std::string rot_reason = "rotation")
      : d_(d_limit),
        rot_(rot_limit),
        d_reason_(std::move(d_reason)),
        rot_reason_(std::move(rot_reason)) {}
  std::optional<Verdict> check(const Probe& p) override;

 private:
  double d_, rot_;
  std::string d_reason_, rot_reason_;
};

class RestRule : public StopRule {
 public:
  // require_decay: RestDetector's growth check (off for the pulses: speed alone).
  RestRule(double v_rest, double hold, double from, bool require_decay = true)
      : detector_(v_rest, hold, require_decay), v_rest_(v_rest), hold_(hold), from_(from) {}
  // Also refuse a creep (CreepDetector, engine/motion.hpp): rest needs the motion measure
  // max(d / d_scale, rot / rot_scale) to have grown by at most `tolerance` over the hold
  // window. Needs RunSpec::track_motion.
  //
  // With it, a structure going back is also at rest: slow for the whole hold window, and no
  // free block's own motion measure (its displacement and rotation since the start of the run,
  // scaled as above) has grown over the window. Its kinetic energy may grow meanwhile: a
  // structure that the kinetic damping stopped past its equilibrium swings slowly back to it
  // (docs/capacity.md, "A structure going back is at rest"). A mechanism under its constant
  // load moves away from the start, so some block's measure grows.
  RestRule& refuse_creep(double d_scale, double rot_scale, double tolerance) {
    d_ = d_scale;
    rot_ = rot_scale;
    creep_.emplace(hold_, tolerance);
    return *this;
  }
  std::optional<Verdict> check(const Probe& p) override;

 private:
  // Records every free block's measure at this sample (slow samples only) and tells whether
  // none has grown over the last hold window.
  bool going_back(const Probe& p);

  RestDetector detector_;
  double v_rest_;
  double kinetic_floor_ = -1.0;  // [J], set at the first sample (check)
  double hold_, from_;
  double d_ = 1.0, rot_ = 1.0;
  std::optional<CreepDetector> creep_;
  struct BlockSample {
    double t;
    std::vector<double> measure;  // per block; 0 for fixed blocks
  };
  std::deque<BlockSample> blocks_;  // the slow samples of the last hold window and one before
};

class TrendRule : public StopRule {
 public:
  TrendRule(double d_scale, double rot_scale, double measure_from, double from, double limit)
      : d_(d_scale), rot_(rot_scale), measure_from_(measure_from), from_(from), limit_(limit) {}
  std::optional<Verdict> check(const Probe& p) override;

 private:
  double d_, rot_, measure_from_, from_, limit_;
  std::vector<double> measure_;
};

// Limits the user or a test sets on every run; the engine turns them into guard rules.
struct RunLimits {
  double drift_limit = kEnergyDriftLimit;            // <= 0: energy guard off
  long long drift_arm_steps = kEnergyDriftArmSteps;  // energy guard from this absolute step on
  long long max_steps = 0;  // --max-steps N: a run still going after N steps fails; 0 = none
};

// The engine's options for every command that runs (run, capacity, sweep, pulse, stability).
void add_limit_options(CLI::App* cmd, RunLimits& limits);

// Where the engine reports a step.
struct StepInfo {
  bool sample = false;  // this step is on the sample grid
  bool last = false;    // this step reaches end_step
};

struct RunSpec {
  std::string label = "run";                     // names the run in errors and progress lines
  std::optional<LoadProgram> loads;              // none: ctx.body_ax/ay are left as they are
  std::vector<std::unique_ptr<StopRule>> rules;  // in order; the first verdict decides
  RunLimits limits;
  double sample_every = kSampleTime;  // [s], rounded to whole steps (at least one)
  long long sample_origin = -1;       // samples on steps origin + k every; -1: the start
  bool sample_at_start = false;       // on_sample before the first step (no rules)
  bool sample_last = false;           // a sample at end_step even off the grid
  long long end_step = -1;            // absolute step at which the run ends; -1: none
  double end_time = std::numeric_limits<double>::infinity();  // run time limit [s]
  double min_time = 0.0;                 // a decided run goes on to this run time [s]
  bool track_motion = false;             // compute Probe::motion at samples
  std::vector<BlockMotion> motion_base;  // reference of Probe::motion; empty: the start
  // Called after every step. The nodes of rigid blocks are in step with their bodies only at
  // samples and at the end (the step moves bodies, not nodes): a hook that reads them at other
  // steps calls sync_rigid_nodes (core/rigid.hpp) first.
  std::function<void(Simulation&, const StepInfo&)> on_step;
  std::function<bool(const Simulation&, const Probe&)> on_sample;  // false: stop the run
  // Progress on stderr every progress_period of wall time unless quiet.
  bool quiet = true;
  double progress_period = kProgressPeriod;  // [s] wall
  std::function<void(const Probe&, double wall_s)> progress;
};

struct Outcome {
  bool decided = false;
  bool collapsed = false;
  std::string reason;        // the verdict's; "" when a limit or on_sample ended the run
  double time = 0.0;         // run time at the end [s]
  double sample_time = 0.0;  // run time of the last sample [s]
  double decided_at = 0.0;   // run time of the verdict [s]
  long long steps = 0;       // steps run
  double wall_s = 0.0;
  MotionExtent motion;       // at the last sample
  MotionExtent peak_motion;  // largest over the samples
};

// Runs `spec` on `sim` (header comment). Throws RunError from the guards.
Outcome run_engine(Simulation& sim, RunSpec& spec);

// Throws RunError naming the run `label`, the step, time, quantity, block and triangle when any
// node position, velocity or force, or any energy of the ledger, is not finite.
void check_finite(const Simulation& sim, const std::string& label = "run");

// Throws RunError naming the run, step, time and the fastest node (its block and a triangle)
// when sim.ledger.balance_error() exceeds `limit`.
void check_energy_balance(const Simulation& sim, double limit = kEnergyDriftLimit,
                          const std::string& label = "run");

}  // namespace voussoir

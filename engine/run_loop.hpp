#pragma once
// `voussoir run`'s configuration of the engine (engine/trial.hpp), also used by the tests:
// advance to an end time, sample the series, write checkpoints, report progress; the engine's
// guards against non-finite state and energy drift stop a broken run.
//
// Guards (docs/robustness.md, "Guards": no NaN silently written). At every sample:
//   - non-finite: any node position, velocity or force, or any term of the energy ledger,
//     that is NaN or infinite stops the run (check_finite);
//   - energy drift: the ledger's balance error |W - K - U - C - D| / (peak energy so far)
//     above kEnergyDriftLimit = 5% stops the run (check_energy_balance), once the run is
//     kEnergyDriftArmSteps = 1000 steps old. The central-difference ledger of engine/step.cpp is
//     exact for linear systems and O(dt^2) otherwise: over whole runs the stiff and extreme
//     cases of tests/unit/test_stability.cpp stay below 1e-2 of their peak energy, 5% being
//     well above that, except where the resolution of the contact energy at 1e-12 m deep
//     overlaps (~1e-5 J, a narrow-phase defect reported in docs/robustness.md) is not small
//     against a tiny peak energy: the arch with density 1 (peak 1e-5 J) trips this guard. The error
//     is relative to the largest energy term seen so far, so the threshold depends on no unit, size
//     or load of the deck. Why armed late: the peak energy of a run from rest starts at zero, and
//     during the first steps the first contact and friction increments are a sizeable share of it
//     (measured: 1.7% at step 100 of the collapsing thin arch, 1.3% at step 50 of the block on a 60
//     degree incline, 21% at step 50 of the E = 200 GPa arch, the last from the contact energy
//     resolution above); by step 1000 the energies have grown past it. What it catches: a time step
//     above the stable limit (twice the limit on the block deck: error 0.92 at step 1000, while the
//     state stays finite -- the viscous term oscillates and books dissipation without bound, and
//     the hyperelastic law keeps even an undamped blow-up finite), work booked twice or lost, a
//     contact energy out of step with its forces.
// Both throw RunError (exit status 1) naming the run, the step, the time, the quantity and
// where: the node, its block and a triangle that holds it.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "engine/step.hpp"
#include "engine/trial.hpp"
#include "io/hdf5_output.hpp"

namespace voussoir {

// (kEnergyDriftLimit, kEnergyDriftArmSteps, check_finite and check_energy_balance: the
// engine's guards, engine/trial.hpp.)

// Largest displacement magnitude of any free node from its reference position [m].
double max_free_displacement(const Model& model);

// One row of the HDF5 time series (io/hdf5_output.hpp) from the simulation as it is: the
// ledger's terms (damping and impact dissipation together), the largest displacement, the
// active contacts, the balance error; no control points (`pulse` adds its own).
SeriesRecord series_record(const Simulation& sim);

// The most steps a run plans (solver.end_time / dt) without --max-steps: a masonry run takes
// 1e4 to 1e7 (dt of 1e-6 to 1e-5 s over seconds); 1e8 steps is minutes to hours of wall, and
// beyond that a deck whose step or end time is out of range (solver.dt_safety = 1e-9 planned
// 1e10 steps) would run for days without a word.
inline constexpr double kMaxPlannedSteps = 1e8;

struct LoopStats {
  long long steps = 0;
  double wall_s = 0.0;
  std::int64_t max_active_pairs = 0;
};

struct LoopOptions {
  double end_time = 0.0;                   // [s] of simulated time, counted from step 0
  double sample_every = 0.0;               // [s]; rounded to a whole number of steps (at least one)
  bool quiet = false;                      // no progress on stderr
  std::string label = "run";               // progress line prefix
  double drift_limit = kEnergyDriftLimit;  // <= 0: energy guard off
  long long drift_arm_steps = kEnergyDriftArmSteps;  // guard checked from this step on
  RunLimits limits;                                  // the user's limits (drift fields above win)
  std::optional<LoadProgram> loads;                  // none: the loads of ctx are left as they are
  // Checkpoints: `checkpoint(sim, stats)` after every `checkpoint_every` seconds of simulated
  // time (rounded to whole steps, at least one; 0 = never), after that step's sample if it has
  // one; and, with checkpoint_at_end, after the last step too -- but before its sample when
  // that step is off the sample grid (the end-of-run sample that a longer run would not take),
  // so that a run restarted from it and extended samples exactly as the longer run does.
  double checkpoint_every = 0.0;
  bool checkpoint_at_end = false;
  std::function<void(const Simulation&, const LoopStats&)> checkpoint;
};

// Refuses (DeckError, exit 2) a loop whose `steps` still to run exceed kMaxPlannedSteps when
// opts.limits.max_steps is not given, naming the steps and the wall they imply (a few steps of
// a copy of `sim`, timed); --max-steps N runs it (and fails it after N steps).
void refuse_absurd_plan(const Simulation& sim, double steps, const LoopOptions& opts);

// Advances from sim.step until `end_time`, calling `sample(sim)` every `sample_every` seconds
// of simulated time (steps that are multiples of the sample interval, and the last step), and
// once at the start when starting from step 0; stops early when `sample` returns false.
// Checks the guards above at every sample. Resumable: a simulation restored at step k
// (engine/checkpoint) continues exactly as the uninterrupted loop would, since samples and
// checkpoints are placed by the absolute step number; `resume` carries the stats of the part
// already run (max_active_pairs, wall_s), which the returned stats include.
LoopStats run_loop(Simulation& sim, const LoopOptions& opts,
                   const std::function<bool(const Simulation&)>& sample,
                   const LoopStats& resume = {});

// Same with the default guards and no checkpoints.
LoopStats run_loop(Simulation& sim, double end_time, double sample_every,
                   const std::function<bool(const Simulation&)>& sample, bool quiet,
                   const std::string& label);

}  // namespace voussoir

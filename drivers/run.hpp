#pragma once
// The time loop shared by `run`, `capacity`, `pulse` and the tests: advance the simulation,
// guard against non-finite state, sample the series, report progress.

#include <cstdint>
#include <functional>
#include <string>

#include "core/step.hpp"

namespace voussoir {

// Largest displacement magnitude of any free node from its reference position [m].
double max_free_displacement(const Model& model);

// Throws RunError naming the step, time, block and triangle when any node position or velocity
// is not finite.
void check_finite(const Simulation& sim);

struct LoopStats {
  long long steps = 0;
  double wall_s = 0.0;
  std::int64_t max_active_pairs = 0;
};

// Advances until `end_time`, calling `sample(sim)` every `sample_every` seconds of simulated
// time (and once at the start and at the end); stops early when `sample` returns false.
// Checks the state for non-finite numbers at every sample. Progress on stderr unless quiet.
LoopStats run_loop(Simulation& sim, double end_time, double sample_every,
                   const std::function<bool(const Simulation&)>& sample, bool quiet,
                   const std::string& label);

}  // namespace voussoir

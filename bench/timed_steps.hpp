#pragma once
// The timed loop of the step benchmarks: advance() once per benchmark iteration with the stage
// timers of engine/step.hpp on (reset first); returns the steps taken.
#include <benchmark/benchmark.h>

#include "engine/step.hpp"

namespace voussoir {

inline long long timed_steps(benchmark::State& state, Simulation& sim) {
  sim.timers = StageTimers{};
  sim.timers.enabled = true;
  long long steps = 0;
  for (auto _ : state) {
    advance(sim);
    ++steps;
  }
  return steps;
}

}  // namespace voussoir

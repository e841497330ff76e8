// Full explicit step (broad phase when needed, CST elements + damping, contact + friction,
// loads, integration) on the shipped semicircular arch with elastic blocks
// (cases/circular_arch.toml with material.model=elastic: 11 voussoirs, t/R = 0.2, mu = 0.6)
// under gravity, one thread. The mesh density is varied with
// mesh.through_thickness: 1, 2 and 5 give 48, 188 and 936 triangles (the band mesher has
// nothing between 54 and 188, so "about 100" is 188). The arch first settles for 2000 steps
// so that the joints are in contact, then the timed loop runs.
//
// Run: OMP_NUM_THREADS=1 build-*/bench_step
// Figure of merit: "tri_steps_per_s" = triangles x steps / wall second (target >= 3e7).
#include <benchmark/benchmark.h>

#include <string>

#include "bench/timed_steps.hpp"
#include "engine/setup.hpp"
#include "engine/step.hpp"
#include "io/deck.hpp"

using namespace voussoir;

namespace {

Simulation arch(int through_thickness) {
  const Config config = load_deck(std::string(VOUSSOIR_SOURCE_DIR) + "/cases/circular_arch.toml",
                                  {"material.model=elastic",
                                   "mesh.through_thickness=" + std::to_string(through_thickness)});
  Simulation sim = make_simulation(config);
  for (int k = 0; k < 2000; ++k) advance(sim);
  return sim;
}

void BM_StepCircularArch(benchmark::State& state) {
  Simulation sim = arch(static_cast<int>(state.range(0)));
  for (auto _ : state) advance(sim);
  const double tris = static_cast<double>(sim.model.tris.size());
  state.counters["triangles"] = tris;
  state.counters["candidates"] = static_cast<double>(sim.contact.candidate_pairs());
  state.counters["active"] = static_cast<double>(sim.contact.active_pairs());
  state.counters["tri_steps_per_s"] =
      benchmark::Counter(tris, benchmark::Counter::kIsIterationInvariantRate);
}
// The counter "triangles" reports the exact number.
BENCHMARK(BM_StepCircularArch)->Arg(1)->Arg(2)->Arg(5)->Unit(benchmark::kMicrosecond);

// Where the time goes (stage timers of advance(), wall clock), for the 936-triangle arch.
void BM_StepStages(benchmark::State& state) {
  Simulation sim = arch(static_cast<int>(state.range(0)));
  const long long steps = timed_steps(state, sim);
  const StageTimers& t = sim.timers;
  const double per = 1e9 / static_cast<double>(steps);
  state.counters["broad_ns"] = t.broad * per;
  state.counters["elements_ns"] = t.elements * per;
  state.counters["contact_ns"] = t.contact * per;
  state.counters["loads_ns"] = t.loads * per;
  state.counters["integrate_ns"] = t.integrate * per;
}
BENCHMARK(BM_StepStages)->Arg(5)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();

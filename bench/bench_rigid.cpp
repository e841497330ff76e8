// One explicit step of the shipped churches with rigid blocks (cases/church_b.toml: 236 blocks,
// monolithic supports; cases/church_a.toml: 315 blocks, supports of courses), one thread, after
// a gravity settle of 20 000 steps (joints in contact, the candidate list of a structure at
// rest; undamped joints), with the stage split of engine/step.hpp (StageTimers) as counters in
// microseconds per step. As in the engine's runs, the joints' elastic energy is computed at the
// steps whose ledger is read (the samples, one step in hundreds): `/energy:0`; `/energy:1` computes
// it at every step.
//
// Run: OMP_NUM_THREADS=1 build/bench_rigid
// Figures: the time per step, us_contact, us_integrate, ..., the touching pairs (active).
#include <benchmark/benchmark.h>

#include <string>

#include "bench/timed_steps.hpp"
#include "engine/setup.hpp"
#include "engine/step.hpp"
#include "io/deck.hpp"

using namespace voussoir;

namespace {

Simulation settled_church(const std::string& name) {
  // Undamped joints, as the capacity trials take them (the physical runs add the joints'
  // dashpot and a step 2.6 times shorter: docs/rigid.md).
  const Config config = load_deck(
      std::string(VOUSSOIR_SOURCE_DIR) + "/cases/" + name + ".toml", {"contact.restitution=1"});
  Simulation sim = make_simulation(config);
  sim.ctx.contact_energy = false;
  for (int k = 0; k < 20000; ++k) advance(sim);
  return sim;
}

void step_church(benchmark::State& state, const std::string& name) {
  Simulation sim = settled_church(name);
  sim.ctx.contact_energy = state.range(0) != 0;
  const long long steps = timed_steps(state, sim);
  const double per = 1e6 / static_cast<double>(steps);
  const StageTimers& t = sim.timers;
  state.counters["us_broad"] = t.broad * per;
  state.counters["us_contact"] = t.contact * per;
  state.counters["us_loads"] = t.loads * per;
  state.counters["us_integrate"] = t.integrate * per;
  state.counters["bodies"] = static_cast<double>(sim.model.blocks.size());
  state.counters["candidates"] = static_cast<double>(sim.contact.candidate_pairs());
  state.counters["active"] = static_cast<double>(sim.contact.active_pairs());
}

void BM_StepChurchB(benchmark::State& state) {
  step_church(state, "church_b");
}
void BM_StepChurchA(benchmark::State& state) {
  step_church(state, "church_a");
}

}  // namespace

BENCHMARK(BM_StepChurchB)->ArgName("energy")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StepChurchA)->ArgName("energy")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();

// Throughput of the element stage and of a whole explicit step with contact off (element
// forces + body loads + central-difference integration), one thread, in triangle-steps per
// second. Meshes: a structured rectangle of ~1e3 and ~1e5 triangles (alternating diagonals),
// E = 40 GPa, nu = 0.2, rho = 2000, gravity on, Munjiza damping factor 1 (or 0: "undamped").
// Run: build/bench_elements  (figures go to docs/benchmarks.md). The rate counter divides by
// CPU time (Google Benchmark's default), which is the single-thread figure even when other
// processes share the machine.

#include <benchmark/benchmark.h>

#include <array>
#include <cstdint>
#include <vector>

#include "bench/wall.hpp"
#include "core/cst.hpp"
#include "core/integrate.hpp"
#include "engine/step.hpp"

namespace {

using namespace voussoir;

// nx x ny cells of 0.01 m, two triangles each.
Simulation make_rectangle_sim(int nx, int ny, double damping_factor) {
  Simulation sim;
  add_grid_rectangle(sim.model, 0.0, 0.0, 0.01 * nx, 0.01 * ny, nx, ny, false, "bench");
  finalize_model(sim.model);
  sim.ctx.contact_on = false;
  sim.ctx.body_ax = 0.0;
  sim.ctx.body_ay = -9.81;
  prepare_context(sim, damping_factor);
  sim.ctx.dt = 0.5 * stable_time_step(sim);
  // A small deformation so the kernels see a general state.
  Nodes& n = sim.model.nodes;
  for (Index i = 0; i < n.size(); ++i) {
    n.x[i] += 1e-6 * n.y0[i];
    n.vy[i] = 1e-3 * n.x0[i];
  }
  return sim;
}

// Grid sizes: 16 x 32 cells = 1024 triangles; 160 x 320 = 102400 triangles.
int cells_x(int64_t tris) {
  return tris < 10000 ? 32 : 320;
}
int cells_y(int64_t tris) {
  return tris < 10000 ? 16 : 160;
}

void set_rate(benchmark::State& state, const Simulation& sim) {
  state.counters["tri_steps_per_s"] = benchmark::Counter(
      double(sim.model.tris.size()) * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["triangles"] = double(sim.model.tris.size());
}

// One whole step with contact off: clear, elements, body loads, integration, ledger.
void BM_Step(benchmark::State& state) {
  Simulation sim =
      make_rectangle_sim(cells_x(state.range(0)), cells_y(state.range(0)), double(state.range(1)));
  for (auto _ : state) {
    advance(sim);
    benchmark::DoNotOptimize(sim.model.nodes.x.data());
  }
  set_rate(state, sim);
}

// The element stage alone (forces accumulate; values stay finite for the bench length).
void BM_Elements(benchmark::State& state) {
  Simulation sim =
      make_rectangle_sim(cells_x(state.range(0)), cells_y(state.range(0)), double(state.range(1)));
  const CstLaw law{sim.ctx.lame_lambda, sim.ctx.shear_modulus, sim.ctx.eta};
  sim.viscous_piola.assign(4 * std::size_t(sim.model.tris.size()), 0.0);
  double sink = 0.0;
  for (auto _ : state) {
    clear_forces(sim.model.nodes);
    const ElementStageResult r = add_element_forces(
        sim.model, law, law.eta > 0.0 ? sim.viscous_piola.data() : nullptr, &sim.element_work);
    sink += r.strain_energy;
  }
  benchmark::DoNotOptimize(sink);
  set_rate(state, sim);
}

// Args: {triangles (approx.), damping factor}.
BENCHMARK(BM_Step)
    ->ArgNames({"tris", "damping"})
    ->Args({1000, 1})
    ->Args({100000, 1})
    ->Args({1000, 0})
    ->Args({100000, 0});
BENCHMARK(BM_Elements)
    ->ArgNames({"tris", "damping"})
    ->Args({1000, 1})
    ->Args({100000, 1})
    ->Args({1000, 0})
    ->Args({100000, 0});

}  // namespace

BENCHMARK_MAIN();

// NBS broad phase cost per triangle, 1e3 to 1e6 triangles (the claim: linear cost, so the
// time per triangle stays flat). Layout: a square lattice of free square blocks (two triangles
// each, every triangle on a block boundary, so all take part), side a = 1 cm, gap 0.05 a,
// jittered by 0.02 a, on a fixed ground strip; buffer = the default (0.1 a), so neighbours are
// candidates as in a masonry structure. Also the narrow phase over the candidates of a lattice
// whose blocks overlap their neighbours by 1e-4 a (no jitter).
//
// Run: OMP_NUM_THREADS=1 build-*/bench_contact
// Figures: "time_per_tri" = detection CPU time / participating triangles; "time_per_pair" =
// contact stage CPU time / candidate pairs.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "contact/broad_phase.hpp"
#include "contact/contact.hpp"

using namespace voussoir;

namespace {

// blocks squares of side a = 1 cm at pitch `pitch` x a, positions jittered by +-jit x a.
Model lattice(int blocks, double pitch_factor, double jit) {
  const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(blocks))));
  const double a = 0.01, pitch = pitch_factor * a;
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> jitter(-jit * a, jit * a);
  Model m;
  const std::vector<Vec2> ground = {
      {-a, -a}, {side * pitch + a, -a}, {side * pitch + a, 0.0}, {-a, 0.0}};
  add_block(m, ground, ground, {{0, 1, 2}, {0, 2, 3}}, true, "ground");
  int made = 0;
  for (int j = 0; j < side && made < blocks; ++j)
    for (int i = 0; i < side && made < blocks; ++i, ++made) {
      const double x = i * pitch + jitter(rng), y = j * pitch + jitter(rng) + (pitch - a);
      const std::vector<Vec2> p = {{x, y}, {x + a, y}, {x + a, y + a}, {x, y + a}};
      add_block(m, p, p, {{0, 1, 2}, {0, 2, 3}}, false, "block");
    }
  finalize_model(m);
  return m;
}

void BM_NbsDetect(benchmark::State& state) {
  const Model m = lattice(static_cast<int>(state.range(0)) / 2, 1.05, 0.02);
  const Participants parts = select_participants(m);
  BroadPhase bp;
  bp.setup(m, default_buffer(m, parts));
  std::vector<IndexPair> out;
  for (auto _ : state) {
    bp.detect(m.nodes, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["triangles"] = static_cast<double>(parts.size());
  state.counters["pairs"] = static_cast<double>(out.size());
  // Seconds per participating triangle (printed with an SI prefix: 90n = 90 ns).
  state.counters["time_per_tri"] = benchmark::Counter(
      static_cast<double>(parts.size()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_NbsDetect)->RangeMultiplier(10)->Range(1000, 1000000)->Unit(benchmark::kMicrosecond);

void BM_NarrowPhase(benchmark::State& state) {
  Model m = lattice(static_cast<int>(state.range(0)) / 2, 1.0 - 1e-4, 0.0);
  ContactSystem contact;
  ContactParams cp;
  cp.penalty = 1e12;
  cp.friction = state.range(1) ? 0.6 : 0.0;
  contact.setup(m, cp);
  contact.detect(m);
  EnergyLedger ledger;
  for (auto _ : state) {
    contact.add_forces(m, 1e-6, ledger);
    benchmark::DoNotOptimize(m.nodes.fx.data());
  }
  state.counters["triangles"] = static_cast<double>(m.tris.size());
  state.counters["candidates"] = static_cast<double>(contact.candidate_pairs());
  state.counters["active"] = static_cast<double>(contact.active_pairs());
  state.counters["time_per_pair"] = benchmark::Counter(
      static_cast<double>(contact.candidate_pairs()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_NarrowPhase)->Args({10000, 0})->Args({10000, 1})->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();

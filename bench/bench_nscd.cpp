// The contact solver of non-smooth contact dynamics (contact/nscd.hpp) on church_b
// (cases/church_b.toml, 236 rigid blocks, solver.scheme = "nscd" at its defaults) while it rocks
// and slides: the deck settled as `pulse` settles it, then shaken by the first record of
// `voussoir synth --ag 0.25 --soil B --seed 1` scaled to a PGA of 0.30 g (about the collapse
// PGA of that record, docs/ida.md), and stopped 1, 2 and 3 s into the record. Each benchmark
// starts from one of these states, copied, and times the next 200 steps (0.2 s) on one thread.
// A copy of the same state steps to the same numbers every time (`repeatable` = 1: the last
// iteration's bodies equal the first's, bit for bit), so two builds of the solver compare on
// the same contacts, by wall time or by instruction counts (valgrind --tool=callgrind).
//
// Run: OMP_NUM_THREADS=1 build/bench_nscd
// Figures: the time per step (us_step), and per step the cone solve's share (cone), its
// factorisations of the face's matrix (factorisations), its products with W (products), the
// Gauss-Seidel sweeps (sweeps); the steps left at the sweep cap (unconverged, over the 200).
// Preparing the three states takes about a minute.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "engine/load_trial.hpp"
#include "engine/step.hpp"
#include "engine/trial.hpp"
#include "io/deck.hpp"
#include "seismic/base_motion.hpp"
#include "seismic/synth.hpp"

using namespace voussoir;

namespace {

constexpr double kPga = 0.30;                 // [g]
constexpr int kStepsTimed = 200;              // a benchmark iteration
constexpr double kStops[] = {1.0, 2.0, 3.0};  // [s] of the record

struct Shaken {
  BaseSignal signal;
  LoadProgram loads;
  std::vector<Simulation> states;  // at kStops
};

BaseSignal first_record(double gravity) {
  const SynthSettings settings;
  const Ec8Soil soil = *ec8_type1_soil('B');
  const std::vector<double> periods = synth_periods(settings);
  const SynthRecord r = synthesize_record(
      settings, [&](double t) { return ec8_elastic_spectrum(t, 0.25, soil); }, periods, 1, 0);
  Accelerogram record;
  for (std::size_t k = 0; k < r.accel.size(); ++k) {
    record.time.push_back(double(k) * settings.dt);
    record.accel.push_back(r.accel[k] * kPga * gravity / r.pga);
  }
  return BaseSignal::table(record);
}

const Shaken& shaken() {
  static const Shaken s = [] {
    const Config config = load_deck(std::string(VOUSSOIR_SOURCE_DIR) + "/cases/church_b.toml",
                                    {"solver.scheme=\"nscd\""});
    const SettledState settled = settle(config, TrialCriteria{}, true);
    Shaken out{first_record(settled.gravity), {}, {}};
    Simulation sim = settled.sim;
    out.loads.gravity = settled.gravity;
    out.loads.start = sim.ctx.time;
    out.loads.signal_start = sim.ctx.time;
    for (const double stop : kStops) {
      while (sim.ctx.time - out.loads.signal_start < stop) {
        out.loads.signal = &out.signal;
        out.loads.apply(sim);
        advance(sim);
      }
      out.states.push_back(sim);
    }
    return out;
  }();
  return s;
}

void BM_NscdChurchB(benchmark::State& state) {
  const Shaken& s = shaken();
  LoadProgram loads = s.loads;
  loads.signal = &s.signal;
  const Simulation& from = s.states[std::size_t(state.range(0))];
  NscdStats sum;
  std::vector<double> first_cx;
  bool repeatable = true;
  double stepping = 0.0;  // [s]
  for (auto _ : state) {
    state.PauseTiming();
    Simulation sim = from;
    state.ResumeTiming();
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < kStepsTimed; ++k) {
      loads.apply(sim);
      advance(sim);
    }
    stepping += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    state.PauseTiming();
    sum.add_run(sim.nscd_stats, from.nscd_stats);
    if (first_cx.empty())
      first_cx = sim.model.rigid.cx;
    else
      repeatable = repeatable && first_cx == sim.model.rigid.cx;
    state.ResumeTiming();
  }
  const double steps = double(std::max<long long>(sum.steps, 1));
  state.counters["us_step"] = 1e6 * stepping / steps;
  state.counters["cone"] = double(sum.cone_steps) / steps;
  state.counters["factorisations"] = double(sum.factorisations) / steps;
  state.counters["products"] = double(sum.cone_products) / steps;
  state.counters["sweeps"] = double(sum.iterations) / steps;
  state.counters["unconverged"] = double(sum.unconverged_steps) / double(state.iterations());
  state.counters["repeatable"] = repeatable ? 1.0 : 0.0;
}

}  // namespace

BENCHMARK(BM_NscdChurchB)
    ->ArgName("state")
    ->Arg(0)
    ->Arg(1)
    ->Arg(2)
    ->Iterations(2)
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();

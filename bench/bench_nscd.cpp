// The contact solver of non-smooth contact dynamics (contact/nscd.hpp) on church_b
// (cases/church_b.toml, 236 rigid blocks, solver.scheme = "nscd" at its defaults) while it rocks
// and slides: the deck settled as `pulse` settles it, then shaken by the first record of
// `voussoir synth --ag 0.25 --soil B --seed 1` scaled to a PGA of 0.30 g (about the collapse
// PGA of that record, docs/ida.md), with its state kept every 0.02 s from 1.00 to 2.98 s into
// the record. A benchmark times one step from a copy of each of fifty states (second 1: 1.00 to
// 1.98 s; second 2: 2.00 to 2.98 s), on one thread. One step from many states, because the
// solver's work is not a smooth function of its input: rounding the Tresca box differently
// (a + (b - a) for b) raised the median factorisations of the first second's steps from 7 to
// 20, and stepping on from a state soon compares two builds on different contacts.
//
// The states depend on the solver that made them. To compare two builds on the same states,
// set BENCH_NSCD_STATES=DIR: the first run writes the states there as checkpoints
// (engine/checkpoint.hpp), later runs, of either build, read them. A copy of the same state
// steps to the same numbers every time (`repeatable` = 1: the last iteration's bodies equal the
// first's, bit for bit), so the counts, and the instructions (valgrind --tool=callgrind), are
// the same on every run of a build.
//
// Run: OMP_NUM_THREADS=1 [BENCH_NSCD_STATES=DIR] build/bench_nscd
// Figures, per step: the time (us_step), the share that took the cone solve (cone), its
// factorisations of the face's matrix (factorisations; the median, 90th percentile and largest
// of the fifty steps: fact_median, fact_p90, fact_max), its products with W (products), the
// Gauss-Seidel sweeps (sweeps); the steps left at the sweep cap (unconverged, of the fifty).
// Preparing the states takes about half a minute.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/checkpoint.hpp"
#include "engine/load_trial.hpp"
#include "engine/step.hpp"
#include "engine/trial.hpp"
#include "io/deck.hpp"
#include "seismic/base_motion.hpp"
#include "seismic/synth.hpp"

using namespace voussoir;

namespace {

// The deck, the record (its number in `synth --seed 1`) and its PGA [g]: church_b, 1, 0.30, or
// BENCH_NSCD_DECK (a name in cases/), BENCH_NSCD_RECORD, BENCH_NSCD_PGA.
struct Setting {
  std::string deck = "church_b";
  int record = 1;
  double pga = 0.30;
};
Setting setting() {
  Setting s;
  if (const char* v = std::getenv("BENCH_NSCD_DECK")) s.deck = v;
  if (const char* v = std::getenv("BENCH_NSCD_RECORD")) s.record = std::atoi(v);
  if (const char* v = std::getenv("BENCH_NSCD_PGA")) s.pga = std::atof(v);
  if (s.record < 1 || !(s.pga > 0.0))
    throw std::invalid_argument("BENCH_NSCD_RECORD must be 1 or more, BENCH_NSCD_PGA positive");
  return s;
}
constexpr double kFirstStop = 1.0;  // [s] of the record
constexpr double kSpacing = 0.02;   // [s] between the states
constexpr int kStates = 100;        // 1.00, 1.02, ... 2.98 s
constexpr int kStatesEach = 50;     // a benchmark: 1.00 to 1.98 s, or 2.00 to 2.98 s
constexpr int kStepsEach = 1;       // steps timed from each state

struct Shaken {
  BaseSignal signal;
  LoadProgram loads;
  std::vector<Simulation> states;
};

BaseSignal shaking(const Setting& set, double gravity) {
  const SynthSettings settings;
  const Ec8Soil soil = *ec8_type1_soil('B');
  const std::vector<double> periods = synth_periods(settings);
  const SynthRecord r = synthesize_record(
      settings, [&](double t) { return ec8_elastic_spectrum(t, 0.25, soil); }, periods, 1,
      set.record - 1);
  Accelerogram record;
  for (std::size_t k = 0; k < r.accel.size(); ++k) {
    record.time.push_back(double(k) * settings.dt);
    record.accel.push_back(r.accel[k] * set.pga * gravity / r.pga);
  }
  return BaseSignal::table(record);
}

// The states, prepared by this build, or read from (or written to) BENCH_NSCD_STATES.
const Shaken& shaken() {
  static const Shaken s = [] {
    const Setting set = setting();
    const Config config =
        load_deck(std::string(VOUSSOIR_SOURCE_DIR) + "/cases/" + set.deck + ".toml",
                  {"solver.scheme=\"nscd\"", "material.model=\"rigid\""});
    const SettledState settled = settle(config, TrialCriteria{}, true);
    Shaken out{shaking(set, settled.gravity), {}, {}};
    Simulation sim = settled.sim;
    out.loads.gravity = settled.gravity;
    out.loads.start = sim.ctx.time;
    out.loads.signal_start = sim.ctx.time;
    out.loads.signal = &out.signal;
    const char* dir = std::getenv("BENCH_NSCD_STATES");
    const std::uint64_t fingerprint = simulation_fingerprint(sim, config.contact.friction);
    auto path = [&](int k) {
      return (std::filesystem::path(dir) / ("state_" + std::to_string(k) + ".ckpt")).string();
    };
    // Kept with the states: the record's start (another build's settle can end at another
    // time), the record and its PGA.
    if (dir && std::filesystem::exists(path(kStates - 1))) {
      for (int k = 0; k < kStates; ++k) {
        out.states.push_back(sim);
        const std::vector<double> kept = read_checkpoint(path(k), out.states.back(), fingerprint);
        if (kept.size() != 3 || kept[1] != set.record || kept[2] != set.pga)
          throw std::invalid_argument(path(k) + " holds the states of another record or PGA");
        out.loads.start = out.loads.signal_start = kept[0];
      }
      return out;
    }
    if (dir) std::filesystem::create_directories(dir);
    for (int k = 0; k < kStates; ++k) {
      while (sim.ctx.time - out.loads.signal_start < kFirstStop + k * kSpacing) {
        out.loads.apply(sim);
        advance(sim);
      }
      out.states.push_back(sim);
      if (dir)
        write_checkpoint(path(k), sim, fingerprint, config.contact.friction,
                         {out.loads.signal_start, double(set.record), set.pga});
    }
    return out;
  }();
  return s;
}

void BM_NscdChurchB(benchmark::State& state) {
  const Shaken& s = shaken();
  LoadProgram loads = s.loads;
  loads.signal = &s.signal;
  const int first = int(state.range(0) - 1) * kStatesEach;
  NscdStats sum;
  std::vector<std::vector<double>> first_cx;
  bool repeatable = true;
  std::vector<double> per_state;  // factorisations of the steps from each state
  double stepping = 0.0;          // [s]
  for (auto _ : state) {
    for (int k = first; k < first + kStatesEach; ++k) {
      state.PauseTiming();
      const Simulation& from = s.states[std::size_t(k)];
      Simulation sim = from;
      state.ResumeTiming();
      const auto t0 = std::chrono::steady_clock::now();
      for (int i = 0; i < kStepsEach; ++i) {
        loads.apply(sim);
        advance(sim);
      }
      stepping += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      state.PauseTiming();
      sum.add_run(sim.nscd_stats, from.nscd_stats);
      if (first_cx.size() < std::size_t(kStatesEach)) {
        per_state.push_back(double(sim.nscd_stats.factorisations - from.nscd_stats.factorisations));
        first_cx.push_back(sim.model.rigid.cx);
      } else {
        repeatable = repeatable && first_cx[std::size_t(k - first)] == sim.model.rigid.cx;
      }
      state.ResumeTiming();
    }
  }
  const double steps = double(std::max<long long>(sum.steps, 1));
  state.counters["us_step"] = 1e6 * stepping / steps;
  state.counters["cone"] = double(sum.cone_steps) / steps;
  state.counters["factorisations"] = double(sum.factorisations) / steps;
  state.counters["products"] = double(sum.cone_products) / steps;
  std::sort(per_state.begin(), per_state.end());
  const auto quantile = [&](double q) {
    return per_state[std::size_t(q * double(per_state.size() - 1) + 0.5)];
  };
  state.counters["fact_median"] = quantile(0.5);
  state.counters["fact_p90"] = quantile(0.9);
  state.counters["fact_max"] = per_state.back();
  state.counters["sweeps"] = double(sum.iterations) / steps;
  state.counters["unconverged"] = double(sum.unconverged_steps) / double(state.iterations());
  state.counters["repeatable"] = repeatable ? 1.0 : 0.0;
}

}  // namespace

BENCHMARK(BM_NscdChurchB)
    ->ArgName("second")
    ->Arg(1)
    ->Arg(2)
    ->Iterations(2)
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();

// `voussoir pulse DECK`: one base-excitation run (JSON, optional HDF5 and CSV series), or with
// --curve the amplitude-frequency failure curve (CSV, plot, JSON). Criteria and decisions in
// pulse.hpp.

#include "commands/pulse.hpp"

#include <omp.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "commands/common.hpp"
#include "core/fnv.hpp"
#include "core/rigid.hpp"
#include "engine/bracket.hpp"
#include "engine/dealer.hpp"
#include "engine/motion.hpp"
#include "engine/run_loop.hpp"
#include "engine/setup.hpp"
#include "engine/solver_report.hpp"
#include "engine/trial.hpp"
#include "io/deck.hpp"
#include "io/hdf5_output.hpp"
#include "io/json.hpp"
#include "io/plot.hpp"
#include "seismic/accelerogram.hpp"
#include "seismic/spectrum.hpp"

namespace voussoir {
namespace {

using Clock = std::chrono::steady_clock;

// Node of block b nearest to p.
Index nearest_node(const Model& model, Index b, Vec2 p) {
  const Block& blk = model.blocks[b];
  const Nodes& n = model.nodes;
  Index best = blk.first_node;
  double d2 = std::numeric_limits<double>::infinity();
  for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i) {
    const double d = (n.x0[i] - p.x) * (n.x0[i] - p.x) + (n.y0[i] - p.y) * (n.y0[i] - p.y);
    if (d < d2) d2 = d, best = i;
  }
  return best;
}

}  // namespace

std::vector<ControlPoint> find_control_points(const Model& model) {
  std::vector<ControlPoint> out;
  std::vector<Index> vous;
  for (Index b = 0; b < static_cast<Index>(model.blocks.size()); ++b)
    if (model.blocks[b].role == "voussoir" && !model.blocks[b].fixed) vous.push_back(b);
  if (!vous.empty()) {
    // Order from the left springing by reference centroid x.
    std::vector<double> cx(model.blocks.size(), 0.0);
    for (Index b : vous) {
      const Block& blk = model.blocks[b];
      double m = 0.0, sx = 0.0;
      for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i) {
        m += model.nodes.mass[i];
        sx += model.nodes.mass[i] * model.nodes.x0[i];
      }
      cx[b] = m > 0.0 ? sx / m : 0.0;
    }
    std::sort(vous.begin(), vous.end(), [&](Index a, Index b) { return cx[a] < cx[b]; });
    const int n = static_cast<int>(vous.size());
    const int k = std::min(6, (n + 1) / 2);
    struct Pick {
      Index block;
      std::string side;
    };
    std::vector<Pick> picks = {{vous[k - 1], "left"}};
    if (n - k != k - 1) picks.push_back({vous[n - k], "right"});
    for (const Pick& p : picks) {
      // Extrados ends of the block's joints, springing side first (smaller joint position).
      std::vector<const Joint*> joints;
      for (const Joint& j : model.joints)
        if (j.block_a == p.block || j.block_b == p.block) joints.push_back(&j);
      std::sort(joints.begin(), joints.end(),
                [](const Joint* a, const Joint* b) { return a->position_deg < b->position_deg; });
      if (joints.size() != 2) continue;  // not a voussoir between two joints
      // Left half: the springing side has the smaller angular position; right half: larger.
      if (p.side == "right") std::swap(joints[0], joints[1]);
      const char* names[2] = {"springing_side", "crown_side"};
      for (int s = 0; s < 2; ++s) {
        ControlPoint c;
        c.name = p.side + std::to_string(k) + "_" + names[s];
        c.block = p.block;
        c.node = nearest_node(model, p.block, joints[s]->b);
        c.x0 = model.nodes.x0[c.node];
        c.y0 = model.nodes.y0[c.node];
        out.push_back(c);
      }
    }
    if (!out.empty()) return out;
  }
  for (Index b = 0; b < static_cast<Index>(model.blocks.size()) && out.size() < 8; ++b) {
    const Block& blk = model.blocks[b];
    if (blk.fixed || blk.node_count == 0) continue;
    Index top = blk.first_node;
    for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i)
      if (model.nodes.y0[i] > model.nodes.y0[top] ||
          (model.nodes.y0[i] == model.nodes.y0[top] && model.nodes.x0[i] < model.nodes.x0[top]))
        top = i;
    out.push_back(ControlPoint{"block" + std::to_string(b) + "_top", b, top, model.nodes.x0[top],
                               model.nodes.y0[top]});
  }
  return out;
}

PulseResult run_pulse(const SettledState& settled, const BaseSignal& signal, double lambda,
                      const std::vector<ControlPoint>& points, const PulseCriteria& crit,
                      const PulseRecorder& recorder, double record_every,
                      const std::function<void(const Simulation&)>& at_end,
                      const std::atomic<bool>* cancel) {
  const auto wall0 = Clock::now();
  Simulation sim = settled.sim;     // deep copy
  fit_step_to_signal(sim, signal);  // nscd: no step longer than a record's sampling interval
  const double g = settled.gravity;
  const double dt = sim.ctx.dt;
  const long long step0 = sim.step;

  char label[96];
  std::snprintf(label, sizeof label, "the pulse run of peak base acceleration %.6g g",
                signal.peak_acceleration() / std::max(g, 1e-12));
  // Loads: gravity, lambda g ramped on before the signal as in a capacity trial, then the
  // signal from its time 0 (the end of the ramp).
  LoadProgram loads;
  loads.gravity = g;
  loads.lambda = lambda;
  loads.lambda_ramp = load_ramp(crit.settle, sim);
  loads.start = sim.ctx.time;
  if (lambda != 0.0) {
    RunSpec ramp;
    ramp.label = std::string(label) + " (lambda ramp)";
    ramp.loads = loads;
    ramp.limits = crit.settle.limits;
    ramp.sample_every = crit.sample_time;
    ramp.sample_origin = step0;
    ramp.end_time = std::max(load_ramp(crit.settle, sim), dt);
    run_engine(sim, ramp);
  }

  const double t0 = sim.ctx.time;
  const long long rec_every = std::max(1LL, std::llround(record_every / dt));
  const double duration = signal.duration();
  const double v_rest = crit.rest_speed * std::sqrt(std::max(g, 1e-12) * settled.l_ref);
  const double d_fall = crit.fall_displacement * settled.l_ref;
  std::vector<double> cx0(points.size()), cy0(points.size());
  for (size_t p = 0; p < points.size(); ++p) {
    cx0[p] = sim.model.nodes.x[points[p].node];
    cy0[p] = sim.model.nodes.y[points[p].node];
  }

  PulseResult r;
  r.signal_duration = duration;
  r.control.resize(points.size());
  for (size_t p = 0; p < points.size(); ++p) r.control[p].point = points[p];
  PulseSample sample;
  sample.control_ux.resize(points.size());
  sample.control_uy.resize(points.size());
  auto update_controls = [&](const Simulation& s) {
    for (size_t p = 0; p < points.size(); ++p) {
      const double ux = s.model.nodes.x[points[p].node] - cx0[p];
      const double uy = s.model.nodes.y[points[p].node] - cy0[p];
      ControlSummary& c = r.control[p];
      c.max_abs_ux = std::max(c.max_abs_ux, std::abs(ux));
      c.max_abs_uy = std::max(c.max_abs_uy, std::abs(uy));
      c.max_displacement = std::max(c.max_displacement, std::hypot(ux, uy));
      c.final_ux = ux;
      c.final_uy = uy;
      sample.control_ux[p] = ux;
      sample.control_uy[p] = uy;
    }
  };
  auto record = [&](const Simulation& s) {
    if (!recorder) return;
    const double t = s.ctx.time - t0;
    sample.time = t;
    sample.table_acceleration = signal.acceleration(t);
    sample.table_velocity = signal.velocity(t);
    sample.table_displacement = signal.displacement(t);
    update_controls(s);
    recorder(s, sample);
  };

  record(sim);
  // Energy balance. imbalance = W - K - U - C - D [J]; its value at the signal start is what
  // the settling left (the ledger runs from the unloaded state); the pulse's own error is the
  // change from there.
  auto imbalance_of = [](const EnergyLedger& l) {
    return l.external_work - l.stored() - l.dissipated();
  };
  const double imbalance0 = imbalance_of(sim.ledger);
  double max_imbalance = std::abs(imbalance0);  // largest |imbalance| at the samples
  double max_pulse_imbalance = 0.0;             // largest |imbalance - imbalance0|

  // The signal: fall at any time; after the signal, rest (speed alone) or the trend at
  // duration + free_time. Samples and records on the grids counted from the settled state.
  RunSpec spec;
  spec.label = label;
  spec.loads = loads;
  spec.loads->signal = &signal;
  spec.loads->signal_start = t0;
  spec.limits = crit.settle.limits;
  spec.sample_every = crit.sample_time;
  spec.sample_origin = step0;
  spec.track_motion = true;
  spec.rules.push_back(std::make_unique<CollapseRule>(d_fall, crit.fall_rotation, "fall", "fall"));
  spec.rules.push_back(std::make_unique<RestRule>(v_rest, crit.hold_time, duration, false));
  spec.rules.push_back(std::make_unique<TrendRule>(d_fall, crit.fall_rotation, duration, duration,
                                                   duration + crit.free_time));
  spec.on_step = [&](Simulation& s, const StepInfo&) {
    if (cancel && cancel->load(std::memory_order_relaxed)) throw RunError("run cancelled");
    r.max_kinetic_energy = std::max(r.max_kinetic_energy, s.ledger.kinetic);
    if ((s.step - step0) % rec_every != 0) return;
    sync_rigid_nodes(s.model);
    record(s);
  };
  spec.on_sample = [&](const Simulation& s, const Probe&) {
    const EnergyLedger& l = s.ledger;
    max_imbalance = std::max(max_imbalance, std::abs(imbalance_of(l)));
    max_pulse_imbalance = std::max(max_pulse_imbalance, std::abs(imbalance_of(l) - imbalance0));
    update_controls(s);
    return true;
  };
  const Outcome o = run_engine(sim, spec);
  r.collapsed = o.collapsed;
  r.reason = o.reason;
  r.decided_at = o.sample_time;
  r.max_displacement = o.peak_motion.displacement;
  r.max_rotation = o.peak_motion.rotation;
  r.residual_displacement = o.motion.displacement;
  r.residual_rotation = o.motion.rotation;
  record(sim);
  if (at_end) at_end(sim);
  r.steps = sim.step - step0;
  // Largest imbalance over the run relative to the run's peak energy (docs/robustness.md, "Guards":
  // below 1% of the peak energy). Not the largest of balance_error() over time: early in a run that
  // divides by the small energies of the settled state, and round-off-sized imbalances then read as
  // tens of percent.
  const EnergyLedger& l = sim.ledger;
  max_imbalance = std::max(max_imbalance, std::abs(imbalance_of(l)));
  max_pulse_imbalance = std::max(max_pulse_imbalance, std::abs(imbalance_of(l) - imbalance0));
  r.energy_balance_error = l.balance_error();
  r.peak_energy = l.max_energy;
  r.max_energy_balance_error = l.max_energy > 0.0 ? max_imbalance / l.max_energy : 0.0;
  r.pulse_energy_balance_error = l.max_energy > 0.0 ? max_pulse_imbalance / l.max_energy : 0.0;
  const double tol = kHingeFraction * settled.l_ref;
  r.hinges = find_hinges(sim.model, tol, tol);
  r.wall_s = seconds_since(wall0);
  return r;
}

std::vector<double> stable_above_collapse(const std::vector<PulseResult>& runs) {
  double lowest = std::numeric_limits<double>::infinity();
  for (const PulseResult& r : runs)
    if (r.collapsed) lowest = std::min(lowest, r.amplitude_g);
  std::vector<double> out;
  for (const PulseResult& r : runs)
    if (!r.collapsed && r.amplitude_g > lowest) out.push_back(r.amplitude_g);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::string pulse_fingerprint(const SettledState& settled, const BaseConfig& base,
                              const PulseCriteria& crit) {
  Fnv f;
  f.text(settled_fingerprint(settled, crit.settle));
  f.text(base.signal);
  f.value(base.cycles);
  f.value(base.band[0]);
  f.value(base.band[1]);
  for (double v : {crit.fall_displacement, crit.fall_rotation, crit.rest_speed, crit.hold_time,
                   crit.free_time, crit.sample_time})
    f.value(v);
  return f.hex();
}

nlohmann::json pulse_run_record(const PulseResult& r) {
  return {{"frequency", r.frequency},
          {"amplitude", r.amplitude_g},
          {"signal_duration", r.signal_duration},
          {"collapsed", r.collapsed},
          {"reason", r.reason},
          {"decided_at", r.decided_at},
          {"steps", r.steps},
          {"wall_s", r.wall_s},
          {"max_kinetic_energy", r.max_kinetic_energy},
          {"energy_balance_error", r.energy_balance_error},
          {"max_energy_balance_error", r.max_energy_balance_error},
          {"pulse_energy_balance_error", r.pulse_energy_balance_error},
          {"peak_energy", r.peak_energy},
          {"max_displacement", r.max_displacement},
          {"max_rotation", r.max_rotation},
          {"residual_displacement", r.residual_displacement},
          {"residual_rotation", r.residual_rotation},
          {"hinges", hinges_record(r.hinges)}};
}

PulseResult pulse_run_from_record(const nlohmann::json& j) {
  PulseResult r;
  r.frequency = j.at("frequency");
  r.amplitude_g = j.at("amplitude");
  r.signal_duration = j.at("signal_duration");
  r.collapsed = j.at("collapsed");
  r.reason = j.at("reason");
  r.decided_at = j.at("decided_at");
  r.steps = j.at("steps");
  r.wall_s = j.at("wall_s");
  r.max_kinetic_energy = j.at("max_kinetic_energy");
  r.energy_balance_error = j.at("energy_balance_error");
  r.max_energy_balance_error = j.at("max_energy_balance_error");
  r.pulse_energy_balance_error = j.at("pulse_energy_balance_error");
  r.peak_energy = j.at("peak_energy");
  r.max_displacement = j.at("max_displacement");
  r.max_rotation = j.at("max_rotation");
  r.residual_displacement = j.at("residual_displacement");
  r.residual_rotation = j.at("residual_rotation");
  r.hinges = hinges_from_record(j.at("hinges"));
  return r;
}

// nlohmann's conversions of a run (its journal record) and of a point, field by field.
void to_json(nlohmann::json& j, const PulseResult& r) {
  j = pulse_run_record(r);
}
void from_json(const nlohmann::json& j, PulseResult& r) {
  r = pulse_run_from_record(j);
}
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(CurvePoint, frequency, amplitude, lo, hi, bracketed,
                                   collapses_everywhere, trials, wall_s, max_energy_balance_error,
                                   stable_above, runs)

nlohmann::json curve_point_record(const CurvePoint& point) {
  return point;
}
CurvePoint curve_point_from_record(const nlohmann::json& record) {
  return record.get<CurvePoint>();
}

bool same_search(const nlohmann::json& run, double frequency, const SearchKey& key) {
  if (run.value("frequency", -1.0) != frequency) return false;
  for (const auto& [name, value] : key.fields.items())
    if (!run.contains(name) || run.at(name) != value) return false;
  return true;
}

namespace {
// One run of a search: the signal of `base` at `frequency` scaled to a peak of `a` g.
PulseResult search_run(const SettledState& settled, const BaseConfig& base, double frequency,
                       double a, const std::vector<ControlPoint>& points, const PulseCriteria& crit,
                       const std::atomic<bool>* cancel) {
  const BaseSignal signal = make_base_signal(base, a, frequency, settled.gravity);
  PulseResult r = run_pulse(settled, signal, 0.0, points, crit, nullptr, 1e-3, nullptr, cancel);
  r.amplitude_g = a;
  r.frequency = frequency;
  r.control.clear();  // not needed per trial
  return r;
}
}  // namespace

CurvePoint find_collapse_amplitude(const SettledState& settled, const BaseConfig& base,
                                   double frequency, const AmplitudeSearchOptions& search,
                                   const PulseCriteria& crit, bool quiet, Journal* journal,
                                   const SearchKey& key, RunsAhead<PulseResult>* ahead,
                                   std::size_t ahead_search) {
  const auto wall0 = Clock::now();
  CurvePoint cp;
  cp.frequency = frequency;
  const std::vector<ControlPoint> points = find_control_points(settled.sim.model);
  // A run of this frequency and amplitude in the journal, or none.
  auto from_journal = [&](double a, PulseResult& r) {
    bool found = false;
#pragma omp critical(pulse_journal)
    for (const nlohmann::json& j : journal->records())
      if (same_search(j, frequency, key) && j.value("amplitude", -1.0) == a) {
        r = pulse_run_from_record(j);
        found = true;
        break;
      }
    return found;
  };
  // The run of `a`; `next`: the amplitudes the search will most likely ask for after it, best
  // first, for a board of runs ahead (those in the journal left out).
  auto trial = [&](double a, std::vector<double> next) {
    PulseResult r;
    const bool resumed = journal && from_journal(a, r);
    if (!resumed) {
      if (ahead) {
        PulseResult unused;
        if (journal)
          next.erase(std::remove_if(next.begin(), next.end(),
                                    [&](double x) { return from_journal(x, unused); }),
                     next.end());
        r = ahead->take(ahead_search, a, std::move(next));
      } else {
        r = search_run(settled, base, frequency, a, points, crit, nullptr);
      }
      if (journal) {
        nlohmann::json record = pulse_run_record(r);
        record.update(key.fields);
#pragma omp critical(pulse_journal)
        journal->append(record);
      }
    }
    cp.max_energy_balance_error = std::max(cp.max_energy_balance_error, r.max_energy_balance_error);
    if (!quiet) {
      char name[64];
      std::snprintf(name, sizeof name, "f = %6.3f Hz", frequency);
      std::fprintf(stderr, "  %s  A = %.5f g  %-9s (%s at t = %.3f s, %lld steps, %.1f s wall)%s\n",
                   key.label.empty() ? name : key.label.c_str(), a,
                   r.collapsed ? "collapsed" : "survived", r.reason.c_str(), r.decided_at, r.steps,
                   r.wall_s, resumed ? " [journal]" : "");
    }
    cp.runs.push_back(r);
    return r.collapsed;
  };

  // Bracket: up from the start by `growth` until a collapse, or down until a survival.
  const bool stepping = search.search == AmplitudeSearch::Step;
  const double growth = stepping ? 1.0 + search.step : kBracketGrowth;
  // What the search asks for next (the plans of the runs ahead; they change no result). The
  // stepping search's steps above a first collapse at `collapse`, as it runs them below.
  auto steps_above = [&](double collapse) {
    std::vector<double> out;
    for (int k = 0; stepping && k < search.steps_above && collapse * growth <= kMaxAmplitude; ++k)
      out.push_back(collapse *= growth);
    return out;
  };
  // The bisection's probe in `c`, unless `c` is narrow enough (shrink_bracket's test).
  auto probe_in = [&](const Bracket& c, std::vector<double>& out) {
    if (c.hi - c.lo > search.tolerance * c.hi)
      out.push_back(bracket_probes(c, 1, ProbePlacement::Midpoint)[0]);
  };
  // Stepping up from `a` (survived at `lo`, when `lo` > 0): the next step (also the first step
  // above `a` should it collapse) and the one after, then the bisection below `a`.
  auto after_step_up = [&](double a, double lo) {
    std::vector<double> next;
    if (a * growth <= kMaxAmplitude) next.push_back(a * growth);
    if (a * growth * growth <= kMaxAmplitude) next.push_back(a * growth * growth);
    if (lo > 0.0) probe_in(Bracket{lo, a}, next);
    return next;
  };
  double lo = 0.0, hi = 0.0;
  bool have_hi = false, have_lo = false;
  double a = search.start;
  if (trial(a, after_step_up(a, 0.0))) {
    hi = a, have_hi = true;
    while (!have_lo && a > kMinAmplitude) {
      a /= growth;
      std::vector<double> next;
      if (a > kMinAmplitude) next.push_back(a / growth);
      probe_in(Bracket{a, hi}, next);
      if (trial(a, next)) {
        hi = a;
      } else {
        lo = a, have_lo = true;
      }
    }
  } else {
    lo = a, have_lo = true;
    while (!have_hi && a * growth <= kMaxAmplitude) {
      a *= growth;
      if (trial(a, after_step_up(a, lo))) {
        hi = a, have_hi = true;
      } else {
        lo = a;
      }
    }
  }
  cp.bracketed = have_hi;
  // Every amplitude run collapsed, down to the smallest tried: no survival to bisect from (a
  // bracket [0, hi] would take runs until hi underflows). The point says so, with A_c = hi the
  // smallest amplitude run (an upper bound of the collapse amplitude).
  cp.collapses_everywhere = have_hi && !have_lo;
  const double first_collapse = hi;
  if (have_hi && have_lo) {  // bisection (engine/bracket.hpp)
    Bracket b{lo, hi};
    shrink_bracket(
        b, search.tolerance, 1, ProbePlacement::Midpoint,
        [&](const std::vector<double>& amplitudes) {
          // Next: the steps above (sure to come), then the probe below this one (more often a
          // survival: the longer run), then the probe above it.
          const double m = amplitudes[0];
          std::vector<double> next = steps_above(first_collapse);
          probe_in(Bracket{b.lo, m}, next);
          probe_in(Bracket{m, b.hi}, next);
          return std::vector<bool>{trial(m, next)};
        },
        [](const Bracket&) {});
    lo = b.lo;
    hi = b.hi;
  }
  // Stepping: the steps above the first collapse (non-monotone check; A_c stays hi).
  if (stepping && have_hi && have_lo) {
    const std::vector<double> above = steps_above(first_collapse);
    for (std::size_t k = 0; k < above.size(); ++k)
      trial(above[k], std::vector<double>(above.begin() + k + 1, above.end()));
  }
  cp.lo = lo;
  cp.hi = have_hi ? hi : lo;
  cp.amplitude = cp.hi;
  cp.stable_above = stable_above_collapse(cp.runs);
  cp.trials = static_cast<int>(cp.runs.size());
  cp.wall_s = seconds_since(wall0);
  return cp;
}

std::string point_note(const CurvePoint& point, double scale) {
  if (point.collapses_everywhere)
    return std::string("  (") + kCollapsesEverywhere + ", down to " +
           option_number(point.amplitude * scale) + " g: an upper bound)";
  return point.bracketed ? "" : "  (no collapse up to the cap: censored)";
}

std::optional<TiltingCapacity> study_capacity(const Config& config, const TrialCriteria& settle,
                                              double given, int points, const std::string& resume,
                                              bool quiet) {
  if (given >= 0.0) return TiltingCapacity{given, 0.0, false};
  nlohmann::json found;
  std::exception_ptr failure;
  if (is_dealer_rank()) try {
      if (!quiet) std::fprintf(stderr, "tilting capacity lambda* (voussoir capacity)...\n");
      // lambda* is a quasi-static limit: a trial is stable when it comes to rest, and under
      // nscd a contact solve stopped at a loose tolerance lets a stable structure creep
      // (church_b at 1e-4: trials at 0.0993 and 0.0981 neither rested nor fell within their 3
      // s, lambda* 0.0979 against 0.10407). So the search runs at the default tolerance when
      // the study's is looser; the study's runs keep theirs.
      Config capacity_config = config;
      const double converged = SolverConfig{}.tolerance;
      if (tolerance_too_loose_for_rest(config)) {
        capacity_config.solver.tolerance = converged;
        if (!quiet)
          std::fprintf(stderr, "  at solver.tolerance = %s (the default; the runs use %s)\n",
                       option_number(converged).c_str(),
                       option_number(config.solver.tolerance).c_str());
      }
      CapacitySearch capacity_search;
      capacity_search.points = points;
      capacity_search.quiet = quiet;
      if (!resume.empty()) capacity_search.journal = resume + ".capacity";
      const CapacityResult cap = find_capacity(capacity_config, settle, capacity_search);
      // Without a collapse there is no tilting capacity, hence no quasi-static limit to start
      // the searches from or to compare them with.
      if (!cap.bracketed) {
        char buf[200];
        std::snprintf(buf, sizeof buf,
                      "the tilting capacity search found %s = %.4f: no quasi-static limit to "
                      "start from (give one with --lambda-star)",
                      kNoCollapse, cap.lo);
        throw RunError(buf);
      }
      found = {{"lambda_star", cap.lambda_star}, {"wall_s", cap.wall_s}};
    } catch (...) {
      failure = std::current_exception();
      found = {{"failed", true}};
    }
  found = share_from_dealer(found);
  if (failure) std::rethrow_exception(failure);
  if (found.is_null() || found.contains("failed")) return std::nullopt;
  TiltingCapacity out{found["lambda_star"], found["wall_s"], true};
  if (!quiet) std::fprintf(stderr, "lambda* = %.4f (%.1f s wall)\n", out.lambda_star, out.wall_s);
  return out;
}

std::vector<SearchOutcome> deal_searches(
    const SettledState& settled, const std::vector<SearchCell>& cells,
    const std::vector<std::size_t>& order, const PulseCriteria& crit, int threads, bool quiet,
    Journal* journal, const std::function<void(std::size_t, const SearchOutcome&)>& done) {
  std::vector<SearchOutcome> outcomes(cells.size());
  const bool spread = rank_count() > 1 && journal;
  auto runs_of = [&](const SearchCell& cell) {
    nlohmann::json runs = nlohmann::json::array();
    for (const nlohmann::json& j : journal->records())
      if (same_search(j, cell.frequency, cell.key)) runs.push_back(j);
    return runs;
  };
  CellWork work;
  work.cells = cells.size();
  if (spread) work.input = [&](std::size_t k) { return runs_of(cells[order[k]]); };
  // In one process, threads with no search left run the searches' next runs ahead.
  const std::vector<ControlPoint> points = find_control_points(settled.sim.model);
  std::optional<RunsAhead<PulseResult>> ahead;
  if (rank_count() == 1 && (threads > 0 ? threads : omp_get_max_threads()) > 1) {
    ahead.emplace(cells.size(), [&](std::size_t i, double a, const std::atomic<bool>& cancel) {
      return search_run(settled, cells[i].base, cells[i].frequency, a, points, crit, &cancel);
    });
    work.idle = [&] { ahead->help(); };
  }
  work.run = [&](std::size_t k, const nlohmann::json& given) {
    const std::size_t i = order[k];
    const SearchCell& cell = cells[i];
    Journal share(given.is_array() ? given.get<std::vector<nlohmann::json>>()
                                   : std::vector<nlohmann::json>());
    CurvePoint p;
    std::string error;
    try {
      // Under mpirun the progress is a line per search, printed by rank 0 as it arrives.
      p = find_collapse_amplitude(settled, cell.base, cell.frequency, cell.search, crit,
                                  quiet || rank_count() > 1, spread ? &share : journal, cell.key,
                                  ahead ? &*ahead : nullptr, i);
    } catch (const std::exception& e) {
      error = e.what();
      p.frequency = cell.frequency;
    }
    if (ahead) ahead->done(i);
    nlohmann::json record = curve_point_record(p);
    record["error"] = error;
    return record;
  };
  work.take = [&](std::size_t k, const nlohmann::json& record) {
    const std::size_t i = order[k];
    SearchOutcome& out = outcomes[i];
    out.point = curve_point_from_record(record);
    out.error = record.at("error");
    if (spread) {
      const nlohmann::json known = runs_of(cells[i]);
      for (const nlohmann::json& run : record.at("runs"))
        if (std::none_of(known.begin(), known.end(), [&](const nlohmann::json& j) {
              return j.at("amplitude") == run.at("amplitude");
            })) {
          nlohmann::json tagged = run;
          tagged.update(cells[i].key.fields);
          journal->append(tagged);
        }
    }
    if (done) done(i, out);
  };
  deal_cells(work, threads, quiet);
  if (ahead && !quiet) {
    const AheadStats st = ahead->stats();
    if (st.started > 0)
      std::fprintf(stderr,
                   "runs ahead on idle threads: %d, %d of them used (%d cancelled, %.1f s of "
                   "wall on runs not used)\n",
                   st.started, st.used, st.cancelled, st.unused_s);
  }
  if (!is_dealer_rank()) return {};
  return outcomes;
}

void check_lambda_star_option(const std::string& command, bool given, double lambda_star) {
  if (given && !(lambda_star > 0.0 && std::isfinite(lambda_star)))
    throw DeckError(command + " --lambda-star " + option_number(lambda_star) +
                    " is not allowed: the tilting capacity must be a positive number (leave the "
                    "option out to compute it)");
}

void validate_pulse_options(const PulseOptions& opts) {
  check_lambda_star_option("pulse", opts.lambda_star_given, opts.lambda_star);
  if (!(opts.free_time > 0.0 && std::isfinite(opts.free_time)))
    throw DeckError("pulse --free-time " + option_number(opts.free_time) +
                    " s is not allowed: the free motion after the signal must be a positive time");
  if (!opts.curve) return;
  if (opts.freqs.empty()) throw DeckError("pulse --curve needs --freqs F1,F2,... (Hz)");
  for (double f : opts.freqs)
    if (!(f > 0.0) || !std::isfinite(f))
      throw DeckError("pulse --freqs: frequency " + option_number(f) +
                      " Hz is not allowed: every frequency must be a positive number of Hz");
  if (opts.search != "step" && opts.search != "bisect")
    throw DeckError("pulse --search \"" + opts.search +
                    "\" is not allowed: use \"step\" (raise the amplitude step by step, the "
                    "default) or \"bisect\"");
  check_stepping_options("pulse", "amplitude", "0.05: each step 5% above the last",
                         opts.start_given, opts.start, opts.step, opts.steps_above, opts.tolerance);
  if (opts.tilt_reference_given &&
      !(opts.tilt_reference > 0.0 && std::isfinite(opts.tilt_reference)))
    throw DeckError("pulse --tilt-reference " + option_number(opts.tilt_reference) +
                    " is not allowed: a measured tilting capacity must be a positive number");
}

}  // namespace voussoir

namespace voussoir {

namespace {

using Clock = std::chrono::steady_clock;

nlohmann::json control_json(const std::vector<ControlSummary>& control) {
  nlohmann::json out = nlohmann::json::object();
  for (const ControlSummary& c : control)
    out[c.point.name] = {{"block", c.point.block},
                         {"node", c.point.node},
                         {"x0", c.point.x0},
                         {"y0", c.point.y0},
                         {"max_abs_ux", c.max_abs_ux},
                         {"max_abs_uy", c.max_abs_uy},
                         {"max_displacement", c.max_displacement},
                         {"final_ux", c.final_ux},
                         {"final_uy", c.final_uy}};
  return out;
}

SeriesRecord series_record(const Simulation& sim, const PulseSample& s) {
  SeriesRecord r = series_record(sim);
  r.time = s.time;
  r.control_displacements = {s.table_acceleration, s.table_velocity, s.table_displacement};
  for (size_t p = 0; p < s.control_ux.size(); ++p) {
    r.control_displacements.push_back(s.control_ux[p]);
    r.control_displacements.push_back(s.control_uy[p]);
  }
  return r;
}

// --spectrum: the 5%-damped pseudo-acceleration spectrum (seismic/spectrum.hpp) of the signal the
// run uses (read, baseline-corrected, band-passed and scaled as make_base_signal gives it), at
// the written spectrum periods; CSV period,sa_g.

void write_spectrum(const Config& config, const PulseOptions& opts) {
  const BaseSignal signal = make_base_signal(config.load.base, config.load.gravity);
  if (signal.kind() == BaseSignal::Kind::None)
    throw DeckError(config.deck_path +
                    ": load.base.signal = \"none\": --spectrum needs a base signal");
  const std::vector<double> periods = written_spectrum_periods();
  const std::vector<double> sa =
      response_spectrum(signal.samples(), signal.sample_dt(), periods, kCodeDamping);
  // Under mpirun (pulse --curve) every rank reads and checks the record; rank 0 writes.
  if (!is_dealer_rank()) return;
  const double g = config.load.gravity;
  std::size_t top = 0;
  for (std::size_t i = 0; i < sa.size(); ++i)
    if (sa[i] > sa[top]) top = i;
  {
    std::ofstream csv(opts.spectrum);
    if (!csv) throw OutputError(opts.spectrum + ": cannot write the spectrum CSV");
    csv.precision(9);
    csv << "period,sa_g\n";
    for (std::size_t i = 0; i < sa.size(); ++i) csv << periods[i] << "," << sa[i] / g << "\n";
    if (!csv.flush()) throw OutputError(opts.spectrum + ": cannot write the spectrum CSV");
  }
  std::printf("spectrum (%.0f%% damping) of %s: PGA %.4g g, peak Sa %.4g g at T = %.3g s; %s\n",
              100.0 * kCodeDamping,
              config.load.base.signal == "file" ? config.load.base.file.c_str()
                                                : config.load.base.signal.c_str(),
              signal.peak_acceleration() / g, sa[top] / g, periods[top], opts.spectrum.c_str());
  if (!opts.spectrum_plot.empty())
    draw_with_script("plot_spectrum", {opts.spectrum, "-o", opts.spectrum_plot},
                     opts.spectrum_plot);
}

int single_run(const Config& config, const CommonOptions& common, const PulseOptions& opts) {
  const auto wall0 = Clock::now();
  const PulseCriteria crit = pulse_criteria(common.limits, opts.free_time);
  const BaseSignal signal = make_base_signal(config.load.base, config.load.gravity);
  if (signal.kind() == BaseSignal::Kind::None)
    throw DeckError(config.deck_path +
                    ": load.base.signal = \"none\": `voussoir pulse` needs a base signal "
                    "(windowed_sine, sine_pulse or file)");
  const SettledState settled = settle(config, crit.settle, common.quiet);
  if (!settled.settled) throw RunError(unsettled_message(settled, crit.settle));
  const std::vector<ControlPoint> points = find_control_points(settled.sim.model);

  const std::string out_path = opts.output.empty() ? config.output.file : opts.output;
  const bool write_h5 = !out_path.empty();
  const bool want_stress = std::find(config.output.fields.begin(), config.output.fields.end(),
                                     "stress") != config.output.fields.end();
  RunWriter writer;
  std::unique_ptr<std::ofstream> csv;
  if (write_h5) {
    writer.open(out_path, settled.sim.model, config.output.fields);
    std::vector<std::string> cols = {"table_acceleration", "table_velocity", "table_displacement"};
    for (const ControlPoint& p : points) {
      cols.push_back(p.name + "_ux");
      cols.push_back(p.name + "_uy");
    }
    writer.set_control_columns(cols);
  }
  if (!opts.series.empty()) {
    csv = std::make_unique<std::ofstream>(opts.series);
    if (!*csv) throw OutputError(opts.series + ": cannot write the series CSV");
    *csv << "time,table_acceleration,table_velocity,table_displacement,kinetic,external_work,"
            "energy_balance_error";
    for (const ControlPoint& p : points) *csv << "," << p.name << "_ux," << p.name << "_uy";
    *csv << "\n";
    csv->precision(9);
  }
  // Series every 1/10 of the snapshot interval (as `run`); snapshots every output.every.
  const double record_every = std::max(settled.sim.ctx.dt, config.output.every / 10.0);
  double next_snapshot = 0.0;
  auto recorder = [&](const Simulation& sim, const PulseSample& s) {
    if (write_h5) {
      writer.append_series(series_record(sim, s));
      if (s.time >= next_snapshot - 0.5 * sim.ctx.dt) {
        writer.write_snapshot(s.time, sim.model,
                              want_stress ? triangle_stresses(sim) : std::vector<double>{});
        next_snapshot += config.output.every;
      }
    }
    if (csv) {
      *csv << s.time << "," << s.table_acceleration << "," << s.table_velocity << ","
           << s.table_displacement << "," << sim.ledger.kinetic << "," << sim.ledger.external_work
           << "," << sim.ledger.balance_error();
      for (size_t p = 0; p < s.control_ux.size(); ++p)
        *csv << "," << s.control_ux[p] << "," << s.control_uy[p];
      *csv << "\n";
    }
  };
  PulseResult r;
  try {
    // --picture: the final state with its line of thrust (as `run --picture`).
    auto picture = [&](const Simulation& sim) {
      char title[128];
      std::snprintf(title, sizeof title, "end of the pulse run: t = %.4g s, %s %.4g g at %.4g Hz",
                    sim.ctx.time, config.load.base.signal.c_str(), config.load.base.amplitude,
                    config.load.base.frequency);
      draw_current_state(sim, title, opts.picture);
    };
    r = run_pulse(settled, signal, config.load.lambda, points, crit,
                  (write_h5 || csv) ? PulseRecorder(recorder) : PulseRecorder(), record_every,
                  opts.picture.empty() ? std::function<void(const Simulation&)>() : picture);
    if (write_h5) writer.close_complete();
  } catch (const std::exception& e) {
    if (write_h5) writer.close_incomplete(e.what());
    throw;
  }
  r.amplitude_g = config.load.base.amplitude;
  r.frequency = config.load.base.frequency;
  const double wall = std::chrono::duration<double>(Clock::now() - wall0).count();

  const double T = signal.duration();
  std::printf("%s %s: %s (%s at t = %.3f s; signal %.3f s, peak %.4g m/s2)\n",
              config.deck_path.c_str(), config.load.base.signal.c_str(),
              r.collapsed ? "COLLAPSED" : "survived", r.reason.c_str(), r.decided_at, T,
              signal.peak_acceleration());
  std::printf(
      "max kinetic energy %.4g J, max block displacement %.4g m, rotation %.4g rad, "
      "residual %.4g m / %.4g rad\n",
      r.max_kinetic_energy, r.max_displacement, r.max_rotation, r.residual_displacement,
      r.residual_rotation);
  std::printf(
      "energy balance error %.2e (max %.2e, pulse phase %.2e, of peak energy %.4g J); %lld "
      "steps, %.1f s wall (settle %.1f s)\n",
      r.energy_balance_error, r.max_energy_balance_error, r.pulse_energy_balance_error,
      r.peak_energy, r.steps, wall, settled.wall_s);
  for (const ControlSummary& c : r.control)
    std::printf("  %-24s max |ux| %.4g m, |uy| %.4g m, final (%.4g, %.4g) m\n",
                c.point.name.c_str(), c.max_abs_ux, c.max_abs_uy, c.final_ux, c.final_uy);

  if (!common.json_path.empty()) {
    nlohmann::json j = {{"collapsed", r.collapsed},
                        {"reason", r.reason},
                        {"decided_at", r.decided_at},
                        {"signal",
                         {{"kind", config.load.base.signal},
                          {"amplitude_g", config.load.base.amplitude},
                          {"frequency", config.load.base.frequency},
                          {"cycles", config.load.base.cycles},
                          {"duration", T},
                          {"peak_acceleration", signal.peak_acceleration()},
                          {"final_velocity", signal.velocity(T)},
                          {"final_displacement", signal.displacement(T)}}},
                        {"max_kinetic_energy", r.max_kinetic_energy},
                        {"control_points", control_json(r.control)},
                        {"max_displacement", r.max_displacement},
                        {"max_rotation", r.max_rotation},
                        {"residual_displacement", r.residual_displacement},
                        {"residual_rotation", r.residual_rotation},
                        {"energy_balance_error", r.energy_balance_error},
                        {"max_energy_balance_error", r.max_energy_balance_error},
                        {"pulse_energy_balance_error", r.pulse_energy_balance_error},
                        {"peak_energy", r.peak_energy},
                        {"hinges", hinges_to_json(r.hinges)},
                        {"steps", r.steps},
                        {"dt", settled.sim.ctx.dt},
                        {"triangles", settled.sim.model.tris.size()},
                        {"settle_wall_s", settled.wall_s},
                        {"wall_s", wall},
                        {"output", out_path}};
    j["solver"] = solver_json(config, solver_record());
    write_json(j, common.json_path);
  }
  return 0;
}

// The numbers of `v` in %.6g, separated by `sep`.
std::string number_list(const std::vector<double>& v, const char* sep) {
  std::string out;
  char buf[32];
  for (size_t k = 0; k < v.size(); ++k) {
    std::snprintf(buf, sizeof buf, "%.6g", v[k]);
    out += (k ? sep : "") + std::string(buf);
  }
  return out;
}

// The curve CSV (docs/reference/output.md): a row per frequency.
void write_curve_csv(const std::string& csv_path, const std::vector<CurvePoint>& points,
                     const std::vector<std::string>& errors, double lambda_star, double peak_factor,
                     const std::string& search) {
  const double quasi_static = lambda_star / peak_factor;
  std::ofstream csv(csv_path);
  if (!csv) throw OutputError(csv_path + ": cannot write the curve CSV");
  csv << "frequency,amplitude,lo,hi,bracketed,trials,wall_s,max_energy_balance_error,"
         "lambda_star,peak_factor,quasi_static,ratio,search,stable_above,error\n";
  csv.precision(8);
  for (size_t i = 0; i < points.size(); ++i) {
    const CurvePoint& p = points[i];
    csv << p.frequency << "," << p.amplitude << "," << p.lo << "," << p.hi << ","
        << (p.bracketed ? 1 : 0) << "," << p.trials << "," << p.wall_s << ","
        << p.max_energy_balance_error << "," << lambda_star << "," << peak_factor << ","
        << quasi_static << "," << p.amplitude / quasi_static << "," << search << ",\""
        << number_list(p.stable_above, ";") << "\",\"" << errors[i] << "\"\n";
  }
}

// A point of the curve in the JSON summary, with its runs.
nlohmann::json curve_point_summary(const CurvePoint& p, const std::string& error,
                                   double quasi_static) {
  nlohmann::json runs = nlohmann::json::array();
  for (const PulseResult& r : p.runs)
    runs.push_back({{"amplitude", r.amplitude_g},
                    {"collapsed", r.collapsed},
                    {"reason", r.reason},
                    {"decided_at", r.decided_at},
                    {"steps", r.steps},
                    {"wall_s", r.wall_s},
                    {"max_kinetic_energy", r.max_kinetic_energy},
                    {"max_rotation", r.max_rotation},
                    {"residual_rotation", r.residual_rotation},
                    {"energy_balance_error", r.max_energy_balance_error},
                    {"pulse_energy_balance_error", r.pulse_energy_balance_error}});
  nlohmann::json e = {{"frequency", p.frequency},
                      {"amplitude", p.amplitude},
                      {"bracket", {p.lo, p.hi}},
                      {"bracketed", p.bracketed},
                      {"collapses_everywhere", p.collapses_everywhere},
                      {"trials", p.trials},
                      {"wall_s", p.wall_s},
                      {"max_energy_balance_error", p.max_energy_balance_error},
                      {"ratio", p.amplitude / quasi_static},
                      {"stable_above", p.stable_above},
                      {"runs", runs}};
  if (!error.empty()) e["error"] = error;
  return e;
}

int curve_run(const Config& config, const CommonOptions& common, const PulseOptions& opts) {
  const auto wall0 = Clock::now();
  if (config.load.base.signal != "windowed_sine" && config.load.base.signal != "sine_pulse")
    throw DeckError(config.deck_path + ": load.base.signal = \"" + config.load.base.signal +
                    "\": pulse --curve needs an analytic pulse (windowed_sine or sine_pulse)");
  const PulseCriteria crit = pulse_criteria(common.limits, opts.free_time);

  const bool quiet = common.quiet || !is_dealer_rank();
  const std::optional<TiltingCapacity> capacity =
      study_capacity(config, crit.settle, opts.lambda_star, opts.points, opts.resume, quiet);
  if (!capacity) return 1;
  const double lambda_star = capacity->lambda_star;
  const double capacity_wall = capacity->wall_s;
  // Peak of the unit-amplitude pulse (0.891 for the 3-cycle windowed sine, 1 for one sine):
  // the quasi-static limit of the curve is A = lambda* / peak_factor.
  const double peak_factor = make_base_signal(config.load.base, 1.0, 1.0, 1.0).peak_acceleration();
  const double quasi_static = lambda_star / peak_factor;
  AmplitudeSearchOptions search;
  search.search = opts.search == "bisect" ? AmplitudeSearch::Bisect : AmplitudeSearch::Step;
  search.start = opts.start_given                           ? opts.start
                 : search.search == AmplitudeSearch::Bisect ? std::max(lambda_star, 0.01)
                                                            : std::max(quasi_static, 0.01);
  search.step = opts.step;
  search.steps_above = opts.steps_above;
  search.tolerance = opts.tolerance;

  const SettledState settled = settle(config, crit.settle, quiet);
  if (!settled.settled) throw RunError(unsettled_message(settled, crit.settle));
  // Resume: every run of the curve in a journal (commands/pulse.hpp find_collapse_amplitude),
  // kept by rank 0.
  Journal journal(is_dealer_rank() ? opts.resume : std::string(),
                  pulse_fingerprint(settled, config.load.base, crit));
  Journal* runs_journal = opts.resume.empty() ? nullptr : &journal;

  // The costliest frequencies first for the dynamic schedule: for the bisection the lowest (the
  // longest pulses), for the stepping search the highest (the most steps from the quasi-static
  // start: 51 runs at 12 Hz against 6 at 2 Hz on scaled_arch). The order changes no result.
  const std::vector<double>& freqs = opts.freqs;
  std::vector<std::size_t> order(freqs.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  const bool highest_first = search.search == AmplitudeSearch::Step;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return highest_first ? freqs[a] > freqs[b] : freqs[a] < freqs[b];
  });
  std::vector<SearchCell> cells(freqs.size());
  for (std::size_t i = 0; i < freqs.size(); ++i) {
    cells[i].base = config.load.base;
    cells[i].frequency = freqs[i];
    cells[i].search = search;
  }
  const std::vector<SearchOutcome> outcomes = deal_searches(
      settled, cells, order, crit, common.threads, quiet, runs_journal,
      [&](std::size_t i, const SearchOutcome& out) {
        if (!quiet)
          std::fprintf(stderr, "f = %.3f Hz: A = %.4f g (%d trials, %.1f s wall)%s%s\n", freqs[i],
                       out.point.amplitude, out.point.trials, out.point.wall_s,
                       out.error.empty() ? "" : " error: ", out.error.c_str());
      });
  if (!is_dealer_rank()) return 0;  // rank 0 writes the outputs (engine/dealer.hpp)
  std::vector<CurvePoint> points;
  std::vector<std::string> errors;
  for (const SearchOutcome& out : outcomes) {
    points.push_back(out.point);
    errors.push_back(out.error);
  }
  const double wall = std::chrono::duration<double>(Clock::now() - wall0).count();

  const std::string csv_path = opts.csv.empty() ? "curve.csv" : opts.csv;
  write_curve_csv(csv_path, points, errors, lambda_star, peak_factor, opts.search);
  std::printf("lambda* = %.4f (tilting capacity%s)", lambda_star,
              opts.lambda_star < 0.0 ? ", computed" : ", given");
  if (opts.tilt_reference_given)
    std::printf(" against %.4g measured: %+.1f%%", opts.tilt_reference,
                100.0 * (lambda_star / opts.tilt_reference - 1.0));
  std::printf("\nquasi-static limit A_qs = lambda* / %.4f = %.4f g; search: %s", peak_factor,
              quasi_static, opts.search.c_str());
  if (search.search == AmplitudeSearch::Step)
    std::printf(" from %.4f g in steps of %g%%, %d step(s) past the first collapse", search.start,
                100.0 * search.step, search.steps_above);
  std::printf("\n%10s %12s %8s %22s %7s %9s %10s\n", "f [Hz]", "A_c [g]", "A_c/A_qs", "bracket [g]",
              "trials", "wall [s]", "max err");
  for (const CurvePoint& p : points) {
    std::printf("%10.3f %12.5f %8.3f   [%8.5f, %8.5f] %7d %9.1f %10.2e%s\n", p.frequency,
                p.amplitude, p.amplitude / quasi_static, p.lo, p.hi, p.trials, p.wall_s,
                p.max_energy_balance_error, point_note(p).c_str());
    if (!p.stable_above.empty())
      std::printf("%10s survived above A_c (non-monotone) at %s g\n", "",
                  number_list(p.stable_above, ", ").c_str());
  }
  double worst = 0.0;
  for (const CurvePoint& p : points) worst = std::max(worst, p.max_energy_balance_error);
  std::printf("largest energy balance error of any run %.2e; curve %s; %.1f s wall in all\n", worst,
              csv_path.c_str(), wall);
  if (!opts.plot.empty()) {
    draw_with_script("plot_curve", {csv_path, "-o", opts.plot}, opts.plot);
  }

  if (!common.json_path.empty()) {
    nlohmann::json curve = nlohmann::json::array();
    for (size_t i = 0; i < points.size(); ++i) {
      curve.push_back(curve_point_summary(points[i], errors[i], quasi_static));
    }
    nlohmann::json j = {
        {"curve", curve},
        {"lambda_star", lambda_star},
        {"peak_factor", peak_factor},
        {"quasi_static", quasi_static},
        {"lambda_star_computed", opts.lambda_star < 0.0},
        {"search",
         {{"kind", opts.search},
          {"start", search.start},
          {"step", search.search == AmplitudeSearch::Step ? search.step : kBracketGrowth - 1.0},
          {"steps_above", search.search == AmplitudeSearch::Step ? search.steps_above : 0}}},
        {"capacity_wall_s", capacity_wall},
        {"signal", config.load.base.signal},
        {"cycles", config.load.base.cycles},
        {"tolerance", opts.tolerance},
        {"dt", settled.sim.ctx.dt},
        {"triangles", settled.sim.model.tris.size()},
        {"csv", csv_path},
        {"ranks", rank_count()},
        {"wall_s", wall}};
    if (opts.tilt_reference_given) j["tilt_reference"] = opts.tilt_reference;
    j["solver"] = solver_json(config, solver_record());
    write_json(j, common.json_path);
  }
  for (const std::string& e : errors)
    if (!e.empty()) return 1;
  return 0;
}

}  // namespace

int command_pulse(const Config& config, const CommonOptions& common, const PulseOptions& opts) {
  validate_pulse_options(opts);
  if (opts.curve && !opts.picture.empty())
    throw DeckError(
        "--picture draws a single pulse run's final state: not with --curve (the "
        "curve's picture is --plot)");
  if (opts.spectrum.empty() && (opts.spectrum_only || !opts.spectrum_plot.empty()))
    throw DeckError(std::string(opts.spectrum_only ? "--spectrum-only" : "--spectrum-plot") +
                    " needs --spectrum FILE.csv");
  if (!opts.spectrum.empty()) write_spectrum(config, opts);
  if (opts.spectrum_only) return 0;
  return opts.curve ? curve_run(config, common, opts) : single_run(config, common, opts);
}

// The options of `pulse` (docs/reference/commands.md).
CommandAction add_pulse_command(CLI::App& cmd, CommandLine& line) {
  auto opts = std::make_shared<PulseOptions>();
  PulseOptions& o = *opts;
  CLI::App* cmd_ptr = &cmd;
  add_common(cmd, line);
  add_limit_options(&cmd, line.common.limits);
  cmd.add_option("-o,--output", o.output, "HDF5 output file (overrides output.file)");
  cmd.add_option("--picture", o.picture,
                 "picture (PNG/SVG) of the single run's final state with its line of thrust");
  cmd.add_option("--series", o.series,
                 "CSV time series of the run (input, energy, control points)");
  cmd.add_flag("--curve", o.curve,
               "failure curve: the collapse amplitude per frequency (--search)");
  cmd.add_option("--freqs", o.freqs, "curve frequencies F1,F2,... [Hz]")->delimiter(',');
  cmd.add_option("--csv", o.csv, "curve CSV (default curve.csv)");
  cmd.add_option("--plot", o.plot, "curve PNG (scripts/plot_curve)");
  cmd.add_option("--lambda-star", o.lambda_star,
                 "tilting capacity to draw (skips the capacity search)");
  cmd.add_option("--tolerance", o.tolerance,
                 "relative bracket width of the amplitude (default 0.02)");
  cmd.add_option("--points", o.points, "capacity trials per round (default 2)")
      ->check(CLI::Range(1, 64));
  cmd.add_option("--search", o.search,
                 "curve amplitude search: step (raise A step by step, then bisect the first "
                 "collapsing step; default) or bisect (grow by 1.5, then bisect)");
  cmd.add_option("--start", o.start,
                 "first amplitude of the curve search [g] (default lambda*/peak factor; "
                 "bisect: lambda*)");
  cmd.add_option("--step", o.step,
                 "relative amplitude step of --search step (default 0.05: 5% a step)");
  cmd.add_option("--steps-above", o.steps_above,
                 "steps run past the first collapse, to find survivals above it (default 2)");
  cmd.add_option("--resume", o.resume,
                 "curve: journal of finished runs (and FILE.capacity of the tilting "
                 "capacity): created, or resumed after a kill");
  cmd.add_option("--free-time", o.free_time,
                 "free motion after the signal before an undecided run is classified by its "
                 "trend [s] (default 1.5)");
  cmd.add_option("--tilt-reference", o.tilt_reference,
                 "a measured tilting capacity to report lambda* against");
  cmd.add_option("--spectrum", o.spectrum,
                 "CSV of the 5%-damped pseudo-acceleration spectrum of the base signal "
                 "(period,sa_g; docs/records.md), written before the run");
  cmd.add_option("--spectrum-plot", o.spectrum_plot,
                 "PNG of that spectrum (scripts/plot_spectrum; needs --spectrum)");
  cmd.add_flag("--spectrum-only", o.spectrum_only, "write the spectrum and stop (no simulation)");
  CommandAction action;
  action.run = [&line, opts, cmd_ptr] {
    const Config config = load_command_deck(line);
    require_gravity(config, "pulse");
    opts->start_given = cmd_ptr->count("--start") > 0;
    opts->lambda_star_given = cmd_ptr->count("--lambda-star") > 0;
    opts->tilt_reference_given = cmd_ptr->count("--tilt-reference") > 0;
    return command_pulse(config, line.common, *opts);
  };
  action.dealt = [opts] { return opts->curve; };
  return action;
}

}  // namespace voussoir

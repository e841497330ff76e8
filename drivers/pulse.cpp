// Base-excitation runs and the failure curve (criteria and decisions in pulse.hpp).

#include "drivers/pulse.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>

#include "core/fnv.hpp"
#include "core/rigid.hpp"
#include "drivers/bracket.hpp"
#include "drivers/dealer.hpp"
#include "drivers/motion.hpp"
#include "drivers/run.hpp"
#include "drivers/setup.hpp"
#include "drivers/trial.hpp"
#include "io/accelerogram.hpp"

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
                      const std::function<void(const Simulation&)>& at_end) {
  const auto wall0 = Clock::now();
  Simulation sim = settled.sim;  // deep copy
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
  // Largest imbalance over the run relative to the run's peak energy (SPEC: "below 1% of the
  // peak energy"). Not the largest of balance_error() over time: early in a run that divides
  // by the small energies of the settled state, and round-off-sized imbalances then read as
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

CurvePoint find_collapse_amplitude(const SettledState& settled, const BaseConfig& base,
                                   double frequency, const AmplitudeSearchOptions& search,
                                   const PulseCriteria& crit, bool quiet, Journal* journal,
                                   const SearchKey& key) {
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
  auto trial = [&](double a) {
    PulseResult r;
    const bool resumed = journal && from_journal(a, r);
    if (!resumed) {
      const BaseSignal signal = make_base_signal(base, a, frequency, settled.gravity);
      r = run_pulse(settled, signal, 0.0, points, crit);
      r.amplitude_g = a;
      r.frequency = frequency;
      r.control.clear();  // not needed per trial
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
  double lo = 0.0, hi = 0.0;
  bool have_hi = false, have_lo = false;
  double a = search.start;
  if (trial(a)) {
    hi = a, have_hi = true;
    while (!have_lo && a > kMinAmplitude) {
      a /= growth;
      if (trial(a)) {
        hi = a;
      } else {
        lo = a, have_lo = true;
      }
    }
  } else {
    lo = a, have_lo = true;
    while (!have_hi && a * growth <= kMaxAmplitude) {
      a *= growth;
      if (trial(a)) {
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
  if (have_hi && have_lo) {  // bisection (drivers/bracket.hpp)
    Bracket b{lo, hi};
    shrink_bracket(
        b, search.tolerance, 1, ProbePlacement::Midpoint,
        [&](const std::vector<double>& amplitudes) {
          return std::vector<bool>{trial(amplitudes[0])};
        },
        [](const Bracket&) {});
    lo = b.lo;
    hi = b.hi;
  }
  // Stepping: the steps above the first collapse (non-monotone check; A_c stays hi).
  if (stepping && have_hi && have_lo) {
    double above = first_collapse;
    for (int k = 0; k < search.steps_above && above * growth <= kMaxAmplitude; ++k) {
      above *= growth;
      trial(above);
    }
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
      CapacitySearch capacity_search;
      capacity_search.points = points;
      capacity_search.quiet = quiet;
      if (!resume.empty()) capacity_search.journal = resume + ".capacity";
      const CapacityResult cap = find_capacity(config, settle, capacity_search);
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
  work.run = [&](std::size_t k, const nlohmann::json& given) {
    const SearchCell& cell = cells[order[k]];
    Journal share(given.is_array() ? given.get<std::vector<nlohmann::json>>()
                                   : std::vector<nlohmann::json>());
    CurvePoint p;
    std::string error;
    try {
      // Under mpirun the progress is a line per search, printed by rank 0 as it arrives.
      p = find_collapse_amplitude(settled, cell.base, cell.frequency, cell.search, crit,
                                  quiet || rank_count() > 1, spread ? &share : journal, cell.key);
    } catch (const std::exception& e) {
      error = e.what();
      p.frequency = cell.frequency;
    }
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
  if (opts.start_given && !(opts.start > 0.0 && std::isfinite(opts.start)))
    throw DeckError("pulse --start " + option_number(opts.start) +
                    " g is not allowed: the first amplitude must be a positive number of g");
  if (!(opts.step > 0.0 && std::isfinite(opts.step)))
    throw DeckError("pulse --step " + option_number(opts.step) +
                    " is not allowed: the relative amplitude step must be positive (0.05: each "
                    "step 5% above the last)");
  if (opts.steps_above < 0)
    throw DeckError("pulse --steps-above " + std::to_string(opts.steps_above) +
                    " is not allowed: the number of steps past the first collapse must be 0 or "
                    "more");
  if (!(opts.tolerance > 0.0 && opts.tolerance < 1.0))
    throw DeckError("pulse --tolerance " + option_number(opts.tolerance) +
                    " is not allowed: the relative bracket width must lie in (0, 1)");
  if (opts.tilt_reference_given &&
      !(opts.tilt_reference > 0.0 && std::isfinite(opts.tilt_reference)))
    throw DeckError("pulse --tilt-reference " + option_number(opts.tilt_reference) +
                    " is not allowed: a measured tilting capacity must be a positive number");
}

}  // namespace voussoir

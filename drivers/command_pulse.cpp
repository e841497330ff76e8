// `voussoir pulse DECK`: one base-excitation run (JSON, optional HDF5 and CSV series), or with
// --curve the amplitude-frequency failure curve (CSV, plot, JSON). Criteria in pulse.hpp.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "core/spectrum.hpp"
#include "drivers/solver_report.hpp"
#include "drivers/commands.hpp"
#include "drivers/dealer.hpp"
#include "drivers/plot.hpp"
#include "drivers/pulse.hpp"
#include "drivers/run.hpp"
#include "drivers/setup.hpp"
#include "io/accelerogram.hpp"
#include "io/deck.hpp"
#include "io/hdf5_output.hpp"
#include "io/json.hpp"

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
  const EnergyLedger& l = sim.ledger;
  SeriesRecord r;
  r.time = s.time;
  r.kinetic = l.kinetic;
  r.strain = l.strain;
  r.contact = l.contact;
  r.damping_dissipated = l.damping_dissipated + l.impact_dissipated;  // io/hdf5_output.hpp
  r.friction_dissipated = l.friction_dissipated;
  r.external_work = l.external_work;
  r.max_displacement = max_free_displacement(sim.model);
  r.active_contacts = sim.contact.active_pairs();
  r.energy_balance_error = l.balance_error();
  r.control_displacements = {s.table_acceleration, s.table_velocity, s.table_displacement};
  for (size_t p = 0; p < s.control_ux.size(); ++p) {
    r.control_displacements.push_back(s.control_ux[p]);
    r.control_displacements.push_back(s.control_uy[p]);
  }
  return r;
}

// --spectrum: the 5%-damped pseudo-acceleration spectrum (core/spectrum.hpp) of the signal the
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
  // Resume: every run of the curve in a journal (drivers/pulse.hpp find_collapse_amplitude),
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
  if (!is_dealer_rank()) return 0;  // rank 0 writes the outputs (drivers/dealer.hpp)
  std::vector<CurvePoint> points;
  std::vector<std::string> errors;
  for (const SearchOutcome& out : outcomes) {
    points.push_back(out.point);
    errors.push_back(out.error);
  }
  const double wall = std::chrono::duration<double>(Clock::now() - wall0).count();

  auto list_of = [](const std::vector<double>& v, const char* sep) {
    std::string out;
    char buf[32];
    for (size_t k = 0; k < v.size(); ++k) {
      std::snprintf(buf, sizeof buf, "%.6g", v[k]);
      out += (k ? sep : "") + std::string(buf);
    }
    return out;
  };
  const std::string csv_path = opts.csv.empty() ? "curve.csv" : opts.csv;
  {
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
          << quasi_static << "," << p.amplitude / quasi_static << "," << opts.search << ",\""
          << list_of(p.stable_above, ";") << "\",\"" << errors[i] << "\"\n";
    }
  }
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
                  list_of(p.stable_above, ", ").c_str());
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
      const CurvePoint& p = points[i];
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
      if (!errors[i].empty()) e["error"] = errors[i];
      curve.push_back(e);
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

}  // namespace voussoir

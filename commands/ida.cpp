// `voussoir ida`: incremental dynamic analysis and the fragility of collapse (ida.hpp).

#include "commands/ida.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands/pulse.hpp"
#include "core/fnv.hpp"
#include "engine/bracket.hpp"
#include "engine/dealer.hpp"
#include "engine/run_loop.hpp"
#include "engine/solver_report.hpp"
#include "io/json.hpp"
#include "io/plot.hpp"
#include "seismic/accelerogram.hpp"
#include "seismic/fragility.hpp"
#include "seismic/spectrum.hpp"

namespace voussoir {

namespace {

using Clock = std::chrono::steady_clock;

// A record of the study: its signal as the runs use it and what the search needs of it.
struct Record {
  std::string file;    // as given on the command line
  BaseConfig base;     // the deck's [load.base] with this file
  double pga = 0.0;    // [g] of the record as read and processed (amplitude 0)
  double ratio = 1.0;  // IM / PGA (header comment)
  std::string hash;    // of the file's bytes (core/fnv.hpp)
};

Record read_record(const Config& config, const std::string& file, const IdaOptions& opts) {
  Record r;
  r.file = file;
  r.base = config.load.base;
  r.base.signal = "file";
  r.base.file = std::filesystem::absolute(file).string();
  if (config.load.base.signal != "file") r.base.units = "g";
  r.base.amplitude = 0.0;
  const double g = config.load.gravity;
  // Reads and checks the file (DeckError naming the file and the line).
  const BaseSignal as_read = make_base_signal(r.base, 0.0, 0.0, g);
  r.pga = as_read.peak_acceleration() / g;
  if (!(r.pga > 0.0))
    throw DeckError(file + ": --records: the record's accelerations are all zero");
  // Sa(T) / PGA of the record as read: a scaled record scales both alike.
  if (opts.im == "sa")
    r.ratio =
        response_spectrum(as_read.samples(), as_read.sample_dt(), {opts.period})[0] / (r.pga * g);
  std::ifstream in(file, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Fnv f;
  f.text(bytes);
  r.hash = f.hex();
  return r;
}

std::string list_of(const std::vector<double>& v, const char* sep) {
  std::string out;
  char buf[32];
  for (std::size_t k = 0; k < v.size(); ++k) {
    std::snprintf(buf, sizeof buf, "%.6g", v[k]);
    out += (k ? sep : "") + std::string(buf);
  }
  return out;
}

// [lo, hi] of the median's interval; an unbounded end (+infinity) is null, and so is the
// interval when no resample was drawn.
nlohmann::json median_ci_json(const MedianInterval& ci) {
  if (ci.resamples == 0) return nullptr;
  auto end = [](double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
  };
  return {end(ci.lo), end(ci.hi)};
}

std::vector<double> scaled(const std::vector<double>& v, double by) {
  std::vector<double> out;
  for (double x : v) out.push_back(x * by);
  return out;
}

}  // namespace

std::string ida_runs_csv(const std::string& csv) {
  const std::filesystem::path p(csv);
  return (p.parent_path() / (p.stem().string() + "_runs.csv")).string();
}

void validate_ida_options(const IdaOptions& opts) {
  if (opts.records.empty())
    throw DeckError("ida needs --records F1,F2,... (PEER .AT2 or two-column files)");
  check_lambda_star_option("ida", opts.lambda_star_given, opts.lambda_star);
  if (opts.im != "pga" && opts.im != "sa")
    throw DeckError("ida --im \"" + opts.im +
                    "\" is not allowed: use \"pga\" (peak ground acceleration) or \"sa\" "
                    "(5%-damped spectral acceleration at --period T)");
  if (opts.im == "sa" && !opts.period_given)
    throw DeckError("ida --im sa needs --period T (s): the period of Sa(T)");
  if (opts.period_given && !(opts.period > 0.0 && std::isfinite(opts.period)))
    throw DeckError("ida --period " + option_number(opts.period) +
                    " s is not allowed: the period must be a positive number of seconds");
  if (opts.period_given && opts.im != "sa") throw DeckError("ida --period applies to --im sa only");
  check_stepping_options("ida", "intensity", "0.1: each step 10% above the last", opts.start_given,
                         opts.start, opts.step, opts.steps_above, opts.tolerance);
  if (!(opts.free_time > 0.0 && std::isfinite(opts.free_time)))
    throw DeckError("ida --free-time " + option_number(opts.free_time) +
                    " s is not allowed: the free motion after the record must be a positive time");
  if (opts.bootstrap < 1)
    throw DeckError("ida --bootstrap " + std::to_string(opts.bootstrap) +
                    " is not allowed: the number of resamples must be 1 or more");
  if (!(opts.confidence > 0.0 && opts.confidence < 1.0))
    throw DeckError("ida --confidence " + option_number(opts.confidence) +
                    " is not allowed: the confidence level must lie in (0, 1)");
  if (opts.seed < 0)
    throw DeckError("ida --seed " + std::to_string(opts.seed) +
                    " is not allowed: the seed must be 0 or more");
  if (opts.csv.empty()) throw DeckError("ida --csv needs a file name");
}

namespace {

// The search of each record: in PGA, stepping up from --start (in the IM) or lambda* g.
std::vector<SearchCell> ida_cells(const std::vector<Record>& records, const IdaOptions& opts,
                                  double lambda_star) {
  std::vector<SearchCell> cells(records.size());
  for (std::size_t i = 0; i < records.size(); ++i) {
    const Record& r = records[i];
    SearchCell& c = cells[i];
    c.base = r.base;
    c.search.search = AmplitudeSearch::Step;
    c.search.start = opts.start_given ? opts.start / r.ratio : std::max(lambda_star, 0.01);
    c.search.step = opts.step;
    c.search.steps_above = opts.steps_above;
    c.search.tolerance = opts.tolerance;
    c.key.fields = {{"record", r.file}, {"record_hash", r.hash}};
    c.key.label = std::filesystem::path(r.file).filename().string();
  }
  return cells;
}

// The CSV of the records (a line per record, intensities in the IM) and the CSV of every run.
void write_ida_csvs(const std::string& csv_path, const std::string& runs_csv,
                    const std::vector<Record>& records,
                    const std::vector<SearchOutcome>& outcomes) {
  {
    std::ofstream csv(csv_path);
    if (!csv) throw OutputError(csv_path + ": cannot write the IDA CSV");
    csv.precision(8);
    csv << "record,pga_g,im_per_pga,collapse_im,lo,hi,collapse_pga,bracketed,trials,wall_s,"
           "max_energy_balance_error,stable_above,error\n";
    for (std::size_t i = 0; i < records.size(); ++i) {
      const CurvePoint& p = outcomes[i].point;
      const double r = records[i].ratio;
      csv << records[i].file << "," << records[i].pga << "," << r << "," << p.amplitude * r << ","
          << p.lo * r << "," << p.hi * r << "," << p.amplitude << "," << (p.bracketed ? 1 : 0)
          << "," << p.trials << "," << p.wall_s << "," << p.max_energy_balance_error << ",\""
          << list_of(scaled(p.stable_above, r), ";") << "\",\"" << outcomes[i].error << "\"\n";
    }
    if (!csv.flush()) throw OutputError(csv_path + ": cannot write the IDA CSV");
  }
  {
    std::ofstream csv(runs_csv);
    if (!csv) throw OutputError(runs_csv + ": cannot write the IDA runs CSV");
    csv.precision(8);
    csv << "record,scale,pga_g,im,collapsed,reason,decided_at,max_rotation,max_displacement,"
           "residual_rotation,residual_displacement,wall_s\n";
    for (std::size_t i = 0; i < records.size(); ++i) {
      std::vector<PulseResult> runs = outcomes[i].point.runs;
      std::sort(runs.begin(), runs.end(), [](const PulseResult& a, const PulseResult& b) {
        return a.amplitude_g < b.amplitude_g;
      });
      for (const PulseResult& run : runs)
        csv << records[i].file << "," << run.amplitude_g / records[i].pga << "," << run.amplitude_g
            << "," << run.amplitude_g * records[i].ratio << "," << (run.collapsed ? 1 : 0) << ","
            << run.reason << "," << run.decided_at << "," << run.max_rotation << ","
            << run.max_displacement << "," << run.residual_rotation << ","
            << run.residual_displacement << "," << run.wall_s << "\n";
    }
    if (!csv.flush()) throw OutputError(runs_csv + ": cannot write the IDA runs CSV");
  }
}

// A record of the JSON summary (docs/reference/output.md, ida), with its runs.
nlohmann::json ida_record_summary(const Record& record, const SearchOutcome& outcome) {
  const CurvePoint& p = outcome.point;
  const double r = record.ratio;
  nlohmann::json runs = nlohmann::json::array();
  for (const PulseResult& run : p.runs)
    runs.push_back({{"im", run.amplitude_g * r},
                    {"pga", run.amplitude_g},
                    {"collapsed", run.collapsed},
                    {"reason", run.reason},
                    {"max_rotation", run.max_rotation},
                    {"wall_s", run.wall_s}});
  nlohmann::json e = {{"file", record.file},
                      {"pga", record.pga},
                      {"im_per_pga", r},
                      {"collapse_im", p.amplitude * r},
                      {"bracket", {p.lo * r, p.hi * r}},
                      {"bracketed", p.bracketed},
                      {"collapses_everywhere", p.collapses_everywhere},
                      {"trials", p.trials},
                      {"wall_s", p.wall_s},
                      {"max_energy_balance_error", p.max_energy_balance_error},
                      {"stable_above", scaled(p.stable_above, r)},
                      {"runs", runs}};
  if (!outcome.error.empty()) e["error"] = outcome.error;
  return e;
}

}  // namespace

int command_ida(const Config& config, const CommonOptions& common, const IdaOptions& opts) {
  validate_ida_options(opts);
  const auto wall0 = Clock::now();
  // Every rank reads and checks every record before any run (exit 2 on a bad one).
  std::vector<Record> records;
  for (const std::string& file : opts.records) records.push_back(read_record(config, file, opts));

  const PulseCriteria crit = pulse_criteria(common.limits, opts.free_time);
  const bool quiet = common.quiet || !is_dealer_rank();
  const std::optional<TiltingCapacity> capacity =
      study_capacity(config, crit.settle, opts.lambda_star, opts.points, opts.resume, quiet);
  if (!capacity) return 1;
  const double lambda_star = capacity->lambda_star;

  const SettledState settled = settle(config, crit.settle, quiet);
  if (!settled.settled) throw RunError(unsettled_message(settled, crit.settle));
  // The journal's fingerprint: what a run of a record at a PGA depends on besides the record.
  Fnv f;
  f.text("ida");
  f.text(pulse_fingerprint(settled, config.load.base, crit));
  f.text(config.load.base.baseline);
  f.text(config.load.base.signal == "file" ? config.load.base.units : "g");
  Journal journal(is_dealer_rank() ? opts.resume : std::string(), f.hex());
  Journal* runs_journal = opts.resume.empty() ? nullptr : &journal;

  const std::vector<SearchCell> cells = ida_cells(records, opts, lambda_star);
  std::vector<std::size_t> order(records.size());
  for (std::size_t i = 0; i < records.size(); ++i) order[i] = i;
  const char* unit = opts.im == "pga" ? "PGA" : "Sa";
  if (!quiet)
    std::fprintf(stderr, "%zu records, searched in PGA from %s\n", records.size(),
                 opts.start_given ? "--start" : "lambda* g");
  std::size_t finished = 0;
  const std::vector<SearchOutcome> outcomes = deal_searches(
      settled, cells, order, crit, common.threads, quiet, runs_journal,
      [&](std::size_t i, const SearchOutcome& out) {
        ++finished;
        if (!quiet)
          std::fprintf(stderr,
                       "[%zu/%zu] %s: collapse at %s = %.4f g (%d trials, %.1f s wall)%s%s\n",
                       finished, records.size(), cells[i].key.label.c_str(), unit,
                       out.point.amplitude * records[i].ratio, out.point.trials, out.point.wall_s,
                       out.error.empty() ? "" : " error: ", out.error.c_str());
      });
  if (!is_dealer_rank()) return 0;  // rank 0 writes the outputs (engine/dealer.hpp)

  // The fit: a collapse intensity per record, censored where the search found none.
  std::vector<IntensitySample> samples;
  for (std::size_t i = 0; i < records.size(); ++i) {
    const SearchOutcome& out = outcomes[i];
    if (!out.error.empty()) continue;
    samples.push_back({out.point.amplitude * records[i].ratio, !out.point.bracketed,
                       out.point.collapses_everywhere});
  }
  const LognormalFit fit = fit_lognormal(samples);
  const MedianInterval ci =
      fit.ok ? bootstrap_median(samples, opts.bootstrap, static_cast<std::uint64_t>(opts.seed),
                                opts.confidence)
             : MedianInterval{};
  const double wall = std::chrono::duration<double>(Clock::now() - wall0).count();

  const std::string runs_csv = ida_runs_csv(opts.csv);
  write_ida_csvs(opts.csv, runs_csv, records, outcomes);

  const std::string im_name =
      opts.im == "pga" ? std::string("PGA") : "Sa(" + option_number(opts.period) + " s)";
  std::printf("lambda* = %.4f (tilting capacity%s); intensity measure %s%s\n", lambda_star,
              capacity->computed ? ", computed" : ", given", im_name.c_str(),
              opts.im == "sa" ? " (5% damping)" : "");
  std::printf("%-28s %9s %10s %22s %7s %9s\n", "record", "PGA [g]", "IM_c [g]", "bracket [g]",
              "trials", "wall [s]");
  for (std::size_t i = 0; i < records.size(); ++i) {
    const CurvePoint& p = outcomes[i].point;
    const double r = records[i].ratio;
    std::printf("%-28s %9.4f %10.4f   [%8.4f, %8.4f] %7d %9.1f%s%s\n", cells[i].key.label.c_str(),
                records[i].pga, p.amplitude * r, p.lo * r, p.hi * r, p.trials, p.wall_s,
                point_note(p, r).c_str(),
                outcomes[i].error.empty() ? "" : ("  error: " + outcomes[i].error).c_str());
    if (!p.stable_above.empty())
      std::printf("%28s survived above IM_c at %s g\n", "",
                  list_of(scaled(p.stable_above, r), ", ").c_str());
  }
  if (fit.ok)
    std::printf(
        "fragility: median %s = %.4f g, beta = %.3f (%d records, %d censored); "
        "%.0f%% interval of the median [%.4f, %.4f] g (%d bootstrap resamples)\n",
        im_name.c_str(), fit.median, fit.beta, fit.samples, fit.censored, 100.0 * opts.confidence,
        ci.lo, ci.hi, ci.resamples);
  else
    std::printf("fragility: not fitted: %s\n", fit.why.c_str());
  std::printf("records %s, runs %s; %.1f s wall in all\n", opts.csv.c_str(), runs_csv.c_str(),
              wall);
  if (!opts.plot.empty()) {
    std::vector<std::string> args = {opts.csv, runs_csv, "-o", opts.plot, "--im", im_name};
    if (fit.ok)
      for (const std::string& a : {std::string("--median"), option_number(fit.median),
                                   std::string("--beta"), option_number(fit.beta),
                                   std::string("--ci"), option_number(ci.lo), option_number(ci.hi)})
        args.push_back(a);
    draw_with_script("plot_ida", args, opts.plot);
  }

  if (!common.json_path.empty()) {
    nlohmann::json recs = nlohmann::json::array();
    for (std::size_t i = 0; i < records.size(); ++i) {
      recs.push_back(ida_record_summary(records[i], outcomes[i]));
    }
    nlohmann::json fragility = nullptr;
    if (fit.ok)
      fragility = {{"median", fit.median},
                   {"beta", fit.beta},
                   {"median_ci", median_ci_json(ci)},
                   {"confidence", opts.confidence},
                   {"bootstrap", ci.resamples},
                   {"records", fit.samples},
                   {"censored", fit.censored}};
    nlohmann::json j = {{"im", opts.im},
                        {"period", opts.im == "sa" ? opts.period : 0.0},
                        {"damping", kCodeDamping},
                        {"records", recs},
                        {"fragility", fragility},
                        {"lambda_star", lambda_star},
                        {"lambda_star_computed", capacity->computed},
                        {"capacity_wall_s", capacity->wall_s},
                        {"search",
                         {{"start", opts.start_given ? opts.start : lambda_star},
                          {"step", opts.step},
                          {"steps_above", opts.steps_above},
                          {"tolerance", opts.tolerance}}},
                        {"dt", settled.sim.ctx.dt},
                        {"csv", opts.csv},
                        {"runs_csv", runs_csv},
                        {"ranks", rank_count()},
                        {"wall_s", wall}};
    if (!fit.ok) j["fragility_missing"] = fit.why;
    j["solver"] = solver_json(config, solver_record());
    write_json(j, common.json_path);
  }
  for (const SearchOutcome& out : outcomes)
    if (!out.error.empty()) return 1;
  return 0;
}

// The options of `ida` (docs/reference/commands.md).
CommandAction add_ida_command(CLI::App& cmd, CommandLine& line) {
  auto opts = std::make_shared<IdaOptions>();
  IdaOptions& o = *opts;
  CLI::App* cmd_ptr = &cmd;
  add_common(cmd, line);
  add_limit_options(&cmd, line.common.limits);
  cmd.add_option("--records", o.records,
                 "ground-motion records F1,F2,... (PEER .AT2 or two-column; docs/records.md)")
      ->delimiter(',');
  cmd.add_option("--im", o.im, "intensity measure: pga (default) or sa (5%-damped Sa at --period)");
  cmd.add_option("--period", o.period, "period T of Sa(T) [s] (with --im sa)");
  cmd.add_option("--lambda-star", o.lambda_star,
                 "tilting capacity to start from (skips the capacity search)");
  cmd.add_option("--points", o.points, "capacity trials per round (default 2)")
      ->check(CLI::Range(1, 64));
  cmd.add_option("--start", o.start, "first intensity [g of the IM] (default: lambda* in PGA)");
  cmd.add_option("--step", o.step,
                 "relative intensity step (default 0.1: each run 10% above the last)");
  cmd.add_option("--steps-above", o.steps_above,
                 "runs past the first collapse, looking for survivals (default 2)");
  cmd.add_option("--tolerance", o.tolerance,
                 "relative bracket width of the bisection (default 0.05)");
  cmd.add_option("--free-time", o.free_time,
                 "free motion after the record before a timeout decision [s] (default 1.5)");
  cmd.add_option("--bootstrap", o.bootstrap,
                 "bootstrap resamples for the median's interval (default 1000)");
  cmd.add_option("--confidence", o.confidence,
                 "confidence level of the median's interval (default 0.95)");
  cmd.add_option("--seed", o.seed, "seed of the bootstrap (default 1)");
  cmd.add_option("--csv", o.csv,
                 "a line per record (default ida.csv); the runs go to its stem + _runs.csv");
  cmd.add_option("--plot", o.plot, "PNG of the IDA points and the fragility (scripts/plot_ida)");
  cmd.add_option("--resume", o.resume, "journal of the runs: created, or resumed after a kill");
  CommandAction action;
  action.run = [&line, opts, cmd_ptr] {
    const Config config = load_command_deck(line);
    require_gravity(config, "ida");
    opts->period_given = cmd_ptr->count("--period") > 0;
    opts->start_given = cmd_ptr->count("--start") > 0;
    opts->lambda_star_given = cmd_ptr->count("--lambda-star") > 0;
    return command_ida(config, line.common, *opts);
  };
  action.dealt = [] { return true; };
  return action;
}

}  // namespace voussoir

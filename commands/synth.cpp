// `voussoir synth`: N artificial accelerograms compatible with the EN 1998-1 Type 1 elastic
// spectrum (method in seismic/synth.hpp), written as PEER AT2 records with their spectra, a plot
// and a JSON summary (docs/records.md "Artificial records").

#include "seismic/synth.hpp"

#include <omp.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "commands/synth.hpp"
#include "core/schema.hpp"
#include "engine/motion.hpp"
#include "io/json.hpp"
#include "io/plot.hpp"
#include "seismic/accelerogram.hpp"

namespace voussoir {

namespace {

constexpr double kGravity = 9.81;        // [m/s2] for the ground velocity and displacement
constexpr double kMeanFloor = 0.9;       // EN 1998-1 3.2.3.1.2 (4): mean >= 90% of target
constexpr double kStrongMinimum = 10.0;  // [s] EN 1998-1 3.2.3.1.2 (3): strong part
constexpr double kMaxAg = 2.0;           // [g] beyond any seismic zone: a unit slip
constexpr int kMaxCount = 999;
constexpr std::size_t kMaxSamples = 200000;  // per record (cost: components x samples)
constexpr double kLongestPeriod = 4.0;       // [s] where the EC8 spectrum's formulas stop

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

[[noreturn]] void refuse(const std::string& option, const std::string& value,
                         const std::string& why) {
  throw DeckError(option + " " + value + ": " + why);
}

Ec8Soil check_options(const SynthOptions& o) {
  if (o.spectrum != "ec8")
    refuse("--spectrum", o.spectrum,
           "unknown target spectrum (allowed: ec8, the EN 1998-1 Type 1 elastic spectrum)");
  if (!(std::isfinite(o.ag) && o.ag > 0.0))
    refuse("--ag", num(o.ag), "the design ground acceleration must be a number > 0, in g");
  if (o.ag > kMaxAg)
    refuse("--ag", num(o.ag),
           "--ag is in g (ag on type A ground), and " + num(o.ag) +
               " g is beyond any seismic zone: was it given in m/s2?");
  std::optional<Ec8Soil> soil;
  if (o.soil.size() == 1)
    soil = ec8_type1_soil(static_cast<char>(std::toupper(static_cast<unsigned char>(o.soil[0]))));
  if (!soil)
    refuse("--soil", o.soil,
           "unknown ground type (allowed: A, B, C, D, E of EN 1998-1 Table 3.1; S1 and S2 need "
           "a special study)");
  if (o.count < 1 || o.count > kMaxCount)
    refuse("--count", std::to_string(o.count),
           "the number of records must be 1 to " + std::to_string(kMaxCount) +
               " (EN 1998-1 asks for at least 3, and 7 for mean results)");
  if (o.seed < 0) refuse("--seed", std::to_string(o.seed), "the seed must be >= 0");
  if (!(std::isfinite(o.dt) && o.dt > 0.0))
    refuse("--dt", num(o.dt), "the time step must be a number > 0 [s]");
  if (!(std::isfinite(o.duration) && o.duration >= kMinDuration))
    refuse("--duration", num(o.duration),
           "too short: at least " + num(kMinDuration) + " s (the envelope's " + num(kEnvelopeRise) +
               " s rise and 3 s after it)");
  if (o.duration / o.dt + 1.0 > static_cast<double>(kMaxSamples))
    refuse("--dt", num(o.dt),
           "gives " + num(std::floor(o.duration / o.dt) + 1.0) + " samples over " +
               num(o.duration) + " s (at most " + std::to_string(kMaxSamples) + ")");
  const std::string range = o.range.size() == 2 ? num(o.range[0]) + "," + num(o.range[1]) : "?";
  if (o.range.size() != 2 ||
      !(o.range[0] > 0.0 && o.range[0] < o.range[1] && o.range[1] <= kLongestPeriod))
    refuse("--range", range, "expected TMIN,TMAX [s] with 0 < TMIN < TMAX <= 4");
  if (o.dt > o.range[0] / 4.0)
    refuse("--dt", num(o.dt),
           "too coarse for the range from " + num(o.range[0]) + " s: at most TMIN / 4 = " +
               num(o.range[0] / 4.0) + " s (the records hold frequencies up to 1 / (4 dt))");
  return *soil;
}

// Least and greatest ratio of `sa` to `target` over the periods in [lo, hi], with the periods.
struct RatioSpan {
  double least = 0.0, least_period = 0.0, greatest = 0.0, greatest_period = 0.0;
};
RatioSpan ratio_span(const std::vector<double>& periods, const std::vector<double>& sa,
                     const std::vector<double>& target, double lo, double hi) {
  RatioSpan r;
  bool first = true;
  for (std::size_t j = 0; j < periods.size(); ++j) {
    if (periods[j] < lo || periods[j] > hi) continue;
    const double q = sa[j] / target[j];
    if (first || q < r.least) r.least = q, r.least_period = periods[j];
    if (first || q > r.greatest) r.greatest = q, r.greatest_period = periods[j];
    first = false;
  }
  return r;
}

void write_spectra_csv(const std::string& path, const std::vector<double>& periods,
                       const std::vector<double>& target, const SynthSet& set,
                       const std::vector<std::string>& names) {
  std::ofstream csv(path);
  if (!csv) throw OutputError(path + ": cannot write the spectra CSV");
  csv.precision(9);
  csv << "period,target";
  for (const std::string& n : names) csv << "," << n;
  csv << ",mean\n";
  for (std::size_t j = 0; j < periods.size(); ++j) {
    csv << periods[j] << "," << target[j];
    for (const SynthRecord& r : set.records) csv << "," << r.sa[j];
    csv << "," << set.mean[j] << "\n";
  }
  if (!csv.flush()) throw OutputError(path + ": cannot write the spectra CSV");
}

}  // namespace

namespace {

// Writes the records of `set` as OUTPUT/synth_NN.AT2 (their names and files appended to
// `names` and `files`), a line each on stdout; returns their entries of the JSON summary.
nlohmann::json write_records(const SynthOptions& o, const SynthSet& set,
                             const std::vector<double>& periods, const std::vector<double>& target,
                             const std::string& soil_name, std::vector<std::string>& names,
                             std::vector<std::string>& files) {
  std::error_code ec;
  std::filesystem::create_directories(o.output, ec);
  if (ec) throw OutputError(o.output + ": cannot create the output folder: " + ec.message());
  const int width = std::max(2, static_cast<int>(std::to_string(o.count).size()));
  nlohmann::json records = nlohmann::json::array();
  const double ag = o.ag;
  for (int i = 0; i < o.count; ++i) {
    const SynthRecord& r = set.records[static_cast<std::size_t>(i)];
    std::string number = std::to_string(i + 1);
    number.insert(0, static_cast<std::size_t>(width) - number.size(), '0');
    names.push_back("synth_" + number);
    const std::string file = (std::filesystem::path(o.output) / (names.back() + ".AT2")).string();
    std::ostringstream note;
    note << "EN 1998-1 Type 1, ag = " << ag << " g, soil " << soil_name << ", 5% damping; record "
         << i + 1 << " of " << o.count << ", seed " << o.seed << ", duration " << o.duration
         << " s";
    write_at2(file, r.accel, o.dt,
              "voussoir synth: artificial accelerogram compatible with an elastic spectrum "
              "(not a recorded motion)",
              note.str());
    files.push_back(file);
    const RatioSpan span = ratio_span(periods, r.sa, target, o.range[0], o.range[1]);
    const GroundMotion g = ground_motion(r.accel, o.dt);
    std::printf("  %s: PGA %.4g g, Sa / target %.3f to %.3f over %g-%g s (iterate %d of %d)\n",
                file.c_str(), r.pga, span.least, span.greatest, o.range[0], o.range[1], r.kept,
                r.iterations);
    records.push_back({{"file", file},
                       {"pga_g", r.pga},
                       {"pgv_m_s", g.peak_velocity * kGravity},
                       {"pgd_m", g.peak_displacement * kGravity},
                       {"end_velocity_m_s", g.end_velocity * kGravity},
                       {"end_displacement_m", g.end_displacement * kGravity},
                       {"ratio_min", span.least},
                       {"ratio_max", span.greatest},
                       {"iterations", r.iterations},
                       {"iterate_kept", r.kept}});
  }
  return records;
}

}  // namespace

int command_synth(const SynthOptions& o) {
  const auto wall0 = std::chrono::steady_clock::now();
  const Ec8Soil soil = check_options(o);
  if (o.threads > 0) omp_set_num_threads(o.threads);

  SynthSettings settings;
  settings.dt = o.dt;
  settings.duration = o.duration;
  settings.range_lo = o.range[0];
  settings.range_hi = o.range[1];
  const SynthEnvelope env = make_synth_envelope(o.duration);
  const std::vector<double> periods = synth_periods(settings);
  const double ag = o.ag;
  auto target_of = [&](double t) { return ec8_elastic_spectrum(t, ag, soil); };
  std::vector<double> target(periods.size());
  for (std::size_t j = 0; j < periods.size(); ++j) target[j] = target_of(periods[j]);
  const std::string soil_name(1, soil.name);

  std::printf(
      "synth: %d record%s, EN 1998-1 Type 1 spectrum, ag = %g g, soil %s (S = %g, TB = %g s, "
      "TC = %g s, TD = %g s), %g s at dt = %g s (rise %g s, strong part %.3g s), seed %lld\n",
      o.count, o.count == 1 ? "" : "s", ag, soil_name.c_str(), soil.s, soil.tb, soil.tc, soil.td,
      o.duration, o.dt, env.rise, env.strong_length(), o.seed);
  if (env.strong_length() < kStrongMinimum)
    std::fprintf(stderr,
                 "voussoir: warning: the strong part lasts %.3g s, less than the 10 s of EN "
                 "1998-1 3.2.3.1.2 (3) (--duration %g; 20 s gives 10.8 s)\n",
                 env.strong_length(), o.duration);
  std::fflush(stdout);

  const double pga_floor = ag * soil.s;
  const SynthSet set = synthesize_set(settings, target_of, periods,
                                      static_cast<std::uint64_t>(o.seed), o.count, pga_floor);
  const double gen_seconds = seconds_since(wall0);

  std::vector<std::string> names, files;
  const nlohmann::json records = write_records(o, set, periods, target, soil_name, names, files);
  const std::string csv = (std::filesystem::path(o.output) / "spectra.csv").string();
  write_spectra_csv(csv, periods, target, set, names);
  files.push_back(csv);

  const RatioSpan mean = ratio_span(periods, set.mean, target, o.range[0], o.range[1]);
  const bool spectrum_ok = mean.least >= kMeanFloor;
  const bool pga_ok = set.mean_pga >= pga_floor * (1.0 - 1e-12);
  std::printf(
      "mean spectrum / target over %g-%g s: least %.3f at T = %.3g s, greatest %.3f at T = %.3g "
      "s; EN 1998-1 3.2.3.1.2 (4), mean >= 0.9 target: %s\n",
      o.range[0], o.range[1], mean.least, mean.least_period, mean.greatest, mean.greatest_period,
      spectrum_ok ? "met" : "NOT met");
  const std::string scaled =
      set.scale > 1.0 ? " (the records scaled by " + num(set.scale) + " to reach it)" : "";
  std::printf("mean PGA %.4g g, ag S = %.4g g%s; mean PGA >= ag S: %s\n", set.mean_pga, pga_floor,
              scaled.c_str(), pga_ok ? "met" : "NOT met");

  std::string plot =
      o.plot.empty() ? (std::filesystem::path(o.output) / "spectra.png").string() : o.plot;
  if (!o.no_plot) {
    const std::string title = "EN 1998-1 Type 1, ag = " + num(ag) + " g, soil " + soil_name + ": " +
                              std::to_string(o.count) + " artificial records, seed " +
                              std::to_string(o.seed);
    if (draw_with_script("plot_synth",
                         {csv, "-o", plot, "--range", num(o.range[0]) + "," + num(o.range[1]),
                          "--record", files.front(), "--title", title},
                         plot))
      files.push_back(plot);
  }
  const double wall = seconds_since(wall0);
  std::printf("wrote %d AT2 record%s and %s in %s (%.2f s, records %.2f s)\n", o.count,
              o.count == 1 ? "" : "s", "spectra.csv", o.output.c_str(), wall, gen_seconds);

  if (!o.json.empty()) {
    nlohmann::json j = {
        {"command", "synth"},
        {"spectrum", o.spectrum},
        {"ag_g", ag},
        {"soil", soil_name},
        {"S", soil.s},
        {"TB", soil.tb},
        {"TC", soil.tc},
        {"TD", soil.td},
        {"damping", settings.damping},
        {"count", o.count},
        {"duration", o.duration},
        {"dt", o.dt},
        {"seed", o.seed},
        {"range", {o.range[0], o.range[1]}},
        {"envelope", {{"rise", env.rise}, {"strong_end", env.strong_end}, {"decay", env.decay}}},
        {"records", records},
        {"mean",
         {{"pga_g", set.mean_pga},
          {"ag_S_g", pga_floor},
          {"ratio_min", mean.least},
          {"ratio_min_period", mean.least_period},
          {"ratio_max", mean.greatest},
          {"ratio_max_period", mean.greatest_period}}},
        {"scale", set.scale},
        {"ec8_mean_spectrum_ok", spectrum_ok},
        {"ec8_mean_pga_ok", pga_ok},
        {"files", files},
        {"wall_s", wall}};
    write_json(j, o.json);
  }
  // The rule's outcome is the exit status (docs/records.md "Artificial records"): a set that
  // fails it is written for inspection, and a script (synth, then ida on its records) stops.
  if (!spectrum_ok || !pga_ok)
    throw RunError(std::string("the set fails EN 1998-1 3.2.3.1.2 (4): ") +
                   (!spectrum_ok ? "its mean spectrum falls to " + num(mean.least) +
                                       " x the target at T = " + num(mean.least_period) +
                                       " s (at least 0.9 needed)"
                                 : "") +
                   (!spectrum_ok && !pga_ok ? "; " : "") +
                   (!pga_ok ? "its mean PGA " + num(set.mean_pga) +
                                  " g is below ag S = " + num(pga_floor) + " g"
                            : "") +
                   "; the records are written in " + o.output + " for inspection");
  return 0;
}

// The options of `synth` (docs/reference/commands.md).
CommandAction add_synth_command(CLI::App& cmd, CommandLine& line) {
  auto opts = std::make_shared<SynthOptions>();
  SynthOptions& o = *opts;
  cmd.add_option("--spectrum", o.spectrum, "target spectrum: ec8 (EN 1998-1 Type 1)")
      ->capture_default_str();
  cmd.add_option("--ag", o.ag, "design ground acceleration on type A ground [g]")->required();
  cmd.add_option("--soil", o.soil, "ground type A, B, C, D or E (EN 1998-1 Table 3.2)")
      ->capture_default_str();
  cmd.add_option("--count", o.count, "number of records")->capture_default_str();
  cmd.add_option("--duration", o.duration, "length of each record [s]")->capture_default_str();
  cmd.add_option("--dt", o.dt, "time step of the records [s]")->capture_default_str();
  cmd.add_option("--seed", o.seed, "seed of the random phases (>= 0)")->capture_default_str();
  cmd.add_option("--range", o.range,
                 "TMIN,TMAX: periods [s] where the mean spectrum is checked against 90% of the "
                 "target (default 0.05,3)")
      ->delimiter(',')
      ->expected(2);
  cmd.add_option("-o,--output", o.output, "output folder")->capture_default_str();
  cmd.add_option("--plot", o.plot,
                 "PNG of the spectra and the first record (default DIR/spectra.png; "
                 "scripts/plot_synth)");
  cmd.add_flag("--no-plot", o.no_plot, "no plot");
  cmd.add_option("--json", o.json, "write a JSON summary to FILE ('-' for stdout)");
  cmd.add_option("--threads", o.threads, "OpenMP threads (records in parallel)")
      ->check(CLI::Range(1, 1024));
  CommandAction action;
  action.run = [opts] { return command_synth(*opts); };
  return action;
}

}  // namespace voussoir

// Incremental dynamic analysis (`voussoir ida`, commands/ida.hpp) and its lognormal fragility
// fit (seismic/fragility.hpp): the maximum-likelihood fit against a hand case and against samples
// drawn from a known lognormal, with and without censoring; the bootstrap interval; an IDA of
// a slender rigid block under three records, its intensity measures, threads, resume and bad
// input; a record the block outlasts, censored, in the fit of a real run. The figures printed here
// are quoted in docs/ida.md:
//   build/test_ida   (or: ctest --test-dir build -R Ida -V)

#include <gtest/gtest.h>
#include <unistd.h>

#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "seismic/fragility.hpp"
#include "seismic/spectrum.hpp"
#include "slender_block.hpp"
#include "subprocess.hpp"

namespace voussoir {
namespace {

using testing::run_process;

// n samples of a lognormal of median theta and log-deviation beta, by the normal quantile of
// uniforms from mt19937_64 (the same numbers on every standard library).
std::vector<double> lognormal_samples(int n, double theta, double beta, std::uint64_t seed) {
  std::mt19937_64 draw(seed);
  const boost::math::normal unit;
  std::vector<double> out;
  for (int i = 0; i < n; ++i) {
    const double u = (static_cast<double>(draw() >> 11) + 0.5) * 0x1.0p-53;
    out.push_back(theta * std::exp(beta * boost::math::quantile(unit, u)));
  }
  return out;
}

TEST(Fragility, HandCase) {
  // ln 0.2 and ln 0.4: mean ln sqrt(0.08), deviation (1/n) ln 2 / 2.
  const LognormalFit fit = fit_lognormal({{0.2, false}, {0.4, false}});
  ASSERT_TRUE(fit.ok);
  EXPECT_NEAR(fit.median, std::sqrt(0.08), 1e-14);
  EXPECT_NEAR(fit.beta, 0.5 * std::log(2.0), 1e-14);
  EXPECT_DOUBLE_EQ(collapse_probability(fit, fit.median), 0.5);
  // One standard deviation above the median: Phi(1).
  EXPECT_NEAR(collapse_probability(fit, fit.median * std::exp(fit.beta)), 0.841344746068543, 1e-12);
}

TEST(Fragility, NeedsTwoCollapses) {
  EXPECT_FALSE(fit_lognormal({{0.3, false}}).ok);
  EXPECT_FALSE(fit_lognormal({{0.3, false}, {0.3, false}, {0.5, true}}).ok);
  EXPECT_FALSE(fit_lognormal({{0.3, true}, {0.5, true}}).ok);
  EXPECT_THROW(fit_lognormal({{0.3, false}, {-1.0, false}}), std::invalid_argument);
}

// Maximum likelihood recovers a known median and beta from 200 lognormal samples within their
// sampling error: the standard error of ln(median) is beta / sqrt(n), that of beta
// beta / sqrt(2 n); the fit must land within 3 of each (a 0.3% chance of failing for an
// unbiased estimator, and the draws are fixed).
TEST(Fragility, RecoversKnownLognormal) {
  const double theta = 0.35, beta = 0.4;
  const int n = 200;
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    std::vector<IntensitySample> s;
    for (double x : lognormal_samples(n, theta, beta, seed)) s.push_back({x, false});
    const LognormalFit fit = fit_lognormal(s);
    ASSERT_TRUE(fit.ok);
    std::printf("seed %d: median %.4f (true %.2f, error %.2f SE), beta %.4f (true %.2f, %.2f SE)\n",
                static_cast<int>(seed), fit.median, theta,
                std::log(fit.median / theta) / (beta / std::sqrt(n)), fit.beta, beta,
                (fit.beta - beta) / (beta / std::sqrt(2.0 * n)));
    EXPECT_LT(std::abs(std::log(fit.median / theta)), 3.0 * beta / std::sqrt(n));
    EXPECT_LT(std::abs(fit.beta - beta), 3.0 * beta / std::sqrt(2.0 * n));
  }
}

// Records that did not collapse up to a cap enter censored: the samples above the cap
// c = theta exp(0.5 beta) (31% of them) are replaced by the cap. The censored fit recovers the
// truth within 4 of the uncensored standard errors (censoring loses information, so its error
// is larger). Fitting the caps as if they were collapses instead gives the moments of
// beta min(Z, 0.5): with phi and Phi the normal density and CDF at 0.5,
//     E = -phi + 0.5 (1 - Phi),   E2 = Phi - 0.5 phi + 0.25 (1 - Phi),
// median theta exp(beta E) and beta sqrt(E2 - E^2) (0.323 and 0.298 here): the naive fit lands
// there, within the same 4 standard errors, far from the truth.
TEST(Fragility, CensoredRecordsRecoverKnownLognormal) {
  const double theta = 0.35, beta = 0.4;
  const int n = 200;
  const double cap = theta * std::exp(0.5 * beta);
  const std::vector<double> x = lognormal_samples(n, theta, beta, 4);
  std::vector<IntensitySample> censored, naive;
  int above = 0;
  for (double v : x) {
    censored.push_back({std::min(v, cap), v > cap});
    naive.push_back({std::min(v, cap), false});
    above += v > cap;
  }
  const LognormalFit fit = fit_lognormal(censored);
  const LognormalFit wrong = fit_lognormal(naive);
  ASSERT_TRUE(fit.ok);
  EXPECT_EQ(fit.censored, above);
  const boost::math::normal unit;
  const double phi = boost::math::pdf(unit, 0.5), cdf = boost::math::cdf(unit, 0.5);
  const double e1 = -phi + 0.5 * (1.0 - cdf), e2 = cdf - 0.5 * phi + 0.25 * (1.0 - cdf);
  const double naive_median = theta * std::exp(beta * e1),
               naive_beta = beta * std::sqrt(e2 - e1 * e1);
  std::printf(
      "%d of %d censored at %.4f: censored fit median %.4f beta %.4f (true %.2f, %.2f); "
      "caps taken as collapses: median %.4f beta %.4f (expected %.4f, %.4f)\n",
      above, n, cap, fit.median, fit.beta, theta, beta, wrong.median, wrong.beta, naive_median,
      naive_beta);
  const double se_median = beta / std::sqrt(n), se_beta = beta / std::sqrt(2.0 * n);
  EXPECT_LT(std::abs(std::log(fit.median / theta)), 4.0 * se_median);
  EXPECT_LT(std::abs(fit.beta - beta), 4.0 * se_beta);
  EXPECT_LT(std::abs(std::log(wrong.median / naive_median)), 4.0 * se_median);
  EXPECT_LT(std::abs(wrong.beta - naive_beta), 4.0 * se_beta);
}

// The percentile bootstrap of the median. Coverage: over 60 independent sets of 30 records
// drawn from a known lognormal, the 90% interval holds the true median in about 54 of them;
// the count is binomial (60, 0.9) for an exact interval (mean 54, deviation 2.3) and a
// percentile bootstrap of 30 samples under-covers by a point or two, so at least 47 (3
// deviations below the mean) must hold it. Width: for 200 samples the 95% interval's width
// in ln(median) is within 25% of the normal theory's 2 x 1.96 beta / sqrt(n) (the
// resampling noise of 1000 resamples is a few percent). The same seed, the same interval.
TEST(Fragility, BootstrapIntervalOfTheMedian) {
  const double theta = 0.35, beta = 0.4;
  int covered = 0;
  const int sets = 60;
  for (int k = 0; k < sets; ++k) {
    std::vector<IntensitySample> s;
    for (double x : lognormal_samples(30, theta, beta, 100 + k)) s.push_back({x, false});
    const MedianInterval ci = bootstrap_median(s, 1000, 7, 0.90);
    covered += ci.lo < theta && theta < ci.hi;
  }
  std::printf("90%% intervals of the median from 30 records: %d of %d hold the true median\n",
              covered, sets);
  EXPECT_GE(covered, 47);

  const int n = 200;
  std::vector<IntensitySample> s;
  for (double x : lognormal_samples(n, theta, beta, 5)) s.push_back({x, false});
  const LognormalFit fit = fit_lognormal(s);
  const MedianInterval ci = bootstrap_median(s, 1000, 7);
  const MedianInterval again = bootstrap_median(s, 1000, 7);
  EXPECT_EQ(ci.lo, again.lo);
  EXPECT_EQ(ci.hi, again.hi);
  EXPECT_EQ(ci.resamples, 1000);
  const double width = std::log(ci.hi / ci.lo);
  const double normal_width = 2.0 * 1.959964 * fit.beta / std::sqrt(n);
  std::printf(
      "200 records: median %.4f, 95%% interval [%.4f, %.4f]: width %.4f in ln against "
      "%.4f\n",
      fit.median, ci.lo, ci.hi, width, normal_width);
  EXPECT_LT(ci.lo, fit.median);
  EXPECT_GT(ci.hi, fit.median);
  EXPECT_NEAR(width, normal_width, 0.25 * normal_width);
}

// ln(1 - Phi(z)) stays finite where erfc underflows (z ~ 38 and beyond, which the beta search
// reaches with a censored record far above a narrow fit): against the first terms of Mills'
// ratio, -z^2/2 - ln(z sqrt(2 pi)) + ln(1 - 1/z^2 + 3/z^4), whose next term is 15/z^6; and
// without a jump where it changes method (z = 30).
TEST(Fragility, LogSurvivalFarInTheUpperTail) {
  for (const double z : {40.0, 100.0, 1e3, 1e5}) {
    const double want = -0.5 * z * z - std::log(z * std::sqrt(2.0 * std::numbers::pi)) +
                        std::log(1.0 - 1.0 / (z * z) + 3.0 / (z * z * z * z));
    const double got = log_normal_survival(z);
    ASSERT_TRUE(std::isfinite(got)) << z;
    // (Plus the rounding of numbers of size z^2 / 2.)
    EXPECT_NEAR(got, want, 20.0 / std::pow(z, 6.0) + 4e-16 * std::abs(want)) << z;
  }
  // Across z = 30: the slope there is about -30, so 1e-9 apart the values differ by 3e-8.
  EXPECT_NEAR(log_normal_survival(30.0 - 1e-9), log_normal_survival(30.0), 1e-7);
  // Below, the library's erfc: ln(1 - Phi(0)) = ln 1/2, and the lower tail tends to 0.
  EXPECT_DOUBLE_EQ(log_normal_survival(0.0), std::log(0.5));
  EXPECT_NEAR(log_normal_survival(-40.0), 0.0, 1e-300);
}

// A record that collapses at every intensity tried, down to the smallest x (commands/pulse.hpp
// kMinAmplitude), enters the fit censored below: ln Phi(z). The fit is the maximum of that
// likelihood: no point of a fine grid around it does better, and the record pulls the median
// down.
TEST(Fragility, RecordCensoredBelowEntersAsAnUpperBound) {
  const std::vector<IntensitySample> collapsed = {
      {0.5, false}, {0.8, false}, {1.0, false}, {1.3, false}};
  std::vector<IntensitySample> with = collapsed;
  with.push_back({0.3, false, true});
  const LognormalFit plain = fit_lognormal(collapsed), fit = fit_lognormal(with);
  ASSERT_TRUE(plain.ok && fit.ok);
  EXPECT_EQ(fit.censored, 1);
  EXPECT_LT(fit.median, plain.median);
  auto log_l = [&](double mu, double beta) {
    double sum = 0.0;
    for (const IntensitySample& s : with) {
      const double z = (std::log(s.im) - mu) / beta;
      sum +=
          s.below ? std::log(0.5 * std::erfc(-z / std::sqrt(2.0))) : -std::log(beta) - 0.5 * z * z;
    }
    return sum;
  };
  const double best = log_l(std::log(fit.median), fit.beta);
  for (int i = -20; i <= 20; ++i)
    for (int k = -20; k <= 20; ++k) {
      const double mu = std::log(fit.median) + 0.01 * i, beta = fit.beta * (1.0 + 0.01 * k);
      EXPECT_LE(log_l(mu, beta), best + 1e-12) << "mu " << mu << ", beta " << beta;
    }
  EXPECT_THROW(fit_lognormal({{0.3, false}, {0.5, false}, {0.4, true, true}}),
               std::invalid_argument);
}

// Every resample counts: three records, one of which never collapsed. 1 resample in 27 draws
// it three times and has no collapse at all: its median lies above every intensity run, so the
// 95% interval (whose upper end is the 97.5% quantile) is unbounded above; 6 in 27 draw
// one collapse intensity only and enter at it.
TEST(Fragility, BootstrapKeepsResamplesWithoutAFit) {
  const std::vector<IntensitySample> s = {{0.4, false}, {0.6, false}, {2.0, true}};
  const MedianInterval ci = bootstrap_median(s, 1000, 3, 0.95);
  EXPECT_EQ(ci.resamples, 1000);
  EXPECT_GT(ci.without_fit, 0);
  EXPECT_TRUE(std::isinf(ci.hi)) << ci.hi;
  EXPECT_GE(ci.lo, 0.4);
  EXPECT_LT(ci.lo, 0.6);
  // Two collapses only: every resample holds at most two distinct values; none is unbounded.
  const MedianInterval two = bootstrap_median({{0.4, false}, {0.6, false}}, 1000, 3, 0.95);
  EXPECT_EQ(two.resamples, 1000);
  EXPECT_DOUBLE_EQ(two.lo, 0.4);
  EXPECT_DOUBLE_EQ(two.hi, 0.6);
}

// ---------------------------------------------------------------------------------------------
// The command.

std::filesystem::path temp_dir() {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("voussoir_ida_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

// A two-column record [s, g]: a sum of sinusoids of fixed frequencies and phases (the k-th
// record takes its own) under a rise-hold-decay envelope, 6 s at 0.01 s, peak 0.3 g.
std::string write_record(int k) {
  const double pi = std::numbers::pi;
  const double freqs[] = {0.9, 1.7, 2.6, 3.3, 4.4, 5.8};
  std::vector<double> a;
  double peak = 0.0;
  for (int i = 0; i <= 600; ++i) {
    const double t = 0.01 * i;
    double v = 0.0;
    for (int j = 0; j < 6; ++j)
      v += std::sin(2.0 * pi * freqs[j] * t + 1.3 * (k + 1) * (j + 1)) / std::sqrt(freqs[j]);
    const double env = std::min(1.0, t * t) * (t > 4.0 ? std::exp(-1.5 * (t - 4.0)) : 1.0);
    a.push_back(v * env);
    peak = std::max(peak, std::abs(v * env));
  }
  const std::string path = (temp_dir() / ("rec" + std::to_string(k) + ".txt")).string();
  std::ofstream out(path);
  out.precision(17);
  out << "# time [s], acceleration [g]\n";
  for (std::size_t i = 0; i < a.size(); ++i) out << 0.01 * i << ", " << 0.3 * a[i] / peak << "\n";
  return path;
}

// The slender rigid block (slender_block.hpp: 0.2 x 1 m, stiff joints, full impact damping),
// its tilting capacity given as b/h = 0.2.
std::vector<std::string> block_args(const std::vector<std::string>& extra) {
  std::vector<std::string> args = testing::slender_block_args("ida");
  args.insert(args.end(), {"--lambda-star", "0.2"});
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

std::string text_of(const std::string& path) {
  return testing::read_text_file(path);
}

// The CSV with its wall_s column removed.
std::string without_wall(const std::string& path) {
  std::istringstream in(text_of(path));
  std::string line, out;
  int wall = -1;
  bool header = true;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::string cell;
    bool quoted = false;
    for (char c : line) {
      if (c == '"') quoted = !quoted;
      if (c == ',' && !quoted) {
        cells.push_back(cell);
        cell.clear();
      } else {
        cell += c;
      }
    }
    cells.push_back(cell);
    if (header)
      for (std::size_t i = 0; i < cells.size(); ++i)
        if (cells[i] == "wall_s") wall = static_cast<int>(i);
    header = false;
    for (std::size_t i = 0; i < cells.size(); ++i)
      if (static_cast<int>(i) != wall) out += cells[i] + ",";
    out += "\n";
  }
  return out;
}

struct IdaRun {
  testing::ProcessResult process;
  nlohmann::json json;
  std::string csv, runs_csv;
};

IdaRun run_ida(const std::string& name, const std::vector<std::string>& records,
               std::vector<std::string> extra) {
  const std::filesystem::path dir = temp_dir();
  IdaRun r;
  r.csv = (dir / (name + ".csv")).string();
  r.runs_csv = (dir / (name + "_runs.csv")).string();
  const std::string json = (dir / (name + ".json")).string();
  std::string list;
  for (const std::string& f : records) list += (list.empty() ? "" : ",") + f;
  for (const std::string& a :
       {std::string("--records"), list, std::string("--csv"), r.csv, std::string("--json"), json})
    extra.push_back(a);
  r.process = run_process(block_args(extra), {.wall_s = 300, .cpu_s = 600}, (dir / name).string());
  if (r.process.exited && r.process.status == 0) r.json = nlohmann::json::parse(text_of(json));
  return r;
}

// Three records on the slender block: each record's search brackets a collapse (its lower end
// survived, its upper end collapsed, both among the runs), the IM is the record's PGA, and the
// fragility is fitted. Sa(T) as the IM: the same runs (the search is in PGA), every intensity
// multiplied by the record's Sa(T) / PGA, checked against the spectrum of the file computed
// here. Two threads give the same CSV as one (wall times aside), also for one record, whose
// search the second thread runs ahead; --resume runs nothing again.
TEST(Ida, SlenderBlockUnderThreeRecords) {
  const std::vector<std::string> records = {write_record(0), write_record(1), write_record(2)};
  const IdaRun pga = run_ida("pga", records, {"--threads", "1", "-q"});
  ASSERT_TRUE(pga.process.exited && pga.process.status == 0) << pga.process.describe() << "\n"
                                                             << pga.process.err;
  std::printf("%s", pga.process.out.c_str());
  const nlohmann::json& j = pga.json;
  EXPECT_EQ(j.at("im"), "pga");
  EXPECT_EQ(j.at("ranks"), 1);
  ASSERT_EQ(j.at("records").size(), 3u);
  for (const nlohmann::json& rec : j.at("records")) {
    EXPECT_TRUE(rec.at("bracketed").get<bool>()) << rec.at("file");
    const double lo = rec.at("bracket")[0], hi = rec.at("bracket")[1];
    EXPECT_EQ(rec.at("collapse_im").get<double>(), hi);
    EXPECT_LE(hi - lo, 0.05 * hi * (1.0 + 1e-12));
    EXPECT_NEAR(rec.at("pga").get<double>(), 0.3, 1e-9);
    bool survived_lo = false, collapsed_hi = false;
    for (const nlohmann::json& run : rec.at("runs")) {
      if (run.at("im").get<double>() == lo && !run.at("collapsed").get<bool>()) survived_lo = true;
      if (run.at("im").get<double>() == hi && run.at("collapsed").get<bool>()) collapsed_hi = true;
    }
    EXPECT_TRUE(survived_lo && collapsed_hi) << rec.dump();
    // A record whose peak stays below lambda* g cannot tip the block.
    EXPECT_GE(lo, 0.2);
  }
  // docs/reference/output.md's fields.
  for (const char* key : {"im", "period", "records", "fragility", "ranks", "wall_s"})
    EXPECT_TRUE(j.contains(key)) << key;
  for (const char* key : {"file", "collapse_im", "bracket", "trials", "wall_s"})
    EXPECT_TRUE(j.at("records")[0].contains(key)) << key;
  ASSERT_FALSE(j.at("fragility").is_null());
  const nlohmann::json& fr = j.at("fragility");
  for (const char* key : {"median", "beta", "median_ci"}) EXPECT_TRUE(fr.contains(key)) << key;
  // Every record bracketed, none censored: the fit is the closed form of the records' collapse
  // intensities, median exp(mean ln x) and beta the 1/n deviation of ln x.
  double mean = 0.0, var = 0.0;
  for (const nlohmann::json& rec : j.at("records"))
    mean += std::log(rec.at("collapse_im").get<double>());
  mean /= 3.0;
  for (const nlohmann::json& rec : j.at("records"))
    var += std::pow(std::log(rec.at("collapse_im").get<double>()) - mean, 2.0);
  EXPECT_NEAR(fr.at("median").get<double>(), std::exp(mean), 1e-12 * std::exp(mean));
  EXPECT_NEAR(fr.at("beta").get<double>(), std::sqrt(var / 3.0), 1e-12);
  EXPECT_EQ(fr.at("censored").get<int>(), 0);
  // The interval of the median: two numbers around it, or null where the records leave it
  // unbounded.
  ASSERT_EQ(fr.at("median_ci").size(), 2u);
  if (!fr.at("median_ci")[0].is_null()) {
    EXPECT_LE(fr.at("median_ci")[0].get<double>(), fr.at("median").get<double>());
  }
  if (!fr.at("median_ci")[1].is_null()) {
    EXPECT_GE(fr.at("median_ci")[1].get<double>(), fr.at("median").get<double>());
  }

  // Sa(0.5 s): the same PGAs, intensities scaled by the record's own ratio.
  const double period = 0.5;
  const IdaRun sa =
      run_ida("sa", records, {"--threads", "1", "-q", "--im", "sa", "--period", "0.5"});
  ASSERT_TRUE(sa.process.exited && sa.process.status == 0) << sa.process.err;
  for (std::size_t i = 0; i < records.size(); ++i) {
    // The record's spectrum, computed here from the file (sampled at 0.01 s, linear between).
    std::vector<double> accel;
    std::istringstream in(text_of(records[i]));
    std::string line;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#') continue;
      accel.push_back(std::stod(line.substr(line.find(',') + 1)) / 0.3);  // unit PGA
    }
    const double ratio = response_spectrum(accel, 0.01, {period})[0];
    const nlohmann::json& a = pga.json.at("records")[i];
    const nlohmann::json& b = sa.json.at("records")[i];
    EXPECT_NEAR(b.at("im_per_pga").get<double>(), ratio, 1e-6 * ratio);
    EXPECT_NEAR(b.at("collapse_im").get<double>(),
                a.at("collapse_im").get<double>() * b.at("im_per_pga").get<double>(), 1e-12);
  }

  const IdaRun two = run_ida("two", records, {"--threads", "2", "-q"});
  ASSERT_TRUE(two.process.exited && two.process.status == 0) << two.process.err;
  EXPECT_EQ(without_wall(two.csv), without_wall(pga.csv));
  EXPECT_EQ(without_wall(two.runs_csv), without_wall(pga.runs_csv));
  // One record on two threads: the second thread has no search from the start and runs the
  // search's next runs ahead (engine/runs_ahead.hpp); the runs are those of one thread.
  const IdaRun lone = run_ida("lone", {records[1]}, {"--threads", "1", "-q"});
  const IdaRun lone_two = run_ida("lone_two", {records[1]}, {"--threads", "2", "-q"});
  ASSERT_TRUE(lone.process.exited && lone.process.status == 0) << lone.process.err;
  ASSERT_TRUE(lone_two.process.exited && lone_two.process.status == 0) << lone_two.process.err;
  EXPECT_EQ(without_wall(lone_two.runs_csv), without_wall(lone.runs_csv));
  EXPECT_GT(text_of(lone.runs_csv).size(), 0u);

  const std::string journal = (temp_dir() / "ida.journal").string();
  const IdaRun first = run_ida("first", records, {"--threads", "2", "--resume", journal});
  ASSERT_TRUE(first.process.exited && first.process.status == 0) << first.process.err;
  const std::string kept = text_of(journal);
  const IdaRun again = run_ida("again", records, {"--threads", "2", "--resume", journal});
  ASSERT_TRUE(again.process.exited && again.process.status == 0) << again.process.err;
  EXPECT_EQ(text_of(journal), kept) << "a resumed IDA ran again what the journal held";
  EXPECT_EQ(text_of(again.runs_csv), text_of(first.runs_csv));
  EXPECT_NE(again.process.err.find("[journal]"), std::string::npos);
}

// A record [s, g] the slender block outlasts at every intensity the search tries: four cycles
// of a 100 Hz sine, sampled at 0.5 ms, peak 0.3 g (at 20 g the ground moves by 0.5 mm).
std::string write_burst() {
  const std::string path = (temp_dir() / "burst.txt").string();
  std::ofstream out(path);
  out.precision(17);
  out << "# time [s], acceleration [g]\n";
  for (int i = 0; i <= 80; ++i)
    out << 5e-4 * i << ", " << 0.3 * std::sin(2.0 * std::numbers::pi * 100.0 * 5e-4 * i) << "\n";
  return path;
}

// ln L(mu, beta) of the lognormal fit (seismic/fragility.hpp's header), written out again: a
// collapsed record -ln beta - z^2 / 2, one censored above ln(1 - Phi(z)), one censored below
// ln Phi(z), z = (ln x - mu) / beta.
double log_likelihood(const std::vector<IntensitySample>& samples, double mu, double beta) {
  double sum = 0.0;
  for (const IntensitySample& s : samples) {
    const double z = (std::log(s.im) - mu) / beta;
    if (s.below)
      sum += std::log(0.5 * std::erfc(-z / std::numbers::sqrt2));
    else if (s.censored)
      sum += std::log(0.5 * std::erfc(z / std::numbers::sqrt2));
    else
      sum += -std::log(beta) - 0.5 * z * z;
  }
  return sum;
}

// The maximum of f on [lo, hi] by golden-section search (f unimodal there), to 1e-13 of the
// interval's scale.
template <class F>
double golden_max(F f, double lo, double hi) {
  const double r = 0.5 * (std::sqrt(5.0) - 1.0);
  double c = hi - r * (hi - lo), d = lo + r * (hi - lo);
  double fc = f(c), fd = f(d);
  while (hi - lo > 1e-13 * (1.0 + std::abs(lo) + std::abs(hi))) {
    if (fc > fd) {
      hi = d, d = c, fd = fc;
      c = hi - r * (hi - lo), fc = f(c);
    } else {
      lo = c, c = d, fc = fd;
      d = lo + r * (hi - lo), fd = f(d);
    }
  }
  return 0.5 * (lo + hi);
}

// The censored fit inside a real IDA: three records that fell the block and one it outlasts up
// to the search's cap (censored at the largest intensity it survived). The JSON's fragility is
// the maximum-likelihood lognormal of the records as the same JSON gives them, found here by
// golden-section searches (ln L is concave in mu at fixed beta; the profile over ln beta is
// searched the same way), independently of seismic/fragility.cpp's Brent searches; and it is not
// the fit that would take the censored record for a collapse.
TEST(Ida, CensoredRecordEntersTheFragilityFit) {
  const std::vector<std::string> records = {write_record(0), write_record(1), write_record(2),
                                            write_burst()};
  const IdaRun run = run_ida("censored", records, {"--threads", "2", "-q", "--steps-above", "0"});
  ASSERT_TRUE(run.process.exited && run.process.status == 0) << run.process.describe() << "\n"
                                                             << run.process.err;
  std::printf("%s", run.process.out.c_str());
  const nlohmann::json& j = run.json;
  ASSERT_EQ(j.at("records").size(), 4u);
  std::vector<IntensitySample> samples;
  int censored = 0;
  for (const nlohmann::json& rec : j.at("records")) {
    const bool bracketed = rec.at("bracketed");
    const double im = rec.at("collapse_im");
    samples.push_back({im, !bracketed, rec.at("collapses_everywhere").get<bool>()});
    if (bracketed) continue;
    // Censored above: no run collapsed, and the record enters at the largest IM it survived.
    ++censored;
    double largest = 0.0;
    for (const nlohmann::json& r : rec.at("runs")) {
      EXPECT_FALSE(r.at("collapsed").get<bool>()) << rec.at("file");
      largest = std::max(largest, r.at("im").get<double>());
    }
    EXPECT_EQ(im, largest) << rec.at("file");
  }
  ASSERT_EQ(censored, 1) << "the burst must outlast the cap and the three records must fell "
                            "the block";
  EXPECT_FALSE(j.at("records")[3].at("bracketed").get<bool>());
  const nlohmann::json& fr = j.at("fragility");
  ASSERT_FALSE(fr.is_null()) << j.value("fragility_missing", "");
  EXPECT_EQ(fr.at("records").get<int>(), 4);
  EXPECT_EQ(fr.at("censored").get<int>(), 1);

  // The maximum likelihood, profiled over mu at each beta.
  double lo_y = INFINITY, hi_y = -INFINITY;
  for (const IntensitySample& s : samples)
    lo_y = std::min(lo_y, std::log(s.im)), hi_y = std::max(hi_y, std::log(s.im));
  auto best_mu = [&](double beta) {
    return golden_max([&](double mu) { return log_likelihood(samples, mu, beta); },
                      lo_y - 20.0 * beta, hi_y + 20.0 * beta);
  };
  const double log_beta = golden_max(
      [&](double lb) {
        const double beta = std::exp(lb);
        return log_likelihood(samples, best_mu(beta), beta);
      },
      std::log(1e-3), std::log(1e2));
  const double beta = std::exp(log_beta), median = std::exp(best_mu(beta));
  const double fit_median = fr.at("median"), fit_beta = fr.at("beta");
  std::printf("censored MLE: here median %.8g g beta %.8g; ida median %.8g g beta %.8g\n", median,
              beta, fit_median, fit_beta);
  EXPECT_NEAR(fit_median, median, 1e-6 * median);
  EXPECT_NEAR(fit_beta, beta, 1e-6 * beta);
  // The program's pair is a maximum at least as high as the one found here.
  EXPECT_GE(log_likelihood(samples, std::log(fit_median), fit_beta),
            log_likelihood(samples, std::log(median), beta) - 1e-12);
  // Taken for a collapse, the burst would give the closed form: another median.
  double mean = 0.0;
  for (const IntensitySample& s : samples) mean += std::log(s.im) / 4.0;
  EXPECT_GT(std::abs(std::log(fit_median) - mean), 0.01);
}

// Bad input: exit status 2, the message naming what is wrong.
TEST(Ida, BadInputExitsTwo) {
  const std::string good = write_record(0);
  auto expect_refused = [&](const std::vector<std::string>& extra, const std::string& says) {
    std::vector<std::string> args = block_args(extra);
    const testing::ProcessResult p =
        run_process(args, {.wall_s = 60, .cpu_s = 60}, (temp_dir() / "bad").string());
    EXPECT_TRUE(p.exited && p.status == 2) << p.describe() << " for " << says << "\n" << p.err;
    EXPECT_NE(p.err.find(says), std::string::npos) << p.err;
  };
  const std::filesystem::path dir = temp_dir();
  const std::string missing = (dir / "missing.AT2").string();
  const std::string short_at2 = (dir / "short.AT2").string();
  std::ofstream(short_at2) << "PEER\nrecord\nUNITS OF G\nNPTS=  5, DT= .0100 SEC\n"
                              "  .1E-01  .2E-01\n  .3E-01\n";
  const std::string zero_dt = (dir / "zero_dt.AT2").string();
  std::ofstream(zero_dt)
      << "PEER\nrecord\nUNITS OF G\nNPTS=  3, DT= 0.0 SEC\n  .1E-01  .2E-01  .3E-01\n";
  const std::string bad_value = (dir / "bad_value.AT2").string();
  std::ofstream(bad_value)
      << "PEER\nrecord\nUNITS OF G\nNPTS=  3, DT= .01 SEC\n  .1E-01\n x12  .3E-01\n";
  expect_refused({}, "--records");
  expect_refused({"--records", missing}, "missing.AT2");
  expect_refused({"--records", good + "," + short_at2}, "short.AT2:6");
  expect_refused({"--records", zero_dt}, "zero_dt.AT2:4");
  expect_refused({"--records", bad_value}, "bad_value.AT2:6");
  expect_refused({"--records", good, "--im", "pgv"}, "--im \"pgv\"");
  expect_refused({"--records", good, "--im", "sa"}, "--period");
  expect_refused({"--records", good, "--im", "sa", "--period", "0"}, "--period 0");
  expect_refused({"--records", good, "--im", "sa", "--period", "-1"}, "--period -1");
  expect_refused({"--records", good, "--step", "0"}, "--step 0");
  expect_refused({"--records", good, "--tolerance", "1.5"}, "--tolerance 1.5");
  expect_refused({"--records", good, "--bootstrap", "0"}, "--bootstrap 0");
}

}  // namespace
}  // namespace voussoir

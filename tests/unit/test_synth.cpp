// Artificial accelerograms (`voussoir synth`, seismic/synth.hpp): the EN 1998-1 Type 1 spectrum
// against hand values, a set of 7 records against the EC8 rules for a suite, reproducibility by
// the seed, the AT2 writer against the reader, and the command's refusals. The figures printed
// here are quoted in docs/records.md "Artificial records":
//   build/test_synth   (or: ctest --test-dir build -R Synth -V)

#include <gtest/gtest.h>
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "seismic/accelerogram.hpp"
#include "seismic/spectrum.hpp"
#include "seismic/synth.hpp"
#include "subprocess.hpp"

namespace voussoir {
namespace {

std::filesystem::path temp_dir() {
  return std::filesystem::temp_directory_path() / ("voussoir_synth_" + std::to_string(::getpid()));
}

// EN 1998-1 3.2.2.2 (1)P with Table 3.2, eta = 1, by hand:
//   soil B (S 1.2, TB 0.15, TC 0.5, TD 2), ag = 0.3 g: ag S = 0.36 g, plateau 2.5 x 0.36 = 0.9 g;
//     T = 0.075 (TB / 2): 0.36 (1 + 0.5 x 1.5) = 0.63;  T = 1: 0.9 x 0.5 / 1 = 0.45;
//     T = 3: 0.9 x 0.5 x 2 / 9 = 0.1.
//   soil D (S 1.35, TB 0.2, TC 0.8, TD 2), ag = 0.2 g: ag S = 0.27 g, plateau 0.675 g;
//     T = 0.1: 0.27 x 1.75 = 0.4725;  T = 1.6: 0.675 x 0.8 / 1.6 = 0.3375;
//     T = 4: 0.675 x 0.8 x 2 / 16 = 0.0675.
TEST(SynthSpectrum, Ec8Type1AgainstHandValues) {
  const Ec8Soil b = *ec8_type1_soil('B');
  EXPECT_EQ(b.s, 1.2);
  EXPECT_EQ(b.tb, 0.15);
  EXPECT_EQ(b.tc, 0.5);
  EXPECT_EQ(b.td, 2.0);
  const double tol = 1e-12;
  EXPECT_NEAR(ec8_elastic_spectrum(0.0, 0.3, b), 0.36, tol);
  EXPECT_NEAR(ec8_elastic_spectrum(0.075, 0.3, b), 0.63, tol);
  EXPECT_NEAR(ec8_elastic_spectrum(0.15, 0.3, b), 0.9, tol);
  EXPECT_NEAR(ec8_elastic_spectrum(0.3, 0.3, b), 0.9, tol);
  EXPECT_NEAR(ec8_elastic_spectrum(0.5, 0.3, b), 0.9, tol);
  EXPECT_NEAR(ec8_elastic_spectrum(1.0, 0.3, b), 0.45, tol);
  EXPECT_NEAR(ec8_elastic_spectrum(2.0, 0.3, b), 0.225, tol);
  EXPECT_NEAR(ec8_elastic_spectrum(3.0, 0.3, b), 0.1, tol);
  const Ec8Soil d = *ec8_type1_soil('D');
  EXPECT_EQ(d.s, 1.35);
  EXPECT_NEAR(ec8_elastic_spectrum(0.0, 0.2, d), 0.27, tol);
  EXPECT_NEAR(ec8_elastic_spectrum(0.1, 0.2, d), 0.4725, tol);
  EXPECT_NEAR(ec8_elastic_spectrum(0.5, 0.2, d), 0.675, tol);
  EXPECT_NEAR(ec8_elastic_spectrum(1.6, 0.2, d), 0.3375, tol);
  EXPECT_NEAR(ec8_elastic_spectrum(4.0, 0.2, d), 0.0675, tol);
  // The other classes' soil factors and corner periods (Table 3.2), and no other letters.
  EXPECT_EQ(ec8_type1_soil('A')->s, 1.0);
  EXPECT_EQ(ec8_type1_soil('A')->tc, 0.4);
  EXPECT_EQ(ec8_type1_soil('C')->s, 1.15);
  EXPECT_EQ(ec8_type1_soil('C')->tc, 0.6);
  EXPECT_EQ(ec8_type1_soil('E')->s, 1.4);
  EXPECT_EQ(ec8_type1_soil('E')->tb, 0.15);
  EXPECT_FALSE(ec8_type1_soil('F').has_value());
  EXPECT_FALSE(ec8_type1_soil('b').has_value());
}

TEST(SynthSpectrum, EnvelopeRiseStrongDecay) {
  const SynthEnvelope e = make_synth_envelope(20.0);
  EXPECT_DOUBLE_EQ(e.rise, 2.0);
  EXPECT_DOUBLE_EQ(e.strong_end, 12.8);
  EXPECT_NEAR(e.strong_length(), 10.8, 1e-12);  // >= 10 s: EN 1998-1 3.2.3.1.2 (3)
  EXPECT_DOUBLE_EQ(e.at(0.0), 0.0);
  EXPECT_DOUBLE_EQ(e.at(1.0), 0.25);
  EXPECT_DOUBLE_EQ(e.at(5.0), 1.0);
  EXPECT_NEAR(e.at(20.0), kEnvelopeEnd, 1e-12);
  EXPECT_DOUBLE_EQ(e.at(20.5), 0.0);
}

// The defaults of `voussoir synth --ag 0.25`: 7 records, soil B, 20 s at dt = 0.01 s, seed 1.
struct DefaultSet {
  SynthSettings settings;
  Ec8Soil soil = *ec8_type1_soil('B');
  double ag = 0.25;
  std::vector<double> periods = synth_periods(settings);
  double target(double t) const { return ec8_elastic_spectrum(t, ag, soil); }
  SynthSet make(std::uint64_t seed, int count) const {
    return synthesize_set(
        settings, [this](double t) { return target(t); }, periods, seed, count, ag * soil.s);
  }
};

// EN 1998-1 3.2.3.1.2 (4) on the default set: the mean spectrum within [0.9, 1.3] of the target
// over 0.05-3 s, the mean PGA >= ag S; every record ends at rest and starts from a(0) = 0.
TEST(SynthSet, SevenRecordsMeetTheEc8Rules) {
  const DefaultSet d;
  const SynthSet set = d.make(1, 7);
  ASSERT_EQ(set.records.size(), 7u);
  double least = 1e9, greatest = 0.0, t_least = 0.0;
  for (std::size_t j = 0; j < d.periods.size(); ++j) {
    if (d.periods[j] < 0.05 || d.periods[j] > 3.0) continue;
    const double q = set.mean[j] / d.target(d.periods[j]);
    if (q < least) least = q, t_least = d.periods[j];
    greatest = std::max(greatest, q);
  }
  std::printf(
      "mean / target over 0.05-3 s: %.4f (T = %.3f s) to %.4f; mean PGA %.4f g, "
      "ag S %.3f g, scale %.4f\n",
      least, t_least, greatest, set.mean_pga, d.ag * d.soil.s, set.scale);
  EXPECT_GE(least, 0.9);
  EXPECT_LE(greatest, 1.3);
  EXPECT_GE(set.mean_pga, d.ag * d.soil.s * (1.0 - 1e-12));
  // The range's ends are control periods.
  EXPECT_NE(std::find(d.periods.begin(), d.periods.end(), 0.05), d.periods.end());
  EXPECT_NE(std::find(d.periods.begin(), d.periods.end(), 3.0), d.periods.end());
  for (const SynthRecord& r : set.records) {
    ASSERT_EQ(r.accel.size(), 2001u);
    EXPECT_EQ(r.accel.front(), 0.0);
    const GroundMotion g = ground_motion(r.accel, d.settings.dt);
    std::printf(
        "  PGA %.4f g, PGV %.3f m/s, PGD %.3f m, end v %.1e m/s, end d %.1e m, "
        "iterate %d of %d\n",
        r.pga, g.peak_velocity * 9.81, g.peak_displacement * 9.81, g.end_velocity * 9.81,
        g.end_displacement * 9.81, r.kept, r.iterations);
    EXPECT_LT(std::abs(g.end_velocity * 9.81), 1e-10);
    EXPECT_LT(std::abs(g.end_displacement * 9.81), 1e-10);
    // The stored spectrum is the record's (up to the scale applied to both).
    const std::vector<double> sa = response_spectrum(r.accel, d.settings.dt, d.periods, 0.05);
    for (std::size_t j = 0; j < sa.size(); j += 17) EXPECT_NEAR(sa[j], r.sa[j], 1e-12 * sa[j]);
  }
}

// The same seed gives the same records bit for bit (also on one thread or two, and record i
// whatever the count); another seed gives other records.
TEST(SynthSet, SeedReproducesRecordsBitForBit) {
  const DefaultSet d;
  auto target = [&d](double t) { return d.target(t); };
  const SynthRecord a = synthesize_record(d.settings, target, d.periods, 7, 1);
  const SynthRecord b = synthesize_record(d.settings, target, d.periods, 7, 1);
  EXPECT_EQ(a.accel, b.accel);
  EXPECT_EQ(a.sa, b.sa);
  const SynthRecord other_seed = synthesize_record(d.settings, target, d.periods, 8, 1);
  const SynthRecord other_index = synthesize_record(d.settings, target, d.periods, 7, 0);
  ASSERT_EQ(other_seed.accel.size(), a.accel.size());
  EXPECT_NE(other_seed.accel, a.accel);
  EXPECT_NE(other_index.accel, a.accel);
  double diff = 0.0;
  for (std::size_t k = 0; k < a.accel.size(); ++k)
    diff = std::max(diff, std::abs(a.accel[k] - other_seed.accel[k]));
  EXPECT_GT(diff, 0.1 * a.pga);  // not a rounding difference: another record
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  const SynthSet one = d.make(7, 2);
  omp_set_num_threads(2);
  const SynthSet two = d.make(7, 2);
  omp_set_num_threads(saved);
  EXPECT_EQ(one.records[1].accel, a.accel);
  EXPECT_EQ(two.records[1].accel, a.accel);
  EXPECT_EQ(one.records[0].accel, other_index.accel);
  EXPECT_EQ(two.mean, one.mean);
}

// write_at2 then parse_at2: the count and DT exactly, the values to the 10 digits written (a
// relative 5e-10), and a record read back writes the same text again (so it reads back bit for
// bit).
TEST(SynthAt2, WriteThenReadRoundTrips) {
  std::vector<double> a;
  for (int k = 0; k < 1003; ++k)  // not a multiple of 5: a short last line
    a.push_back(std::sin(0.37 * k) * std::pow(10.0, (k % 9) - 6) * (k % 2 ? -1.0 : 1.0));
  a[0] = -0.0;
  a[1] = 0.0;
  a[2] = 1.0 / 3.0;
  for (const double dt : {0.01, 0.005, 0.0123456789, 1.0 / 3.0}) {
    const std::string text = format_at2(a, dt, "title\nline", "note");
    const Accelerogram rec = parse_at2(text, "mem.AT2", 1.0);
    ASSERT_EQ(rec.accel.size(), a.size());
    EXPECT_EQ(rec.time[1], dt) << dt;
    EXPECT_EQ(rec.time[1000], 1000 * dt) << dt;
    for (std::size_t k = 0; k < a.size(); ++k)
      ASSERT_LE(std::abs(rec.accel[k] - a[k]), 5e-10 * std::abs(a[k])) << k;
    EXPECT_EQ(format_at2(rec.accel, dt, "title\nline", "note"), text);
    const Accelerogram again = parse_at2(text, "mem.AT2", 1.0);
    EXPECT_EQ(again.accel, rec.accel);
  }
  const std::string text = format_at2(a, 0.01, "t", "n");
  EXPECT_EQ(text.substr(0, 4), "t\nn\n");
  EXPECT_NE(text.find("\nNPTS= 1003, DT= 0.01 SEC\n  0.000000000E+00  0.000000000E+00"),
            std::string::npos)
      << text.substr(0, 200);
  // Through a file, read as any deck's record is.
  std::filesystem::create_directories(temp_dir());
  const std::string path = (temp_dir() / "round.AT2").string();
  write_at2(path, a, 0.01, "t", "n");
  const Accelerogram file = read_accelerogram(path, "g", 1.0);
  EXPECT_EQ(file.accel, parse_at2(text, "mem.AT2", 1.0).accel);
  std::filesystem::remove_all(temp_dir());
}

testing::ProcessResult run_synth(std::vector<std::string> extra) {
  std::vector<std::string> args = {VOUSSOIR_BINARY, "synth"};
  args.insert(args.end(), extra.begin(), extra.end());
  testing::Limits limits;
  limits.wall_s = 60;
  std::filesystem::create_directories(temp_dir());
  return testing::run_process(args, limits, (temp_dir() / "child").string());
}

// The command: two records written and read back, the CSV's columns, the JSON; each bad option
// refused with exit status 2 and a message naming the option and its value.
TEST(SynthCommand, WritesRecordsAndRefusesBadOptions) {
  const std::string out = (temp_dir() / "out").string();
  const std::string json = (temp_dir() / "synth.json").string();
  testing::ProcessResult r = run_synth({"--ag", "0.2", "--soil", "c", "--count", "2", "--seed", "3",
                                        "-o", out, "--no-plot", "--json", json});
  ASSERT_TRUE(r.exited && r.status == 0) << r.describe() << r.err;
  EXPECT_NE(r.out.find("mean PGA >= ag S: met"), std::string::npos) << r.out;
  const Accelerogram rec = read_accelerogram(out + "/synth_02.AT2", "g", 1.0);
  EXPECT_EQ(rec.accel.size(), 2001u);
  EXPECT_EQ(rec.time[1], 0.01);
  std::ifstream csv(out + "/spectra.csv");
  std::string head;
  std::getline(csv, head);
  EXPECT_EQ(head, "period,target,synth_01,synth_02,mean");
  int rows = 0;
  for (std::string line; std::getline(csv, line);) ++rows;
  EXPECT_EQ(rows, 102);  // 100 log-spaced periods and the range's two ends
  EXPECT_TRUE(std::filesystem::exists(json));
  EXPECT_NE(testing::read_text_file(json).find("\"ec8_mean_pga_ok\": true"), std::string::npos);

  struct Bad {
    std::vector<std::string> args;
    std::string names;  // the option and value the message must name
  };
  const std::vector<Bad> bad = {
      {{"--ag", "0.25", "--count", "0"}, "--count 0"},
      {{"--ag", "0"}, "--ag 0"},
      {{"--ag", "-0.1"}, "--ag -0.1"},
      {{"--ag", "nan"}, "--ag nan"},
      {{"--ag", "9.81"}, "--ag 9.81"},
      {{"--ag", "0.25", "--soil", "F"}, "--soil F"},
      {{"--ag", "0.25", "--spectrum", "asce"}, "--spectrum asce"},
      {{"--ag", "0.25", "--duration", "4"}, "--duration 4"},
      {{"--ag", "0.25", "--dt", "0"}, "--dt 0"},
      {{"--ag", "0.25", "--dt", "-0.01"}, "--dt -0.01"},
      {{"--ag", "0.25", "--dt", "0.02"}, "--dt 0.02"},
      {{"--ag", "0.25", "--seed", "-1"}, "--seed -1"},
      {{"--ag", "0.25", "--range", "3,0.05"}, "--range 3,0.05"},
      {{"--count", "3"}, "--ag"},  // --ag is required
  };
  for (const Bad& b : bad) {
    std::vector<std::string> args = b.args;
    args.insert(args.end(), {"-o", (temp_dir() / "bad").string(), "--no-plot"});
    r = run_synth(args);
    EXPECT_TRUE(r.exited && r.status == 2) << b.names << ": " << r.describe();
    EXPECT_NE(r.err.find(b.names), std::string::npos) << b.names << ": " << r.err;
  }
  EXPECT_FALSE(std::filesystem::exists(temp_dir() / "bad"));  // refused before writing
  std::filesystem::remove_all(temp_dir());
}

}  // namespace
}  // namespace voussoir

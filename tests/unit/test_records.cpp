// Earthquake records (seismic/accelerogram: the PEER AT2 reader, the baseline correction) and their
// response spectra (seismic/spectrum: exact integration of the piecewise-linear record) against
// hand-written files and closed forms. The figures printed here are quoted in docs/records.md:
//   build/test_records   (or: ctest --test-dir build -R Records -V)

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "seismic/accelerogram.hpp"
#include "seismic/base_motion.hpp"
#include "seismic/spectrum.hpp"
#include "subprocess.hpp"

namespace voussoir {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kG = 9.81;

// Writes `text` to a file in the test's temporary folder and returns its path.
std::filesystem::path temp_dir() {
  return std::filesystem::temp_directory_path() /
         ("voussoir_records_" + std::to_string(::getpid()));
}

std::string write_file(const std::string& name, const std::string& text) {
  const std::filesystem::path dir = temp_dir();
  std::filesystem::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

// The message of the DeckError that reading `path` throws ("no error" if none).
std::string read_error(const std::string& path, const std::string& units = "g") {
  try {
    read_accelerogram(path, units, kG);
  } catch (const DeckError& e) {
    return e.what();
  }
  return "no error";
}

const char* kHeader3 =
    "PEER NGA STRONG MOTION DATABASE RECORD\n"
    "Synthetic test record, voussoir\n"
    "ACCELERATION TIME SERIES IN UNITS OF G\n";
// Seven values, five then two a line, Fortran style.
const char* kValues =
    "  .1234E-02 -.5000E+00  0.2500E+00  1.0D-03   -2.5E-1\n"
    "   .7500E+00  0.0000E+00\n";
const double kExpected[7] = {.1234E-02, -.5000E+00, 0.2500E+00, 1.0E-03, -2.5E-1, .7500E+00, 0.0};

void expect_exact(const Accelerogram& rec, double dt) {
  ASSERT_EQ(rec.accel.size(), 7u);
  ASSERT_EQ(rec.time.size(), 7u);
  for (int k = 0; k < 7; ++k) {
    EXPECT_EQ(rec.accel[k], kExpected[k] * kG) << k;
    EXPECT_EQ(rec.time[k], k * dt) << k;
  }
}

TEST(RecordsAt2, ReadsBothHeaderFormsExactly) {
  // NGA-West2 header, detected by the extension.
  const std::string west2 =
      write_file("west2.AT2", std::string(kHeader3) + "NPTS=     7, DT=   .0050 SEC\n" + kValues);
  expect_exact(read_accelerogram(west2, "g", kG), 0.005);
  // The older header, detected by its 4th line (no .AT2 extension).
  const std::string old =
      write_file("older.txt", std::string(kHeader3) + "    7    0.0100    NPTS, DT\n" + kValues);
  expect_exact(read_accelerogram(old, "g", kG), 0.01);
  // A lower-case extension and no space after '='.
  const std::string lower =
      write_file("lower.at2", std::string(kHeader3) + "NPTS=7, DT=.02 SEC\n" + kValues);
  expect_exact(read_accelerogram(lower, "g", kG), 0.02);
  // The two-column reader still reads two-column files.
  const std::string two = write_file("two.csv", "0, 0\n0.01, 0.5\n0.02, -0.25\n");
  EXPECT_EQ(read_accelerogram(two, "g", kG).accel[1], 0.5 * kG);
  std::filesystem::remove_all(temp_dir());
}

TEST(RecordsAt2, MalformedFilesNameFileAndLine) {
  const std::string h = kHeader3;
  // Fewer values than NPTS: the last line.
  std::string e = read_error(write_file("short.AT2", h + "NPTS= 8, DT= .005 SEC\n" + kValues));
  EXPECT_NE(e.find("short.AT2:6:"), std::string::npos) << e;
  EXPECT_NE(e.find("found 7 values"), std::string::npos) << e;
  // More values than NPTS: the line of the first extra value.
  e = read_error(write_file("long.AT2", h + "NPTS= 4, DT= .005 SEC\n" + kValues));
  EXPECT_NE(e.find("long.AT2:5:"), std::string::npos) << e;
  EXPECT_NE(e.find("more values than NPTS = 4"), std::string::npos) << e;
  // DT <= 0, DT not a number, NPTS missing.
  e = read_error(write_file("dt0.AT2", h + "NPTS= 7, DT= 0.0 SEC\n" + kValues));
  EXPECT_NE(e.find("dt0.AT2:4:"), std::string::npos) << e;
  EXPECT_NE(e.find("DT = 0 s is not > 0"), std::string::npos) << e;
  e = read_error(write_file("dtneg.AT2", h + "7  -0.01  NPTS, DT\n" + kValues));
  EXPECT_NE(e.find("dtneg.AT2:4:"), std::string::npos) << e;
  e = read_error(write_file("dtbad.AT2", h + "NPTS= 7, DT= abc SEC\n" + kValues));
  EXPECT_NE(e.find("dtbad.AT2:4:"), std::string::npos) << e;
  e = read_error(write_file("nohead.AT2", h + "7 0.005\n" + kValues));
  EXPECT_NE(e.find("nohead.AT2:4:"), std::string::npos) << e;
  e = read_error(write_file("npts.AT2", h + "NPTS= 6.5, DT= .005 SEC\n" + kValues));
  EXPECT_NE(e.find("npts.AT2:4:"), std::string::npos) << e;
  // A value that is not a number, and one that is not finite.
  e = read_error(
      write_file("word.AT2", h + "NPTS= 7, DT= .005 SEC\n" + "  .1E-02 .2E-02\n .3E-02 x12 .5\n"));
  EXPECT_NE(e.find("word.AT2:6:"), std::string::npos) << e;
  EXPECT_NE(e.find("'x12' is not a finite number"), std::string::npos) << e;
  e = read_error(write_file("inf.AT2", h + "NPTS= 3, DT= .005 SEC\n" + "  .1E-02 inf 0.0\n"));
  EXPECT_NE(e.find("inf.AT2:5:"), std::string::npos) << e;
  // A header cut short; AT2 values are in g.
  e = read_error(write_file("cut.AT2", "PEER\nline two\n"));
  EXPECT_NE(e.find("cut.AT2:2:"), std::string::npos) << e;
  e = read_error(write_file("units.AT2", h + "NPTS= 7, DT= .005 SEC\n" + kValues), "m/s2");
  EXPECT_NE(e.find("units.AT2: a PEER AT2 record is in g"), std::string::npos) << e;
  std::filesystem::remove_all(temp_dir());
}

// Exact double integration of a uniform piecewise-linear record from rest (the table motion of
// seismic/base_motion.hpp): the final table velocity and displacement.
void final_motion(const Accelerogram& rec, double& v, double& d) {
  v = d = 0.0;
  for (std::size_t k = 0; k + 1 < rec.time.size(); ++k) {
    const double h = rec.time[k + 1] - rec.time[k];
    d += h * v + h * h * (2.0 * rec.accel[k] + rec.accel[k + 1]) / 6.0;
    v += h * (rec.accel[k] + rec.accel[k + 1]) / 2.0;
  }
}

// A 3-cycle windowed sine at 1 Hz (0.3 g; it ends at rest and at d = 0, seismic/base_motion.hpp)
// in a 20 s record at dt = 0.01 s, plus a drift `offset + slope t` [m/s2, m/s3].
Accelerogram drifting_record(double offset, double slope) {
  Accelerogram rec;
  for (int k = 0; k <= 2000; ++k) {
    const double t = 0.01 * k;
    rec.time.push_back(t);
    rec.accel.push_back(windowed_sine(t, 0.3 * kG, 1.0, 3) + offset + slope * t);
  }
  return rec;
}

TEST(RecordsBaseline, RemovesAnOffsetAndALinearDrift) {
  double v0, d0, v, d;
  final_motion(drifting_record(0.0, 0.0), v0, d0);  // the clean record ends near rest
  // A constant offset of 0.01 g: v(T) = 0.0981 T, d(T) = 0.0981 T^2 / 2 (1.96 m/s, 19.6 m).
  Accelerogram rec = drifting_record(0.01 * kG, 0.0);
  final_motion(rec, v, d);
  std::printf("baseline: clean record ends at v = %.3e m/s, d = %.3e m\n", v0, d0);
  std::printf("baseline: offset 0.01 g, none:     v = %.4f m/s, d = %.4f m\n", v, d);
  EXPECT_NEAR(v, 0.01 * kG * 20.0, 1e-3);
  EXPECT_NEAR(d, 0.01 * kG * 200.0, 1e-2);
  correct_baseline(rec, baseline_degree("constant"));
  final_motion(rec, v, d);
  std::printf("baseline: offset 0.01 g, constant: v = %.3e m/s, d = %.3e m\n", v, d);
  EXPECT_LT(std::abs(v), 1e-3);  // of 1.96 m/s
  EXPECT_LT(std::abs(d), 1e-3);  // of 19.6 m
  // An offset and a slope: the linear correction removes both.
  rec = drifting_record(0.01 * kG, 0.002 * kG);
  final_motion(rec, v, d);
  std::printf("baseline: offset 0.01 g + 0.002 g/s, none:   v = %.4f m/s, d = %.4f m\n", v, d);
  correct_baseline(rec, baseline_degree("linear"));
  final_motion(rec, v, d);
  std::printf("baseline: offset 0.01 g + 0.002 g/s, linear: v = %.3e m/s, d = %.3e m\n", v, d);
  EXPECT_LT(std::abs(v), 1e-3);  // of 5.89 m/s
  EXPECT_LT(std::abs(d), 1e-3);  // of 45.8 m
  // A parabolic drift on top, 0.0002 g/s^2 t^2: the linear correction leaves a part of it, the
  // quadratic one removes it.
  rec = drifting_record(0.01 * kG, 0.002 * kG);
  for (std::size_t k = 0; k < rec.accel.size(); ++k)
    rec.accel[k] += 0.0002 * kG * rec.time[k] * rec.time[k];
  Accelerogram linear = rec;
  correct_baseline(linear, baseline_degree("linear"));
  double v_lin, d_lin;
  final_motion(linear, v_lin, d_lin);
  correct_baseline(rec, baseline_degree("quadratic"));
  final_motion(rec, v, d);
  std::printf(
      "baseline: parabolic drift, linear: v = %.3e m/s, d = %.3e m; quadratic: v = %.3e "
      "m/s, d = %.3e m\n",
      v_lin, d_lin, v, d);
  EXPECT_LT(std::abs(v), 1e-3);
  EXPECT_LT(std::abs(d), 1e-3);
  EXPECT_GT(std::abs(d_lin), 0.1);
  // "none" leaves the record as it is.
  rec = drifting_record(0.01 * kG, 0.0);
  const Accelerogram same = rec;
  correct_baseline(rec, baseline_degree("none"));
  EXPECT_EQ(rec.accel, same.accel);
  // Only for file signals.
  BaseConfig base;
  base.signal = "windowed_sine";
  base.baseline = "linear";
  EXPECT_THROW(make_base_signal(base, kG), DeckError);
}

// (a) Harmonic base acceleration a_g = A sin(w_g t). The oscillator u'' + 2 z w u' + w^2 u =
// -a_g settles to u = -A / w^2 H sin(w_g t - phi) with the dynamic amplification
//     H = 1 / sqrt((1 - r^2)^2 + (2 z r)^2),   r = w_g / w,
// so its steady pseudo-acceleration is Sa = w^2 max|u| = A H. The transient decays as
// e^{-z w t}: over 60 s it is below e^{-0.05 pi 60} = 8e-5 of its start for T <= 2 s; the peak
// is read over the last 20 s of an 80 s record, at dt = 0.002 s (500 samples a cycle).
TEST(RecordsSpectrum, HarmonicSteadyStateAmplitude) {
  const double a = 1.0, tg = 1.0, wg = 2.0 * kPi / tg, dt = 0.002, z = 0.05;
  std::vector<double> acc(40001);
  for (std::size_t k = 0; k < acc.size(); ++k) acc[k] = a * std::sin(wg * dt * double(k));
  for (double period : {0.25, 0.5, 0.9, 1.0, 1.1, 2.0}) {
    const double w = 2.0 * kPi / period, r = wg / w;
    const double closed = a / std::sqrt((1 - r * r) * (1 - r * r) + (2 * z * r) * (2 * z * r));
    const double sa = w * w * sdof_peak_displacement(acc, dt, period, z, 30000, acc.size());
    std::printf("harmonic: T = %.2f s (r = %.2f): Sa = %.6f, closed form %.6f, error %.2e\n",
                period, r, sa, closed, sa / closed - 1.0);
    EXPECT_NEAR(sa / closed, 1.0, 1e-3);  // the contract: 1%
  }
}

// (b) Ramped step, z = 0: a_g rises linearly from 0 to A over t_r, then stays. With
// w_r = w t_r, during the ramp u = -(A / w^2) (t / t_r - sin(w t) / w_r); after it
//     u = -(A / w^2) [1 + (sin w (t - t_r) - sin w t) / w_r],
// whose oscillating part has amplitude 2 |sin(w t_r / 2)| / w_r, so
//     Sa = w^2 max|u| = A (1 + |sin(pi t_r / T)| / (pi t_r / T))
// (the dynamic amplification of a ramp, Chopra 4.5). The ramp is exactly piecewise linear on
// the samples (t_r a multiple of dt), so only the reading of the peak at samples errs.
TEST(RecordsSpectrum, RampedStepPeak) {
  const double a = 2.0, dt = 0.001, period = 1.0;
  for (double tr : {0.2, 0.5, 0.75, 1.0, 1.6, 3.3}) {
    const std::size_t nr = static_cast<std::size_t>(std::lround(tr / dt));
    std::vector<double> acc(nr + 3000);
    for (std::size_t k = 0; k < acc.size(); ++k) acc[k] = k < nr ? a * double(k) / double(nr) : a;
    const double x = kPi * tr / period;
    const double closed = a * (1.0 + std::abs(std::sin(x)) / x);
    const double w = 2.0 * kPi / period;
    const double sa = w * w * sdof_peak_displacement(acc, dt, period, 0.0, 0, acc.size());
    std::printf("ramp: t_r / T = %.2f: Sa / A = %.6f, closed form %.6f, error %.2e\n", tr / period,
                sa / a, closed / a, sa / closed - 1.0);
    EXPECT_NEAR(sa / closed, 1.0, 1e-6);  // the contract: 1%
  }
}

// (c) T -> 0: the stiff oscillator follows the base, Sa -> PGA. A two-sine record (1.3 and
// 2.9 Hz) at dt = 0.005 s: at T = 0.02 s the quasi-static error is about (2.9 T)^2 ~ 0.3%.
TEST(RecordsSpectrum, ShortPeriodsGiveThePga) {
  std::vector<double> acc(2001);
  for (std::size_t k = 0; k < acc.size(); ++k) {
    const double t = 0.005 * double(k);
    acc[k] = 0.3 * std::sin(2 * kPi * 1.3 * t) + 0.2 * std::sin(2 * kPi * 2.9 * t + 0.4);
  }
  double pga = 0.0;
  for (double x : acc) pga = std::max(pga, std::abs(x));
  const std::vector<double> periods = {0.001, 0.005, 0.02};
  const std::vector<double> sa = response_spectrum(acc, 0.005, periods);
  for (std::size_t i = 0; i < periods.size(); ++i)
    std::printf("short periods: T = %.3f s: Sa / PGA = %.6f\n", periods[i], sa[i] / pga);
  EXPECT_NEAR(sa[0] / pga, 1.0, 1e-3);
  EXPECT_NEAR(sa[1] / pga, 1.0, 5e-3);
  EXPECT_NEAR(sa[2] / pga, 1.0, 0.01);
}

// The step matrices of an undamped oscillator against the closed form of one step:
// u1 = p1/k + (u0 - p0/k) cos wh + (v0 - (p1 - p0)/(k h)) sin(wh) / w, k = w^2.
TEST(RecordsSpectrum, UndampedStepMatrices) {
  const double w = 3.0, h = 0.1, k = w * w, c = std::cos(w * h), s = std::sin(w * h);
  const SdofStep m = make_sdof_step(w, 0.0, h);
  EXPECT_NEAR(m.a00, c, 1e-14);
  EXPECT_NEAR(m.a01, s / w, 1e-14);
  EXPECT_NEAR(m.b00, (-c + s / (w * h)) / k, 1e-14);
  EXPECT_NEAR(m.b01, (1.0 - s / (w * h)) / k, 1e-14);
  EXPECT_NEAR(m.a10, -w * s, 1e-14);
  EXPECT_NEAR(m.a11, c, 1e-14);
  const std::vector<double> t = log_spaced_periods(0.02, 4.0, 100);
  ASSERT_EQ(t.size(), 100u);
  EXPECT_DOUBLE_EQ(t.front(), 0.02);
  EXPECT_DOUBLE_EQ(t.back(), 4.0);
  EXPECT_NEAR(t[1] / t[0], t[99] / t[98], 1e-12);
}

// `voussoir pulse DECK --spectrum F.csv --spectrum-only` on an AT2 record: the CSV of 100
// periods from 0.02 to 4 s, Sa(0.02 s) close to the PGA; a malformed record and
// --spectrum-only without --spectrum exit 2 (the record's message names file and line).
TEST(RecordsSpectrum, PulseWritesTheSpectrumCsv) {
  std::string values;
  for (int k = 0; k < 400; ++k) {
    char v[32];
    std::snprintf(v, sizeof v, " %.7E%s", 0.2 * std::sin(2 * kPi * 2.0 * 0.01 * k),
                  k % 5 == 4 ? "\n" : "");
    values += v;
  }
  const std::string rec =
      write_file("cli.AT2", std::string(kHeader3) + "NPTS=   400, DT=   .0100 SEC\n" + values);
  const std::string csv = (temp_dir() / "spectrum.csv").string();
  const std::string deck = std::string(VOUSSOIR_SOURCE_DIR) + "/cases/circular_arch.toml";
  auto pulse = [&](const std::string& file, std::vector<std::string> extra) {
    std::vector<std::string> args = {VOUSSOIR_BINARY,
                                     "pulse",
                                     deck,
                                     "--set",
                                     "load.base.signal=\"file\"",
                                     "--set",
                                     "load.base.file=\"" + file + "\""};
    args.insert(args.end(), extra.begin(), extra.end());
    testing::Limits limits;
    limits.wall_s = 30;
    return testing::run_process(args, limits, (temp_dir() / "child").string());
  };
  testing::ProcessResult r = pulse(rec, {"--spectrum", csv, "--spectrum-only"});
  ASSERT_TRUE(r.exited && r.status == 0) << r.describe() << r.err;
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "period,sa_g");
  std::vector<double> period, sa;
  while (std::getline(in, line)) {
    period.push_back(std::stod(line));
    sa.push_back(std::stod(line.substr(line.find(',') + 1)));
  }
  ASSERT_EQ(period.size(), 100u);
  EXPECT_NEAR(period.front(), 0.02, 1e-12);
  EXPECT_NEAR(period.back(), 4.0, 1e-12);
  EXPECT_NEAR(sa.front() / 0.2, 1.0, 0.02);  // 2 Hz at T = 0.02 s: quasi-static
  const std::string bad = write_file("bad.AT2", std::string(kHeader3) + "NPTS= 9, DT= .01\n1 2\n");
  r = pulse(bad, {"--spectrum", csv, "--spectrum-only"});
  EXPECT_TRUE(r.exited && r.status == 2) << r.describe();
  EXPECT_NE(r.err.find("bad.AT2:5:"), std::string::npos) << r.err;
  r = pulse(rec, {"--spectrum-only"});
  EXPECT_TRUE(r.exited && r.status == 2) << r.describe();
  std::filesystem::remove_all(temp_dir());
}

}  // namespace
}  // namespace voussoir

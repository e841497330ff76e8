// Earthquake records (io/accelerogram: the PEER AT2 reader, the baseline correction) against
// hand-written files. The figures printed here are quoted in docs/records.md:
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

#include "core/base_motion.hpp"
#include "io/accelerogram.hpp"

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
// core/base_motion.hpp): the final table velocity and displacement.
void final_motion(const Accelerogram& rec, double& v, double& d) {
  v = d = 0.0;
  for (std::size_t k = 0; k + 1 < rec.time.size(); ++k) {
    const double h = rec.time[k + 1] - rec.time[k];
    d += h * v + h * h * (2.0 * rec.accel[k] + rec.accel[k + 1]) / 6.0;
    v += h * (rec.accel[k] + rec.accel[k + 1]) / 2.0;
  }
}

// A 3-cycle windowed sine at 1 Hz (0.3 g; it ends at rest and at d = 0, core/base_motion.hpp)
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

}  // namespace
}  // namespace voussoir

// Base-excitation signals (seismic/base_motion; the accelerogram reader in seismic/accelerogram): the Bohman window, the windowed sine ending at
// rest, the integration of table velocity and displacement, the zero-phase band-pass filter,
// and the accelerogram reader.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "io/deck.hpp"
#include "seismic/accelerogram.hpp"

namespace voussoir {
namespace {

constexpr double kPi = std::numbers::pi;

// Composite Simpson rule of f over [a, b] with n (even) intervals: an integration independent
// of the one in BaseSignal.
template <class F>
double simpson(F f, double a, double b, int n) {
  const double h = (b - a) / n;
  double s = f(a) + f(b);
  for (int i = 1; i < n; ++i) s += (i % 2 ? 4.0 : 2.0) * f(a + i * h);
  return s * h / 3.0;
}

TEST(BohmanWindow, ValuesAtZeroHalfAndOne) {
  EXPECT_DOUBLE_EQ(bohman_window(0.0), 1.0);
  EXPECT_NEAR(bohman_window(0.5), 1.0 / kPi, 1e-15);
  EXPECT_NEAR(bohman_window(-0.5), 1.0 / kPi, 1e-15);
  EXPECT_NEAR(bohman_window(1.0), 0.0, 1e-15);
  EXPECT_NEAR(bohman_window(-1.0), 0.0, 1e-15);
  EXPECT_EQ(bohman_window(1.5), 0.0);
}

TEST(WindowedSine, FormulaAndSupport) {
  const double a = 2.0, f = 4.0;
  const int cycles = 3;
  const double t = 0.3;  // inside T = 0.75 s
  EXPECT_NEAR(windowed_sine(t, a, f, cycles),
              a * bohman_window(2.0 * t / 0.75 - 1.0) * std::sin(2.0 * kPi * f * t), 1e-15);
  EXPECT_EQ(windowed_sine(-0.01, a, f, cycles), 0.0);
  EXPECT_EQ(windowed_sine(0.76, a, f, cycles), 0.0);
  const BaseSignal s = BaseSignal::windowed(a, f, cycles);
  EXPECT_DOUBLE_EQ(s.duration(), 0.75);
  EXPECT_DOUBLE_EQ(s.acceleration(t), windowed_sine(t, a, f, cycles));
}

// The table velocity at the end of the windowed sine is zero (relative 1e-6 of A/f), by an
// independent quadrature of the formula and by the signal's own integration, for several
// cycle counts; mid-way it is not, and there the two integrations agree.
TEST(WindowedSine, EndsWithZeroTableVelocity) {
  const double a = 9.81 * 0.3;
  for (int cycles : {1, 3, 5}) {
    for (double f : {2.0, 7.5}) {
      const double duration = cycles / f;
      auto acc = [&](double t) { return windowed_sine(t, a, f, cycles); };
      const double v_end = simpson(acc, 0.0, duration, 200000);
      EXPECT_LT(std::abs(v_end), 1e-6 * a / f) << cycles << " cycles at " << f << " Hz";
      const BaseSignal s = BaseSignal::windowed(a, f, cycles);
      EXPECT_LT(std::abs(s.velocity(duration)), 1e-6 * a / f);
      EXPECT_LT(std::abs(s.velocity(duration + 1.0)), 1e-6 * a / f);
      // Not trivially zero: a quarter of the way in the table moves at a fraction of A/f.
      const double tq = 0.25 * duration;
      const double v_q = simpson(acc, 0.0, tq, 200000);
      EXPECT_GT(std::abs(v_q), 1e-3 * a / f);
      EXPECT_NEAR(s.velocity(tq), v_q, 1e-6 * a / f);
      // Displacement: independent double integral d(t) = int_0^t (t - s) a(s) ds.
      const double d_end =
          simpson([&](double u) { return (duration - u) * acc(u); }, 0.0, duration, 200000);
      EXPECT_NEAR(s.displacement(duration), d_end, 1e-6 * a / (f * f));
      // At rest after the pulse: the displacement stays.
      EXPECT_NEAR(s.displacement(duration + 1.0), s.displacement(duration), 1e-6 * a / (f * f));
    }
  }
}

// One sine cycle: v(t) = A/(2 pi f) (1 - cos 2 pi f t), d(1/f) = A / (2 pi f^2).
TEST(SinePulse, ClosedFormMotion) {
  const double a = 3.0, f = 5.0, w = 2.0 * kPi * f;
  const BaseSignal s = BaseSignal::one_sine(a, f);
  EXPECT_DOUBLE_EQ(s.duration(), 0.2);
  EXPECT_DOUBLE_EQ(s.acceleration(0.05), a);
  EXPECT_EQ(s.acceleration(0.25), 0.0);
  for (double t : {0.013, 0.05, 0.1, 0.17}) {
    EXPECT_NEAR(s.velocity(t), a / w * (1.0 - std::cos(w * t)), 1e-6 * a / f) << t;
    EXPECT_NEAR(s.displacement(t), a / w * (t - std::sin(w * t) / w), 1e-6 * a / (f * f)) << t;
  }
  EXPECT_NEAR(s.velocity(0.2), 0.0, 1e-9 * a / f);
  EXPECT_NEAR(s.displacement(0.2), a / (w * f), 1e-6 * a / (f * f));
  // After the pulse the table coasts at zero velocity: displacement constant.
  EXPECT_NEAR(s.displacement(1.0), a / (w * f), 1e-6 * a / (f * f));
}

// Largest |x| over samples with index in [begin, end).
double peak(const std::vector<double>& x, std::size_t begin, std::size_t end) {
  double p = 0.0;
  for (std::size_t i = begin; i < end; ++i) p = std::max(p, std::abs(x[i]));
  return p;
}

// band [1, 50] Hz: a 10 Hz sine passes within 1% (pointwise, so also without phase shift);
// 0.2 Hz and 100 Hz sines come out below 5% of their amplitude. Sampled at 1 kHz for 60 s;
// read in the middle 20 s, away from the onset transients.
TEST(BandPass, PassesTenHertzRemovesPointTwoAndHundred) {
  const double dt = 1e-3, duration = 60.0;
  const std::size_t n = static_cast<std::size_t>(duration / dt) + 1;
  const std::size_t m0 = n / 3, m1 = 2 * n / 3;
  auto sine = [&](double f) {
    std::vector<double> x(n);
    for (std::size_t k = 0; k < n; ++k) x[k] = std::sin(2.0 * kPi * f * k * dt);
    return x;
  };
  {
    const std::vector<double> x = sine(10.0);
    std::size_t tail = 0;
    const std::vector<double> y = bandpass_zero_phase(x, dt, 1.0, 50.0, &tail);
    ASSERT_EQ(y.size(), n + tail);
    EXPECT_NEAR(peak(y, m0, m1), 1.0, 0.01);
    double err = 0.0;
    for (std::size_t k = m0; k < m1; ++k) err = std::max(err, std::abs(y[k] - x[k]));
    EXPECT_LT(err, 0.01);
  }
  EXPECT_LT(peak(bandpass_zero_phase(sine(0.2), dt, 1.0, 50.0), m0, m1), 0.05);
  EXPECT_LT(peak(bandpass_zero_phase(sine(100.0), dt, 1.0, 50.0), m0, m1), 0.05);

  // The same through an accelerogram table (the production path: resampling + filter).
  Accelerogram rec;
  for (std::size_t k = 0; k < n; ++k) {
    rec.time.push_back(k * dt);
    rec.accel.push_back(std::sin(2.0 * kPi * 10.0 * k * dt) + std::sin(2.0 * kPi * 0.2 * k * dt) +
                        std::sin(2.0 * kPi * 100.0 * k * dt));
  }
  const BaseSignal s = BaseSignal::table(rec, 1.0, 50.0);
  double err = 0.0;
  for (double t = 20.0; t < 40.0; t += 0.0007)
    err = std::max(err, std::abs(s.acceleration(t) - std::sin(2.0 * kPi * 10.0 * t)));
  // 0.2 Hz and 100 Hz residues (< 5% each) plus the linear interpolation of a 10 Hz sine
  // between 1 ms samples (< (2 pi 10 dt)^2 / 8 = 0.5%).
  EXPECT_LT(err, 0.1);
}

// Filter design: the digital cut-off of each 4th-order section pair is exactly 1/sqrt(2)
// (pre-warped bilinear transform), and the one-pass gain follows 1/sqrt(1 + (f/fc)^8) at low
// frequency.
TEST(BandPass, ButterworthCutOffs) {
  const double dt = 1e-3;
  const auto lp = butterworth4(50.0, dt, false), hp = butterworth4(1.0, dt, true);
  EXPECT_NEAR(cascade_gain(lp, 50.0, dt), 1.0 / std::sqrt(2.0), 1e-12);
  // The 1 Hz sections at dt = 1 ms have poles within 2 pi f dt = 6.3e-3 of z = 1: their gain
  // is computed with a condition number ~ 1 / (2 pi f dt)^2, so rounding (which differs with
  // and without FMA, -march=native) reaches ~eps / (2 pi f dt)^2 = 5.6e-12; allow 100 times it.
  const double hp_rounding = 100.0 * std::numeric_limits<double>::epsilon() /
                             std::pow(2.0 * std::acos(-1.0) * 1.0 * dt, 2);
  EXPECT_NEAR(cascade_gain(hp, 1.0, dt), 1.0 / std::sqrt(2.0), hp_rounding);
  EXPECT_NEAR(cascade_gain(lp, 0.0, dt), 1.0, 1e-12);
  EXPECT_NEAR(cascade_gain(hp, 0.0, dt), 0.0, hp_rounding);
  EXPECT_NEAR(cascade_gain(hp, 0.2, dt), std::pow(0.2, 4) / std::sqrt(1.0 + std::pow(0.2, 8)),
              1e-5);
}

TEST(Accelerogram, ParsesCommentsCommasAndUnits) {
  const std::string text =
      "# time, acceleration [g]\n"
      "0.0, 0.0\n"
      "\n"
      "0.01  0.5   # peak\n"
      "0.02,\t-0.25\r\n";
  const Accelerogram rec = parse_accelerogram(text, "rec.csv", "g", 9.81);
  ASSERT_EQ(rec.time.size(), 3u);
  EXPECT_DOUBLE_EQ(rec.time[1], 0.01);
  EXPECT_DOUBLE_EQ(rec.accel[1], 0.5 * 9.81);
  EXPECT_DOUBLE_EQ(rec.accel[2], -0.25 * 9.81);
  const Accelerogram si = parse_accelerogram(text, "rec.csv", "m/s2", 9.81);
  EXPECT_DOUBLE_EQ(si.accel[1], 0.5);

  // Linear interpolation, zero outside the record.
  const BaseSignal s = BaseSignal::table(rec);
  EXPECT_NEAR(s.acceleration(0.005), 0.25 * 9.81, 1e-12);
  EXPECT_NEAR(s.acceleration(0.015), 0.125 * 9.81, 1e-12);
  EXPECT_EQ(s.acceleration(0.03), 0.0);
  EXPECT_EQ(s.acceleration(-0.001), 0.0);
}

// A bad line names the file and the line number.
TEST(Accelerogram, BadInputNamesFileAndLine) {
  auto message = [](const std::string& text) {
    try {
      parse_accelerogram(text, "quake.txt", "g", 9.81);
    } catch (const DeckError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("0 0\n0.1 0.2\n0.2 abc\n").find("quake.txt:3:"), std::string::npos);
  EXPECT_NE(message("0 0\n0.1 0.2 0.3\n").find("quake.txt:2:"), std::string::npos);
  EXPECT_NE(message("# c\n0 0\n0.1 1\n0.1 2\n").find("quake.txt:4:"), std::string::npos);
  EXPECT_NE(message("0 0\n").find("at least two samples"), std::string::npos);
  EXPECT_NE(message("0 nan\n1 0\n").find("quake.txt:1:"), std::string::npos);
}

TEST(BaseSignalConfig, BandOnlyForFilesAndScaling) {
  BaseConfig base;
  base.signal = "windowed_sine";
  base.amplitude = 0.5;
  base.frequency = 2.0;
  const BaseSignal s = make_base_signal(base, 9.81);
  EXPECT_NEAR(s.acceleration(0.75), windowed_sine(0.75, 0.5 * 9.81, 2.0, 3), 1e-15);
  base.band = {1.0, 50.0};
  EXPECT_THROW(make_base_signal(base, 9.81), DeckError);
  base.signal = "none";
  base.band = {0.0, 0.0};
  EXPECT_EQ(make_base_signal(base, 9.81).acceleration(0.3), 0.0);
}

}  // namespace
}  // namespace voussoir

// The stepping amplitude search of `voussoir pulse --curve` (commands/pulse.hpp) on a case whose
// collapse is not monotone in the amplitude: a slender rigid block (width 0.2 m, height 1 m,
// b/h = 0.2, mu = 0.8 so it rocks and never slides) under one full sine cycle of base
// acceleration (`sine_pulse`) at 5 Hz.
//
// The reference is computed beside the test by a separate method: Housner's (1963) rocking
// equation of a rigid block on a rigid base, integrated here by RK4,
//     theta'' = -p^2 [sin(alpha sgn(theta) - theta) + (a_g / g) cos(alpha sgn(theta) - theta)],
//     p^2 = 3 g / (4 R),  R = half the diagonal,  alpha = atan(b / h),
// rocking starting when |a_g| > g tan(alpha), each impact (theta crossing 0) multiplying the
// angular velocity by r. It gives the three regimes of Zhang & Makris (2001):
//   - overturning after one impact (mode 2) from an onset A_2(r) that depends on r;
//   - a band of amplitudes above it where the block survives;
//   - overturning without any impact (mode 1) from A_1, which no impact law changes.
// voussoir's joint (penalty springs with a restitution dashpot) dissipates at impact a little
// less than Housner's plastic impact r_H = 1 - 1.5 sin^2(alpha): its ratio lies within the 5%
// of r_H that the rigid tests allow (docs/rigid.md, Rigid.RockingBlockImpactConvergesAsTheJoint
// Stiffens: 0.942 to 0.948 of the angular velocity kept against Housner's 0.912 on a 0.25 x 1
// block), so its mode-2 onset must lie in [A_2(1), A_2(r_H)].
//
// Checks: stepping from 1.2 g in 8% steps finds the mode-2 onset inside that interval, and its
// steps past the first collapse report survivals inside the band below A_1 that Housner's
// equation also survives with an impact ratio within 5% of r_H, while the steps above A_1
// collapse; the single bisection
// started inside the band jumps over the mode-2 collapses and lands on A_1 (within 5%: joint
// compliance, kn = 1e10 N/m3). And exit status 2 for a start, step or frequency that is zero or
// negative. The values found (stepping A_c, the survivals above it, the bisection's A_1) are in
// docs/dynamics.md, "The failure curve"; about 2.5 s in all.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "slender_block.hpp"
#include "subprocess.hpp"

namespace {

constexpr double kG = 9.81;
constexpr double kWidth = 0.2, kHeight = 1.0, kFrequency = 5.0;  // [m], [m], [Hz]

enum class Fate { Survives, FallsAfterImpact, FallsWithoutImpact };

// Housner's block under A g sin(2 pi f t), 0 <= t <= 1/f, followed to 1.5 s after the pulse
// (voussoir's free time). Falls as voussoir's pulse runs do: centroid displacement beyond
// L_ref = sqrt(b h) or rotation beyond 1 rad; still past alpha at the end: falling (voussoir's
// trend rule calls it collapsed).
Fate housner_block(double amplitude, double restitution) {
  const double alpha = std::atan(kWidth / kHeight);
  const double radius = 0.5 * std::hypot(kWidth, kHeight);
  const double p2 = 3.0 * kG / (4.0 * radius);
  const double l_ref = std::sqrt(kWidth * kHeight);
  const double duration = 1.0 / kFrequency, end = duration + 1.5, dt = 5e-5;
  auto ground = [&](double t) {  // a_g / g
    return t <= duration ? amplitude * std::sin(2.0 * M_PI * kFrequency * t) : 0.0;
  };
  auto accel = [&](double t, double th) {
    const double s = th > 0.0 ? 1.0 : -1.0;
    return -p2 * (std::sin(s * alpha - th) + ground(t) * std::cos(s * alpha - th));
  };
  double th = 0.0, om = 0.0;
  bool rocking = false, impacted = false;
  for (double t = 0.0; t < end; t += dt) {
    if (!rocking) {
      const double a = ground(t);
      if (std::abs(a) <= std::tan(alpha)) continue;
      rocking = true;
      th = a > 0.0 ? -1e-12 : 1e-12;  // a_g > 0 pushes the block to -x
      om = 0.0;
    }
    const double k1t = om, k1o = accel(t, th);
    const double k2t = om + 0.5 * dt * k1o, k2o = accel(t + 0.5 * dt, th + 0.5 * dt * k1t);
    const double k3t = om + 0.5 * dt * k2o, k3o = accel(t + 0.5 * dt, th + 0.5 * dt * k2t);
    const double k4t = om + dt * k3o, k4o = accel(t + dt, th + dt * k3t);
    double thn = th + dt / 6.0 * (k1t + 2.0 * k2t + 2.0 * k3t + k4t);
    double omn = om + dt / 6.0 * (k1o + 2.0 * k2o + 2.0 * k3o + k4o);
    if (thn * th < 0.0) {  // impact on the other corner
      thn = thn > 0.0 ? 1e-12 : -1e-12;
      omn *= restitution;
      impacted = true;
    }
    th = thn, om = omn;
    const double centroid = 2.0 * radius * std::abs(std::sin(0.5 * th));
    if (centroid > l_ref || std::abs(th) > 1.0)
      return impacted ? Fate::FallsAfterImpact : Fate::FallsWithoutImpact;
  }
  if (std::abs(th) > alpha) return impacted ? Fate::FallsAfterImpact : Fate::FallsWithoutImpact;
  return Fate::Survives;
}

// Smallest amplitude of a 0.01 g scan from g tan(alpha) up that satisfies `falls`.
template <class Pred>
double first_amplitude(Pred falls) {
  for (double a = kWidth / kHeight; a < 8.0; a += 0.01)
    if (falls(a)) return a;
  return 8.0;
}

// The rigid slender block with stiff joints and the full impact damping of the dashpot.
std::vector<std::string> block_curve_args(const std::string& json) {
  std::vector<std::string> args = voussoir::testing::slender_block_args("pulse");
  args.insert(args.end(), {"-q", "--set", "load.base.signal=\"sine_pulse\"", "--curve", "--freqs",
                           "5", "--lambda-star", "0.2", "--threads", "1", "--csv", json + ".csv",
                           "--json", json});
  return args;
}

nlohmann::json run_curve(const std::string& json, const std::vector<std::string>& extra) {
  std::vector<std::string> args = block_curve_args(json);
  args.insert(args.end(), extra.begin(), extra.end());
  const auto r = voussoir::testing::run_process(args, {120, 240, 2ull << 30},
                                                ::testing::TempDir() + "stepping");
  EXPECT_TRUE(r.exited && r.status == 0) << r.describe() << "\n" << r.err;
  std::ifstream in(json);
  return nlohmann::json::parse(in);
}

TEST(PulseStepping, SlenderBlockFindsTheLowerCollapseBandAndReportsTheSurvivalAbove) {
  const double r_housner = 1.0 - 1.5 * std::pow(std::sin(std::atan(kWidth / kHeight)), 2);
  const double onset_lossless =
      first_amplitude([](double a) { return housner_block(a, 1.0) != Fate::Survives; });
  const double onset_housner =
      first_amplitude([&](double a) { return housner_block(a, r_housner) != Fate::Survives; });
  const double mode1 =
      first_amplitude([](double a) { return housner_block(a, 1.0) == Fate::FallsWithoutImpact; });
  // The reference itself: a mode-2 band below mode 1 for every r in [r_H, 1].
  ASSERT_LT(onset_lossless, onset_housner);
  ASSERT_LT(onset_housner, 0.8 * mode1);
  ASSERT_EQ(housner_block(mode1, r_housner), Fate::FallsWithoutImpact);
  std::printf("Housner: mode-2 onset %.2f g (r = 1) to %.2f g (r = %.3f), mode 1 from %.2f g\n",
              onset_lossless, onset_housner, r_housner, mode1);

  const std::string json = ::testing::TempDir() + "stepping_block.json";
  const nlohmann::json j =
      run_curve(json, {"--start", "1.2", "--step", "0.08", "--steps-above", "10"});
  ASSERT_EQ(j.at("curve").size(), 1u);
  const auto& p = j.at("curve")[0];
  ASSERT_TRUE(p.at("bracketed").get<bool>());
  EXPECT_EQ(j.at("search").at("kind"), "step");
  const double a_c = p.at("amplitude").get<double>();
  const double lo = p.at("bracket")[0].get<double>();
  EXPECT_GE(a_c, onset_lossless) << "collapsed below the lossless mode-2 onset";
  EXPECT_LE(a_c, onset_housner) << "survived above Housner's mode-2 onset";
  EXPECT_LE(a_c - lo, 0.02 * a_c);
  EXPECT_NEAR(p.at("ratio").get<double>(), a_c / 0.2, 1e-9);
  EXPECT_LT(p.at("max_energy_balance_error").get<double>(), 0.01);

  // The stepping runs: 1.2 (1.08)^k up to the first collapse, then ten steps past it.
  double largest = 0.0;
  for (const auto& r : p.at("runs")) largest = std::max(largest, r.at("amplitude").get<double>());
  EXPECT_GT(largest, 1.04 * mode1) << "the steps past the first collapse did not pass mode 1";
  const std::vector<double> stable = p.at("stable_above").get<std::vector<double>>();
  ASSERT_FALSE(stable.empty()) << "no survival reported above the collapse band";
  auto housner_survives = [&](double a) {  // at some impact ratio within 5% of r_H
    for (double r = 0.95 * r_housner; r <= std::min(1.0, 1.05 * r_housner); r += 0.005)
      if (housner_block(a, r) == Fate::Survives) return true;
    return false;
  };
  for (double a : stable) {
    EXPECT_GT(a, a_c);
    EXPECT_LT(a, mode1) << "survived above the impact-free overturning amplitude";
    EXPECT_TRUE(housner_survives(a)) << a << " g";
  }
  // Every run above mode 1 collapsed.
  for (const auto& r : p.at("runs"))
    if (r.at("amplitude").get<double>() > 1.02 * mode1) {
      EXPECT_TRUE(r.at("collapsed").get<bool>()) << r.at("amplitude");
    }
  std::ifstream c(json + ".csv");
  std::string header, row;
  std::getline(c, header);
  std::getline(c, row);
  EXPECT_NE(header.find("quasi_static,ratio,search,stable_above"), std::string::npos) << header;
  EXPECT_NE(row.find(",step,\""), std::string::npos) << row;
}

TEST(PulseStepping, BisectionFromInsideTheSurvivalBandFindsOnlyTheImpactFreeThreshold) {
  const double mode1 =
      first_amplitude([](double a) { return housner_block(a, 1.0) == Fate::FallsWithoutImpact; });
  const double r_housner = 1.0 - 1.5 * std::pow(std::sin(std::atan(kWidth / kHeight)), 2);
  ASSERT_EQ(housner_block(3.0, r_housner), Fate::Survives);  // 3 g: inside the band

  const std::string json = ::testing::TempDir() + "bisect_block.json";
  const nlohmann::json j = run_curve(json, {"--search", "bisect", "--start", "3.0"});
  const auto& p = j.at("curve")[0];
  ASSERT_TRUE(p.at("bracketed").get<bool>());
  EXPECT_EQ(j.at("search").at("kind"), "bisect");
  const double a_c = p.at("amplitude").get<double>();
  EXPECT_NEAR(a_c / mode1, 1.0, 0.05);
  EXPECT_TRUE(p.at("stable_above").empty());  // nothing run above its first collapse survived
}

TEST(PulseStepping, ZeroOrNegativeStartStepOrFrequencyIsExit2NamingTheOption) {
  const std::string deck = std::string(VOUSSOIR_SOURCE_DIR) + "/cases/block.toml";
  struct Bad {
    std::vector<std::string> args;
    std::string names;
  };
  const std::vector<Bad> bad = {{{"--freqs", "2,0"}, "--freqs"},
                                {{"--freqs", "-3"}, "--freqs"},
                                {{"--freqs", "2", "--start", "0"}, "--start"},
                                {{"--freqs", "2", "--start", "-0.1"}, "--start"},
                                {{"--freqs", "2", "--step", "0"}, "--step"},
                                {{"--freqs", "2", "--step", "-0.05"}, "--step"},
                                {{"--freqs", "2", "--search", "up"}, "--search"}};
  for (const Bad& b : bad) {
    std::vector<std::string> args = {VOUSSOIR_BINARY, "pulse",         deck, "-q",
                                     "--curve",       "--lambda-star", "0.5"};
    args.insert(args.end(), b.args.begin(), b.args.end());
    const auto r = voussoir::testing::run_process(args, {30, 30, 2ull << 30},
                                                  ::testing::TempDir() + "stepping_bad");
    EXPECT_TRUE(r.exited && r.status == 2) << b.names << ": " << r.describe();
    EXPECT_NE(r.err.find(b.names), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("not allowed"), std::string::npos) << r.err;
  }
  // The deck's own frequency.
  const auto r = voussoir::testing::run_process(
      {VOUSSOIR_BINARY, "pulse", deck, "-q", "--set", "load.base.frequency=0"},
      {30, 30, 2ull << 30}, ::testing::TempDir() + "stepping_bad");
  EXPECT_TRUE(r.exited && r.status == 2) << r.describe();
  EXPECT_NE(r.err.find("load.base.frequency"), std::string::npos) << r.err;
}

}  // namespace

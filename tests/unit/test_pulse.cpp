// Base-excitation runs (commands/pulse.hpp): a rigid block under a constant base acceleration (a
// step from a file accelerogram) rocks over exactly when the acceleration exceeds
// g width / height, the control points of the shaking-table arch, and the `pulse` command's
// JSON.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "commands/pulse.hpp"
#include "io/deck.hpp"
#include "mesh/scene.hpp"
#include "seismic/accelerogram.hpp"

namespace voussoir {
namespace {

// The block of cases/block.toml (width 0.5, height 1, mu = 0.8 > width/height, so it cannot
// slide first), one element size across the width, E lowered to 1 GPa (still rigid: the
// gravity strain is 2e-5) for a 4x larger time step.
Config block_config(const std::string& record) {
  const std::string deck =
      "[model]\nkind = \"block\"\nwidth = 0.5\nheight = 1.0\n"
      "[mesh]\nsize = 0.5\n"
      "[material]\ndensity = 2000.0\nyoung = 1e9\npoisson = 0.2\n"
      "[contact]\nfriction = 0.8\n"
      "[load.base]\nsignal = \"file\"\nfile = \"" +
      record + "\"\nunits = \"g\"\n";
  return parse_deck(deck, "block-step");
}

// A base step of `a_g` [g] held for `duration` seconds, as a two-sample file.
std::string write_step(double a_g, double duration) {
  const std::string path = ::testing::TempDir() + "step_" + std::to_string(a_g) + ".txt";
  std::ofstream out(path);
  out << "# constant base acceleration [g]\n0, " << a_g << "\n" << duration << ", " << a_g << "\n";
  return path;
}

PulseResult run_step(double a_g, double duration) {
  const Config config = block_config(write_step(a_g, duration));
  const PulseCriteria crit;
  const SettledState settled = settle(config, crit.settle, true);
  EXPECT_TRUE(settled.settled);
  const BaseSignal signal = make_base_signal(config.load.base, config.load.gravity);
  EXPECT_NEAR(signal.peak_acceleration(), std::abs(a_g) * config.load.gravity, 1e-12);
  return run_pulse(settled, signal, 0.0, find_control_points(settled.sim.model), crit);
}

// Quasi-static rocking threshold: the block (b/h = 0.5) tips about a base corner when the
// inertial force m a_g times h/2 exceeds the weight times b/2, i.e. a_g > g b/h = 0.5 g.
// Below (0.45 g, held 1.5 s) it does not rock: rotation stays elastic (< 1e-3 rad) and it
// comes to rest when the step ends. Above (0.55 g) it overturns: under a net tipping moment
// of 0.05 m g h/2 the rotation grows past the fall threshold (1 rad, beyond the point of no
// return atan(b/h) = 0.46 rad) within the step. The inertial force -m a_g points to -x for
// a_g > 0, so the top moves to -x.
TEST(PulseBlock, BaseStepBelowThresholdDoesNotRockAboveOverturns) {
  const PulseResult below = run_step(0.45, 1.5);
  EXPECT_FALSE(below.collapsed) << below.reason;
  EXPECT_EQ(below.reason, "rest");
  EXPECT_LT(below.max_rotation, 1e-3);
  EXPECT_GE(below.decided_at, 1.5);  // classified only after the step ended
  EXPECT_LT(below.max_energy_balance_error, 0.01);
  EXPECT_LT(below.pulse_energy_balance_error, 0.01);

  const PulseResult above = run_step(0.55, 3.0);
  EXPECT_TRUE(above.collapsed);
  EXPECT_EQ(above.reason, "fall");
  EXPECT_GT(above.max_rotation, 1.0);
  EXPECT_LT(above.decided_at, 3.0);  // fell during the step
  ASSERT_EQ(above.control.size(), 1u);
  EXPECT_LT(above.control[0].final_ux, -0.2);  // the top went to -x
  EXPECT_LT(above.max_energy_balance_error, 0.01);
  EXPECT_LT(above.pulse_energy_balance_error, 0.01);
}

// Control points of the shaking-table arch: the extrados corners of the sixth voussoir from
// each springing (13 voussoirs: blocks 6th from the left and from the right are mirror images),
// on the extrados circle R + t/2, and mirrored about x = 0.
TEST(PulseControlPoints, ScaledArchSixthVoussoirExtrados) {
  const Config config = load_deck(std::string(VOUSSOIR_SOURCE_DIR) + "/cases/scaled_arch.toml",
                                  {"mesh.through_thickness=1"});
  const Model model = build_model(scene_params(config));
  const std::vector<ControlPoint> points = find_control_points(model);
  ASSERT_EQ(points.size(), 4u);
  EXPECT_EQ(points[0].name, "left6_springing_side");
  EXPECT_EQ(points[1].name, "left6_crown_side");
  EXPECT_EQ(points[2].name, "right6_springing_side");
  EXPECT_EQ(points[3].name, "right6_crown_side");
  const double r_ext = 0.375 + 0.036 / 2;
  const double kDeg = std::acos(-1.0) / 180.0;
  // Joint k (from the left springing, k = 0..13) lies at 20 + 140 k / 13 degrees from +x
  // measured clockwise from the left springing: angle 160 - 140 k / 13 from +x.
  auto expected = [&](int k) {
    const double a = (160.0 - 140.0 * k / 13.0) * kDeg;
    return std::array<double, 2>{r_ext * std::cos(a), r_ext * std::sin(a)};
  };
  const std::array<int, 4> joint = {5, 6, 8, 7};
  for (int p = 0; p < 4; ++p) {
    EXPECT_NEAR(std::hypot(points[p].x0, points[p].y0), r_ext, 1e-9) << points[p].name;
    const auto e = expected(joint[p]);
    EXPECT_NEAR(points[p].x0, e[0], 1e-9) << points[p].name;
    EXPECT_NEAR(points[p].y0, e[1], 1e-9) << points[p].name;
  }
  EXPECT_NEAR(points[0].x0, -points[2].x0, 1e-9);
  EXPECT_NEAR(points[1].y0, points[3].y0, 1e-9);
  EXPECT_EQ(model.blocks[points[0].block].role, "voussoir");
}

// `voussoir pulse --json` writes the keys of docs/reference/output.md and exits 0; a deck without a
// signal is refused with exit status 2.
TEST(PulseCommand, JsonSummary) {
  const std::string record = write_step(0.3, 0.2);
  const std::string json = ::testing::TempDir() + "pulse_block.json";
  const std::string cmd = std::string(VOUSSOIR_BINARY) + " pulse " + VOUSSOIR_SOURCE_DIR +
                          "/cases/block.toml -q --set mesh.size=0.5 --set material.young=1e9"
                          " --set load.base.signal=\\\"file\\\" --set load.base.file=\\\"" +
                          record + "\\\" --json " + json + " > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_FALSE(j.at("collapsed").get<bool>());
  EXPECT_GT(j.at("max_kinetic_energy").get<double>(), 0.0);
  EXPECT_TRUE(j.at("control_points").contains("block0_top"));
  EXPECT_GT(j.at("wall_s").get<double>(), 0.0);
  EXPECT_LT(j.at("energy_balance_error").get<double>(), 0.01);
  EXPECT_NEAR(j.at("signal").at("peak_acceleration").get<double>(), 0.3 * 9.81, 1e-9);

  const std::string bad = std::string(VOUSSOIR_BINARY) + " pulse " + VOUSSOIR_SOURCE_DIR +
                          "/cases/block.toml -q 2> /dev/null";
  const int rc = std::system(bad.c_str());
  EXPECT_EQ(WEXITSTATUS(rc), 2);
}

}  // namespace
}  // namespace voussoir

// Joint resultants (engine/thrust.hpp; the statics checks of docs/thrust.md): a block on a ground
// carries its weight through the joint's middle; under lambda g the centre of pressure moves by
// lambda (h/2) W / N towards the toe; the semicircular arch under gravity keeps every centre of
// pressure inside its joints and its springings carry its weight; at the collapsed trial of its
// capacity search the hinge joints have their centre of pressure at an edge. Rigid blocks
// (material.model = "rigid") keep these fast.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands/capacity.hpp"
#include "engine/thrust.hpp"
#include "io/deck.hpp"
#include "subprocess.hpp"

namespace voussoir {
namespace {

constexpr double kWidth = 0.5, kHeight = 1.0;

Config block_deck() {
  return parse_deck("[model]\nkind = \"block\"\nwidth = " + std::to_string(kWidth) +
                        "\nheight = " + std::to_string(kHeight) +
                        "\n[material]\nmodel = \"rigid\"\n[contact]\nfriction = 0.8\n",
                    "block.toml");
}

Config arch_deck(const std::vector<std::string>& sets = {}) {
  return parse_deck(R"(
[model]
kind = "circular_arch"
radius = 1.0
thickness = 0.2
embrace = 180.0
voussoirs = 11
[material]
model = "rigid"
[contact]
friction = 0.6
)",
                    "arch.toml", sets);
}

TrialCriteria quasi_static() {
  TrialCriteria crit;
  crit.quasi_static = true;
  return crit;
}

double free_weight(const Model& m, double g) {
  double w = 0.0;
  for (const Block& b : m.blocks)
    if (!b.fixed) w += b.mass * g;
  return w;
}

TEST(Thrust, BlockOnGroundCarriesItsWeightThroughTheMiddle) {
  const SettledState s = settle(block_deck(), quasi_static(), true);
  ASSERT_TRUE(s.settled);
  const std::vector<JointResultant> joints =
      joint_resultants(s.sim.model, s.sim.contact, s.sim.ctx.dt);
  ASSERT_EQ(joints.size(), 1u);
  const JointResultant& j = joints[0];
  const double w = free_weight(s.sim.model, s.gravity);
  ASSERT_TRUE(j.closed);
  EXPECT_NEAR(j.normal_force, w, 1e-6 * w);
  EXPECT_NEAR(j.shear_force, 0.0, 1e-6 * w);
  EXPECT_NEAR(j.eccentricity, 0.0, 1e-6);
  EXPECT_NEAR(j.point.x, 0.0, 1e-6 * kWidth);
  EXPECT_NEAR(j.point.y, 0.0, 1e-6 * kWidth);
}

// Moment balance about the base middle: lambda W h/2 = N x, so the centre of pressure lies at
// x = lambda (h/2) W / N, e = x / (b/2), and reaches the toe (e = 1) at lambda = b/h = 0.5.
TEST(Thrust, CentreOfPressureMovesByLambdaHalfHeightWeightOverNormal) {
  const TrialCriteria crit = quasi_static();
  const SettledState s = settle(block_deck(), crit, true);
  ASSERT_TRUE(s.settled);
  const double w = free_weight(s.sim.model, s.gravity);
  for (double lambda : {0.1, 0.25, 0.4}) {
    const TrialResult r = run_trial(s, lambda, crit, true);
    ASSERT_FALSE(r.collapsed) << lambda;
    ASSERT_EQ(r.joints.size(), 1u);
    const JointResultant& j = r.joints[0];
    ASSERT_TRUE(j.closed) << lambda;
    EXPECT_NEAR(j.normal_force, w, 1e-4 * w) << lambda;
    // V: the ground's force on the block along the joint (a -> b is +x) holds back lambda W.
    EXPECT_NEAR(j.shear_force, -lambda * w, 1e-4 * w) << lambda;
    const double x = lambda * 0.5 * kHeight * w / j.normal_force;
    EXPECT_NEAR(j.point.x, x, 1e-3 * kWidth) << lambda;
    EXPECT_NEAR(j.eccentricity, x / (0.5 * kWidth), 2e-3) << lambda;
  }
  // Beyond b/h the block overturns about its toe: the centre of pressure is at the toe.
  const TrialResult over = run_trial(s, 0.6, crit, true);
  ASSERT_TRUE(over.collapsed);
  ASSERT_TRUE(over.joints[0].closed);
  EXPECT_GT(over.joints[0].eccentricity, 0.99);
}

TEST(Thrust, SemicircularArchUnderGravityThrustInsideAndSpringingsCarryTheWeight) {
  const SettledState s = settle(arch_deck(), quasi_static(), true);
  ASSERT_TRUE(s.settled);
  const Model& m = s.sim.model;
  const std::vector<JointResultant> joints = joint_resultants(m, s.sim.contact, s.sim.ctx.dt);
  ASSERT_EQ(joints.size(), m.joints.size());
  double springings = 0.0;
  int fixed_joints = 0;
  for (const JointResultant& j : joints) {
    ASSERT_TRUE(j.closed) << "joint " << j.joint;
    EXPECT_GT(j.normal_force, 0.0) << "joint " << j.joint;
    EXPECT_LT(std::abs(j.eccentricity), 1.0) << "joint " << j.joint;
    // The force on the arch from a fixed abutment.
    if (m.blocks[std::size_t(j.block_a)].fixed) springings += j.force.y, ++fixed_joints;
    if (m.blocks[std::size_t(j.block_b)].fixed) springings -= j.force.y, ++fixed_joints;
  }
  EXPECT_EQ(fixed_joints, 2);
  const double w = free_weight(m, s.gravity);
  EXPECT_NEAR(springings, w, 1e-6 * w);
}

// A rigid buttress's minimal mesh has no node at the extrados end of its springing joint (its
// straight top loses the point): the joint is still found and closed. Every joint of the
// buttressed arch carries compression inside its length, and the ground carries everything.
TEST(Thrust, ButtressedArchUnderGravityEveryJointClosedAndTheGroundCarriesTheWeight) {
  const Config config = parse_deck(
      std::string("[model]\nkind = \"buttressed_arch\"\nshape = \"circular\"\nradius = 1.0\n") +
          "thickness = 0.2\nembrace = 180.0\nvoussoirs = 11\nbuttress_width = 0.8\n" +
          "base_depth = 3.0\ncourses = 0\n[material]\nmodel = \"rigid\"\n[contact]\n" +
          "friction = 0.9\n",
      "buttressed.toml");
  const SettledState s = settle(config, quasi_static(), true);
  ASSERT_TRUE(s.settled);
  const Model& m = s.sim.model;
  const std::vector<JointResultant> joints = joint_resultants(m, s.sim.contact, s.sim.ctx.dt);
  double ground = 0.0;
  for (const JointResultant& j : joints) {
    ASSERT_TRUE(j.closed) << "joint " << j.joint;
    EXPECT_GT(j.normal_force, 0.0) << "joint " << j.joint;
    EXPECT_LT(std::abs(j.eccentricity), 1.0) << "joint " << j.joint;
    if (m.blocks[std::size_t(j.block_a)].fixed) ground += j.force.y;
    if (m.blocks[std::size_t(j.block_b)].fixed) ground -= j.force.y;
  }
  const double w = free_weight(m, s.gravity);
  EXPECT_NEAR(ground, w, 1e-6 * w);
}

TEST(Thrust, HingeJointsOfTheCollapsedTrialHaveTheirThrustAtAnEdge) {
  const CapacityResult r =
      find_capacity(arch_deck({"capacity.tolerance=0.02"}), quasi_static(), 2, true);
  ASSERT_TRUE(r.bracketed);
  ASSERT_TRUE(r.has_collapsed);
  ASSERT_TRUE(r.has_stable);
  int hinges = 0;
  for (const Hinge& h : r.hinges) {
    if (h.kind != "hinge") continue;
    ++hinges;
    const JointResultant& j = r.joints_collapsed[std::size_t(h.joint)];
    ASSERT_TRUE(j.closed) << "joint " << h.joint;
    EXPECT_GT(std::abs(j.eccentricity), 0.9) << "joint " << h.joint;
    // At the edge where the blocks keep touching.
    EXPECT_EQ(j.eccentricity < 0.0, h.side == "intrados") << "joint " << h.joint;
  }
  EXPECT_GE(hinges, 3);
}

// Through the program: `run --json` ends with the joints under the names of
// docs/reference/output.md. The shipped block (0.5 x 1 m, elastic) under lambda = 0.3: e = lambda h
// / b = 0.6 at the end.
TEST(Thrust, RunJsonCarriesTheJoints) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "voussoir_thrust_cli";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string json = (dir / "run.json").string();
  const auto r = testing::run_process(
      {VOUSSOIR_BINARY, "run", std::string(VOUSSOIR_SOURCE_DIR) + "/cases/block.toml", "-q",
       "--set", "solver.end_time=0.05", "--set", "load.lambda=0.3", "-o", (dir / "run.h5").string(),
       "--json", json},
      {}, (dir / "child").string());
  ASSERT_TRUE(r.exited && r.status == 0) << r.describe() << r.err;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  fs::remove_all(dir);
  ASSERT_TRUE(j.contains("joints"));
  ASSERT_EQ(j["joints"].size(), 1u);
  const nlohmann::json& joint = j["joints"][0];
  for (const char* key :
       {"joint", "blocks", "normal_force", "shear_force", "eccentricity", "point"})
    EXPECT_TRUE(joint.contains(key)) << key;
  EXPECT_EQ(joint["joint"].get<int>(), 0);
  const double w = 2000.0 * kWidth * kHeight * 9.81;
  EXPECT_NEAR(joint["normal_force"].get<double>(), w, 1e-4 * w);
  EXPECT_NEAR(joint["eccentricity"].get<double>(), 0.3 * kHeight / kWidth, 1e-4);
}

}  // namespace
}  // namespace voussoir

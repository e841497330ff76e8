// Supports that move ([supports], core/supports.hpp): the ramp, moved rigid and elastic
// supports reaching their pose exactly with the energy ledger balanced, the deck's refusals
// (exit status 2 naming key and value), model.fixed on generated scenes, limit analysis of the
// moved blocks, the supports' acceptance checks (the semicircular arch, rigid blocks, with its
// supports spread apart carries the least thrust of limit analysis, pushed together the
// greatest; spread by 1% of its span, its lambda* lies between the limit analyses with the
// open joints as points and closed, and at the peak of its pushover), and the spreading study
// (commands/spread.hpp) and its command.

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands/capacity.hpp"
#include "commands/spread.hpp"
#include "core/rigid.hpp"
#include "core/supports.hpp"
#include "engine/setup.hpp"
#include "engine/thrust.hpp"
#include "io/deck.hpp"
#include "limit/limit_analysis.hpp"
#include "mesh/scene.hpp"
#include "subprocess.hpp"

namespace voussoir {
namespace {

std::string case_path(const std::string& name) {
  return std::string(VOUSSOIR_SOURCE_DIR) + "/cases/" + name + ".toml";
}

// Both abutments of the shipped arch (blocks 11 left, 12 right) moved outward by d [m].
std::vector<std::string> spread(double d, double ramp = 0.1) {
  return {"supports.moves=[{block = 11, dx = " + std::to_string(-d) +
              "}, {block = 12, dx = " + std::to_string(d) + "}]",
          "supports.ramp=" + std::to_string(ramp)};
}

// Runs `sim` under gravity with the deck's supports moving from t = 0 until `end` [s]; the
// largest energy balance error after step `arm` (the ledger's early steps are noisy).
double run_moving_supports(Simulation& sim, const Config& config, double end, long long arm) {
  start_support_motion(sim.supports, 0.0, config.supports.ramp);
  set_static_load(sim, config.load.gravity, 0.0);
  double worst = 0.0;
  while (sim.ctx.time < end) {
    advance(sim);
    if (sim.step > arm) worst = std::max(worst, sim.ledger.balance_error());
  }
  return worst;
}

TEST(SupportRamp, StartsAndStopsWithoutJumps) {
  EXPECT_EQ(support_ramp(0.0), 0.0);
  EXPECT_EQ(support_ramp(-1.0), 0.0);
  EXPECT_DOUBLE_EQ(support_ramp(1.0), 1.0);
  EXPECT_DOUBLE_EQ(support_ramp(2.0), 1.0);
  EXPECT_NEAR(support_ramp(0.5), 0.5, 1e-15);
  // s'(0) = s'(1) = 0: the first and last steps move by O(h^3).
  const double h = 1e-3;
  EXPECT_LT(support_ramp(h), h * h * h * 7.0);
  EXPECT_LT(1.0 - support_ramp(1.0 - h), h * h * h * 7.0);
}

TEST(Supports, RigidSupportReachesItsPoseAndTheLedgerBalances) {
  // The arch's left abutment moved and turned during a run; the body ends at the pose exactly,
  // its nodes with it, and the energy ledger (support work booked as external work) balances.
  const Config config =
      load_deck(case_path("circular_arch"),
                {"supports.moves=[{block = 11, dx = -0.003, dy = -0.001, rotation = 0.2}]",
                 "supports.ramp=0.05"});
  Simulation sim = make_simulation(config);
  ASSERT_TRUE(sim.model.blocks[11].prescribed);
  const double worst = run_moving_supports(sim, config, 0.08, 2000);
  const RigidBodies& r = sim.model.rigid;
  EXPECT_EQ(r.ux[11], -0.003);
  EXPECT_EQ(r.uy[11], -0.001);
  EXPECT_DOUBLE_EQ(r.theta[11], 0.2 * M_PI / 180.0);
  EXPECT_EQ(r.vx[11], 0.0);
  sync_rigid_nodes(sim.model);
  const Block& b = sim.model.blocks[11];
  const Index i = b.first_node;
  const double c = std::cos(r.theta[11]), s = std::sin(r.theta[11]);
  EXPECT_NEAR(sim.model.nodes.x[i], r.cx[11] + c * r.rx[i] - s * r.ry[i], 1e-15);
  EXPECT_LT(worst, 0.01) << "energy balance error";
  EXPECT_GT(sim.ledger.external_work, 0.0);
}

TEST(Supports, ElasticSupportReachesItsPoseAndTheLedgerBalances) {
  // The same with elastic blocks: the support's nodes at their pose, the broad phase following
  // them, the ledger within 1%.
  const Config config = load_deck(
      case_path("circular_arch"),
      {"material.model=elastic", "supports.moves=[{block = 11, dx = -0.006, rotation = 0.1}]",
       "supports.ramp=0.01"});
  Simulation sim = make_simulation(config);
  const double worst = run_moving_supports(sim, config, 0.015, 1000);
  const Block& b = sim.model.blocks[11];
  const Vec2 c0 = sim.supports.centroid[0];
  const double th = 0.1 * M_PI / 180.0;
  for (Index i = b.first_node; i < b.first_node + b.node_count; ++i) {
    const double rx = sim.model.nodes.x0[i] - c0.x, ry = sim.model.nodes.y0[i] - c0.y;
    EXPECT_NEAR(sim.model.nodes.x[i], c0.x - 0.006 + std::cos(th) * rx - std::sin(th) * ry, 1e-15);
    EXPECT_NEAR(sim.model.nodes.y[i], c0.y + std::sin(th) * rx + std::cos(th) * ry, 1e-15);
    EXPECT_EQ(sim.model.nodes.vx[i], 0.0);
  }
  EXPECT_LT(worst, 0.01) << "energy balance error";
  EXPECT_GT(sim.contact.detections(), 1);
}

TEST(Supports, DeckRefusalsNameKeyAndValue) {
  struct Case {
    std::string set, expect;
  };
  const std::vector<Case> cases = {
      {"supports.moves=[{block = 3, dx = 0.01}]", "supports.moves[0].block = 3"},
      {"supports.moves=[{block = 99, dx = 0.01}]", "supports.moves[0].block = 99"},
      {"supports.moves=[{block = 11, dx = nan}]", "supports.moves[0].dx = nan"},
      {"supports.moves=[{block = 11, dy = inf}]", "supports.moves[0].dy = inf"},
      {"supports.moves=[{block = 11, spin = 1.0}]", "supports.moves[0].spin"},
      {"supports.ramp=-1", "supports.ramp = -1"},
  };
  for (const Case& c : cases) {
    const testing::ProcessResult p = testing::run_process(
        {VOUSSOIR_BINARY, "check", case_path("circular_arch"), "--quiet", "--set", c.set}, {},
        ::testing::TempDir() + "supports_refusal");
    EXPECT_TRUE(p.exited && p.status == 2) << c.set << ": " << p.describe();
    EXPECT_NE(p.err.find(c.expect), std::string::npos) << c.set << ": " << p.err;
  }
  // A good move is listed by check.
  const testing::ProcessResult ok =
      testing::run_process({VOUSSOIR_BINARY, "check", case_path("circular_arch"), "--set",
                            "supports.moves=[{block = 11, dx = -0.002}]"},
                           {}, ::testing::TempDir() + "supports_ok");
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_NE(ok.out.find("move block 11 (abutment): dx = -0.002 m"), std::string::npos) << ok.out;
}

// The horizontal force on the arch at its springings (the joints with an abutment), the mean
// of the two sides [N].
double springing_thrust(const SettledState& s) {
  const Model& m = s.sim.model;
  return support_thrust(m, joint_resultants(m, s.sim.contact, s.sim.ctx.dt)).mean();
}

// The supports' acceptance check (docs/supports.md): spread apart by 1 mm each (0.09% of the 2.2 m
// span), the arch forms its three hinges and its thrust falls to the least thrust; pushed together
// it rises to the greatest (here friction at the horizontal springings, mu = 0.6, bounds it: the LP
// has the same friction). Quasi-static settle and movement, as `capacity` runs them.
TEST(SupportsAcceptance, SpreadArchCarriesTheLeastThrustPushedTheGreatest) {
  TrialCriteria crit;
  crit.quasi_static = true;
  for (const double d : {0.001, -0.001}) {
    const Config config = load_deck(case_path("circular_arch"), spread(d));
    const SettledState s = settle(config, crit, true);
    ASSERT_TRUE(s.settled) << d;
    const double h = springing_thrust(s);
    const LimitResult la =
        limit_thrust(build_model(scene_params(config)), config.contact.friction,
                     config.load.gravity, d > 0.0 ? ThrustBound::Min : ThrustBound::Max);
    ASSERT_EQ(la.status, "optimal");
    std::printf(
        "supports moved %+.4f m each: springing thrust %.2f N, limit analysis %s %.2f N "
        "(%+.2f%%), %.3f s simulated, %.2f s wall\n",
        d, h, d > 0.0 ? "min" : "max", la.thrust, 100.0 * (h / la.thrust - 1.0), s.settle_time,
        s.wall_s);
    EXPECT_NEAR(h, la.thrust, 0.03 * la.thrust) << d;
  }
}

// The acceptance of a moved structure (docs/supports.md "The acceptance"): the arch spread by
// 1% of its 2 m span (each abutment 10 mm out), its FDEM lambda* (`capacity`) lies between
// limit analysis of the moved blocks with the open joints as point contacts at their pivots
// (`limit --open-joints points`) and with every joint closed (`limit`), and within 2% of the
// peak of a pushover of the moved arch. The pushover ends at 12 mm of the crown (capacity's
// collapse displacement, 5% of L_ref), past its peak near 5 mm (the peak must lie before the
// end: its last point has fallen below it). The figures, run through the program as the table
// of docs/supports.md gives them.
TEST(SupportsAcceptance, SpreadArchLambdaStarLiesBetweenTheTwoLimitAnalysesAndAtThePushoverPeak) {
  const std::string dir = ::testing::TempDir();
  const std::string moves = "supports.moves=[{block = 11, dx = -0.01}, {block = 12, dx = 0.01}]";
  auto run = [&](const std::string& name, std::vector<std::string> extra) {
    std::vector<std::string> args = {
        VOUSSOIR_BINARY, extra[0], case_path("circular_arch"), "--quiet", "--set",
        moves,           "--json", dir + name + ".json"};
    args.insert(args.end(), extra.begin() + 1, extra.end());
    const testing::ProcessResult p =
        testing::run_process(args, {.wall_s = 300, .cpu_s = 600}, dir + name);
    EXPECT_TRUE(p.exited && p.status == 0) << name << ": " << p.describe() << p.err;
    return nlohmann::json::parse(testing::read_text_file(dir + name + ".json"));
  };
  const nlohmann::json points = run("la_points", {"limit", "--open-joints", "points"});
  const nlohmann::json closed = run("la_closed", {"limit"});
  const nlohmann::json fdem = run("capacity", {"capacity"});
  const nlohmann::json push = run("pushover", {"pushover", "--max-displacement", "0.012"});
  ASSERT_EQ(points.at("status"), "optimal");
  ASSERT_EQ(closed.at("status"), "optimal");
  EXPECT_EQ(points.at("open_joints"), "points");
  EXPECT_EQ(closed.at("open_joints"), "closed");
  EXPECT_TRUE(closed.at("point_contacts").empty());
  EXPECT_FALSE(points.at("point_contacts").empty());
  const double lower = points.at("lambda_la"), upper = closed.at("lambda_la");
  const double lambda_star = fdem.at("lambda_star");
  const double peak = push.at("peak").at("lambda");
  const nlohmann::json& curve = push.at("curve");
  ASSERT_FALSE(curve.empty());
  EXPECT_LT(curve.back().at("lambda").get<double>(), peak) << "the pushover ended at its peak";
  std::printf(
      "spread 1%%: LP (points) %.2g, FDEM lambda* %.5f, LP (closed) %.5f, pushover peak %.5f "
      "(lambda* / peak - 1 = %+.2f%%); %zu joints taken as points\n",
      lower, lambda_star, upper, peak, 100.0 * (lambda_star / peak - 1.0),
      points.at("point_contacts").size());
  EXPECT_LE(lower, lambda_star);
  EXPECT_LE(lambda_star, upper);
  EXPECT_NEAR(lambda_star, peak, 0.02 * peak);
  // Without moved supports the blocks stand as built: no joint to take as a point.
  const testing::ProcessResult refused = testing::run_process(
      {VOUSSOIR_BINARY, "limit", case_path("circular_arch"), "--quiet", "--open-joints", "points"},
      {}, dir + "la_refused");
  EXPECT_TRUE(refused.exited && refused.status == 2) << refused.describe();
  EXPECT_NE(refused.err.find("--open-joints points needs [supports] moves"), std::string::npos)
      << refused.err;
}

// The spreading study (commands/spread.hpp) on the same arch, its left support moved out in
// two steps of 5.5 mm (0.25% of the width): at rest each time, on three hinges, its thrust
// within 3% of the least thrust and growing with the spread (the arch flattens); the CSV and
// the JSON carry every state.
TEST(Spread, ArchOnASpreadingSupportKeepsTheLeastThrustAndThreeHinges) {
  const Config config = load_deck(case_path("circular_arch"), {"supports.ramp=0.2"});
  SpreadOptions opts;
  opts.step = 0.0055;
  opts.max_movement = 0.011;
  const SpreadResult r = run_spread(config, opts, true);
  EXPECT_EQ(r.block, 11);
  EXPECT_EQ(r.direction.x, -1.0);
  EXPECT_FALSE(r.collapsed);
  ASSERT_EQ(r.states.size(), 3u);  // the settled state and two steps
  for (std::size_t k = 1; k < r.states.size(); ++k) {
    const SpreadState& s = r.states[k];
    ASSERT_FALSE(s.collapsed) << k;
    EXPECT_NEAR(s.thrust, r.thrust_min, 0.03 * r.thrust_min) << k;
    EXPECT_NEAR(s.thrust_left, s.thrust_right, 1e-3 * s.thrust) << k;
    EXPECT_EQ(s.hinges.size(), 3u) << k;
  }
  EXPECT_GT(r.states[2].thrust, r.states[1].thrust);
  EXPECT_NEAR(r.states[2].movement, 0.011, 1e-15);
}

// model.fixed on a generated scene fixes the listed blocks besides its supports (a church
// pier to settle); an index out of range is a bad deck.
TEST(Supports, ModelFixedMakesAnyBlockASupport) {
  const Model m = build_model(scene_params(load_deck(case_path("church_b"), {"model.fixed=[1]"})));
  EXPECT_TRUE(m.blocks[1].fixed);
  EXPECT_EQ(m.blocks[1].role, "pier");
  EXPECT_FALSE(m.blocks[2].fixed);
  EXPECT_THROW(
      build_model(scene_params(load_deck(case_path("circular_arch"), {"model.fixed=[99]"}))),
      DeckError);
}

// Limit analysis of the moved blocks: with supports that did not move, the carried outlines
// and interfaces give back the reference lambda_la; spread by 1 cm, a lower one.
TEST(Supports, LimitAnalysisOfTheMovedBlocks) {
  TrialCriteria crit;
  crit.quasi_static = true;
  const Config still = load_deck(case_path("circular_arch"), {"supports.moves=[{block = 11}]"});
  const SettledState s0 = settle(still, crit, true);
  ASSERT_TRUE(s0.settled);
  const double reference =
      limit_analysis(build_model(scene_params(still)), 0.6, 9.81, false).lambda_la;
  EXPECT_NEAR(limit_of_settled(s0, 0.6, 1.0).lambda_la, reference, 1e-3 * reference);
  EXPECT_NEAR(limit_of_settled(s0, 0.6, -1.0).lambda_la, reference, 1e-3 * reference);
  const SettledState s1 = settle(load_deck(case_path("circular_arch"), spread(0.005)), crit, true);
  ASSERT_TRUE(s1.settled);
  const double moved = limit_of_settled(s1, 0.6, 1.0).lambda_la;
  EXPECT_LT(moved, reference);
  EXPECT_GT(moved, 0.9 * reference);
}

// `voussoir spread` writes its table, CSV and JSON.
TEST(Spread, CommandWritesCsvAndJson) {
  const std::string dir = ::testing::TempDir();
  const testing::ProcessResult p =
      testing::run_process({VOUSSOIR_BINARY, "spread", case_path("circular_arch"), "--quiet",
                            "--step", "0.0055", "--max", "0.0055", "--set", "supports.ramp=0.2",
                            "--csv", dir + "spread.csv", "--json", dir + "spread.json"},
                           {}, dir + "spread_cmd");
  ASSERT_TRUE(p.exited && p.status == 0) << p.describe() << p.err;
  EXPECT_NE(p.out.find("collapse    none up to 0.0055 m"), std::string::npos) << p.out;
  const std::string csv = testing::read_text_file(dir + "spread.csv");
  EXPECT_EQ(csv.rfind("movement,collapsed,thrust,thrust_left,thrust_right,hinges", 0), 0u);
  const nlohmann::json j = nlohmann::json::parse(testing::read_text_file(dir + "spread.json"));
  EXPECT_EQ(j.at("block"), 11);
  EXPECT_EQ(j.at("states").size(), 2u);
  EXPECT_TRUE(j.at("collapse_movement").is_null());
  EXPECT_NEAR(j.at("thrust_min").get<double>(), 1848.55, 0.01);
  EXPECT_EQ(j.at("states")[1].at("hinges").size(), 3u);
}

}  // namespace
}  // namespace voussoir

// Rigid blocks by non-smooth contact dynamics (contact/nscd.hpp, engine/step.cpp advance_nscd;
// docs/nscd.md): the local law solved exactly, the contact points of two pieces, a block at
// rest stays still, free fall, the incline's stick and slip, Housner's loss at a rocking
// impact, the energy ledger, a long chain of voussoirs settled by the cone solve, restart bit
// for bit, the capacity of a block and of the arch
// against limit analysis, and bad input refused by name.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "contact/nscd.hpp"
#include "core/rigid.hpp"
#include "engine/checkpoint.hpp"
#include "engine/setup.hpp"
#include "io/deck.hpp"
#include "split_restart.hpp"
#include "subprocess.hpp"

namespace voussoir {
namespace {

constexpr double kG = 9.81;

Simulation deck_sim(const std::string& text, const std::vector<std::string>& sets = {}) {
  return make_simulation(parse_deck(text, "test", sets));
}

// A rigid block w x h on a fixed ground (scene "block"), by non-smooth contact dynamics.
std::string block_deck(double width, double height, double friction, const std::string& more = "") {
  return "[model]\nkind = \"block\"\nwidth = " + std::to_string(width) +
         "\nheight = " + std::to_string(height) + "\n" + more +
         "[material]\nmodel = \"rigid\"\n[contact]\nfriction = " + std::to_string(friction) +
         "\n[solver]\nscheme = \"nscd\"\n";
}

Index free_block(const Model& m) {
  for (Index b = 0; b < Index(m.blocks.size()); ++b)
    if (!m.blocks[std::size_t(b)].fixed) return b;
  return -1;
}

void run_for(Simulation& sim, double seconds) {
  const double end = sim.ctx.time + seconds - 0.5 * sim.ctx.dt;
  while (sim.ctx.time < end) advance(sim);
}

TEST(NscdLaw, TheLocalSolutionSatisfiesSignoriniAndCoulomb) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int open = 0, stick = 0, slide = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    // A positive definite 2x2 block, a free velocity, a least normal velocity, a friction.
    const double a = 0.2 + std::abs(u(rng)), c = 0.2 + std::abs(u(rng));
    const double b = 0.9 * std::sqrt(a * c) * u(rng);
    const double qn = u(rng), qt = u(rng), u_min = 0.3 * u(rng), mu = 0.8 * std::abs(u(rng));
    const PointImpulse r = solve_point(a, b, c, qn, qt, u_min, mu);
    const double un = a * r.rn + b * r.rt + qn, ut = b * r.rn + c * r.rt + qt;
    const double tol = 1e-12;
    EXPECT_GE(r.rn, 0.0);
    EXPECT_GE(un, u_min - tol);
    EXPECT_NEAR(r.rn * (un - u_min), 0.0, tol);
    EXPECT_LE(std::abs(r.rt), mu * r.rn + tol);
    if (r.rn == 0.0) {
      ++open;
    } else if (std::abs(r.rt) < mu * r.rn * (1.0 - 1e-9)) {
      ++stick;
      EXPECT_NEAR(ut, 0.0, tol);
    } else {
      ++slide;
      EXPECT_LE(r.rt * ut, tol);  // the slip opposes the friction impulse
    }
  }
  // Every case is met.
  EXPECT_GT(open, 100);
  EXPECT_GT(stick, 100);
  EXPECT_GT(slide, 100);
}

TEST(NscdPoints, AFaceOnAFaceGivesTheEndsOfTheSharedSegment) {
  // Unit square P under a wider square Q, 1 mm apart; Q's face spans x in [0.25, 2].
  const Vec2 p[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const Vec2 q[4] = {{0.25, 1.001}, {2, 1.001}, {2, 2}, {0.25, 2}};
  std::vector<ContactPoint> out;
  piece_contact_points(p, 4, 0xfu, q, 4, 0xfu, 0.01, 0, 1, 0, out);
  ASSERT_EQ(out.size(), 2u);
  std::vector<double> xs = {out[0].x.x, out[1].x.x};
  std::sort(xs.begin(), xs.end());
  EXPECT_NEAR(xs[0], 0.25, 1e-12);
  EXPECT_NEAR(xs[1], 1.0, 1e-12);
  for (const ContactPoint& c : out) {
    EXPECT_NEAR(c.gap, 0.001, 1e-12);
    EXPECT_NEAR(c.n.x, 0.0, 1e-12);
    EXPECT_NEAR(c.n.y, 1.0, 1e-12);  // from a (P) into b (Q)
    EXPECT_NEAR(c.x.y, 1.0005, 1e-12);
  }
  // Beyond the alert distance: none.
  out.clear();
  piece_contact_points(p, 4, 0xfu, q, 4, 0xfu, 0.0005, 0, 1, 0, out);
  EXPECT_TRUE(out.empty());
}

TEST(NscdPoints, ACornerInAFaceGivesOnePoint) {
  // A square turned by 45 degrees with its lower corner 0.5 mm into the top face of P.
  const double r = std::sqrt(0.5);
  const Vec2 p[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const Vec2 q[4] = {
      {0.5, 0.9995}, {0.5 + r, 0.9995 + r}, {0.5, 0.9995 + 2 * r}, {0.5 - r, 0.9995 + r}};
  std::vector<ContactPoint> out;
  piece_contact_points(p, 4, 0xfu, q, 4, 0xfu, 0.01, 0, 1, 0, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(out[0].gap, -0.0005, 1e-12);
  EXPECT_NEAR(out[0].x.x, 0.5, 1e-12);
  // Only outline edges are faces: with P's top edge a cut inside its block, no point.
  out.clear();
  piece_contact_points(p, 4, 0xfu & ~(1u << 2), q, 4, 0xfu, 0.01, 0, 1, 0, out);
  EXPECT_TRUE(out.empty());
}

TEST(Nscd, ABlockAtRestStaysStillAndItsLedgerBalances) {
  Simulation sim = deck_sim(block_deck(0.5, 1.0, 0.6));
  const Index b = free_block(sim.model);
  run_for(sim, 2.0);
  const RigidBodies& r = sim.model.rigid;
  // Rigid contacts: nothing moves but the solve's tolerance lets through, at most
  // tolerance x h g a step (docs/nscd.md "Rest is rest").
  const double creep = sim.ctx.nscd_settings.tolerance * sim.ctx.dt * kG * sim.ctx.time;
  EXPECT_LT(std::hypot(r.ux[b], r.uy[b]), creep);
  EXPECT_LT(std::abs(r.theta[b]) * 0.5, creep);
  EXPECT_LT(sim.ledger.balance_error(), 1e-9);
  EXPECT_EQ(sim.nscd_stats.unconverged_steps, 0);
  EXPECT_EQ(sim.nscd_stats.steps, 2000);
}

TEST(Nscd, FreeFallIsExactAtThetaOneHalf) {
  Simulation sim = deck_sim(block_deck(0.5, 1.0, 0.6));
  sim.ctx.contact_on = false;
  const Index b = free_block(sim.model);
  run_for(sim, 0.5);
  const double t = sim.ctx.time;
  EXPECT_NEAR(sim.model.rigid.uy[b], -0.5 * kG * t * t, 1e-12);
  EXPECT_NEAR(sim.model.rigid.vy[b], -kG * t, 1e-12);
  EXPECT_LT(sim.ledger.balance_error(), 1e-12);
  EXPECT_EQ(sim.ledger.damping_dissipated, 0.0);
}

// The block's velocity along the incline's downward direction [m/s].
double down_slope_speed(const Simulation& sim, double incline_deg) {
  const Index b = free_block(sim.model);
  const double th = incline_deg * std::numbers::pi / 180.0;
  const RigidBodies& r = sim.model.rigid;
  // The scene's ground falls towards +x or -x: the speed's magnitude along the slope.
  return std::abs(r.vx[b] * std::cos(th) +
                  std::abs(r.vy[b]) * std::sin(th) * (r.vx[b] >= 0.0 ? 1.0 : -1.0));
}

TEST(Nscd, AnInclineHoldsBelowTheFrictionAngleAndSlidesWithCoulombsAcceleration) {
  {
    Simulation sim = deck_sim(block_deck(0.5, 0.5, 0.6, "incline = 20.0\n"));
    const Index b = free_block(sim.model);
    run_for(sim, 1.0);
    EXPECT_LT(std::hypot(sim.model.rigid.ux[b], sim.model.rigid.uy[b]), 1e-9);
  }
  const double theta = 30.0, mu = 0.3;
  Simulation sim = deck_sim(block_deck(0.5, 0.5, mu, "incline = 30.0\n"));
  run_for(sim, 0.1);
  const double v1 = down_slope_speed(sim, theta), t1 = sim.ctx.time;
  run_for(sim, 0.3);
  const double v2 = down_slope_speed(sim, theta), t2 = sim.ctx.time;
  const double th = theta * std::numbers::pi / 180.0;
  const double expected = kG * (std::sin(th) - mu * std::cos(th));
  EXPECT_NEAR((v2 - v1) / (t2 - t1), expected, 1e-6 * expected);
  EXPECT_LT(std::abs(sim.model.rigid.theta[free_block(sim.model)]), 1e-9);  // slides, no tumble
  EXPECT_GT(sim.ledger.friction_dissipated, 0.0);
  EXPECT_LT(sim.ledger.balance_error(), 1e-9);
}

TEST(Nscd, ARockingImpactLosesHousnersShare) {
  // A 0.25 x 1 block tilted onto its right corner and let go rocks back; at the impact on its
  // left corner a plastic point impact keeps the angular momentum about the new pivot:
  // omega+ / omega- = 1 - 3/2 sin^2(alpha) (Housner 1963).
  const double w = 0.25, h = 1.0;
  Simulation sim = deck_sim(block_deck(w, h, 0.8));
  const Index b = free_block(sim.model);
  const double tilt = 0.05;  // rad, about the right corner (x = w/2, y = 0)
  const double cx = 0.5 * w - (0.5 * w * std::cos(tilt) - 0.5 * h * std::sin(tilt));
  const double cy = 0.5 * w * std::sin(tilt) + 0.5 * h * std::cos(tilt);
  const RigidBodies& r = sim.model.rigid;
  set_rigid_state(sim.model, b, cx, cy, tilt, 0.0, 0.0, 0.0);
  double before = 0.0, after = 0.0;
  while (sim.ctx.time < 2.0) {
    const double theta0 = r.theta[b], omega0 = r.omega[b];
    advance(sim);
    if (theta0 > 0.0 && r.theta[b] <= 0.0) {
      before = omega0;
      // The first step wholly on the new pivot.
      advance(sim);
      after = r.omega[b];
      break;
    }
  }
  ASSERT_LT(before, 0.0);
  const double alpha = std::atan(w / h), s = std::sin(alpha);
  const double housner = 1.0 - 1.5 * s * s;
  EXPECT_NEAR(after / before, housner, 0.02 * housner);
  EXPECT_GT(sim.ledger.impact_dissipated, 0.0);
  EXPECT_LT(sim.ledger.balance_error(), 1e-6);
}

TEST(Nscd, RestartContinuesBitForBit) {
  const std::string deck = block_deck(0.25, 1.0, 0.8);
  const auto make = [&] { return deck_sim(deck); };
  const auto [straight, second] = testing::split_restart(
      make, free_block(make().model), 0.8, ::testing::TempDir() + "nscd_restart.ckpt");
  EXPECT_EQ(second.model.rigid.ux, straight.model.rigid.ux);
  EXPECT_EQ(second.model.rigid.theta, straight.model.rigid.theta);
  EXPECT_EQ(second.model.rigid.omega, straight.model.rigid.omega);
  EXPECT_EQ(second.ledger.impact_dissipated, straight.ledger.impact_dissipated);
  EXPECT_EQ(second.nscd_stats.iterations, straight.nscd_stats.iterations);
  EXPECT_EQ(second.nscd_stats.cone_products, straight.nscd_stats.cone_products);
  EXPECT_EQ(second.nscd_stats.factorisations, straight.nscd_stats.factorisations);
  // The explicit scheme's checkpoint is not this one's.
  Simulation explicit_sim = deck_sim(deck, {"solver.scheme=\"explicit\""});
  EXPECT_NE(simulation_fingerprint(explicit_sim, 0.8), simulation_fingerprint(second, 0.8));
}

TEST(Nscd, ABlockUnderLambdaStandsBelowWidthOverHeightAndTipsAbove) {
  // Under lambda g a 0.5 x 1 block holds below its capacity and moves above it: it tips at
  // lambda = b/h = 0.5 when mu = 0.8, and slides at lambda = mu when mu = 0.3 (cases/README.md,
  // "block.toml"). `motion` reads the rotation or the slip.
  auto moved = [](double mu, double lambda, bool tips) {
    Simulation sim = deck_sim(block_deck(0.5, 1.0, mu));
    set_static_load(sim, kG, lambda);
    run_for(sim, 0.5);
    const Index b = free_block(sim.model);
    return std::abs(tips ? sim.model.rigid.theta[b] : sim.model.rigid.ux[b]);
  };
  EXPECT_LT(moved(0.8, 0.49, true), 1e-9);
  EXPECT_GT(moved(0.8, 0.51, true), 1e-3);
  EXPECT_LT(moved(0.3, 0.29, false), 1e-9);
  EXPECT_GT(moved(0.3, 0.31, false), 1e-3);
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::path(::testing::TempDir()) / name).string();
}

TEST(Nscd, AChainOfNinetyVoussoirsConvergesAndRestsOnItsWeight) {
  // A semicircular arch of 2-degree voussoirs: Gauss-Seidel alone would carry its thrust
  // along the chain one block a sweep; the cone solve (contact/nscd.hpp) puts it in place.
  Simulation sim = deck_sim(
      "[model]\nkind = \"circular_arch\"\nradius = 1.0\nthickness = 0.2\nembrace = 180.0\n"
      "voussoirs = 90\n[material]\nmodel = \"rigid\"\ndensity = 2000.0\n[contact]\n"
      "friction = 0.6\n[solver]\nscheme = \"nscd\"\n");
  run_for(sim, 0.1);
  const RigidBodies& r = sim.model.rigid;
  const std::vector<double> ux = r.ux, uy = r.uy, th = r.theta;
  run_for(sim, 0.2);
  EXPECT_EQ(sim.nscd_stats.unconverged_steps, 0);
  EXPECT_GT(sim.nscd_stats.cone_steps, 0);
  // The cone solve's work is counted: a product with W at least per cone solve, and the
  // Newton steps on the face factor its matrix.
  EXPECT_GE(sim.nscd_stats.cone_products, sim.nscd_stats.cone_steps);
  EXPECT_GT(sim.nscd_stats.factorisations, 0);
  // Rest is rest (docs/nscd.md): a drift below 1e-6 of the span over 2 s, here over 0.2 s,
  // of the 2 m span.
  const double creep = 1e-6 * 2.0 * 0.2 / 2.0;
  double moved = 0.0, weight = 0.0;
  for (std::size_t b = 0; b < sim.model.blocks.size(); ++b) {
    if (sim.model.blocks[b].fixed) continue;
    moved = std::max(
        moved, std::hypot(r.ux[b] - ux[b], r.uy[b] - uy[b]) + 0.1 * std::abs(r.theta[b] - th[b]));
    weight += r.mass[b] * kG;
  }
  EXPECT_LT(moved, creep);
  // The supports carry the weight: the forces of the last step's impulses on the free blocks
  // from the fixed ones.
  double carried = 0.0;
  for (const BlockPairForce& f : sim.contact.block_pair_forces(sim.model, sim.ctx.dt)) {
    const bool a_fixed = sim.model.blocks[std::size_t(f.block_a)].fixed;
    const bool b_fixed = sim.model.blocks[std::size_t(f.block_b)].fixed;
    if (a_fixed && !b_fixed) carried += f.force.y;
    if (b_fixed && !a_fixed) carried -= f.force.y;
  }
  EXPECT_NEAR(carried, weight, 1e-6 * weight);
}

TEST(NscdProgram, TheArchsCapacityLiesBetweenTheExplicitSchemeAndLimitAnalysis) {
  const std::string json = temp_path("nscd_arch.json");
  const std::string limit_json = temp_path("nscd_arch_limit.json");
  const std::string deck = std::string(VOUSSOIR_SOURCE_DIR) + "/cases/circular_arch.toml";
  const testing::ProcessResult cap =
      testing::run_process({VOUSSOIR_BINARY, "capacity", deck, "--set", "solver.scheme=\"nscd\"",
                            "--quiet", "--json", json},
                           {.wall_s = 120, .cpu_s = 240}, temp_path("nscd_arch"));
  ASSERT_TRUE(cap.exited && cap.status == 0) << cap.describe() << cap.err;
  const testing::ProcessResult lim =
      testing::run_process({VOUSSOIR_BINARY, "limit", deck, "--quiet", "--json", limit_json},
                           {.wall_s = 60}, temp_path("nscd_arch_limit"));
  ASSERT_TRUE(lim.exited && lim.status == 0) << lim.describe() << lim.err;
  const nlohmann::json c = nlohmann::json::parse(testing::read_text_file(json));
  const nlohmann::json l = nlohmann::json::parse(testing::read_text_file(limit_json));
  const double lambda = c.at("lambda_star"), la = l.at("lambda_la");
  // Rigid contacts: the collapse load of the rigid blocks, limit analysis's, within the
  // search's tolerance (0.5%) and below it (a trial above lambda_la collapses).
  EXPECT_NEAR(lambda, la, 0.01 * la);
  const nlohmann::json& s = c.at("solver");
  EXPECT_EQ(s.at("scheme"), "nscd");
  EXPECT_EQ(s.at("converged"), true);  // at most kUnconvergedShare of the steps at the cap
  EXPECT_GE(s.at("iterations_max").get<int>(), 1);
  EXPECT_LT(s.at("max_interpenetration").get<double>(), 1e-4);
  // The cone solve's work in the record: products with W whenever it ran.
  const long long cone_steps = s.at("cone_steps"), products = s.at("cone_products");
  EXPECT_GE(products, cone_steps);
  EXPECT_EQ(products > 0, cone_steps > 0);
  EXPECT_GE(s.at("factorisations").get<long long>(), 0);
  EXPECT_EQ(c.at("quasi_static"), false);
}

// A study's tilting capacity (pulse --curve, ida: commands/pulse.hpp study_capacity) is
// searched at the default tolerance when the study's is looser: at 1e-2 the arch's own capacity
// search takes creeping trials for collapses and finds a lower lambda*, and says on stderr that
// it may (engine/solver_report.hpp warn_loose_tolerance); the curve's lambda* is the capacity at
// the default tolerance, to the last digit.
TEST(NscdProgram, AStudysTiltingCapacityIsSearchedAtTheDefaultTolerance) {
  const std::string deck = std::string(VOUSSOIR_SOURCE_DIR) + "/cases/circular_arch.toml";
  const std::string warning = "solver.tolerance = 0.01 is looser than the default 1e-06";
  auto lambda_star = [&](const std::string& name, std::vector<std::string> args,
                         std::string* err = nullptr) {
    const std::string json = temp_path(name + ".json");
    args.insert(args.begin(), {VOUSSOIR_BINARY});
    for (const char* a : {"--set", "solver.scheme=\"nscd\"", "--json"}) args.emplace_back(a);
    args.push_back(json);
    const testing::ProcessResult p =
        testing::run_process(args, {.wall_s = 120, .cpu_s = 240}, temp_path(name));
    EXPECT_TRUE(p.exited && p.status == 0) << p.describe() << p.err;
    if (err != nullptr) *err = p.err;
    return nlohmann::json::parse(testing::read_text_file(json)).at("lambda_star").get<double>();
  };
  std::string converged_err, loose_err;
  const double converged = lambda_star("study_cap_default", {"capacity", deck}, &converged_err);
  const double loose = lambda_star(
      "study_cap_loose", {"capacity", deck, "--set", "solver.tolerance=1e-2"}, &loose_err);
  const double study = lambda_star(
      "study_cap_curve", {"pulse", deck, "--curve", "--freqs", "5", "--set",
                          "load.base.signal=\"sine_pulse\"", "--set", "solver.tolerance=1e-2"});
  EXPECT_LT(loose, converged);
  EXPECT_EQ(study, converged);
  EXPECT_NE(loose_err.find(warning), std::string::npos) << loose_err;
  EXPECT_EQ(converged_err.find("looser than the default"), std::string::npos) << converged_err;
}

TEST(NscdDeck, BadSettingsAreRefusedNamingTheKeyAndValue) {
  const std::string deck = block_deck(0.5, 1.0, 0.6);
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"solver.theta=0.4", "solver.theta"},
      {"solver.theta=1.5", "solver.theta"},
      {"solver.tolerance=0", "solver.tolerance"},
      {"solver.max_iterations=0", "solver.max_iterations"},
      {"solver.dt=-0.001", "solver.dt"},
      {"solver.dt=0", "solver.dt"},
      {"solver.scheme=\"implicit\"", "solver.scheme"},
      {"material.model=\"elastic\"", "solver.scheme"}};
  for (const auto& [set, key] : bad) {
    try {
      parse_deck(deck, "test", {set});
      ADD_FAILURE() << set << " was accepted";
    } catch (const DeckError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
  // The ends of theta's range are allowed.
  for (const char* set : {"solver.theta=0.5", "solver.theta=1", "solver.theta=1.0"})
    EXPECT_NO_THROW(parse_deck(deck, "test", {set})) << set;
  // Through the program: exit status 2.
  const testing::ProcessResult p = testing::run_process(
      {VOUSSOIR_BINARY, "check", std::string(VOUSSOIR_SOURCE_DIR) + "/cases/circular_arch.toml",
       "--set", "solver.scheme=\"nscd\"", "--set", "material.model=\"elastic\""},
      {.wall_s = 60}, temp_path("nscd_bad"));
  EXPECT_TRUE(p.exited && p.status == 2) << p.describe();
  EXPECT_NE(p.err.find("solver.scheme"), std::string::npos) << p.err;
}

}  // namespace
}  // namespace voussoir

// Quasi-static decisions of `capacity` and `sweep` (docs/capacity.md, "Quasi-static decisions"):
// Cundall's local damping (core/integrate.hpp LocalDamping) against its closed form in free fall,
// its energy booked so that the ledger still closes, a disturbed block brought to rest, the
// analytic capacities of the block kept; kinetic damping (core/integrate.hpp KineticDamping): a
// mechanism never reset, a swing stopped at its equilibrium with the ledger closed, a structure out
// of balance not held still by its resets; the load direction (`capacity --direction`) against
// mirror symmetry; bad keys and options refused.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "commands/capacity.hpp"
#include "core/rigid.hpp"
#include "engine/setup.hpp"
#include "engine/step.hpp"
#include "engine/trial.hpp"
#include "io/deck.hpp"
#include "limit/limit_analysis.hpp"
#include "subprocess.hpp"

namespace voussoir {
namespace {

namespace fs = std::filesystem;

// A 0.25 x 1 m block on a fixed ground (scene "block"), rigid or elastic.
std::string block_deck(const std::string& model, double mu = 0.8) {
  return "[model]\nkind = \"block\"\nwidth = 0.25\nheight = 1.0\n[material]\nmodel = \"" + model +
         "\"\n[contact]\nfriction = " + std::to_string(mu) + "\n";
}

Index free_block(const Model& m) {
  for (Index b = 0; b < Index(m.blocks.size()); ++b)
    if (!m.blocks[std::size_t(b)].fixed) return b;
  return -1;
}

TEST(LocalDamping, ForceOpposesTheVelocityInProportionToTheForce) {
  // Full rule: against the velocity, alpha |f|, whatever the sign of the force.
  EXPECT_EQ(local_damping_force(0.8, false, 10.0, 1.0), -8.0);
  EXPECT_EQ(local_damping_force(0.8, false, -10.0, 1.0), -8.0);
  EXPECT_EQ(local_damping_force(0.8, false, 10.0, -1.0), 8.0);
  EXPECT_EQ(local_damping_force(0.8, false, 10.0, 0.0), 0.0);
  EXPECT_EQ(local_damping_force(0.8, false, 0.0, 3.0), 0.0);
  // Outgoing rule: only when the force opposes the velocity, then alpha f.
  EXPECT_EQ(local_damping_force(0.8, true, 10.0, 1.0), 0.0);
  EXPECT_EQ(local_damping_force(0.8, true, -10.0, 1.0), -8.0);
  EXPECT_EQ(local_damping_force(0.8, true, 10.0, -1.0), 8.0);
  EXPECT_EQ(local_damping_force(0.8, true, 10.0, 0.0), 0.0);
}

// A body falling freely under a constant force mg. Full rule: from the second step on, the
// damping force is alpha m g against the motion, so the velocity gains (1 - alpha) g dt per
// step, v^(N+1/2) = -g dt - N (1 - alpha) g dt, and the ledger books the fraction alpha of
// the work of gravity as dissipated. Outgoing rule: the force drives the motion, so nothing
// is damped: v^(N+1/2) = -(N + 1) g dt, as without damping.
void expect_damped_free_fall(const std::string& model, bool outgoing) {
  Simulation sim = make_simulation(parse_deck(block_deck(model), "test"));
  const Index b = free_block(sim.model);
  if (model == "rigid") {
    set_rigid_state(sim.model, b, sim.model.rigid.cx0[b], sim.model.rigid.cy0[b] + 1.0, 0.0, 0.0,
                    0.0, 0.0);
  } else {
    const Block& blk = sim.model.blocks[std::size_t(b)];
    for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i)
      sim.model.nodes.y[i] += 1.0;
  }
  const double alpha = 0.8, g = 9.81, dt = sim.ctx.dt;
  sim.ctx.local_damping = alpha;
  sim.ctx.local_damping_outgoing = outgoing;
  const int steps = 200;  // far less than the 1 m drop
  for (int k = 0; k < steps; ++k) advance(sim);
  sync_rigid_nodes(sim.model);  // rigid blocks: the nodes follow the body when read
  const double expected =
      outgoing ? -steps * g * dt : -g * dt - (steps - 1) * (1.0 - alpha) * g * dt;
  const Block& blk = sim.model.blocks[std::size_t(b)];
  for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i) {
    // Elastic blocks: the element forces of the unstrained block are round-off (E x 1e-16).
    const double tol = (model == "rigid" ? 1e-9 : 1e-8) * std::abs(expected);
    EXPECT_NEAR(sim.model.nodes.vy[i], expected, tol) << model;
    EXPECT_NEAR(sim.model.nodes.vx[i], 0.0, 1e-12) << model;
  }
  if (outgoing) {
    EXPECT_LT(std::abs(sim.ledger.local_dissipated), 1e-9 * sim.ledger.external_work) << model;
  } else {
    // Of the work of gravity, the fraction alpha went into the damping (up to the first step).
    EXPECT_NEAR(sim.ledger.local_dissipated / sim.ledger.external_work, alpha, 0.01) << model;
  }
  EXPECT_LT(sim.ledger.balance_error(), 1e-9) << model;
}

TEST(LocalDamping, FullRuleFreeFallAcceleratesAtOneMinusAlphaG) {
  expect_damped_free_fall("rigid", false);
  expect_damped_free_fall("elastic", false);
}

TEST(LocalDamping, OutgoingRuleLeavesAnAcceleratingBodyAlone) {
  expect_damped_free_fall("rigid", true);
  expect_damped_free_fall("elastic", true);
}

// A rigid block tilted by 0.004 rad and held 0.2 mm above its joint at the lower corner, then
// let go: without damping (restitution 1) it rocks and bounces on the joint springs for good;
// with local damping it comes to rest within a few periods, and the ledger closes in both runs.
TEST(LocalDamping, DisturbedBlockComesToRestAndTheLedgerCloses) {
  for (bool outgoing : {false, true}) {
    double kinetic[2] = {0.0, 0.0};
    for (int damped = 0; damped < 2; ++damped) {
      Simulation sim = make_simulation(parse_deck(block_deck("rigid"), "test"));
      const Index b = free_block(sim.model);
      const double tilt = 0.004, half_width = 0.125;
      set_rigid_state(sim.model, b, sim.model.rigid.cx0[b],
                      sim.model.rigid.cy0[b] + half_width * tilt + 2e-4, tilt, 0.0, 0.0, 0.0);
      sim.ctx.local_damping = damped ? 0.8 : 0.0;
      sim.ctx.local_damping_outgoing = outgoing;
      double worst = 0.0;
      while (sim.ctx.time < 0.3) {
        advance(sim);
        worst = std::max(worst, sim.ledger.balance_error());
      }
      kinetic[damped] = sim.ledger.kinetic;
      EXPECT_LT(worst, 0.01) << "damped " << damped << " outgoing " << outgoing;
      if (damped) {
        EXPECT_GT(sim.ledger.local_dissipated, 0.0);
      } else {
        EXPECT_EQ(sim.ledger.local_dissipated, 0.0);
      }
    }
    EXPECT_GT(kinetic[0], 0.0);
    EXPECT_LT(kinetic[1], 1e-6 * kinetic[0]) << "outgoing " << outgoing;
  }
}

// The capacity trials' rest rule (engine/trial.hpp RestRule with refuse_creep) on a stack of
// two rigid blocks moved by hand, sampled every millisecond at a tenth of the rest speed with
// a kinetic energy that grows at every sample: the decay check alone never calls that rest.
// Going back (every block's displacement since the start shrinks) is rest after one hold
// window; one block going back while the other moves away from the start is not, even when
// the largest displacement shrinks (the creep check reads only that largest one).
struct MovedByHand {
  Simulation sim;
  std::vector<BlockMotion> base;
  std::vector<Index> blocks;
  explicit MovedByHand(const std::string& deck) : sim(make_simulation(parse_deck(deck, "test"))) {
    base = block_motions(sim.model);
    for (Index b = 0; b < Index(sim.model.blocks.size()); ++b)
      if (!sim.model.blocks[std::size_t(b)].fixed) blocks.push_back(b);
  }
  void shift(Index b, double ux) {
    const RigidBodies& r = sim.model.rigid;
    set_rigid_state(sim.model, b, r.cx0[b] + ux, r.cy0[b], 0.0, 0.0, 0.0, 0.0);
  }
};

// Samples the rule for 0.3 s while `move(k)` places the blocks at sample k; the run time of
// the rest verdict, or -1.
template <class Move>
double rest_time(MovedByHand& h, Move move) {
  const double v_rest = 1e-3, hold = 0.1, d_scale = 0.01, rot_scale = 0.05;
  RestRule rule(v_rest, hold, 0.0);
  rule.refuse_creep(d_scale, rot_scale, kCreepTolerance);
  for (int k = 0; k <= 300; ++k) {
    move(k);
    h.sim.ledger.kinetic = 1e-9 * (1.0 + k);  // growing at every sample
    Probe p(h.sim);
    p.time = 1e-3 * k;
    const std::vector<MotionExtent> blocks = motions_since(h.sim.model, h.base);
    p.motion = largest_of(blocks);
    p.blocks = &blocks;
    p.speed = 0.1 * v_rest;
    const std::optional<Verdict> v = rule.check(p);
    if (v) {
      EXPECT_FALSE(v->collapsed);
      return p.time;
    }
  }
  return -1.0;
}

TEST(RestRule, AStructureGoingBackIsAtRestWhileItsKineticEnergyGrows) {
  const std::string deck =
      "[model]\nkind = \"block\"\nwidth = 0.25\nheight = 1.0\nstack = 2\n[material]\nmodel = "
      "\"rigid\"\n";
  MovedByHand back(deck);
  ASSERT_EQ(back.blocks.size(), 2u);
  const double t = rest_time(back, [&](int k) {
    back.shift(back.blocks[0], 2e-3 - 1e-6 * k);
    back.shift(back.blocks[1], 3e-3 - 2e-6 * k);
  });
  EXPECT_GE(t, 0.1);
  EXPECT_LE(t, 0.102);

  MovedByHand away(deck);
  EXPECT_LT(rest_time(away, [&](int k) {
              away.shift(away.blocks[0], 2e-3 + 1e-6 * k);
              away.shift(away.blocks[1], 3e-3 + 2e-6 * k);
            }),
            0.0);

  // One block goes back from 3 mm and stays the largest motion, which is all the creep check
  // reads; the other moves away from 1 mm by 5e-7 m per hold window.
  MovedByHand mixed(deck);
  EXPECT_LT(rest_time(mixed, [&](int k) {
              mixed.shift(mixed.blocks[0], 1e-3 + 5e-9 * k);
              mixed.shift(mixed.blocks[1], 3e-3 - 2e-6 * k);
            }),
            0.0);
}

// Kinetic damping (core/integrate.hpp KineticDamping). A body that the load accelerates has a
// growing kinetic energy: never reset, its fall is the undamped one bit for bit.
TEST(KineticDamping, AcceleratingBodyIsNeverReset) {
  for (const std::string model : {"rigid", "elastic"}) {
    Simulation sims[2] = {make_simulation(parse_deck(block_deck(model), "test")),
                          make_simulation(parse_deck(block_deck(model), "test"))};
    for (int k = 0; k < 2; ++k) {
      Simulation& sim = sims[k];
      const Index b = free_block(sim.model);
      const Block& blk = sim.model.blocks[std::size_t(b)];
      if (model == "rigid") {
        set_rigid_state(sim.model, b, sim.model.rigid.cx0[b], sim.model.rigid.cy0[b] + 1.0, 0.0,
                        0.0, 0.0, 0.0);
      } else {
        for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i)
          sim.model.nodes.y[i] += 1.0;
      }
      sim.ctx.kinetic_damping = k == 1 ? 1e-3 : 0.0;
      for (int s = 0; s < 200; ++s) advance(sim);
      sync_rigid_nodes(sim.model);
    }
    EXPECT_EQ(sims[0].model.nodes.vy, sims[1].model.nodes.vy) << model;
    EXPECT_EQ(sims[0].model.nodes.y, sims[1].model.nodes.y) << model;
    EXPECT_EQ(sims[1].ledger.local_dissipated, 0.0) << model;
    EXPECT_EQ(sims[1].kinetic_peak, sims[1].ledger.kinetic) << model;
  }
}

// A slender rigid block (0.25 x 1 m) standing on its joint, with a horizontal load of 0.1 g
// put on at once (its capacity is 0.25 g): it tilts on the joint springs towards a tilted
// equilibrium. Without damping it swings past that equilibrium to twice its tilt and more
// (it also rocks and bounces: this undamped run is not checked further), and the outgoing
// local damping, which acts only past the equilibrium, still lets it reach about 1 +
// 1/sqrt(1 + alpha) = 1.75 times the tilt. With kinetic damping alone its kinetic energy peaks
// where it crosses the equilibrium, the reset stops it there (within the few steps that
// resolve the block's swing on such stiff springs), and it comes to rest. The damped runs
// close their ledgers, the reset's energy booked as dissipated.
TEST(KineticDamping, SwingIsStoppedAtItsEquilibrium) {
  struct Swing {
    double largest_tilt = 0.0, final_tilt = 0.0, final_kinetic = 0.0, worst_balance = 0.0;
    double removed = 0.0;
  };
  auto swing = [](double kinetic_damping, double local_damping) {
    Simulation sim = make_simulation(parse_deck(block_deck("rigid"), "test"));
    const Index b = free_block(sim.model);
    sim.ctx.kinetic_damping = kinetic_damping;
    sim.ctx.local_damping = local_damping;
    // Settled first under gravity alone, then the load.
    while (sim.ctx.time < 0.02) advance(sim);
    const double theta0 = sim.model.rigid.theta[b];
    sim.ctx.body_ax = 0.1 * 9.81;
    Swing s;
    while (sim.ctx.time < 0.1) {
      advance(sim);
      s.largest_tilt = std::max(s.largest_tilt, std::abs(sim.model.rigid.theta[b] - theta0));
      s.worst_balance = std::max(s.worst_balance, sim.ledger.balance_error());
    }
    s.final_tilt = std::abs(sim.model.rigid.theta[b] - theta0);
    s.final_kinetic = sim.ledger.kinetic;
    s.removed = sim.ledger.local_dissipated;
    return s;
  };
  const Swing both = swing(1e-3, 0.8);  // its end: the equilibrium tilt
  const Swing none = swing(0.0, 0.0), local = swing(0.0, 0.8), kinetic = swing(1e-3, 0.0);
  const double tilt = both.final_tilt;
  ASSERT_GT(tilt, 0.0);
  EXPECT_LT(both.final_kinetic, 1e-12);
  EXPECT_GT(none.largest_tilt, 1.8 * tilt);
  EXPECT_GT(local.largest_tilt, 1.5 * tilt);
  EXPECT_LT(kinetic.largest_tilt, 1.2 * tilt);
  EXPECT_NEAR(kinetic.final_tilt, tilt, 0.02 * tilt);
  EXPECT_LT(kinetic.final_kinetic, 1e-12);
  EXPECT_GT(kinetic.removed, 0.0);
  for (const Swing& s : {both, local, kinetic}) EXPECT_LT(s.worst_balance, 1e-3);
}

// The kinetic damping must never hold still a structure that is not in equilibrium
// (docs/capacity.md, "The step of the quasi-static phases"). The buttressed basket arch
// at beta 150 loaded at 0.16036, the collapsed end of its bracket: at a
// quasi-static step of 0.5 of 2 / omega a joint mode of the coupled blocks turned within one
// step, the kinetic damping reset the velocities at every step from 0.2 s on, and the arch
// stood still, out of balance, until the rest rule called it stable. Here, at the step the
// capacity trials take, the resets must stay rare after the ramp, whether the arch then moves
// on or comes to rest.
TEST(KineticDamping, AStructureOutOfBalanceIsNotHeldStill) {
  const Config config =
      load_deck(std::string(VOUSSOIR_SOURCE_DIR) + "/cases/buttressed_basket.toml",
                {"model.embrace=150"});
  TrialCriteria crit;
  crit.quasi_static = true;
  const SettledState settled = settle(config, crit, true);
  ASSERT_TRUE(settled.settled);
  Simulation sim = settled.sim;
  ASSERT_GT(sim.ctx.kinetic_damping, 0.0);
  LoadProgram loads;
  loads.gravity = settled.gravity;
  loads.lambda = 0.16036;
  loads.lambda_ramp = crit.ramp_time;
  loads.start = sim.ctx.time;
  while (sim.ctx.time - loads.start < 0.2) {  // the ramp and the first swing
    loads.apply(sim);
    advance(sim);
  }
  const long long steps_before = sim.step, resets_before = sim.kinetic_resets;
  while (sim.ctx.time - loads.start < 0.4) {
    loads.apply(sim);
    advance(sim);
  }
  const long long steps = sim.step - steps_before, resets = sim.kinetic_resets - resets_before;
  ASSERT_GT(steps, 10000);
  EXPECT_LT(double(resets), 0.05 * double(steps)) << resets << " resets in " << steps << " steps";
}

// The rest rule's creep check (engine/motion.hpp CreepDetector): a steady creep slow enough
// for the speed criterion (the rigid sliding arch held back by the local damping,
// docs/capacity.md) is refused however long it lasts; a decaying approach to a displaced
// equilibrium, with the same early growth, is accepted once it has settled.
TEST(CreepCheck, SteadyCreepIsRefusedAndADecayingMotionAccepted) {
  const double hold = 0.1, tol = kCreepTolerance, dt = 1e-3;
  // Creep: the measure grows by 4 tolerances per hold window, for ever.
  CreepDetector creep(hold, tol);
  // Decay: the same rate at t = 0, relaxing with a time constant of 0.05 s.
  CreepDetector decay(hold, tol);
  const double rate = 4.0 * tol / hold, tau = 0.05;
  bool creep_refused_always = true, decay_accepted = false;
  double accepted_at = -1.0;
  for (int k = 0; k <= 3000; ++k) {
    const double t = k * dt;
    creep.add(t, 0.2 + rate * t);
    decay.add(t, 0.2 + rate * tau * (1.0 - std::exp(-t / tau)));
    if (t >= hold) {
      creep_refused_always = creep_refused_always && creep.creeping();
      if (!decay_accepted && !decay.creeping()) {
        decay_accepted = true;
        accepted_at = t;
      }
    }
  }
  EXPECT_TRUE(creep_refused_always);
  EXPECT_NEAR(creep.growth(), 4.0 * tol, 1e-9);
  ASSERT_TRUE(decay_accepted);
  // Growth over [t - hold, t] is rate tau e^{-t/tau} (e^{hold/tau} - 1) <= tol: t >= 0.1274 s.
  EXPECT_GT(accepted_at, 0.125);
  EXPECT_LT(accepted_at, 0.131);
  // Too short a history: not known to have stopped.
  CreepDetector fresh(hold, tol);
  fresh.add(0.0, 0.5);
  fresh.add(0.05, 0.5);
  EXPECT_TRUE(fresh.creeping());
  fresh.add(0.1, 0.5);
  EXPECT_FALSE(fresh.creeping());
}

// The analytic capacities of the block (cases/README.md, `block`: overturning at b / h, sliding at
// mu) with quasi-static trials, rigid and elastic blocks.
TEST(QuasiStaticCapacity, BlockKeepsItsAnalyticCapacities) {
  TrialCriteria crit;
  crit.quasi_static = true;
  for (const char* model : {"rigid", "elastic"}) {
    const CapacityResult over =
        find_capacity(parse_deck(block_deck(model, 0.8), "test"), crit, 2, true);
    ASSERT_TRUE(over.bracketed) << model;
    EXPECT_NEAR(over.lambda_star, 0.25, 0.005 * 0.25 + 0.002) << model;
    const CapacityResult slide =
        find_capacity(parse_deck(block_deck(model, 0.2), "test"), crit, 2, true);
    ASSERT_TRUE(slide.bracketed) << model;
    EXPECT_NEAR(slide.lambda_star, 0.2, 0.005 * 0.2 + 0.002) << model;
  }
}

// Three blocks on a fixed ground, the top one overhanging to the right: the structure has no
// mirror symmetry, so its capacity towards -x differs from +x. Limit analysis towards -x must
// equal limit analysis towards +x of the mirrored blocks, and the FDEM search likewise.
std::string polygons(double sign) {
  auto p = [sign](double x, double y) {
    return std::to_string(sign * x) + " " + std::to_string(y) + "\n";
  };
  // Vertices counter-clockwise in both versions (the mirror reverses the order).
  auto block = [&](std::vector<std::array<double, 2>> v) {
    std::string s = "block\n";
    if (sign < 0) std::reverse(v.begin(), v.end());
    for (const auto& q : v) s += p(q[0], q[1]);
    return s + "\n";
  };
  return block({{-0.3, 0.0}, {0.3, 0.0}, {0.3, 0.8}, {-0.3, 0.8}}) +
         block({{-0.2, 0.8}, {0.3, 0.8}, {0.3, 1.4}, {-0.2, 1.4}}) +
         block({{-0.1, 1.4}, {0.45, 1.4}, {0.45, 1.8}, {-0.1, 1.8}}) +
         block({{-2.0, -0.3}, {2.0, -0.3}, {2.0, 0.0}, {-2.0, 0.0}});
}

Config polygon_deck(const fs::path& dir, double sign, const std::vector<std::string>& sets = {}) {
  const fs::path file = dir / (sign > 0 ? "stack.txt" : "stack_mirror.txt");
  std::ofstream(file) << polygons(sign);
  const std::string text = "[model]\nkind = \"polygons\"\nfile = \"" + file.string() +
                           "\"\nfixed = [3]\n[material]\nmodel = \"rigid\"\n"
                           "[contact]\nfriction = 0.8\n";
  return parse_deck(text, (dir / "stack.toml").string(), sets);
}

TEST(Direction, MinusXIsPlusXOfTheMirroredStructure) {
  const fs::path dir = fs::temp_directory_path() / "voussoir_direction_test";
  fs::create_directories(dir);
  const Config plain = polygon_deck(dir, 1.0), mirror = polygon_deck(dir, -1.0);
  const Model m_plain = make_simulation(plain).model, m_mirror = make_simulation(mirror).model;

  // The mirror of the model's outlines is the model of the mirrored file, to limit analysis.
  const LimitResult plus = limit_analysis(m_plain, 0.8, 9.81, false);
  const LimitResult minus = limit_analysis(mirror_x(m_plain), 0.8, 9.81, false);
  const LimitResult mirrored = limit_analysis(m_mirror, 0.8, 9.81, false);
  ASSERT_EQ(plus.status, "optimal");
  ASSERT_EQ(minus.status, "optimal");
  EXPECT_NEAR(minus.lambda_la, mirrored.lambda_la, 1e-9 * mirrored.lambda_la);
  // Not symmetric: the two directions differ by far more than the tolerances.
  EXPECT_GT(std::abs(plus.lambda_la - minus.lambda_la), 0.05 * plus.lambda_la);

  TrialCriteria crit;
  crit.quasi_static = true;
  crit.direction = -1.0;
  const CapacityResult fdem_minus = find_capacity(plain, crit, 2, true);
  crit.direction = 1.0;
  const CapacityResult fdem_mirror = find_capacity(mirror, crit, 2, true);
  ASSERT_TRUE(fdem_minus.bracketed && fdem_mirror.bracketed);
  // Both searches bracket the same threshold to the tolerance (0.5%).
  EXPECT_NEAR(fdem_minus.lambda_star, fdem_mirror.lambda_star, 0.01 * fdem_mirror.lambda_star);
  EXPECT_LT(fdem_minus.lambda_star, minus.lambda_la * 1.01);
  fs::remove_all(dir);
}

// `--direction both` on the symmetric block: two searches, each reported, equal to the
// tolerance; the JSON carries both and the governing one at the top level.
TEST(Direction, BothReportsEachDirectionAndTheSmaller) {
  const fs::path dir = fs::temp_directory_path() / "voussoir_direction_both";
  fs::create_directories(dir);
  const std::string json = (dir / "cap.json").string();
  const testing::ProcessResult r = testing::run_process(
      {VOUSSOIR_BINARY, "capacity", std::string(VOUSSOIR_SOURCE_DIR) + "/cases/block.toml", "--set",
       "material.model=rigid", "--direction", "both", "--quiet", "--json", json},
      {}, (dir / "child").string());
  ASSERT_TRUE(r.exited) << r.describe();
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("direction +x:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("direction -x:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("governing direction"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(json));
  const double plus = j["directions"]["+x"]["lambda_star"];
  const double minus = j["directions"]["-x"]["lambda_star"];
  EXPECT_NEAR(plus, minus, 0.01 * plus);
  EXPECT_EQ(double(j["lambda_star"]), std::min(plus, minus));
  EXPECT_EQ(j["direction"], plus <= minus ? "+x" : "-x");
  // Rigid blocks run the quasi-static trials too (the rest rule refuses a creep), and the
  // JSON says so.
  EXPECT_EQ(j["quasi_static"], true);
  fs::remove_all(dir);
}

// Mass scaling of the quasi-static phases (engine/step.hpp equalize_rigid_inertia) on the stack
// of three unequal blocks: each block's own stable step reaches the model's, which does not
// change; the loads keep the true masses; impact damping and elastic blocks are left alone;
// and lambda* is the same bracket as with the true inertia, towards both directions.
TEST(MassScaling, EveryBlockReachesTheStepAndTheCapacityStays) {
  const fs::path dir = fs::temp_directory_path() / "voussoir_mass_scaling";
  fs::create_directories(dir);
  // Undamped joints, as the quasi-static phases take them (commands/capacity.cpp settle).
  const Config deck = polygon_deck(dir, 1.0, {"contact.restitution=1"});
  Simulation sim = make_simulation(deck);
  const std::vector<double> before = rigid_body_stable_steps(sim);
  const double dt_before = stable_time_step(sim);
  const std::vector<double> node_mass = sim.model.nodes.mass;
  const std::vector<double> mass = sim.model.rigid.mass;
  const InertiaScaling scaled = equalize_rigid_inertia(sim);
  EXPECT_GE(scaled.blocks, 2);  // the three blocks differ: two are slower than the fastest
  EXPECT_LT(scaled.smallest, 0.9);
  const std::vector<double> after = rigid_body_stable_steps(sim);
  ASSERT_EQ(after.size(), before.size());
  for (std::size_t b = 0; b < after.size(); ++b) {
    if (!std::isfinite(before[b])) continue;
    EXPECT_NEAR(after[b], dt_before, 1e-9 * dt_before) << "block " << b;
    EXPECT_LE(sim.model.rigid.mass[b], mass[b]) << "block " << b;
  }
  EXPECT_NEAR(stable_time_step(sim), dt_before, 1e-9 * dt_before);
  EXPECT_EQ(sim.model.nodes.mass, node_mass);  // the loads' masses

  Simulation damped = make_simulation(polygon_deck(dir, 1.0, {"contact.restitution=0.5"}));
  EXPECT_EQ(equalize_rigid_inertia(damped).blocks, 0);
  Simulation elastic = make_simulation(polygon_deck(dir, 1.0, {"material.model=elastic"}));
  EXPECT_EQ(equalize_rigid_inertia(elastic).blocks, 0);

  TrialCriteria crit;
  crit.quasi_static = true;
  for (double direction : {1.0, -1.0}) {
    crit.direction = direction;
    const CapacityResult equalized = find_capacity(deck, crit, 2, true);
    const CapacityResult inertial =
        find_capacity(polygon_deck(dir, 1.0, {"capacity.mass_scaling=none"}), crit, 2, true);
    ASSERT_TRUE(equalized.bracketed && inertial.bracketed) << direction;
    EXPECT_EQ(equalized.lo, inertial.lo) << direction;
    EXPECT_EQ(equalized.hi, inertial.hi) << direction;
    long long steps_equalized = 0, steps_inertial = 0;
    for (const TrialResult& t : equalized.trials) steps_equalized += t.steps;
    for (const TrialResult& t : inertial.trials) steps_inertial += t.steps;
    std::printf("direction %+g: lambda* %.5f, steps %lld with mass scaling, %lld without\n",
                direction, equalized.lambda_star, steps_equalized, steps_inertial);
  }
  fs::remove_all(dir);
}

TEST(QuasiStaticInput, BadDampingAndDirectionAreRefused) {
  for (const std::string key : {"capacity.local_damping", "capacity.kinetic_damping"}) {
    for (const char* v : {"1.0", "-0.1", "2"}) {
      try {
        parse_deck(block_deck("rigid"), "test", {key + "=" + v});
        FAIL() << key << " = " << v;
      } catch (const DeckError& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find(key + " = "), std::string::npos) << msg;
        EXPECT_NE(msg.find(v), std::string::npos) << msg;
        EXPECT_NE(msg.find("[0, 1)"), std::string::npos) << msg;
      }
    }
  }
  try {
    parse_deck(block_deck("rigid"), "test", {"capacity.mass_scaling=fast"});
    FAIL() << "capacity.mass_scaling = fast";
  } catch (const DeckError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("capacity.mass_scaling"), std::string::npos) << msg;
    EXPECT_NE(msg.find("fast"), std::string::npos) << msg;
    EXPECT_NE(msg.find("equalize"), std::string::npos) << msg;
  }
  const fs::path dir = fs::temp_directory_path() / "voussoir_direction_bad";
  fs::create_directories(dir);
  const testing::ProcessResult r = testing::run_process(
      {VOUSSOIR_BINARY, "capacity", std::string(VOUSSOIR_SOURCE_DIR) + "/cases/block.toml",
       "--direction", "up"},
      {}, (dir / "child").string());
  ASSERT_TRUE(r.exited) << r.describe();
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--direction"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace voussoir

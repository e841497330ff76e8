// Rigid blocks and joint stiffness (core/rigid.hpp, contact/joint_stiffness.hpp; docs/rigid.md):
// a block settles by weight / (kn area), shears by force / (ks area), rebounds to e^2 of its
// drop height, keeps its energy balance (also an arch chattering on frictional joints, and a
// block rocking onto its joint, whose impact converges as the joint stiffens);
// the mass and inertia of a body; rigid rotation keeps the shape; bad keys are refused.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "contact/joint_stiffness.hpp"
#include "contact/rigid_contact.hpp"
#include "core/rigid.hpp"
#include "engine/checkpoint.hpp"
#include "engine/setup.hpp"
#include "io/deck.hpp"
#include "mesh/minimal.hpp"
#include "split_restart.hpp"

namespace voussoir {
namespace {

Simulation deck_sim(const std::string& text, const std::vector<std::string>& sets = {},
                    SetupInfo* info = nullptr) {
  return make_simulation(parse_deck(text, "test", sets), info);
}

// A rectangular rigid block on a fixed ground (scene "block"), 0.25 x 1 m, rho 2000.
std::string block_deck(const std::string& contact, const std::string& safety = "0.9") {
  return "[model]\nkind = \"block\"\nwidth = 0.25\nheight = 1.0\n"
         "[material]\nmodel = \"rigid\"\n[solver]\ndt_safety = " +
         safety + "\n[contact]\n" + contact + "\n";
}

Index free_block(const Model& m) {
  for (Index b = 0; b < Index(m.blocks.size()); ++b)
    if (!m.blocks[std::size_t(b)].fixed) return b;
  return -1;
}

// Steps until `time` [s], returning the largest ledger balance error seen.
template <class Each>
double run_until(Simulation& sim, double time, Each&& each) {
  double worst = 0.0;
  while (sim.ctx.time < time) {
    advance(sim);
    worst = std::max(worst, sim.ledger.balance_error());
    each(sim);
  }
  return worst;
}

TEST(Rigid, MassInertiaAndCentroidOfABlock) {
  Simulation sim = deck_sim(block_deck("friction = 0.8"));
  const Model& m = sim.model;
  const Index b = free_block(m);
  const double w = 0.25, h = 1.0, mass = 2000.0 * w * h;
  EXPECT_NEAR(m.rigid.mass[b], mass, 1e-9 * mass);
  EXPECT_NEAR(m.rigid.inertia[b], mass * (w * w + h * h) / 12.0, 1e-9 * mass);
  EXPECT_NEAR(m.rigid.cx0[b], 0.0, 1e-12);
  EXPECT_NEAR(m.rigid.cy0[b], 0.5, 1e-12);
}

TEST(Rigid, TriangleInertiaAgainstTheParallelAxisTheorem) {
  // Right triangle legs a, b at the origin: I about the right-angle vertex = rho A (a^2+b^2)/6.
  const double a = 0.3, b = 0.7, rho = 1500.0;
  const double i0 = triangle_polar_inertia(rho, {0, 0}, {a, 0}, {0, b}, {0, 0});
  EXPECT_NEAR(i0, rho * 0.5 * a * b * (a * a + b * b) / 6.0, 1e-12);
  // About the centroid: I0 - m |g|^2.
  const Vec2 g{a / 3.0, b / 3.0};
  const double ic = triangle_polar_inertia(rho, {0, 0}, {a, 0}, {0, b}, g);
  EXPECT_NEAR(ic, i0 - rho * 0.5 * a * b * (g.x * g.x + g.y * g.y), 1e-12);
}

TEST(Rigid, ABlockKeepsItsShapeWhateverItsRotation) {
  Simulation sim = deck_sim(block_deck("friction = 0.8"));
  Model& m = sim.model;
  const Index b = free_block(m);
  const Block& blk = m.blocks[std::size_t(b)];
  set_rigid_state(m, b, 3.0, 4.0, 2.5, 0.0, 0.0, 0.0);
  for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i)
    for (Index j = blk.first_node; j < i; ++j) {
      const double d = std::hypot(m.nodes.x[i] - m.nodes.x[j], m.nodes.y[i] - m.nodes.y[j]);
      const double d0 = std::hypot(m.nodes.x0[i] - m.nodes.x0[j], m.nodes.y0[i] - m.nodes.y0[j]);
      EXPECT_NEAR(d, d0, 1e-12);
    }
}

TEST(Rigid, FreeFlightIsExactAndConservesEnergy) {
  // No contact reached: a spinning, thrown block follows the parabola and keeps omega.
  Simulation sim = deck_sim(block_deck("friction = 0.8"));
  Model& m = sim.model;
  const Index b = free_block(m);
  set_rigid_state(m, b, 0.0, 10.0, 0.0, 1.0, 2.0, 3.0);
  const double worst = run_until(sim, 0.5, [](const Simulation&) {});
  // Central differences are exact for constant acceleration; the trapezoid ledger too.
  const double t = sim.ctx.time, g = 9.81, dt = sim.ctx.dt;
  EXPECT_NEAR(m.rigid.cx[b], 1.0 * t, 1e-9);
  // x^n = x0 + v^(-1/2) t + g/2 t (t + dt) for the leapfrog started from v^(-1/2) = v0.
  EXPECT_NEAR(m.rigid.cy[b], 10.0 + 2.0 * t - 0.5 * g * t * (t + dt), 1e-9);
  EXPECT_NEAR(m.rigid.omega[b], 3.0, 1e-12);
  EXPECT_LT(worst, 1e-9);
}

TEST(Rigid, BlockSettlesByWeightOverNormalStiffnessTimesArea) {
  const double kn = 1e9;  // soft, so the settlement is large against round-off
  Simulation sim = deck_sim(block_deck("friction = 0.8\nnormal_stiffness = 1e9\nrestitution = 0"));
  const Index b = free_block(sim.model);
  const double worst = run_until(sim, 1.0, [](const Simulation&) {});
  const double weight = 2000.0 * 0.25 * 1.0 * 9.81;
  const double expected = weight / (kn * 0.25 * 1.0);
  const double settled = sim.model.rigid.cy0[b] - sim.model.rigid.cy[b];
  EXPECT_NEAR(settled, expected, 0.01 * expected);
  EXPECT_LT(worst, 0.01);
}

TEST(Rigid, ShearOfTheJointGivesShearStiffness) {
  // A horizontal load below friction shears the base joint by F / (ks area).
  const double ks = 2e8;
  Simulation sim = deck_sim(block_deck("friction = 5\nnormal_stiffness = 1e10\n"
                                       "shear_stiffness = 2e8\nrestitution = 0"),
                            {"load.lambda=0.05"});
  const Index b = free_block(sim.model);
  // Ramp the horizontal load to avoid an overshoot, then hold; the dashpots act normal to the
  // joint only, so the shear mode keeps ringing: average over its last period.
  const double lambda = 0.05, g = 9.81, ramp = 0.2;
  double sum = 0.0, n = 0.0;
  const double mass = 2000.0 * 0.25;
  const double period = 2.0 * std::numbers::pi * std::sqrt(mass / (ks * 0.25));
  const double worst = run_until(sim, 1.0, [&](Simulation& s) {
    s.ctx.body_ax = lambda * g * std::min(1.0, s.ctx.time / ramp);
    const RigidBodies& r = s.model.rigid;
    // Horizontal displacement of the base mid-point (0, -h/2) from the centroid.
    const double ux = r.cx[b] - r.cx0[b] + std::sin(r.theta[b]) * 0.5;
    if (s.ctx.time > 1.0 - 10 * period) sum += ux, n += 1.0;
  });
  const double expected = lambda * mass * g / (ks * 0.25);
  EXPECT_NEAR(sum / n, expected, 0.02 * expected);
  EXPECT_LT(worst, 0.01);
}

// Drop from `height` [m] above the ground; returns the rebound height of the first bounce.
double rebound_height(double restitution, double height, double* worst) {
  // Half the default step: an impact lasts pi / omega, about 9 steps at the default one, where
  // the lagging dashpot leaves e^2 5 to 11% high and the ledger 1.3 to 2.8% off (measured,
  // docs/rigid.md); at half of it both are within the bounds below.
  Simulation sim = deck_sim(block_deck(
      "friction = 0.8\nnormal_stiffness = 1e10\nrestitution = " + std::to_string(restitution),
      "0.45"));
  Model& m = sim.model;
  const Index b = free_block(m);
  const double rest_y = m.rigid.cy0[b];
  set_rigid_state(m, b, m.rigid.cx0[b], rest_y + height, 0.0, 0.0, 0.0, 0.0);
  bool touched = false, left = false;
  double peak = -1.0;
  *worst = run_until(sim, 2.0 * std::sqrt(2.0 * height / 9.81) + 0.05, [&](Simulation& s) {
    const double y = s.model.rigid.cy[b] - rest_y;
    if (s.contact.active_pairs() > 0) touched = true;
    if (touched && s.contact.active_pairs() == 0) left = true;
    if (left) peak = std::max(peak, y);
  });
  return peak;
}

TEST(Rigid, DroppedBlockReboundsToRestitutionSquaredOfItsHeight) {
  for (const double e : {0.5, 0.8}) {
    double worst = 0.0;
    const double h = 0.01;
    const double up = rebound_height(e, h, &worst);
    std::printf("[drop] restitution %.1f: rebound %+.1f%% of e^2 h\n", e,
                100.0 * (up / (h * e * e) - 1.0));
    EXPECT_NEAR(up / h, e * e, 0.05 * e * e) << "restitution " << e;
    EXPECT_LT(worst, 0.01) << "restitution " << e;
  }
}

// No tension (docs/rigid.md, "Impact damping"): a block pressed 1e-7 m into its joint and leaving it at 0.1 m/s,
// with a strong dashpot (restitution 0.1), gets from the joint a normal force that is never a
// pull: the dashpot's 1e5 N would pull against the spring's 250 N; it is held to the spring's
// push, the total zero. Approaching, the dashpot adds to the spring.
TEST(Rigid, SeparatingJointsDashpotNeverPulls) {
  Simulation sim =
      deck_sim(block_deck("friction = 0.8\nnormal_stiffness = 1e10\nshear_stiffness = 1e10\n"
                          "restitution = 0.1"));
  Model& m = sim.model;
  const Index b = free_block(m);
  const double depth = 1e-7, spring = 1e10 * 0.25 * depth;  // kn t_z |O| [N]
  advance(sim);                                             // the contact detection
  auto normal_on_block = [&](double vy) {
    set_rigid_state(m, b, m.rigid.cx0[b], m.rigid.cy0[b] - depth, 0.0, 0.0, vy, 0.0);
    double fy = 0.0;
    for (const BlockPairForce& f : sim.contact.block_pair_forces(m, sim.ctx.dt))
      fy += f.block_b == b ? f.force.y : -f.force.y;
    return fy;
  };
  EXPECT_NEAR(normal_on_block(0.0), spring, 1e-9 * spring);
  const double leaving = normal_on_block(0.1);
  EXPECT_GE(leaving, -1e-9 * spring) << "the joint pulls the leaving block";
  EXPECT_LE(leaving, spring);
  EXPECT_GT(normal_on_block(-0.1), spring) << "the dashpot resists an approach";
}

// The restitution of a normal impact on a spring and a dashpot that pushes only, against the
// oscillator x'' + 2 zeta x' + x = 0 integrated here (x(0) = 0, x'(0) = 1, semi-implicit Euler
// at 1e-6) until the force x + 2 zeta x' vanishes; its inverse gives the zeta back; and it
// exceeds the restitution of the dashpot that may pull, exp(-pi zeta / sqrt(1 - zeta^2)).
TEST(Rigid, NoTensionRestitutionOfTheJointDashpot) {
  for (const double zeta : {0.05, 0.2, 0.5, 0.8, 0.99}) {
    double x = 0.0, v = 1.0;
    const double h = 1e-6;
    while (!(x > 0.0 && x + 2.0 * zeta * v < 0.0)) {
      v -= h * (x + 2.0 * zeta * v);
      x += h * v;
    }
    const double e = no_tension_restitution(zeta);
    EXPECT_NEAR(e, -v, 1e-5) << "zeta " << zeta;
    EXPECT_NEAR(no_tension_damping_ratio(e), zeta, 1e-12) << "zeta " << zeta;
    EXPECT_GT(e, std::exp(-std::numbers::pi * zeta / std::sqrt(1.0 - zeta * zeta)));
  }
  EXPECT_DOUBLE_EQ(no_tension_restitution(1.0), std::exp(-2.0));
  EXPECT_EQ(no_tension_damping_ratio(1.0), 0.0);
  EXPECT_EQ(no_tension_damping_ratio(0.0), 1.0);
}

TEST(Rigid, RestartContinuesBitForBit) {
  // A rocking block with impact damping: 400 steps straight, or 150, a checkpoint, a fresh
  // simulation restored from it and 250 more.
  const std::string deck = block_deck("friction = 0.8\nnormal_stiffness = 1e10\nrestitution = 0.3");
  const auto make = [&] { return deck_sim(deck); };
  const auto [straight, second] = testing::split_restart(
      make, free_block(make().model), 0.8, ::testing::TempDir() + "rigid_restart.ckpt");
  EXPECT_EQ(second.model.nodes.x, straight.model.nodes.x);
  EXPECT_EQ(second.model.nodes.y, straight.model.nodes.y);
  EXPECT_EQ(second.model.rigid.theta, straight.model.rigid.theta);
  EXPECT_EQ(second.ledger.impact_dissipated, straight.ledger.impact_dissipated);
  EXPECT_GT(straight.ledger.impact_dissipated, 0.0);
  // The friction ledger needs the last step's friction forces and stored energy (the state).
  EXPECT_EQ(second.ledger.friction_dissipated, straight.ledger.friction_dissipated);
  EXPECT_GT(straight.ledger.friction_dissipated, 0.0);
}

TEST(Rigid, CheckpointFingerprintTellsJointsApart) {
  const std::string deck = block_deck("friction = 0.8\nnormal_stiffness = 1e10");
  const Simulation a = deck_sim(deck);
  const Simulation b = deck_sim(deck, {"contact.normal_stiffness=2e10"});
  const Simulation c = deck_sim(deck, {"contact.restitution=0.3"});
  const Simulation d = deck_sim(deck, {"contact.shear_stiffness=1e9"});
  const std::uint64_t fa = simulation_fingerprint(a, 0.8);
  for (const Simulation* other : {&b, &c, &d}) EXPECT_NE(simulation_fingerprint(*other, 0.8), fa);
  EXPECT_EQ(simulation_fingerprint(deck_sim(deck), 0.8), fa);
}

TEST(Rigid, NoStressFieldForRigidBlocks) {
  const Config c = parse_deck(block_deck("friction = 0.8"), "test");
  EXPECT_EQ(c.output.fields, (std::vector<std::string>{"position", "velocity"}));
}

TEST(MinimalMesh, StraightSidesLoseTheirMidPointsAndAQuadGetsTwoTriangles) {
  // A 2 x 1 rectangle with nodes every 0.25 along its sides.
  std::vector<Vec2> outline;
  for (int k = 0; k < 8; ++k) outline.push_back({0.25 * k, 0.0});
  for (int k = 0; k < 4; ++k) outline.push_back({2.0, 0.25 * k});
  for (int k = 8; k > 0; --k) outline.push_back({0.25 * k, 1.0});
  for (int k = 4; k > 0; --k) outline.push_back({0.0, 0.25 * k});
  const std::vector<Vec2> s = simplify_outline(outline, 0.01);
  ASSERT_EQ(s.size(), 4u);
  EXPECT_EQ(ear_clip(s).size(), 2u);
}

TEST(MinimalMesh, AnArcKeepsThePointsItsSagittaAsksFor) {
  // Voussoir 0.2 thick, 16 degrees of a unit circle, intrados and extrados with 8 points each.
  std::vector<Vec2> outline;
  const double a0 = 0.0, a1 = 16.0 * std::numbers::pi / 180.0;
  for (int k = 0; k <= 8; ++k) {
    const double a = a0 + (a1 - a0) * k / 8;
    outline.push_back({0.9 * std::cos(a), 0.9 * std::sin(a)});
  }
  for (int k = 8; k >= 0; --k) {
    const double a = a0 + (a1 - a0) * k / 8;
    outline.push_back({1.1 * std::cos(a), 1.1 * std::sin(a)});
  }
  std::reverse(outline.begin(), outline.end());  // counter-clockwise
  // Sagitta of the whole extrados chord: 1.1 (1 - cos 8 deg) = 0.0107, 5.4% of 0.2.
  EXPECT_EQ(simplify_outline(outline, 0.1).size(), 4u);
  const std::vector<Vec2> fine = simplify_outline(outline, 0.01);
  EXPECT_GT(fine.size(), 4u);
  // Every original point within 1% of the thickness of the simplified outline.
  for (const Vec2& p : outline) {
    double d = 1e9;
    for (std::size_t k = 0; k < fine.size(); ++k)
      d = std::min(d, distance_to_segment(p, fine[k], fine[(k + 1) % fine.size()]));
    EXPECT_LE(d, 0.01 * 0.2 + 1e-12);
  }
  EXPECT_EQ(ear_clip(fine).size(), fine.size() - 2);
}

TEST(MinimalMesh, AVeryLongArcTakesTheFastPathWithTheSameBound) {
  // 16 degrees of an arch of radius 2000 m and thickness 0.2 m (a fuzzed deck), 1500 points on
  // each face: above mesh/minimal.cpp's kFastOutline, so its fast paths (the hull's width,
  // Douglas-Peucker). Every original point must still lie within the tolerance, 1% of the
  // outline's width (its smallest extent across the normals of its sides, computed here point
  // by point: 19.7 m, the arc's sagitta and the thickness), of the chord between the kept
  // vertices around it, and the faces must lose most of their points.
  const int per_face = 1500;
  const double r_in = 1999.9, r_out = 2000.1, a1 = 16.0 * std::numbers::pi / 180.0;
  std::vector<Vec2> outline;
  for (int k = 0; k < per_face; ++k) {
    const double a = a1 * k / (per_face - 1);
    outline.push_back({r_out * std::cos(a), r_out * std::sin(a)});
  }
  for (int k = per_face - 1; k >= 0; --k) {
    const double a = a1 * k / (per_face - 1);
    outline.push_back({r_in * std::cos(a), r_in * std::sin(a)});
  }
  const std::vector<Vec2> s = simplify_outline(outline, 0.01);
  ASSERT_GE(s.size(), 4u);
  EXPECT_LT(s.size(), outline.size() / 5);
  // The kept vertices are original points, in order: walk the outline between them.
  std::vector<std::size_t> at;
  for (std::size_t k = 0, j = 0; k < outline.size() && j < s.size(); ++k)
    if (outline[k].x == s[j].x && outline[k].y == s[j].y) at.push_back(k), ++j;
  ASSERT_EQ(at.size(), s.size());
  const std::size_t n = outline.size();
  double width = 1e300;
  for (std::size_t k = 0; k < n; ++k) {
    const Vec2 &a = outline[k], &b = outline[(k + 1) % n];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    double lo = 1e300, hi = -1e300;
    for (const Vec2& p : outline) {
      const double t = (p.x * (b.y - a.y) - p.y * (b.x - a.x)) / len;
      lo = std::min(lo, t), hi = std::max(hi, t);
    }
    width = std::min(width, hi - lo);
  }
  EXPECT_NEAR(width, 2000.1 * (1.0 - std::cos(a1 / 2.0)) + 0.2, 0.01);
  const double tol = 0.01 * width * (1.0 + 1e-9);
  for (std::size_t j = 0; j < at.size(); ++j) {
    const std::size_t a = at[j], b = at[(j + 1) % at.size()];
    for (std::size_t k = (a + 1) % n; k != b; k = (k + 1) % n)
      EXPECT_LE(distance_to_segment(outline[k], outline[a], outline[b]), tol) << k;
  }
  EXPECT_EQ(ear_clip(s).size(), s.size() - 2);
}

TEST(MinimalMesh, NonConvexBlockTriangulatesWithoutOverlap) {
  // A crown block with a notch in its intrados.
  const std::vector<Vec2> poly = {{-1, 0}, {0, 0.3}, {1, 0}, {1, 1}, {-1, 1}};
  const auto tris = ear_clip(poly);
  ASSERT_EQ(tris.size(), 3u);
  double area = 0.0;
  for (const auto& t : tris) {
    const Vec2 &a = poly[t[0]], &b = poly[t[1]], &c = poly[t[2]];
    const double cr = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    EXPECT_GT(cr, 0.0);
    area += 0.5 * cr;
  }
  EXPECT_NEAR(area, 2.0 - 0.3, 1e-12);  // 2 x 1 rectangle less the notch triangle
}

TEST(MinimalMesh, RigidShippedDecksKeepMassAndJoints) {
  for (const char* deck : {"circular_arch", "church_b", "block"}) {
    Config c = load_deck(std::string(VOUSSOIR_SOURCE_DIR) + "/cases/" + deck + ".toml");
    c.material.model = "elastic";  // the churches ship rigid
    Simulation elastic = make_simulation(c);
    Config r = c;
    r.material.model = "rigid";
    r.output.fields = {"position"};
    Simulation rigid = make_simulation(r);
    EXPECT_LT(rigid.model.tris.size(), elastic.model.tris.size()) << deck;
    EXPECT_EQ(rigid.model.joints.size(), elastic.model.joints.size()) << deck;
    EXPECT_NEAR(free_mass(rigid.model), free_mass(elastic.model), 0.01 * free_mass(elastic.model))
        << deck;
  }
}

TEST(Rigid, RestingBlockEnergyBalanceWithoutDamping) {
  // No impact damping: the block bounces on its joint, grazing the ground at each period,
  // the hardest case for the ledger (core/rigid.hpp kRigidStepFraction).
  Simulation sim = deck_sim(block_deck("friction = 0.8"));
  const double worst = run_until(sim, 1.0, [](const Simulation&) {});
  EXPECT_LT(worst, 0.01);
}

TEST(Rigid, ArchOnFrictionalJointsKeepsItsEnergyBalance) {
  // The semicircular arch released under gravity on undamped joints (restitution 1): its
  // voussoirs chatter on their joints, and every pair keeps sticking, slipping, reversing and
  // opening within single steps. The friction is booked as the work its forces take from the
  // blocks less what its springs store (contact/contact.cpp); booked by the return mapping's
  // plastic work instead, this run's ledger drifted to 2.3% by 0.2 s at this step, half the
  // default one (1.7% at the former default, a quarter of today's). At half the default step
  // the scheme's own error is small (0.01%), so what is left is the bookkeeping.
  Config c = load_deck(std::string(VOUSSOIR_SOURCE_DIR) + "/cases/circular_arch.toml");
  c.material.model = "rigid";
  c.solver.dt_safety = 0.45;
  Simulation sim = make_simulation(c);
  const double worst = run_until(sim, 0.2, [](const Simulation&) {});
  EXPECT_GT(sim.ledger.friction_dissipated, 0.0);
  EXPECT_LT(worst, 0.002);
}

TEST(Rigid, StableStepIsSetByTheJointsNotTheElements) {
  SetupInfo elastic, soft, stiff, stiffer;
  const std::string arch =
      "[model]\nkind = \"circular_arch\"\nradius = 1\nthickness = 0.2\nembrace = 180\n"
      "voussoirs = 11\n";
  deck_sim(arch, {}, &elastic);
  // Engineering joints (1e10 N/m3) against the elements and penalty of elastic blocks.
  // Undamped joints (rigid blocks' default restitution is 0.5, contact/joint_stiffness.hpp).
  deck_sim(arch, {"material.model=rigid", "contact.normal_stiffness=1e10", "contact.restitution=1"},
           &soft);
  EXPECT_GT(soft.dt, 10.0 * elastic.dt);
  // kn sets it: a 100 x stiffer joint, a 10 x shorter step.
  deck_sim(arch, {"material.model=rigid", "contact.normal_stiffness=1e12", "contact.restitution=1"},
           &stiff);
  deck_sim(arch, {"material.model=rigid", "contact.normal_stiffness=1e14", "contact.restitution=1"},
           &stiffer);
  EXPECT_NEAR(stiff.dt / stiffer.dt, 10.0, 0.01);
  EXPECT_NE(soft.dt_set_by.find("rigid"), std::string::npos);
  // Impact damping keeps the finer fraction of 2 / omega (core/rigid.hpp), and the dashpot's
  // own rate shortens the step a little more.
  SetupInfo damped;
  deck_sim(arch, {"material.model=rigid", "contact.normal_stiffness=1e10", "contact.restitution=0.99"},
           &damped);
  EXPECT_LT(damped.dt, kRigidDampedStepFraction / kRigidStepFraction * soft.dt);
  EXPECT_GT(damped.dt, 0.9 * kRigidDampedStepFraction / kRigidStepFraction * soft.dt);
}

TEST(Rigid, EachBodysOwnStepBoundsTheModelsStep) {
  // The buttressed arch: voussoirs and buttress courses of different sizes. The model's step
  // is the smallest of the blocks' own limits (the figure `check` prints beside it), the
  // fixed ground has none, and elastic blocks report none.
  const std::string arch =
      "[model]\nkind = \"buttressed_arch\"\nshape = \"circular\"\nembrace = 180\n[material]\nmodel = \"rigid\"\n";
  for (const char* restitution : {"contact.restitution=1", "contact.restitution=0.5"}) {
    Simulation sim = deck_sim(arch, {restitution});
    const std::vector<double> steps = rigid_body_stable_steps(sim);
    ASSERT_EQ(steps.size(), sim.model.blocks.size());
    double smallest = std::numeric_limits<double>::infinity(), largest = 0.0;
    for (std::size_t b = 0; b < steps.size(); ++b) {
      EXPECT_EQ(std::isfinite(steps[b]), !sim.model.blocks[b].fixed) << b;
      smallest = std::min(smallest, steps[b]);
      if (std::isfinite(steps[b])) largest = std::max(largest, steps[b]);
    }
    EXPECT_EQ(smallest, stable_time_step(sim)) << restitution;
    EXPECT_GT(largest, smallest);
  }
  EXPECT_TRUE(rigid_body_stable_steps(deck_sim(arch, {"material.model=elastic"})).empty());
}

void expect_refused(const std::string& text, const std::vector<std::string>& sets,
                    const std::vector<std::string>& words) {
  try {
    parse_deck(text, "test", sets);
    ADD_FAILURE() << "accepted";
  } catch (const DeckError& e) {
    const std::string what = e.what();
    for (const std::string& w : words) EXPECT_NE(what.find(w), std::string::npos) << what;
  }
}

TEST(Rigid, BadKeysAreRefusedNamingKeyValueAndWhatIsAllowed) {
  const std::string deck = block_deck("friction = 0.8");
  expect_refused(deck, {"material.model=plastic"}, {"material.model", "plastic", "rigid"});
  expect_refused(deck, {"contact.normal_stiffness=0"}, {"contact.normal_stiffness", "0", "> 0"});
  expect_refused(deck, {"contact.shear_stiffness=-1e9"}, {"contact.shear_stiffness", "-1e+09"});
  expect_refused(deck, {"contact.normal_stiffness=1e10", "contact.penalty=1e12"},
                 {"contact.normal_stiffness", "contact.penalty", "not both"});
  expect_refused(deck, {"contact.shear_stiffness=1e10", "contact.penalty_factor=10"},
                 {"contact.shear_stiffness", "contact.penalty_factor"});
  expect_refused(deck, {"contact.restitution=1.5"}, {"contact.restitution", "1.5"});
  expect_refused(deck, {"contact.restitution=-0.1"}, {"contact.restitution"});
  expect_refused(deck, {"material.model=elastic", "contact.restitution=0.5"},
                 {"contact.restitution", "rigid"});
}

}  // namespace
}  // namespace voussoir

namespace voussoir {
namespace {

// A 0.25 x 1 m rigid block on its left corner, tilted by half its slenderness angle alpha,
// released at rest at restitution 0: the ratios of its angular velocity just after each of
// the first two impacts to the one just before, each taken where the block has turned through
// a tenth of the tilt on either side of upright and brought to the upright position by the
// free-rocking energy 1/2 I_o omega^2 + m g R cos(alpha - |theta|) = const (I_o about the
// corner). Also the largest ledger error of the run.
struct Rocking {
  double first = -1.0, second = -1.0, worst = 0.0;
};

Rocking rocking_ratios(const std::string& kn) {
  Simulation sim = deck_sim(block_deck("friction = 0.8\nnormal_stiffness = " + kn +
                                       "\nrestitution = 0"));
  Model& m = sim.model;
  const Index b = free_block(m);
  const double w = 0.25, h = 1.0, alpha = std::atan(w / h), R = 0.5 * std::hypot(w, h);
  const double th0 = 0.5 * alpha, probe = 0.1 * th0;
  const double px = m.rigid.cx0[b] - 0.5 * w, py = m.rigid.cy0[b] - 0.5 * h;  // left corner
  const double rx = m.rigid.cx0[b] - px, ry = m.rigid.cy0[b] - py;
  const double c = std::cos(th0), s = std::sin(th0);
  set_rigid_state(m, b, px + c * rx - s * ry, py + s * rx + c * ry, th0, 0.0, 0.0, 0.0);
  const double mass = 2000.0 * w * h, i_o = mass * 4.0 * R * R / 3.0;
  auto upright = [&](double th, double om) {
    return std::sqrt(om * om + 2.0 * mass * 9.81 * R *
                                   (std::cos(alpha - std::abs(th)) - std::cos(alpha)) / i_o);
  };
  // Crossings of +probe down, -probe down (first impact), -probe up, +probe up (second).
  double seen[4] = {-1.0, -1.0, -1.0, -1.0};
  int next = 0;
  Rocking out;
  while (sim.ctx.time < 3.0 && next < 4) {
    advance(sim);
    out.worst = std::max(out.worst, sim.ledger.balance_error());
    const double th = m.rigid.theta[b], om = m.rigid.omega[b];
    const bool crossed = next == 0   ? th < probe
                         : next == 1 ? th < -probe
                         : next == 2 ? th > -probe && om > 0.0
                                     : th > probe;
    if (crossed) seen[next++] = upright(th, om);
  }
  if (next == 4) out.first = seen[1] / seen[0], out.second = seen[3] / seen[2];
  return out;
}

}  // namespace

// The angular velocity a rocking block keeps at each impact, at restitution 0, is
// Housner's 1 - 1.5 sin^2(alpha) (0.912 here) within 5%. The penalty joint's impact is not
// Housner's instantaneous one at the new corner (the whole base meets the ground at once and
// the joint acts along it over several steps), so the ratio is not his exactly: it settles
// near 0.94 as the joint stiffens (docs/rigid.md, "Rocking"). Asserted: within 5% at both
// impacts, converged in kn, and the ledger (impact dashpot included) within 1%.
TEST(Rigid, RockingBlockImpactConvergesAsTheJointStiffens) {
  const double housner = 1.0 - 1.5 * std::pow(std::sin(std::atan(0.25)), 2);
  const Rocking r11 = rocking_ratios("1e11"), r12 = rocking_ratios("1e12");
  std::printf("[rocking] omega after / before the first and second impacts: %.4f, %.4f at kn "
              "1e11; %.4f, %.4f at 1e12; Housner %.4f; largest ledger errors %.1e, %.1e\n",
              r11.first, r11.second, r12.first, r12.second, housner, r11.worst, r12.worst);
  for (const Rocking& r : {r11, r12}) {
    EXPECT_NEAR(r.first, housner, 0.05 * housner);
    EXPECT_NEAR(r.second, housner, 0.05 * housner);
    EXPECT_LT(r.worst, 0.01);
  }
  EXPECT_NEAR(r11.first, r12.first, 0.01);
  EXPECT_NEAR(r11.second, r12.second, 0.01);
}

}  // namespace voussoir

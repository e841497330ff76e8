// Contact in dynamics (advance() with the full contact stage) against analytic results:
// block resting on the ground, block on an incline (stick / slide), rectangular block under a
// horizontal load (overturn / slide / stay), stack of five blocks, energy of a dropped block,
// and the stable-step estimate of the contact stiffness against the true eigenvalue.
//
// Models are built here with add_block (coarse structured meshes, E = 40 GPa, Ep = 100 x
// Lame lambda) so that each test runs in about a second; dt = 0.5 x stable_time_step, the
// safety factor of the shipped decks.
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Dense>
#include <cmath>
#include <numbers>

#include "contact/contact.hpp"
#include "engine/setup.hpp"
#include "engine/step.hpp"
#include "io/deck.hpp"
#include "mesh/rectangle.hpp"

using namespace voussoir;

namespace {

constexpr double kG = 9.81;

// Rotates every node (reference and current) and outline by angle [rad] about the origin.
void rotate_model(Model& m, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  auto rot = [c, s](double& x, double& y) {
    const double xr = c * x - s * y, yr = s * x + c * y;
    x = xr;
    y = yr;
  };
  for (Index i = 0; i < m.nodes.size(); ++i) {
    rot(m.nodes.x0[i], m.nodes.y0[i]);
    rot(m.nodes.x[i], m.nodes.y[i]);
  }
  for (Block& b : m.blocks)
    for (Vec2& p : b.polygon) rot(p.x, p.y);
}

// Ground (fixed, top face y = 0 over [-gw/2, gw/2]) and `stack` blocks w x h centred on x = 0.
Model block_scene(double w, double h, int stack, int nx, int ny, double ground_width = 4.0,
                  double gap = 0.0) {
  Model m;
  add_grid_rectangle(m, -0.5 * ground_width, -0.5, ground_width, 0.5, 8, 1, true, "ground",
                     GridDiagonals::Uniform);
  for (int k = 0; k < stack; ++k)
    add_grid_rectangle(m, -0.5 * w, gap + k * h, w, h, nx, ny, false, "block",
                       GridDiagonals::Uniform);
  return m;
}

Simulation make_sim(Model m, double mu, double damping_factor) {
  Simulation sim;
  sim.model = std::move(m);
  sim.model.material.young = 40e9;
  sim.model.material.poisson = 0.2;
  sim.model.material.density = 2000.0;
  finalize_model(sim.model);
  ContactParams cp;
  cp.penalty = 100.0 * sim.model.material.lame_lambda();
  cp.friction = mu;
  sim.contact.setup(sim.model, cp);
  prepare_context(sim, damping_factor);
  sim.ctx.body_ax = 0.0;
  sim.ctx.body_ay = -kG;
  sim.ctx.dt = 0.5 * stable_time_step(sim);
  return sim;
}

void run_for(Simulation& sim, double seconds) {
  const long long n = std::llround(seconds / sim.ctx.dt);
  for (long long k = 0; k < n; ++k) advance(sim);
}

struct BlockState {
  Vec2 position, velocity;  // mass-weighted mean [m], [m/s]
  double angle = 0.0;       // rotation of the bottom edge (first two corners) [rad]
};

BlockState block_state(const Simulation& sim, Index b) {
  const Block& blk = sim.model.blocks[b];
  const Nodes& n = sim.model.nodes;
  BlockState s;
  double mass = 0.0;
  for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i) {
    mass += n.mass[i];
    s.position.x += n.mass[i] * n.x[i];
    s.position.y += n.mass[i] * n.y[i];
    s.velocity.x += n.mass[i] * n.vx[i];
    s.velocity.y += n.mass[i] * n.vy[i];
  }
  s.position = {s.position.x / mass, s.position.y / mass};
  s.velocity = {s.velocity.x / mass, s.velocity.y / mass};
  // The bottom row of a rectangle block runs from its first node to the last node at the same
  // reference height (its bottom-right corner).
  const Index a = blk.first_node;
  Index bnode = a + 1;
  while (bnode + 1 < blk.first_node + blk.node_count && std::abs(n.y0[bnode + 1] - n.y0[a]) < 1e-12)
    ++bnode;
  const double ref = std::atan2(n.y0[bnode] - n.y0[a], n.x0[bnode] - n.x0[a]);
  s.angle = std::atan2(n.y[bnode] - n.y[a], n.x[bnode] - n.x[a]) - ref;
  return s;
}

// Contact force on block b at the current state, from a copy of the contact system (so the
// simulation's friction history is untouched).
Vec2 contact_force_on(const Simulation& sim, Index b) {
  Model m = sim.model;
  std::fill(m.nodes.fx.begin(), m.nodes.fx.end(), 0.0);
  std::fill(m.nodes.fy.begin(), m.nodes.fy.end(), 0.0);
  ContactSystem c = sim.contact;
  EnergyLedger ledger;
  c.add_forces(m, sim.ctx.dt, ledger);
  const Block& blk = m.blocks[b];
  Vec2 f;
  for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i) {
    f.x += m.nodes.fx[i];
    f.y += m.nodes.fy[i];
  }
  return f;
}

}  // namespace

TEST(ContactBlocks, BlockRestingOnGround) {
  const double w = 0.5, h = 0.5;
  Simulation sim = make_sim(block_scene(w, h, 1, 2, 2), 0.6, 1.0);
  run_for(sim, 0.1);
  const Vec2 f = contact_force_on(sim, 1);
  const double weight = sim.model.blocks[1].mass * kG;
  EXPECT_NEAR(f.y, weight, 0.005 * weight);
  EXPECT_NEAR(f.x, 0.0, 1e-6 * weight);
  // Penetration: the bottom nodes sit in the ground by much less than 1e-4 of the block size.
  const Block& blk = sim.model.blocks[1];
  double lowest = 1.0;
  for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i)
    lowest = std::min(lowest, sim.model.nodes.y[i]);
  EXPECT_LT(lowest, 0.0);  // there is an overlap (potential contact needs one)
  EXPECT_GT(lowest, -1e-4 * h);
  EXPECT_GT(sim.contact.active_pairs(), 0);
  EXPECT_LT(sim.ledger.kinetic, 1e-9 * weight * h);
  std::printf("resting block: reaction/weight = %.6f, penetration = %.3e m, dt = %.3e s\n",
              f.y / weight, -lowest, sim.ctx.dt);
}

// Incline theta, block w x h on it (the whole scene rotated clockwise by theta).
static Simulation incline_sim(double theta_deg, double mu) {
  Model m = block_scene(0.5, 0.5, 1, 2, 2, 6.0);
  const double th = theta_deg * std::numbers::pi / 180.0;
  // Move the block up-slope first so it has room to slide.
  for (Index i = 0; i < m.nodes.size(); ++i)
    if (m.nodes.block[i] == 1) {
      m.nodes.x0[i] -= 2.0;
      m.nodes.x[i] -= 2.0;
    }
  rotate_model(m, -th);
  return make_sim(std::move(m), mu, 1.0);
}

TEST(ContactBlocks, InclineSticksBelowFrictionAngle) {
  // tan 20 deg = 0.364 < mu = 0.6: sticks.
  Simulation sim = incline_sim(20.0, 0.6);
  const BlockState s0 = block_state(sim, 1);
  run_for(sim, 1.0);
  const BlockState s1 = block_state(sim, 1);
  const double moved = std::hypot(s1.position.x - s0.position.x, s1.position.y - s0.position.y);
  std::printf("incline 20, mu 0.6: moved %.3e m in 1 s\n", moved);
  EXPECT_LT(moved, 1e-6);
}

TEST(ContactBlocks, InclineSlidesWithCoulombAcceleration) {
  const double theta = 30.0, mu = 0.3;
  Simulation sim = incline_sim(theta, mu);
  const double th = theta * std::numbers::pi / 180.0;
  const Vec2 down{std::cos(th), -std::sin(th)};
  run_for(sim, 0.1);
  const BlockState s1 = block_state(sim, 1);
  const double t1 = sim.ctx.time;
  run_for(sim, 0.5);
  const BlockState s2 = block_state(sim, 1);
  const double t2 = sim.ctx.time;
  const double v1 = s1.velocity.x * down.x + s1.velocity.y * down.y;
  const double v2 = s2.velocity.x * down.x + s2.velocity.y * down.y;
  const double a = (v2 - v1) / (t2 - t1);
  const double expected = kG * (std::sin(th) - mu * std::cos(th));
  std::printf("incline 30, mu 0.3: a = %.5f m/s2, expected %.5f (%.3f%%)\n", a, expected,
              100.0 * (a / expected - 1.0));
  EXPECT_NEAR(a, expected, 0.02 * expected);
  EXPECT_LT(std::abs(s2.angle), 1e-3);  // slides, does not tumble
  EXPECT_GT(sim.ledger.friction_dissipated, 0.0);
}

// Rectangular block width 0.5, height 1 (b/h = 0.5) under lambda g after settling.
static BlockState lateral_load(double mu, double lambda, double seconds) {
  Simulation sim = make_sim(block_scene(0.5, 1.0, 1, 1, 2), mu, 1.0);
  run_for(sim, 0.05);
  const BlockState s0 = block_state(sim, 1);
  sim.ctx.body_ax = lambda * kG;
  run_for(sim, seconds);
  BlockState s = block_state(sim, 1);
  s.position = {s.position.x - s0.position.x, s.position.y - s0.position.y};
  return s;
}

TEST(ContactBlocks, OverturnsAboveWidthOverHeight) {
  const BlockState stay = lateral_load(0.8, 0.45, 1.0);
  const BlockState tip = lateral_load(0.8, 0.55, 1.0);
  std::printf("mu 0.8: lambda 0.45 angle %.3e rad dx %.3e m; lambda 0.55 angle %.3e rad\n",
              stay.angle, stay.position.x, tip.angle);
  EXPECT_LT(std::abs(stay.angle), 1e-4);
  EXPECT_LT(std::abs(stay.position.x), 1e-5);
  EXPECT_LT(tip.angle, -0.1);  // clockwise: tips over its right (down-load) corner
}

TEST(ContactBlocks, SlidesAboveFrictionCoefficient) {
  const BlockState stay = lateral_load(0.3, 0.25, 1.0);
  const BlockState slide = lateral_load(0.3, 0.35, 1.0);
  std::printf("mu 0.3: lambda 0.25 dx %.3e m; lambda 0.35 dx %.3e m angle %.3e\n", stay.position.x,
              slide.position.x, slide.angle);
  EXPECT_LT(std::abs(stay.position.x), 1e-5);
  // Rigid sliding: x = g (lambda - mu) t^2 / 2 = 0.245 m after 1 s.
  EXPECT_NEAR(slide.position.x, 0.5 * kG * 0.05, 0.05 * 0.5 * kG * 0.05);
  EXPECT_LT(std::abs(slide.angle), 1e-3);
}

TEST(ContactBlocks, StackOfFiveStands) {
  Simulation sim = make_sim(block_scene(0.5, 0.5, 5, 1, 1), 0.6, 1.0);
  const Nodes initial = sim.model.nodes;
  run_for(sim, 2.0);
  double drift = 0.0;
  for (Index i = 0; i < sim.model.nodes.size(); ++i)
    drift = std::max(drift, std::hypot(sim.model.nodes.x[i] - initial.x[i],
                                       sim.model.nodes.y[i] - initial.y[i]));
  std::printf("stack of 5: largest node drift after 2 s = %.3e m\n", drift);
  EXPECT_LT(drift, 1e-5);
}

// Dropped 5 mm, slightly tilted, onto the ground: without damping and friction the ledger
// closes (K + U + C = W) within 1 %; with them the total K + U + C - W never rises.
static void drop(double mu, double damping_factor, double* worst_balance, double* worst_gain) {
  Model m = block_scene(0.5, 0.5, 1, 2, 2, 4.0, 0.005);
  // Tilt the block by 2 degrees about its bottom-left corner so a corner hits first.
  const double a = 2.0 * std::numbers::pi / 180.0, c = std::cos(a), s = std::sin(a);
  for (Index i = 0; i < m.nodes.size(); ++i)
    if (m.nodes.block[i] == 1) {
      const double x = m.nodes.x0[i] + 0.25, y = m.nodes.y0[i] - 0.005;
      m.nodes.x0[i] = m.nodes.x[i] = c * x - s * y - 0.25;
      m.nodes.y0[i] = m.nodes.y[i] = s * x + c * y + 0.005;
    }
  Simulation sim = make_sim(std::move(m), mu, damping_factor);
  *worst_balance = 0.0;
  *worst_gain = -1e300;
  std::int64_t most_active = 0;
  const long long n = std::llround(0.15 / sim.ctx.dt);
  for (long long k = 0; k < n; ++k) {
    advance(sim);
    *worst_balance = std::max(*worst_balance, sim.ledger.balance_error());
    const EnergyLedger& l = sim.ledger;
    *worst_gain = std::max(*worst_gain, (l.stored() - l.external_work) / l.max_energy);
    most_active = std::max(most_active, sim.contact.active_pairs());
  }
  EXPECT_GT(sim.ledger.max_energy, 0.0);
  EXPECT_GT(most_active, 0);  // it did hit the ground
}

TEST(ContactBlocks, DroppedBlockConservesEnergyWithoutDissipation) {
  double balance = 0.0, gain = 0.0;
  drop(0.0, 0.0, &balance, &gain);
  std::printf("drop, no damping/friction: worst balance error %.3e\n", balance);
  EXPECT_LT(balance, 0.01);
}

TEST(ContactBlocks, DroppedBlockNeverGainsEnergy) {
  double balance = 0.0, gain = 0.0;
  drop(0.6, 1.0, &balance, &gain);
  std::printf("drop, damping + friction: worst balance error %.3e, worst gain %.3e\n", balance,
              gain);
  EXPECT_LT(gain, 1e-3);
  EXPECT_LT(balance, 0.01);
}

// The contact part of the stable step: max_omega_squared bounds the largest eigenvalue of
// M^-1 K (K: contact stiffness by central differences of the contact forces, the normal part
// through the positions and the friction part through the slip increment dt v) and is not
// wildly larger. Scenes: a block on the ground; two stacked blocks; two blocks side by side
// with non-matching meshes pressed into each other.
TEST(ContactBlocks, OmegaEstimateBoundsTrueContactFrequency) {
  for (int scene = 0; scene < 3; ++scene) {
    Model m;
    if (scene == 0) m = block_scene(0.5, 0.5, 1, 2, 2);
    if (scene == 1) m = block_scene(0.5, 0.4, 2, 3, 2);
    if (scene == 2) {
      m = block_scene(0.4, 0.5, 0, 1, 1);
      add_grid_rectangle(m, -0.4, 0.0, 0.4, 0.5, 2, 2, false, "block", GridDiagonals::Uniform);
      add_grid_rectangle(m, 0.0, 0.0, 0.3, 0.5, 3, 4, false, "block", GridDiagonals::Uniform);
    }
    Simulation sim = make_sim(std::move(m), 0.6, 1.0);
    // Press the blocks into their neighbours by 1e-4 m (the stiffness of a flat overlap does
    // not depend on its depth).
    Nodes& n = sim.model.nodes;
    for (Index i = 0; i < n.size(); ++i) {
      if (n.block[i] == 0) continue;
      if (scene < 2) n.y[i] -= 1e-4 * n.block[i];
      if (scene == 2) n.y[i] -= 1e-4, n.x[i] += (n.block[i] == 1 ? 1e-4 : -1e-4);
    }
    sim.contact.detect(sim.model);
    std::vector<Index> dof_node;
    for (Index i = 0; i < n.size(); ++i)
      if (n.inv_mass[i] > 0.0) dof_node.push_back(i);
    const int N = 2 * static_cast<int>(dof_node.size());
    auto forces = [&](Eigen::VectorXd& f) {
      Model mm = sim.model;
      std::fill(mm.nodes.fx.begin(), mm.nodes.fx.end(), 0.0);
      std::fill(mm.nodes.fy.begin(), mm.nodes.fy.end(), 0.0);
      ContactSystem c = sim.contact;
      EnergyLedger l;
      c.add_forces(mm, sim.ctx.dt, l);
      for (int k = 0; k < N / 2; ++k) {
        f[2 * k] = mm.nodes.fx[dof_node[k]];
        f[2 * k + 1] = mm.nodes.fy[dof_node[k]];
      }
    };
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(N, N);
    Eigen::VectorXd fp(N), fm(N);
    const double step = 1e-7, slip = 1e-10;
    for (int j = 0; j < N; ++j) {
      double& coord = (j % 2 == 0 ? n.x : n.y)[dof_node[j / 2]];
      coord += step;
      forces(fp);
      coord -= 2 * step;
      forces(fm);
      coord += step;
      K.col(j) = -(fp - fm) / (2 * step);
      // Friction: a slip increment u is dt v; stick, so the force is linear in it.
      double& vel = (j % 2 == 0 ? n.vx : n.vy)[dof_node[j / 2]];
      vel += slip / sim.ctx.dt;
      forces(fp);
      vel -= 2 * slip / sim.ctx.dt;
      forces(fm);
      vel += slip / sim.ctx.dt;
      K.col(j) += -(fp - fm) / (2 * slip);
    }
    Eigen::VectorXd inv_sqrt_m(N);
    for (int k = 0; k < N; ++k) inv_sqrt_m[k] = std::sqrt(n.inv_mass[dof_node[k / 2]]);
    const Eigen::MatrixXd A =
        inv_sqrt_m.asDiagonal() * (0.5 * (K + K.transpose())) * inv_sqrt_m.asDiagonal();
    const double lambda_max =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A).eigenvalues().maxCoeff();
    const double estimate = sim.contact.max_omega_squared(sim.model);
    std::printf("scene %d: contact omega^2 true %.4e, estimate %.4e (ratio %.2f)\n", scene,
                lambda_max, estimate, estimate / lambda_max);
    EXPECT_GE(estimate, lambda_max);
    EXPECT_LT(estimate, 4.0 * lambda_max);
  }
}

// The same incline checks through the shipped scene (cases/block.toml, kind = "block" with
// `incline`; the generator rotates the scene counter-clockwise, so the block slides towards
// -x) and make_simulation (deck penalty, damping and dt).
TEST(ContactBlocks, ShippedBlockSceneOnIncline) {
  for (const auto& [incline, mu] : {std::pair{20.0, 0.6}, std::pair{30.0, 0.3}}) {
    const Config config =
        load_deck(std::string(VOUSSOIR_SOURCE_DIR) + "/cases/block.toml",
                  {"model.height=0.5", "model.incline=" + std::to_string(incline),
                   "contact.friction=" + std::to_string(mu), "mesh.through_thickness=2"});
    Simulation sim = make_simulation(config);
    Index block = -1;
    for (Index b = 0; b < static_cast<Index>(sim.model.blocks.size()); ++b)
      if (!sim.model.blocks[b].fixed) block = b;
    ASSERT_GE(block, 0);
    const double th = incline * std::numbers::pi / 180.0;
    const Vec2 down{-std::cos(th), -std::sin(th)};
    const BlockState s0 = block_state(sim, block);
    run_for(sim, 0.1);
    const BlockState s1 = block_state(sim, block);
    const double t1 = sim.ctx.time;
    run_for(sim, 0.4);
    const BlockState s2 = block_state(sim, block);
    const double t2 = sim.ctx.time;
    if (std::tan(th) < mu) {
      const double moved = std::hypot(s2.position.x - s0.position.x, s2.position.y - s0.position.y);
      std::printf("shipped scene, incline %.0f mu %.1f: moved %.3e m in %.2f s\n", incline, mu,
                  moved, t2);
      EXPECT_LT(moved, 1e-6);
    } else {
      const double v1 = s1.velocity.x * down.x + s1.velocity.y * down.y;
      const double v2 = s2.velocity.x * down.x + s2.velocity.y * down.y;
      const double a = (v2 - v1) / (t2 - t1);
      const double expected = kG * (std::sin(th) - mu * std::cos(th));
      std::printf("shipped scene, incline %.0f mu %.1f: a = %.5f, expected %.5f\n", incline, mu, a,
                  expected);
      EXPECT_NEAR(a, expected, 0.02 * expected);
    }
  }
}

namespace {

// A lattice of n x n blocks 0.1 m wide on a fixed ground, each pressed 1e-5 m into its
// neighbours and the ground (E = 40 GPa).
Model pressed_lattice(int n) {
  Model m;
  add_grid_rectangle(m, -0.1, -0.1, 1.5, 0.1, 12, 1, true, "ground", GridDiagonals::Uniform);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      add_grid_rectangle(m, i * (0.1 - 1e-5), j * (0.1 - 1e-5) - 1e-5, 0.1, 0.1, 1, 1, false,
                         "block", GridDiagonals::Uniform);
  m.material.young = 40e9;
  finalize_model(m);
  return m;
}

// The lattice's contact: Ep = 1e12 Pa, mu = 0.5.
ContactSystem lattice_contact(const Model& m) {
  ContactSystem c;
  ContactParams cp;
  cp.penalty = 1e12;
  cp.friction = 0.5;
  c.setup(m, cp);
  return c;
}

// Moves every free node by a wobble of ~1e-9 m that differs from node to node and from one
// evaluation `it` to the next (its velocity ~1e-3 m/s over 1e-6 s), so that slip histories
// evolve.
void wobble(Model& m, int it) {
  for (Index i = 0; i < m.nodes.size(); ++i) {
    if (m.nodes.inv_mass[i] == 0.0) continue;
    m.nodes.vx[i] = 1e-3 * std::sin(0.37 * i + it);
    m.nodes.vy[i] = 1e-3 * std::cos(0.21 * i - it);
    m.nodes.x[i] += 1e-6 * m.nodes.vx[i];
    m.nodes.y[i] += 1e-6 * m.nodes.vy[i];
  }
}

// One contact evaluation at dt = 1e-6 s from zero nodal forces.
void evaluate_contact(ContactSystem& c, Model& m, EnergyLedger& ledger) {
  std::fill(m.nodes.fx.begin(), m.nodes.fx.end(), 0.0);
  std::fill(m.nodes.fy.begin(), m.nodes.fy.end(), 0.0);
  c.add_forces(m, 1e-6, ledger);
}

}  // namespace

// Results do not depend on the thread count: a lattice of 12 x 12 blocks pressed into their
// neighbours (several hundred candidate pairs, above the parallel threshold) with friction;
// 20 contact evaluations with moving nodes (slip history evolving) give bit-identical forces,
// energies and dissipation on 1 and on 3 threads.
TEST(ContactBlocks, ThreadCountDoesNotChangeResults) {
  const Model base = pressed_lattice(12);
  auto run = [&](int threads, std::vector<double>& out) {
    omp_set_num_threads(threads);
    Model m = base;
    ContactSystem c = lattice_contact(m);
    EnergyLedger ledger;
    for (int it = 0; it < 20; ++it) {
      wobble(m, it);
      if (c.needs_detection(m.nodes)) c.detect(m);
      evaluate_contact(c, m, ledger);
    }
    out = m.nodes.fx;
    out.insert(out.end(), m.nodes.fy.begin(), m.nodes.fy.end());
    out.push_back(ledger.contact);
    out.push_back(ledger.friction_dissipated);
    out.push_back(static_cast<double>(c.active_pairs()));
    EXPECT_GT(c.candidate_pairs(), 128);
    EXPECT_GT(ledger.friction_dissipated, 0.0);
  };
  const int saved = omp_get_max_threads();
  std::vector<double> one, three;
  run(1, one);
  run(3, three);
  omp_set_num_threads(saved);
  ASSERT_EQ(one.size(), three.size());
  for (std::size_t k = 0; k < one.size(); ++k) ASSERT_EQ(one[k], three[k]) << "entry " << k;
}

// A pair that touched at the last step goes to the kernel without the box and edge-line
// pre-tests (contact/contact.cpp evaluate). Those tests only skip pairs whose kernel gives
// nothing, so the forces must be those of the long way: a pressed lattice, moved the same way,
// once detecting only when the broad phase asks (pairs keep their flags) and once detecting
// again before every evaluation (every flag cleared), gives bit-identical forces, energies
// and dissipation, with pairs touching and pairs coming apart along the way.
TEST(ContactBlocks, TouchingPairsSkipThePreTestsWithTheSameForces) {
  const Model base = pressed_lattice(6);
  auto run = [&](bool detect_every_time, std::vector<double>& out) {
    Model m = base;
    ContactSystem c = lattice_contact(m);
    EnergyLedger ledger;
    std::int64_t touching = 0, most = 0;
    for (int it = 0; it < 40; ++it) {
      wobble(m, it);
      if (it >= 20)  // the lattice spreads: its 1e-5 m overlaps open one after another
        for (Index i = 0; i < m.nodes.size(); ++i) {
          if (m.nodes.inv_mass[i] == 0.0) continue;
          m.nodes.x[i] += 3e-5 * (m.nodes.x[i] - 0.3);
          m.nodes.y[i] += 3e-5 * (m.nodes.y[i] - 0.3);
        }
      if (detect_every_time || c.needs_detection(m.nodes)) c.detect(m);
      evaluate_contact(c, m, ledger);
      touching = c.active_pairs();
      most = std::max(most, touching);
      out.insert(out.end(), m.nodes.fx.begin(), m.nodes.fx.end());
      out.insert(out.end(), m.nodes.fy.begin(), m.nodes.fy.end());
      out.push_back(ledger.contact);
      out.push_back(ledger.friction_dissipated);
      out.push_back(static_cast<double>(touching));
    }
    EXPECT_GT(most, 20);        // joints pressed at the start
    EXPECT_LT(touching, most);  // and some of them opened by the end
    EXPECT_GT(ledger.friction_dissipated, 0.0);
  };
  std::vector<double> kept, cleared;
  run(false, kept);
  run(true, cleared);
  ASSERT_EQ(kept.size(), cleared.size());
  for (std::size_t k = 0; k < kept.size(); ++k) ASSERT_EQ(kept[k], cleared[k]) << "entry " << k;
}

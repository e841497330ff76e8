// Stiff and extreme cases (docs/robustness.md, "Stiff and extreme cases"): very stiff
// and very soft blocks, a large contact penalty, sliver triangles, no friction and very high
// friction, very thin and very thick arches, a large lambda, very light and very heavy blocks.
// Each case runs from rest with the automatic time step and asserts:
//   - no NaN or infinity anywhere (node positions, velocities, forces, every ledger term) at
//     any sample (every 50 steps) and at the end;
//   - energy balance: |W - K - U - C - D| at every sample below 1% of the peak energy of the
//     run (the largest energy term it reaches);
//   - the automatic dt is the safety fraction of the stable limit, and stable in fact (the
//     run stays finite and balanced for its whole length);
//   - the expected outcome: stands, collapses, slides or sticks (thresholds below).
// Then the guards of engine/run_loop.hpp: a user dt above the stable limit refused (exit 2, the
// limit named), an unstable step stopped by the energy-drift guard or by the non-finite guard
// with exit 1, the step, block and triangle named and the output file left incomplete.
//
// Figures of every case are printed as one "[stability]" line each; docs/robustness.md
// tabulates them. Coarse meshes (mesh.through_thickness = 1) and short end times keep the
// file fast; the full collapse of the thin arch runs in tests/slow/test_stability_slow.cpp.

#include <gtest/gtest.h>
#include <hdf5.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "commands/common.hpp"
#include "commands/run.hpp"
#include "core/model.hpp"
#include "engine/kinematics.hpp"
#include "engine/run_loop.hpp"
#include "engine/setup.hpp"
#include "engine/step.hpp"
#include "io/deck.hpp"
#include "mesh/scene.hpp"
#include "subprocess.hpp"

namespace voussoir {
namespace {

namespace fs = std::filesystem;

constexpr double kEnergyTolerance = 0.01;  // balance error below 1% of peak energy
constexpr double kG = 9.81;

// Outcome thresholds, on the rigid-body reading of the blocks (engine/kinematics.hpp) with
// L_ref = sqrt(smallest free block area), as capacity trials use them (commands/capacity.hpp):
//   collapsed: some block centroid moved more than 0.05 L_ref or turned more than 0.05 rad
//              (the capacity collapse thresholds);
//   stands:    every block centroid moved less than 0.005 L_ref and turned less than
//              0.005 rad (ten times below them: elastic settling and contact indentation
//              only).
constexpr double kCollapseDisplacement = 0.05, kCollapseRotation = 0.05;
constexpr double kStandDisplacement = 0.005, kStandRotation = 0.005;

// Everything finite: node state and forces, every ledger term.
bool all_finite(const Simulation& sim) {
  const Nodes& n = sim.model.nodes;
  for (Index i = 0; i < n.size(); ++i)
    for (const double v : {n.x[i], n.y[i], n.vx[i], n.vy[i], n.fx[i], n.fy[i]})
      if (!std::isfinite(v)) return false;
  const EnergyLedger& l = sim.ledger;
  for (const double v : {l.kinetic, l.strain, l.contact, l.external_work, l.damping_dissipated,
                         l.friction_dissipated, l.max_energy})
    if (!std::isfinite(v)) return false;
  return true;
}

struct Figures {
  double dt = 0.0, dt_stable = 0.0;
  long long steps = 0;
  bool finite = true;
  std::string error;              // RunError of the loop, if any
  double max_residual = 0.0;      // largest |W - K - U - C - D| over the samples [J]
  double worst_time = 0.0;        // when it was reached [s]
  double peak_energy = 0.0;       // largest energy term of the run [J]
  double max_error = 0.0;         // max_residual / peak_energy
  double final_kinetic = 0.0;     // [J]
  double max_displacement = 0.0;  // largest free-node displacement at the end [m]
  double max_block_move = 0.0;    // largest block centroid displacement / L_ref at the end
  double max_block_turn = 0.0;    // largest block rotation at the end [rad]
  std::vector<BlockMotion> motions;

  bool collapsed() const {
    return max_block_move > kCollapseDisplacement || max_block_turn > kCollapseRotation;
  }
  bool stands() const {
    return max_block_move < kStandDisplacement && max_block_turn < kStandRotation;
  }
};

// Runs `sim` from rest to `end_time` with the loop of `voussoir run` (guards off: this test
// measures what they would act on), sampling every 50 steps, and prints the figures.
Figures run_case(const std::string& name, Simulation& sim, double dt_stable, double end_time) {
  Figures f;
  f.dt = sim.ctx.dt;
  f.dt_stable = dt_stable;
  LoopOptions opts;
  opts.end_time = end_time;
  opts.sample_every = 50 * sim.ctx.dt;
  opts.quiet = true;
  opts.drift_limit = 0.0;
  auto sample = [&](const Simulation& s) {
    if (!all_finite(s)) {
      f.finite = false;
      return false;
    }
    const EnergyLedger& l = s.ledger;
    const double residual = std::abs(l.external_work - l.stored() - l.dissipated());
    if (residual > f.max_residual) {
      f.max_residual = residual;
      f.worst_time = s.ctx.time;
    }
    return true;
  };
  try {
    f.steps = run_loop(sim, opts, sample).steps;
  } catch (const RunError& e) {
    f.finite = false;
    f.error = e.what();
  }
  f.finite = f.finite && all_finite(sim);
  f.peak_energy = sim.ledger.max_energy;
  f.max_error = f.peak_energy > 0.0 ? f.max_residual / f.peak_energy : 0.0;
  f.final_kinetic = sim.ledger.kinetic;
  f.max_displacement = max_free_displacement(sim.model);
  const double l_ref = reference_length(sim.model);
  f.motions = block_motions(sim.model);
  for (std::size_t b = 0; b < f.motions.size(); ++b) {
    if (sim.model.blocks[b].fixed) continue;
    const BlockMotion& m = f.motions[b];
    f.max_block_move = std::max(f.max_block_move, std::hypot(m.ux, m.uy) / l_ref);
    f.max_block_turn = std::max(f.max_block_turn, std::abs(m.rotation));
  }
  std::printf(
      "[stability] %-24s dt %.3e s = %.2f x stable %.3e s, %lld steps, energy error "
      "%.2e of peak %.3e J (worst at t = %.3e s), max disp %.3e m, block move %.3e L_ref, "
      "turn %.2e rad, final KE %.3e J%s\n",
      name.c_str(), f.dt, f.dt / f.dt_stable, f.dt_stable, f.steps, f.max_error, f.peak_energy,
      f.worst_time, f.max_displacement, f.max_block_move, f.max_block_turn, f.final_kinetic,
      f.collapsed() ? ", collapsed" : (f.stands() ? ", stands" : ""));
  return f;
}

// The checks every case shares.
void expect_sound(const Figures& f, const Config& config) {
  EXPECT_TRUE(f.finite) << f.error;
  EXPECT_TRUE(f.error.empty()) << f.error;
  EXPECT_LT(f.max_error, kEnergyTolerance);
  EXPECT_GT(f.peak_energy, 0.0);
  // The automatic step: the deck's safety fraction of the stable limit.
  EXPECT_DOUBLE_EQ(f.dt, config.solver.dt_safety * f.dt_stable);
  EXPECT_LT(f.dt, f.dt_stable);
}

std::string case_path(const std::string& name) {
  return std::string(VOUSSOIR_SOURCE_DIR) + "/cases/" + name + ".toml";
}

// The shipped circular arch (Rc = 1 m, t = 0.2 m, 11 voussoirs, beta = 180, mu = 0.6) on a
// coarse mesh, with extra --set overrides.
Config arch_deck(std::vector<std::string> sets) {
  sets.insert(sets.begin(), "mesh.through_thickness=1");
  return load_deck(case_path("circular_arch"), sets);
}

Config block_deck(std::vector<std::string> sets) {
  return load_deck(case_path("block"), sets);
}

struct Built {
  Simulation sim;
  SetupInfo info;
};

Built build(const Config& config) {
  Built b;
  b.sim = make_simulation(config, &b.info);
  return b;
}

// --- stiff and soft blocks, large penalty, light and heavy blocks: the arch must stand ------

void check_arch_stands(const std::string& name, const std::vector<std::string>& sets,
                       double end_time) {
  const Config config = arch_deck(sets);
  Built b = build(config);
  const Figures f = run_case(name, b.sim, b.info.dt_stable, end_time);
  expect_sound(f, config);
  EXPECT_TRUE(f.stands()) << "block move " << f.max_block_move << " L_ref, turn "
                          << f.max_block_turn;
}

TEST(Stability, SoftBlocksOneGigapascalStand) {
  check_arch_stands("E = 1 GPa", {"material.young=1e9"}, 0.05);
}

TEST(Stability, StiffBlocksTwoHundredGigapascalStand) {
  check_arch_stands("E = 200 GPa", {"material.young=200e9"}, 0.03);
}

TEST(Stability, PenaltyFactorThousandStands) {
  check_arch_stands("penalty factor 1000", {"contact.penalty_factor=1000"}, 0.03);
}

TEST(Stability, DensityOneStands) {
  // dt scales with sqrt(rho): 45 times smaller than at 2000 kg/m3, and so does every elastic
  // time scale (the gravity load scales with rho too), so 4 ms here is 0.18 s at 2000.
  check_arch_stands("density 1", {"material.density=1"}, 0.004);
}

TEST(Stability, DensityEightThousandStands) {
  check_arch_stands("density 8000", {"material.density=8000"}, 0.05);
}

// --- arch geometry and load ------------------------------------------------------------------

TEST(Stability, ThickArchStands) {
  // t/R = 0.5, far above the minimum thickness of a semicircular arch (t/R ~ 0.107, Heyman).
  check_arch_stands("arch t/R = 0.5", {"model.thickness=0.5"}, 0.05);
}

TEST(Stability, ThinArchCollapsesUnderGravity) {
  // t/R = 0.05, half the minimum thickness: no thrust line fits, the arch falls. The first
  // 0.1 s here (the fall through to the abutments: tests/slow).
  const Config config = arch_deck({"model.thickness=0.05"});
  Built b = build(config);
  const Figures f = run_case("arch t/R = 0.05", b.sim, b.info.dt_stable, 0.1);
  expect_sound(f, config);
  EXPECT_TRUE(f.collapsed()) << "block move " << f.max_block_move << " L_ref, turn "
                             << f.max_block_turn;
  // Under gravity only, the crown goes down and the falling blocks' kinetic energy comes from
  // gravity (nothing else does work).
  EXPECT_GT(f.final_kinetic, 0.0);
  double lowest = 0.0;
  for (std::size_t k = 0; k < f.motions.size(); ++k)
    if (!b.sim.model.blocks[k].fixed) lowest = std::min(lowest, f.motions[k].uy);
  EXPECT_LT(lowest, 0.0);
}

TEST(Stability, LambdaThreeCollapses) {
  // lambda = 3, ten times lambda* = 0.29 of this arch (docs/regression.md): it is thrown over.
  const Config config = arch_deck({"load.lambda=3"});
  Built b = build(config);
  const Figures f = run_case("lambda = 3", b.sim, b.info.dt_stable, 0.05);
  expect_sound(f, config);
  EXPECT_TRUE(f.collapsed()) << "block move " << f.max_block_move;
  // Thrown in +x: every free block moves to the right.
  for (std::size_t k = 0; k < f.motions.size(); ++k) {
    if (b.sim.model.blocks[k].fixed) continue;
    EXPECT_GT(f.motions[k].ux, 0.0) << "block " << k;
  }
}

// --- friction extremes on a single block (analytic outcomes, cases/README.md, `block`) --------

TEST(Stability, NoFrictionBlockSlidesAtLambdaG) {
  // mu = 0, lambda = 0.2 < width/height = 0.5 (no overturning): the block slides with
  // acceleration lambda g, x = lambda g t^2 / 2, and no friction work is done.
  const double lambda = 0.2, t_end = 0.1;
  const Config config = block_deck({"contact.friction=0", "load.lambda=0.2"});
  Built b = build(config);
  const Figures f = run_case("mu = 0 (block)", b.sim, b.info.dt_stable, t_end);
  expect_sound(f, config);
  const double expected = 0.5 * lambda * kG * t_end * t_end;
  const std::size_t free_block = b.sim.model.blocks[0].fixed ? 1 : 0;
  ASSERT_FALSE(b.sim.model.blocks[free_block].fixed);
  const BlockMotion& m = f.motions[free_block];
  EXPECT_NEAR(m.ux, expected, 0.02 * expected);
  EXPECT_LT(std::abs(m.rotation), kStandRotation);
  EXPECT_EQ(b.sim.ledger.friction_dissipated, 0.0);
}

TEST(Stability, HighFrictionBlockSticksOnSteepIncline) {
  // mu = 5 on a 60 degree incline: tan 60 = 1.73 < mu, so it sticks (it would slide at
  // g (sin - mu cos) = 8.5 m/s2 with mu = 0), and width/height = 2 > tan 60, so it does not
  // tip over.
  const Config config =
      block_deck({"contact.friction=5", "model.incline=60", "model.width=1.0", "model.height=0.5"});
  Built b = build(config);
  const Figures f = run_case("mu = 5 (block, 60 deg)", b.sim, b.info.dt_stable, 0.1);
  expect_sound(f, config);
  EXPECT_TRUE(f.stands()) << "block move " << f.max_block_move << " L_ref";
  // A slide would have covered (sin - mu cos) g t^2 / 2 = 42 mm by now with mu = 0.
  EXPECT_LT(f.max_displacement, 1e-4);
}

// --- sliver triangles -------------------------------------------------------------------------

// A 0.5 m square block meshed with a sliver along its base: node P = (0, d) a hair above the
// base middle makes the base triangle (A, B, P) with 2-degree angles at A and B; its base edge
// is the block's contact face on the ground. Ground: a fixed 2 m x 0.25 m slab.
Model sliver_model(double min_angle_deg) {
  Model m;
  const double hw = 0.25, h = 0.5;
  const double d = hw * std::tan(min_angle_deg * std::numbers::pi / 180.0);
  add_block(m, {{-1.0, -0.25}, {1.0, -0.25}, {1.0, 0.0}, {-1.0, 0.0}},
            {{-1.0, -0.25}, {1.0, -0.25}, {1.0, 0.0}, {-1.0, 0.0}}, {{{0, 1, 2}}, {{0, 2, 3}}},
            true, "ground");
  const std::vector<Vec2> outline = {{-hw, 0.0}, {hw, 0.0}, {hw, h}, {-hw, h}};
  std::vector<Vec2> points = outline;
  points.push_back({0.0, d});  // P = 4
  add_block(m, outline, points, {{{0, 1, 4}}, {{0, 4, 3}}, {{4, 1, 2}}, {{4, 2, 3}}}, false,
            "test");
  m.material.density = 2000.0;
  m.material.young = 40e9;
  m.material.poisson = 0.2;
  finalize_model(m);
  return m;
}

TEST(Stability, SliverTrianglesStand) {
  Simulation sim;
  sim.model = sliver_model(2.0);
  EXPECT_NEAR(worst_triangle_angle_deg(sim.model), 2.0, 1e-9);
  // What make_simulation does for a deck: default penalty and damping, mu = 0.6, gravity.
  ContactParams cp;
  cp.penalty = 100.0 * sim.model.material.lame_lambda();
  cp.friction = 0.6;
  sim.contact.setup(sim.model, cp);
  prepare_context(sim, 1.0);
  set_static_load(sim, kG, 0.0);
  const double dt_stable = stable_time_step(sim);
  const Config config;  // the default dt_safety, as "auto" would use it
  sim.ctx.dt = config.solver.dt_safety * dt_stable;
  const Figures f = run_case("sliver 2 deg", sim, dt_stable, 0.05);
  expect_sound(f, config);
  EXPECT_TRUE(f.stands()) << "block move " << f.max_block_move << " L_ref, turn "
                          << f.max_block_turn;
  // Resting, not sinking: the base stays within a micrometre of the ground.
  EXPECT_LT(f.max_displacement, 1e-5);
}

// --- guards -----------------------------------------------------------------------------------

TEST(Guards, UserTimeStepAboveStableLimitRefusedWithTheLimit) {
  const Config config = block_deck({});
  const Built b = build(config);
  const double limit = b.info.dt_stable;
  char dt[64];
  std::snprintf(dt, sizeof dt, "solver.dt=%.6e", 1.5 * limit);
  const std::string scratch = (fs::temp_directory_path() / "voussoir_guard_dt").string();
  for (const char* command : {"run", "check"}) {
    const testing::ProcessResult r = testing::run_process(
        {VOUSSOIR_BINARY, command, case_path("block"), "--set", dt, "-q"}, {}, scratch);
    ASSERT_TRUE(r.exited) << r.describe();
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("above the stable limit"), std::string::npos) << r.err;
    // The message names the limit (to the printed precision).
    const std::size_t at = r.err.find("stable limit ");
    ASSERT_NE(at, std::string::npos);
    const double named = std::stod(r.err.substr(at + 13));
    EXPECT_NEAR(named, limit, 1e-5 * limit) << r.err;
  }
  // Just below the limit is accepted.
  std::snprintf(dt, sizeof dt, "solver.dt=%.6e", 0.99 * limit);
  const testing::ProcessResult ok = testing::run_process(
      {VOUSSOIR_BINARY, "check", case_path("block"), "--set", dt}, {}, scratch);
  EXPECT_TRUE(ok.exited && ok.status == 0) << ok.describe() << ok.err;
}

// The block deck with a time step injected at `factor` x the stable limit (what
// make_simulation refuses from a deck). With damping, the unstable element modes saturate
// (the viscous term oscillates from step to step and its booked dissipation grows without
// bound, the state stays finite): only the energy guard sees it. Undamped, they grow
// geometrically to overflow.
Built unstable_block(double factor, bool damped = true) {
  Built b = build(block_deck({damped ? "solver.damping_factor=1" : "solver.damping_factor=0"}));
  b.sim.ctx.dt = factor * b.info.dt_stable;
  return b;
}

// "at step S (t = T s): node I of block B, triangle E" with S > 0, B a free block, E >= 0.
void expect_names_where(const std::string& msg, const Model& model) {
  const std::size_t s = msg.find("at step ");
  ASSERT_NE(s, std::string::npos) << msg;
  EXPECT_GT(std::stoll(msg.substr(s + 8)), 0) << msg;
  const std::size_t b = msg.find("of block ");
  ASSERT_NE(b, std::string::npos) << msg;
  const int block = std::stoi(msg.substr(b + 9));
  ASSERT_GE(block, 0);
  ASSERT_LT(block, static_cast<int>(model.blocks.size()));
  EXPECT_FALSE(model.blocks[block].fixed) << msg;
  const std::size_t t = msg.find("triangle ");
  ASSERT_NE(t, std::string::npos) << msg;
  EXPECT_GE(std::stoi(msg.substr(t + 9)), 0) << msg;
}

TEST(Guards, EnergyDriftNamesStepBlockTriangle) {
  // The guard itself on a ledger off by 6% of its peak: RunError naming where; 4% passes.
  Built b = build(block_deck({}));
  Simulation& sim = b.sim;
  for (int k = 0; k < 10; ++k) advance(sim);
  sim.ledger.max_energy = 1.0;
  sim.ledger.external_work = sim.ledger.stored() + sim.ledger.dissipated() + 0.04;
  EXPECT_NO_THROW(check_energy_balance(sim));
  sim.ledger.external_work += 0.02;
  try {
    check_energy_balance(sim);
    ADD_FAILURE() << "a 6% energy error passed the guard";
  } catch (const RunError& e) {
    EXPECT_NE(std::string(e.what()).find("energy balance error 0.06"), std::string::npos)
        << e.what();
    expect_names_where(e.what(), sim.model);
  }
}

TEST(Guards, EnergyDriftStopsAnUnstableStep) {
  // Twice the stable step: the element modes grow from round-off until the damping term
  // oscillates from step to step. The drift guard (kEnergyDriftLimit, armed after
  // kEnergyDriftArmSteps) must stop the run; the state is finite throughout (the non-finite
  // guard alone would never stop it).
  Built b = unstable_block(2.0);
  LoopOptions opts;
  opts.end_time = 1.0;
  opts.sample_every = b.sim.ctx.dt;  // guards at every step
  opts.quiet = true;
  bool finite_throughout = true;
  std::string msg;
  try {
    run_loop(b.sim, opts, [&](const Simulation& s) {
      finite_throughout = finite_throughout && all_finite(s);
      return true;
    });
  } catch (const RunError& e) {
    msg = e.what();
  }
  ASSERT_FALSE(msg.empty()) << "the unstable run was not stopped";
  EXPECT_NE(msg.find("energy balance error"), std::string::npos) << msg;
  EXPECT_TRUE(finite_throughout);
  EXPECT_TRUE(all_finite(b.sim)) << "stopped only after the state went non-finite";
  EXPECT_GE(b.sim.step, kEnergyDriftArmSteps);
  expect_names_where(msg, b.sim.model);
  std::printf("[guards] drift guard: %s\n", msg.c_str());
}

TEST(Guards, NonFiniteStateStopsTheRunNamingStepBlockTriangle) {
  // A NaN velocity on one node (what an overflow anywhere in a stage leaves behind) with the
  // drift guard off: the non-finite guard stops the run at the next sample, before the
  // sampler (the HDF5 writer of `voussoir run`) sees it, and names that node, its block and a
  // triangle holding it. (An unstable step alone does not get there in this scene: the
  // hyperelastic law keeps the blown-up state finite, tests above; the drift guard stops it.)
  Built b = build(block_deck({}));
  Simulation& sim = b.sim;
  for (int k = 0; k < 20; ++k) advance(sim);
  Index node = -1;
  for (Index i = 0; i < sim.model.nodes.size() && node < 0; ++i)
    if (sim.model.nodes.inv_mass[i] > 0.0 && sim.model.nodes.y0[i] > 0.5) node = i;
  ASSERT_GE(node, 0);
  sim.model.nodes.vx[node] = std::numeric_limits<double>::quiet_NaN();
  LoopOptions opts;
  opts.end_time = 1.0;
  opts.sample_every = 10 * sim.ctx.dt;
  opts.quiet = true;
  opts.drift_limit = 0.0;
  std::string msg;
  bool sampled_non_finite = false;
  try {
    run_loop(sim, opts, [&](const Simulation& s) {
      sampled_non_finite = sampled_non_finite || !all_finite(s);
      return true;
    });
  } catch (const RunError& e) {
    msg = e.what();
  }
  ASSERT_FALSE(msg.empty()) << "the run went on with a NaN";
  EXPECT_NE(msg.find("non-finite"), std::string::npos) << msg;
  EXPECT_FALSE(sampled_non_finite) << "a non-finite state reached the sampler";
  EXPECT_LE(sim.step, 30);  // at the first sample after the NaN
  expect_names_where(msg, sim.model);
  // The NaN spreads through the element forces of the step, so the first node named may be a
  // neighbour; it is in the same block.
  const std::size_t at = msg.find("of block ");
  EXPECT_EQ(std::stoi(msg.substr(at + 9)), sim.model.nodes.block[node]) << msg;
  std::printf("[guards] non-finite guard: %s\n", msg.c_str());
}

int attr_int(hid_t file, const char* name) {
  const hid_t a = H5Aopen_by_name(file, "/", name, H5P_DEFAULT, H5P_DEFAULT);
  if (a < 0) return -1;
  int v = -1;
  H5Aread(a, H5T_NATIVE_INT, &v);
  H5Aclose(a);
  return v;
}

std::string attr_string(hid_t file, const char* name) {
  const hid_t a = H5Aopen_by_name(file, "/", name, H5P_DEFAULT, H5P_DEFAULT);
  if (a < 0) return "";
  const hid_t t = H5Aget_type(a);
  std::string s;
  if (H5Tis_variable_str(t) > 0) {
    char* p = nullptr;
    H5Aread(a, t, &p);
    if (p) s = p;
    H5free_memory(p);
  } else {
    s.assign(H5Tget_size(t), '\0');
    H5Aread(a, t, s.data());
  }
  H5Tclose(t);
  H5Aclose(a);
  return s;
}

TEST(Guards, FailedRunLeavesItsOutputMarkedIncomplete) {
  // `voussoir run` (run_simulation, the body of command_run) on the unstable step: RunError
  // (exit status 1 in app/main.cpp), no file at the output path, the `.tmp` file with
  // complete = 0 and the reason.
  const fs::path dir = fs::temp_directory_path() / "voussoir_guard_output";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string out = (dir / "run.h5").string();
  Config config = block_deck({});
  config.solver.end_time = 1.0;
  Built b = build(config);
  b.sim.ctx.dt = 3.0 * b.info.dt_stable;
  CommonOptions common;
  common.quiet = true;
  RunOptions opts;
  opts.output = out;
  std::string msg;
  try {
    run_simulation(b.sim, b.info, config, common, opts);
  } catch (const RunError& e) {
    msg = e.what();
  }
  ASSERT_FALSE(msg.empty()) << "the unstable run was not stopped";
  expect_names_where(msg, b.sim.model);
  EXPECT_FALSE(fs::exists(out)) << "a failed run left a file looking complete";
  EXPECT_FALSE(fs::exists(dir / "run.xdmf"));
  ASSERT_TRUE(fs::exists(out + ".tmp"));
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t f = H5Fopen((out + ".tmp").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  EXPECT_EQ(attr_int(f, "complete"), 0);
  EXPECT_NE(attr_string(f, "error").find("at step"), std::string::npos);
  H5Fclose(f);
  fs::remove_all(dir);
}

TEST(Guards, OverflowingRunExitsOneAndLeavesOutputIncomplete) {
  // The program end to end: a deck value the deck reader accepts (load.lambda takes any
  // finite number) whose run overflows: exit status 1, the message names the step and where,
  // no file at the output path, the .tmp file flagged incomplete.
  const fs::path dir = fs::temp_directory_path() / "voussoir_guard_exit";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string out = (dir / "run.h5").string();
  const testing::ProcessResult r =
      testing::run_process({VOUSSOIR_BINARY, "run", case_path("block"), "--set",
                            "load.lambda=1e300", "--set", "solver.end_time=0.001", "-o", out, "-q"},
                           {}, (dir / "child").string());
  ASSERT_TRUE(r.exited) << r.describe();
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("run failed: non-finite"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("at step"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("of block"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  ASSERT_TRUE(fs::exists(out + ".tmp"));
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t f = H5Fopen((out + ".tmp").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  EXPECT_EQ(attr_int(f, "complete"), 0);
  H5Fclose(f);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace voussoir

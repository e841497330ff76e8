// Agreement tier (STYLE.md "Tests in tiers"): one thread against two threads, bit for bit.
// The element stage, the integration and the contact stage run on OpenMP threads above size
// thresholds (core/cst.cpp kParallelTriangles, core/integrate.cpp kParallelNodes,
// contact/contact.cpp kParallelPairs) and are built so that no result depends on the thread
// count. Two scenes: the shipped arch (below every threshold: the one-thread path must be
// taken whatever the thread count) and church A meshed at through_thickness 6 (14240
// triangles, 10687 nodes, 200 steps: the threaded element, load and integration paths run).
// The threaded contact path (pairs in parallel, per-node gather of their slots) needs more
// candidate pairs than these scenes have: the tests lower its threshold
// (ContactSystem::set_parallel_pairs) and compare it with the one-thread loop. On a
// loaded machine the two-thread run is the slow part (libgomp spins at barriers while the
// partner thread waits for a core: docs/benchmarks.md).
#include <gtest/gtest.h>
#include <omp.h>

#include <cstring>
#include <string>
#include <vector>

#include "contact/contact.hpp"
#include "core/cst.hpp"
#include "core/integrate.hpp"
#include "engine/setup.hpp"
#include "engine/step.hpp"
#include "io/deck.hpp"

using namespace voussoir;

namespace {

struct Snapshot {
  std::vector<double> x, y, vx, vy;
  EnergyLedger ledger;
};

// Runs `steps` steps of the deck with `threads` OpenMP threads, gravity plus a horizontal
// load lambda g so that the blocks move and slide; parallel_pairs > 0: the contact stage's
// threshold for its threaded path (ContactSystem::set_parallel_pairs).
Snapshot run(const std::string& deck, const std::vector<std::string>& overrides, int steps,
             int threads, std::int64_t parallel_pairs = 0) {
  const Config config = load_deck(std::string(VOUSSOIR_SOURCE_DIR) + "/cases/" + deck, overrides);
  Simulation sim = make_simulation(config);
  set_static_load(sim, 9.81, 0.3);
  if (parallel_pairs > 0) sim.contact.set_parallel_pairs(parallel_pairs);
  const int saved = omp_get_max_threads();
  omp_set_num_threads(threads);
  for (int k = 0; k < steps; ++k) advance(sim);
  omp_set_num_threads(saved);
  const Nodes& n = sim.model.nodes;
  return Snapshot{n.x, n.y, n.vx, n.vy, sim.ledger};
}

// Church A with elastic blocks at `through_thickness` after `steps` steps under gravity and
// lambda = 0.3: a general, moving state.
Simulation moving_church(int through_thickness, int steps) {
  const Config config = load_deck(std::string(VOUSSOIR_SOURCE_DIR) + "/cases/church_a.toml",
                                  {"material.model=elastic",
                                   "mesh.through_thickness=" + std::to_string(through_thickness)});
  Simulation sim = make_simulation(config);
  set_static_load(sim, 9.81, 0.3);
  for (int k = 0; k < steps; ++k) advance(sim);
  return sim;
}

// Bitwise equality of two double arrays (NaN-safe, -0 != +0).
bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof(double)) == 0;
}

void expect_identical(const Snapshot& one, const Snapshot& two) {
  EXPECT_TRUE(same_bits(one.x, two.x));
  EXPECT_TRUE(same_bits(one.y, two.y));
  EXPECT_TRUE(same_bits(one.vx, two.vx));
  EXPECT_TRUE(same_bits(one.vy, two.vy));
  const EnergyLedger &a = one.ledger, &b = two.ledger;
  EXPECT_TRUE(same_bits(a.kinetic, b.kinetic)) << a.kinetic << " " << b.kinetic;
  EXPECT_TRUE(same_bits(a.strain, b.strain)) << a.strain << " " << b.strain;
  EXPECT_TRUE(same_bits(a.contact, b.contact)) << a.contact << " " << b.contact;
  EXPECT_TRUE(same_bits(a.external_work, b.external_work));
  EXPECT_TRUE(same_bits(a.damping_dissipated, b.damping_dissipated));
  EXPECT_TRUE(same_bits(a.friction_dissipated, b.friction_dissipated));
  EXPECT_TRUE(same_bits(a.max_energy, b.max_energy));
}

}  // namespace

TEST(Threads, ArchOneAndTwoThreadsBitIdentical) {
  const std::vector<std::string> set = {"material.model=elastic", "mesh.through_thickness=2"};
  const Snapshot one = run("circular_arch.toml", set, 10000, 1);
  const Snapshot two = run("circular_arch.toml", set, 10000, 2);
  ASSERT_GT(one.ledger.kinetic, 0.0);  // it moved
  expect_identical(one, two);
}

TEST(Threads, LargeChurchOneAndTwoThreadsBitIdentical) {
  const std::vector<std::string> set = {"material.model=elastic", "mesh.through_thickness=6"};
  const Snapshot one = run("church_a.toml", set, 200, 1);
  ASSERT_GE(one.x.size(), 8192u);  // above the element and integration thresholds
  const Snapshot two = run("church_a.toml", set, 200, 2);
  ASSERT_GT(one.ledger.kinetic, 0.0);
  ASSERT_GT(one.ledger.damping_dissipated, 0.0);
  expect_identical(one, two);
}

// The threaded element stage against the one-thread loop on the same state: same forces,
// energies and viscous buffer, bit for bit (core/cst.cpp: the gather repeats the scatter's
// additions in the same order).
TEST(Threads, ThreadedElementStageEqualsOneThreadLoop) {
  const Simulation sim = moving_church(6, 50);
  ASSERT_GE(sim.model.tris.size(), 8192);
  const CstLaw law{sim.ctx.lame_lambda, sim.ctx.shear_modulus, sim.ctx.eta};
  Model serial = sim.model, threaded = sim.model;
  std::vector<double> pv_serial = sim.viscous_piola, pv_threaded = sim.viscous_piola;
  ElementWorkspace work;
  const int saved = omp_get_max_threads();
  omp_set_num_threads(2);
  const ElementStageResult a = add_element_forces(serial, law, pv_serial.data());
  const ElementStageResult b = add_element_forces(threaded, law, pv_threaded.data(), &work);
  omp_set_num_threads(saved);
  ASSERT_FALSE(work.slots.slot.empty());  // the threaded path ran
  EXPECT_TRUE(same_bits(serial.nodes.fx, threaded.nodes.fx));
  EXPECT_TRUE(same_bits(serial.nodes.fy, threaded.nodes.fy));
  EXPECT_TRUE(same_bits(pv_serial, pv_threaded));
  EXPECT_TRUE(same_bits(a.strain_energy, b.strain_energy));
  EXPECT_TRUE(same_bits(a.damping_power, b.damping_power));
  EXPECT_TRUE(same_bits(a.previous_damping_power, b.previous_damping_power));
}

// The threaded contact path (threshold lowered to every pair) against the one-thread loop over
// a whole run of the arch: blocks slide and rock, contacts open and close, pairs are
// re-detected, friction history is carried over; positions and ledger bit for bit.
TEST(Threads, ArchThreadedContactPathBitIdentical) {
  const std::vector<std::string> set = {"material.model=elastic", "mesh.through_thickness=2"};
  const Snapshot one = run("circular_arch.toml", set, 10000, 1);
  const Snapshot two = run("circular_arch.toml", set, 10000, 2, 1);
  ASSERT_GT(one.ledger.kinetic, 0.0);
  ASSERT_GT(one.ledger.friction_dissipated, 0.0);
  expect_identical(one, two);
}

// One contact stage, threaded (threshold lowered) against the one-thread loop on the same
// moving state of church A: same forces, contact energy, friction dissipation, active count
// and friction history (the next step), bit for bit (contact/contact.cpp: each node adds its
// pair slots in the one-thread loop's order).
TEST(Threads, ThreadedContactStageEqualsOneThreadLoop) {
  const Simulation sim = moving_church(2, 300);
  ASSERT_GT(sim.contact.candidate_pairs(), 100);
  Simulation serial = sim, threaded = sim;
  threaded.contact.set_parallel_pairs(1);
  const int saved = omp_get_max_threads();
  omp_set_num_threads(2);
  const CstLaw law{sim.ctx.lame_lambda, sim.ctx.shear_modulus, sim.ctx.eta};
  for (int k = 0; k < 2; ++k) {  // the second call also checks the friction state it left
    // Element forces first, as in the step: with nonzero starting forces the order of the
    // contact additions shows in the bits even at nodes with two contributions.
    for (Model* m : {&serial.model, &threaded.model}) {
      clear_forces(m->nodes);
      add_element_forces(*m, law);
    }
    serial.contact.add_forces(serial.model, serial.ctx.dt, serial.ledger);
    threaded.contact.add_forces(threaded.model, threaded.ctx.dt, threaded.ledger);
  }
  omp_set_num_threads(saved);
  ASSERT_GT(serial.contact.active_pairs(), 10);
  EXPECT_EQ(serial.contact.active_pairs(), threaded.contact.active_pairs());
  EXPECT_TRUE(same_bits(serial.model.nodes.fx, threaded.model.nodes.fx));
  EXPECT_TRUE(same_bits(serial.model.nodes.fy, threaded.model.nodes.fy));
  EXPECT_TRUE(same_bits(serial.ledger.contact, threaded.ledger.contact));
  EXPECT_TRUE(same_bits(serial.ledger.friction_dissipated, threaded.ledger.friction_dissipated));
}

// The thin arch of tests/unit/test_stability.cpp (t/R = 0.05, half the minimum thickness of a
// semicircular arch) followed through 0.4 s of its collapse under gravity: the voussoirs fold,
// knock against one another and fall past the springings. "Cleanly": no NaN or infinity at any
// sample, energy balance within 1% of the peak energy over the whole fall (impacts included),
// the automatic dt the deck's safety fraction of the stable limit, the centre of mass of the
// voussoirs and the lowest one fallen by more than the arch thickness (some haunch voussoirs
// rise as they turn outward), the kinetic energy no more than gravity's work. About a minute
// on one core.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "engine/kinematics.hpp"
#include "engine/run_loop.hpp"
#include "engine/setup.hpp"
#include "io/deck.hpp"

namespace voussoir {
namespace {

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

TEST(StabilitySlow, ThinArchCollapsesCleanlyThroughTheFall) {
  const double end_time = 0.4;
  const Config config = load_deck(std::string(VOUSSOIR_SOURCE_DIR) + "/cases/circular_arch.toml",
                                  {"material.model=elastic", "mesh.through_thickness=1",
                                   "model.thickness=0.05"});
  SetupInfo info;
  Simulation sim = make_simulation(config, &info);
  LoopOptions opts;
  opts.end_time = end_time;
  opts.sample_every = 50 * sim.ctx.dt;
  opts.quiet = true;
  opts.drift_limit = 0.0;  // measured here, not acted on
  bool finite = true;
  double max_residual = 0.0, worst_time = 0.0;
  run_loop(sim, opts, [&](const Simulation& s) {
    finite = finite && all_finite(s);
    const EnergyLedger& l = s.ledger;
    const double r = std::abs(l.external_work - l.stored() - l.dissipated());
    if (r > max_residual) {
      max_residual = r;
      worst_time = s.ctx.time;
    }
    return finite;
  });
  const double peak = sim.ledger.max_energy;
  const std::vector<BlockMotion> motions = block_motions(sim.model);
  // Largest drop of a block centroid, and drop of the centre of mass of the free blocks (some
  // haunch voussoirs rise as they turn outward; the whole must come down).
  double crown_drop = 0.0, mass = 0.0, mass_uy = 0.0;
  for (std::size_t b = 0; b < motions.size(); ++b) {
    const Block& block = sim.model.blocks[b];
    if (block.fixed) continue;
    crown_drop = std::max(crown_drop, -motions[b].uy);
    mass += block.mass;
    mass_uy += block.mass * motions[b].uy;
  }
  const double centre_drop = -mass_uy / mass;
  std::printf(
      "[stability] arch t/R = 0.05 to %.2f s: dt %.3e s = %.2f x stable, %lld steps, "
      "energy error %.2e of peak %.3e J (worst at t = %.3e s), largest drop %.3f m, "
      "final KE %.3e J, centre of mass down by %.3f m\n",
      end_time, info.dt, info.dt / info.dt_stable, sim.step, max_residual / peak, peak, worst_time,
      crown_drop, sim.ledger.kinetic, centre_drop);
  EXPECT_TRUE(finite);
  EXPECT_LT(max_residual, 0.01 * peak);
  EXPECT_DOUBLE_EQ(info.dt, config.solver.dt_safety * info.dt_stable);
  EXPECT_GT(crown_drop, config.model.thickness);
  EXPECT_GT(centre_drop, config.model.thickness);
  // The kinetic energy of the fall comes from gravity: at most m g (centre drop), the rest
  // being stored or dissipated.
  EXPECT_LE(sim.ledger.kinetic, mass * config.load.gravity * centre_drop * 1.01);
}

}  // namespace
}  // namespace voussoir

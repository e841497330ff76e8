#include "drivers/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "drivers/setup.hpp"

namespace voussoir {

double max_free_displacement(const Model& model) {
  const Nodes& n = model.nodes;
  double d2 = 0.0;
  for (Index i = 0; i < n.size(); ++i) {
    if (n.inv_mass[i] == 0.0) continue;
    const double dx = n.x[i] - n.x0[i], dy = n.y[i] - n.y0[i];
    d2 = std::max(d2, dx * dx + dy * dy);
  }
  return std::sqrt(d2);
}

void check_finite(const Simulation& sim) {
  const Nodes& n = sim.model.nodes;
  for (Index i = 0; i < n.size(); ++i) {
    if (std::isfinite(n.x[i]) && std::isfinite(n.y[i]) && std::isfinite(n.vx[i]) &&
        std::isfinite(n.vy[i]))
      continue;
    const Triangles& t = sim.model.tris;
    Index tri = -1;
    for (Index e = 0; e < t.size() && tri < 0; ++e)
      if (t.n0[e] == i || t.n1[e] == i || t.n2[e] == i) tri = e;
    std::ostringstream msg;
    msg << "non-finite state at step " << sim.step << " (t = " << sim.ctx.time << " s): node " << i
        << " of block " << n.block[i] << ", triangle " << tri
        << " (the time step may be too large for the contact penalty; try a smaller "
           "solver.dt_safety)";
    throw RunError(msg.str());
  }
  const EnergyLedger& l = sim.ledger;
  if (!std::isfinite(l.kinetic) || !std::isfinite(l.strain) || !std::isfinite(l.contact)) {
    std::ostringstream msg;
    msg << "non-finite energy at step " << sim.step << " (t = " << sim.ctx.time << " s)";
    throw RunError(msg.str());
  }
}

LoopStats run_loop(Simulation& sim, double end_time, double sample_every,
                   const std::function<bool(const Simulation&)>& sample, bool quiet,
                   const std::string& label) {
  using clock = std::chrono::steady_clock;
  const auto start = clock::now();
  auto last_report = start;
  LoopStats stats;
  const double dt = sim.ctx.dt;
  const long long total_steps = static_cast<long long>(std::ceil(end_time / dt - 1e-9));
  const long long every = std::max(1LL, static_cast<long long>(std::llround(sample_every / dt)));
  bool go_on = sample(sim);
  for (long long s = 0; s < total_steps && go_on; ++s) {
    advance(sim);
    stats.max_active_pairs = std::max(stats.max_active_pairs, sim.contact.active_pairs());
    const bool last = (s + 1 == total_steps);
    if ((s + 1) % every == 0 || last) {
      check_finite(sim);
      go_on = sample(sim);
      const auto now = clock::now();
      if (!quiet && std::chrono::duration<double>(now - last_report).count() > 2.0) {
        last_report = now;
        std::fprintf(stderr, "%s t = %.4f / %.4f s, step %lld, KE %.3e J\n", label.c_str(),
                     sim.ctx.time, end_time, sim.step, sim.ledger.kinetic);
      }
    }
  }
  stats.steps = sim.step;
  stats.wall_s = std::chrono::duration<double>(clock::now() - start).count();
  return stats;
}

}  // namespace voussoir

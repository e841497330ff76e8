#include "drivers/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "drivers/setup.hpp"

namespace voussoir {

namespace {

// A triangle holding node i (the first one in id order), or -1.
Index triangle_of_node(const Triangles& t, Index i) {
  for (Index e = 0; e < t.size(); ++e)
    if (t.n0[e] == i || t.n1[e] == i || t.n2[e] == i) return e;
  return -1;
}

// The free node with the largest speed (a NaN speed counts as the largest), or -1 if none.
Index fastest_node(const Nodes& n) {
  Index best = -1;
  double best_v2 = -1.0;
  for (Index i = 0; i < n.size(); ++i) {
    if (n.inv_mass[i] == 0.0) continue;
    const double v2 = n.vx[i] * n.vx[i] + n.vy[i] * n.vy[i];
    if (!(v2 <= best_v2)) {  // also takes NaN
      best = i;
      best_v2 = v2;
      if (std::isnan(v2)) break;
    }
  }
  return best;
}

// "at step S (t = T s): node I of block B, triangle E".
std::string where(const Simulation& sim, Index node) {
  std::ostringstream s;
  s << "at step " << sim.step << " (t = " << sim.ctx.time << " s)";
  if (node >= 0)
    s << ": node " << node << " of block " << sim.model.nodes.block[node] << ", triangle "
      << triangle_of_node(sim.model.tris, node);
  return s.str();
}

}  // namespace

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
        std::isfinite(n.vy[i]) && std::isfinite(n.fx[i]) && std::isfinite(n.fy[i]))
      continue;
    throw RunError("non-finite state " + where(sim, i) +
                   " (the time step may be too large for the contact penalty; try a smaller "
                   "solver.dt_safety)");
  }
  const EnergyLedger& l = sim.ledger;
  for (const double e : {l.kinetic, l.strain, l.contact, l.external_work, l.damping_dissipated,
                         l.friction_dissipated, l.max_energy}) {
    if (std::isfinite(e)) continue;
    throw RunError("non-finite energy " + where(sim, fastest_node(n)) +
                   " (the fastest node; the loads or the material may be out of range)");
  }
}

void check_energy_balance(const Simulation& sim, double limit) {
  const double err = sim.ledger.balance_error();
  if (!(err > limit)) return;
  const EnergyLedger& l = sim.ledger;
  std::ostringstream msg;
  msg << "energy balance error " << err << " above the limit " << limit << " "
      << where(sim, fastest_node(sim.model.nodes)) << " (the fastest node): external work "
      << l.external_work << " J, kinetic " << l.kinetic << " J, strain " << l.strain
      << " J, contact " << l.contact << " J, dissipated " << l.dissipated()
      << " J (the time step may be too large; try a smaller solver.dt_safety)";
  throw RunError(msg.str());
}

LoopStats run_loop(Simulation& sim, const LoopOptions& opts,
                   const std::function<bool(const Simulation&)>& sample, const LoopStats& resume) {
  using clock = std::chrono::steady_clock;
  const auto start = clock::now();
  auto last_report = start;
  LoopStats stats = resume;
  const double dt = sim.ctx.dt;
  // Steps counted from step 0, so that a resumed loop ends, samples and checkpoints where the
  // uninterrupted one does.
  const double steps_needed = std::ceil(opts.end_time / dt - 1e-9);
  if (!(dt > 0.0) || !(steps_needed < 1e15)) {
    std::ostringstream msg;
    msg << "cannot run to t = " << opts.end_time << " s with a time step of " << dt << " s";
    throw RunError(msg.str());
  }
  const long long total_steps = static_cast<long long>(std::max(0.0, steps_needed));
  auto steps_of = [dt](double interval) {
    return std::max(1LL, static_cast<long long>(std::llround(std::min(interval / dt, 1e15))));
  };
  const long long every = steps_of(opts.sample_every);
  const long long ckpt_every =
      (opts.checkpoint && opts.checkpoint_every > 0.0) ? steps_of(opts.checkpoint_every) : 0;
  bool go_on = sim.step == 0 ? sample(sim) : true;
  auto write_checkpoint = [&] {
    check_finite(sim);  // never checkpoint a broken state
    stats.steps = sim.step;
    stats.wall_s = resume.wall_s + std::chrono::duration<double>(clock::now() - start).count();
    opts.checkpoint(sim, stats);
  };
  while (sim.step < total_steps && go_on) {
    advance(sim);
    stats.max_active_pairs = std::max(stats.max_active_pairs, sim.contact.active_pairs());
    const bool last = sim.step == total_steps;
    const bool on_grid = sim.step % every == 0;
    const bool checkpoint_due = ckpt_every > 0 && ((sim.step % ckpt_every == 0 && !last) ||
                                                   (last && opts.checkpoint_at_end));
    if (checkpoint_due && !on_grid) write_checkpoint();
    if (on_grid || last) {
      check_finite(sim);
      if (opts.drift_limit > 0.0 && sim.step >= opts.drift_arm_steps)
        check_energy_balance(sim, opts.drift_limit);
      go_on = sample(sim);
      const auto now = clock::now();
      if (!opts.quiet && std::chrono::duration<double>(now - last_report).count() > 2.0) {
        last_report = now;
        std::fprintf(stderr, "%s t = %.4f / %.4f s, step %lld, KE %.3e J\n", opts.label.c_str(),
                     sim.ctx.time, opts.end_time, sim.step, sim.ledger.kinetic);
      }
    }
    if (checkpoint_due && on_grid && go_on) write_checkpoint();
  }
  stats.steps = sim.step;
  stats.wall_s = resume.wall_s + std::chrono::duration<double>(clock::now() - start).count();
  return stats;
}

LoopStats run_loop(Simulation& sim, double end_time, double sample_every,
                   const std::function<bool(const Simulation&)>& sample, bool quiet,
                   const std::string& label) {
  LoopOptions opts;
  opts.end_time = end_time;
  opts.sample_every = sample_every;
  opts.quiet = quiet;
  opts.label = label;
  return run_loop(sim, opts, sample);
}

}  // namespace voussoir

#include "engine/run_loop.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/rigid.hpp"
#include "engine/setup.hpp"

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

SeriesRecord series_record(const Simulation& sim) {
  const EnergyLedger& l = sim.ledger;
  SeriesRecord r;
  r.time = sim.ctx.time;
  r.kinetic = l.kinetic;
  r.strain = l.strain;
  r.contact = l.contact;
  r.damping_dissipated = l.damping_dissipated + l.impact_dissipated;  // io/hdf5_output.hpp
  r.friction_dissipated = l.friction_dissipated;
  r.external_work = l.external_work;
  r.max_displacement = max_free_displacement(sim.model);
  r.active_contacts = sim.contact.active_pairs();
  r.energy_balance_error = l.balance_error();
  return r;
}

void refuse_absurd_plan(const Simulation& sim, double steps, const LoopOptions& opts) {
  if (opts.limits.max_steps > 0 || !(steps > kMaxPlannedSteps)) return;
  // The wall they imply: kProbeSteps steps of a copy, timed.
  constexpr int kProbeSteps = 8;
  Simulation probe = sim;
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < kProbeSteps; ++k) advance(probe);
  const double per_step = seconds_since(t0) / kProbeSteps;
  std::ostringstream msg;
  msg.precision(3);
  msg << opts.label << ": solver.end_time = " << opts.end_time << " s at a time step of "
      << sim.ctx.dt << " s (solver.dt, solver.dt_safety) is " << steps << " steps, about "
      << steps * per_step << " s of wall at " << per_step << " s a step: above the "
      << kMaxPlannedSteps << " steps a run plans without --max-steps (give --max-steps "
      << std::llround(std::min(steps, 9e18)) << " to run it anyway)";
  throw DeckError(msg.str());
}

LoopStats run_loop(Simulation& sim, const LoopOptions& opts,
                   const std::function<bool(const Simulation&)>& sample, const LoopStats& resume) {
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
  refuse_absurd_plan(sim, steps_needed - static_cast<double>(sim.step), opts);
  auto steps_of = [dt](double interval) {
    return std::max(1LL, static_cast<long long>(std::llround(std::min(interval / dt, 1e15))));
  };
  const long long ckpt_every =
      (opts.checkpoint && opts.checkpoint_every > 0.0) ? steps_of(opts.checkpoint_every) : 0;

  RunSpec spec;
  spec.label = opts.label;
  spec.loads = opts.loads;
  spec.limits = opts.limits;
  spec.limits.drift_limit = opts.drift_limit;
  spec.limits.drift_arm_steps = opts.drift_arm_steps;
  spec.sample_every = opts.sample_every;
  spec.sample_origin = 0;  // the absolute grid: a resumed run samples where the whole one does
  spec.sample_at_start = sim.step == 0;
  spec.sample_last = true;
  spec.end_step = static_cast<long long>(std::max(0.0, steps_needed));
  spec.quiet = opts.quiet;
  spec.progress_period = 2.0;
  spec.progress = [&](const Probe& p, double) {
    std::fprintf(stderr, "%s t = %.4f / %.4f s, step %lld, KE %.3e J\n", opts.label.c_str(),
                 p.sim.ctx.time, opts.end_time, p.sim.step, p.sim.ledger.kinetic);
  };

  const auto t0 = std::chrono::steady_clock::now();
  auto write_checkpoint = [&](const Simulation& s) {
    check_finite(s, opts.label);  // never checkpoint a broken state
    stats.steps = s.step;
    stats.wall_s = resume.wall_s + seconds_since(t0);
    opts.checkpoint(s, stats);
  };
  // Checkpoints: off the sample grid before that step's sample (the end-of-run sample that a
  // longer run would not take), on the grid after it.
  bool checkpoint_after_sample = false;
  spec.on_step = [&](Simulation& s, const StepInfo& at) {
    stats.max_active_pairs = std::max(stats.max_active_pairs, s.contact.active_pairs());
    const bool due = ckpt_every > 0 && ((s.step % ckpt_every == 0 && !at.last) ||
                                        (at.last && opts.checkpoint_at_end));
    if (due && !at.sample) {
      sync_rigid_nodes(s.model);
      write_checkpoint(s);
    }
    checkpoint_after_sample = due && at.sample;
  };
  spec.on_sample = [&](const Simulation& s, const Probe&) {
    const bool go_on = sample(s);
    if (checkpoint_after_sample && go_on) write_checkpoint(s);
    checkpoint_after_sample = false;
    return go_on;
  };
  run_engine(sim, spec);
  stats.steps = sim.step;
  stats.wall_s = resume.wall_s + seconds_since(t0);
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

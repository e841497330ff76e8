// The engine: one time loop for every run (contract and rules in trial.hpp).

#include "engine/trial.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "core/rigid.hpp"
#include "engine/setup.hpp"
#include "engine/solver_report.hpp"
#include "engine/stop.hpp"

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

// "in LABEL at step S (t = T s): node I of block B, triangle E".
std::string where(const Simulation& sim, Index node, const std::string& label) {
  std::ostringstream s;
  s << "in " << label << " at step " << sim.step << " (t = " << sim.ctx.time << " s)";
  if (node >= 0)
    s << ": node " << node << " of block " << sim.model.nodes.block[node] << ", triangle "
      << triangle_of_node(sim.model.tris, node);
  return s.str();
}

// The first non-finite quantity of node i, or nullptr.
const char* non_finite_quantity(const Nodes& n, Index i) {
  if (!std::isfinite(n.x[i]) || !std::isfinite(n.y[i])) return "position";
  if (!std::isfinite(n.vx[i]) || !std::isfinite(n.vy[i])) return "velocity";
  if (!std::isfinite(n.fx[i]) || !std::isfinite(n.fy[i])) return "force";
  return nullptr;
}

class FiniteGuard : public StopRule {
 public:
  explicit FiniteGuard(const std::string& label) : label_(label) {}
  std::optional<Verdict> check(const Probe& p) override {
    check_finite(p.sim, label_);
    return std::nullopt;
  }

 private:
  const std::string& label_;
};

class EnergyGuard : public StopRule {
 public:
  EnergyGuard(const RunLimits& limits, const std::string& label) : limits_(limits), label_(label) {}
  std::optional<Verdict> check(const Probe& p) override {
    if (limits_.drift_limit > 0.0 && p.sim.step >= limits_.drift_arm_steps)
      check_energy_balance(p.sim, limits_.drift_limit, label_);
    return std::nullopt;
  }

 private:
  const RunLimits& limits_;
  const std::string& label_;
};

// --max-steps: a budget per run (each settle, trial, pulse run, stability cell or `run`),
// counted from the run's start and read at its samples, so a run fails at its first sample
// at or past max_steps steps.
class MaxStepsGuard : public StopRule {
 public:
  MaxStepsGuard(long long max_steps, const std::string& label)
      : max_steps_(max_steps), label_(label) {}
  std::optional<Verdict> check(const Probe& p) override {
    if (max_steps_ <= 0 || p.steps < max_steps_) return std::nullopt;
    std::ostringstream msg;
    msg << "step limit --max-steps " << max_steps_ << " reached " << where(p.sim, -1, label_)
        << " after " << p.steps << " steps of this run";
    throw RunError(msg.str());
  }

 private:
  long long max_steps_;
  const std::string& label_;
};

// The guards every run has, built from its limits, read before the classification rules.
std::vector<std::unique_ptr<StopRule>> make_guards(const RunSpec& spec) {
  std::vector<std::unique_ptr<StopRule>> guards;
  guards.push_back(std::make_unique<FiniteGuard>(spec.label));
  guards.push_back(std::make_unique<EnergyGuard>(spec.limits, spec.label));
  guards.push_back(std::make_unique<MaxStepsGuard>(spec.limits.max_steps, spec.label));
  return guards;
}

}  // namespace

void add_limit_options(CLI::App* cmd, RunLimits& limits) {
  cmd->add_option("--max-steps", limits.max_steps,
                  "fail a run (each settle, trial, pulse run or cell) still going after N steps")
      ->check(CLI::PositiveNumber);
}

void LoadProgram::apply(Simulation& sim) const {
  const double t = sim.ctx.time + sim.ctx.load_lead - start;
  const double g = gravity_ramp > 0.0 ? gravity * std::min(1.0, t / gravity_ramp) : gravity;
  const double l = lambda_ramp > 0.0 ? lambda * std::min(1.0, t / lambda_ramp) : lambda;
  double ax = l * gravity;
  if (signal) ax -= signal->acceleration(sim.ctx.time + sim.ctx.load_lead - signal_start);
  sim.ctx.body_ax = ax;
  sim.ctx.body_ay = -g;
}

std::vector<MotionExtent> motions_since(const Model& model, const std::vector<BlockMotion>& base) {
  const std::vector<BlockMotion> now = block_motions(model);
  std::vector<MotionExtent> m(now.size());
  for (size_t b = 0; b < now.size(); ++b) {
    if (model.blocks[b].fixed) continue;
    m[b] = {std::hypot(now[b].ux - base[b].ux, now[b].uy - base[b].uy),
            std::abs(now[b].rotation - base[b].rotation)};
  }
  return m;
}

MotionExtent largest_of(const std::vector<MotionExtent>& blocks) {
  MotionExtent m;
  for (const MotionExtent& b : blocks) {
    m.displacement = std::max(m.displacement, b.displacement);
    m.rotation = std::max(m.rotation, b.rotation);
  }
  return m;
}

std::optional<Verdict> CollapseRule::check(const Probe& p) {
  if (p.motion.displacement > d_) return Verdict{true, d_reason_};
  if (p.motion.rotation > rot_) return Verdict{true, rot_reason_};
  return std::nullopt;
}

std::optional<Verdict> RestRule::check(const Probe& p) {
  if (p.time < from_) return std::nullopt;
  // Kinetic energy below a millionth of the free mass's at the rest speed counts as none: at
  // rest a structure's kinetic energy is round-off of its contact forces, 0 after a kinetic-
  // damping reset and 1e-22 J the next step, which would read as growing.
  if (kinetic_floor_ < 0.0)
    kinetic_floor_ = 0.5 * free_mass(p.sim.model) * 1e-6 * v_rest_ * v_rest_;
  const double kinetic = p.sim.ledger.kinetic > kinetic_floor_ ? p.sim.ledger.kinetic : 0.0;
  const bool still = detector_.update(p.time, p.speed, kinetic);
  // A refused rest is retried at the next sample: the speed window stays open.
  if (creep_) creep_->add(p.time, std::max(p.motion.displacement / d_, p.motion.rotation / rot_));
  if (still && !(creep_ && creep_->creeping())) return Verdict{false, "rest"};
  if (creep_ && going_back(p)) return Verdict{false, "rest"};
  return std::nullopt;
}

bool RestRule::going_back(const Probe& p) {
  if (!p.blocks || !detector_.slow()) {
    blocks_.clear();
    return false;
  }
  BlockSample sample{p.time, std::vector<double>(p.blocks->size())};
  for (std::size_t b = 0; b < sample.measure.size(); ++b)
    sample.measure[b] = std::max((*p.blocks)[b].displacement / d_, (*p.blocks)[b].rotation / rot_);
  blocks_.push_back(std::move(sample));
  // Keep one sample at or before the start of the window.
  while (blocks_.size() > 2 && blocks_[1].t <= p.time - hold_) blocks_.pop_front();
  if (!detector_.slow_for_hold(p.time) || p.time - blocks_.front().t < hold_ * (1.0 - 1e-9))
    return false;
  const std::vector<double>& first = blocks_.front().measure;
  const std::vector<double>& last = blocks_.back().measure;
  for (std::size_t b = 0; b < last.size(); ++b)
    if (last[b] > first[b]) return false;
  return true;
}

std::optional<Verdict> TrendRule::check(const Probe& p) {
  if (p.time >= measure_from_)
    measure_.push_back(std::max(p.motion.displacement / d_, p.motion.rotation / rot_));
  if (p.time < from_ || p.time < limit_ || measure_.empty()) return std::nullopt;
  const size_t cut = measure_.size() * 2 / 3;
  const double earlier = *std::max_element(measure_.begin(), measure_.begin() + cut + 1);
  return Verdict{measure_.back() > 1.1 * earlier, "timeout"};
}

Outcome run_engine(Simulation& sim, RunSpec& spec) {
  using clock = std::chrono::steady_clock;
  const auto wall0 = clock::now();
  const double dt = sim.ctx.dt;
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    std::ostringstream msg;
    msg << spec.label << ": cannot run with a time step of " << dt << " s";
    throw RunError(msg.str());
  }
  const double t_start = sim.ctx.time;
  const long long step_start = sim.step;
  const long long origin = spec.sample_origin >= 0 ? spec.sample_origin : step_start;
  const long long every =
      std::max(1LL, static_cast<long long>(std::llround(std::min(spec.sample_every / dt, 1e15))));
  const std::vector<BlockMotion> base =
      spec.track_motion && spec.motion_base.empty() ? block_motions(sim.model) : spec.motion_base;
  std::vector<std::unique_ptr<StopRule>> guards = make_guards(spec);
  ProgressTicker ticker(spec.quiet);
  double next_progress = spec.progress_period;

  Outcome out;
  auto clock_probe = [&] {  // time and steps only: what the guards read
    Probe p(sim);
    p.time = sim.ctx.time - t_start;
    p.steps = sim.step - step_start;
    return p;
  };
  std::vector<MotionExtent> blocks;  // each block's motion at the sample
  auto probe_now = [&] {
    Probe p = clock_probe();
    if (spec.track_motion) {
      blocks = motions_since(sim.model, base);
      p.motion = largest_of(blocks);
      p.blocks = &blocks;
    }
    p.speed = max_free_speed(sim.model.nodes);
    return p;
  };
  sync_rigid_nodes(sim.model);
  const NscdStats solver_start = sim.nscd_stats;
  if (spec.sample_at_start && spec.on_sample && !spec.on_sample(sim, probe_now())) {
    out.steps = 0;
    out.wall_s = seconds_since(wall0);
    return out;
  }
  for (;;) {
    throw_if_stopped();
    if (spec.end_step >= 0 && sim.step >= spec.end_step) break;
    if (!(sim.ctx.time - t_start < spec.end_time)) break;
    if (spec.loads) spec.loads->apply(sim);
    {
      // The ledger is read at samples and at the end: the joints' energy is wanted there.
      const long long next = sim.step + 1;
      sim.ctx.contact_energy = (next - origin) % every == 0 ||
                               (spec.end_step >= 0 && next >= spec.end_step) ||
                               !(sim.ctx.time + 2.0 * dt - t_start < spec.end_time);
    }
    advance(sim);
    StepInfo info;
    info.last = spec.end_step >= 0 && sim.step == spec.end_step;
    info.sample = (sim.step - origin) % every == 0;
    const bool ends = info.last || !(sim.ctx.time - t_start < spec.end_time);
    // Rigid blocks' nodes follow their bodies where something reads them: samples and ends.
    if (info.sample || ends) sync_rigid_nodes(sim.model);
    if (spec.on_step) spec.on_step(sim, info);
    if (!info.sample && !(info.last && spec.sample_last)) {
      // The last step of a run that ends off the sample grid is still guarded, and so is the
      // step that reaches --max-steps (a sample may lie far beyond it at a tiny step).
      if (ends || (spec.limits.max_steps > 0 && sim.step - step_start >= spec.limits.max_steps))
        for (auto& g : guards) g->check(clock_probe());
      continue;
    }
    for (auto& g : guards) g->check(clock_probe());
    const Probe p = probe_now();
    out.sample_time = p.time;
    out.motion = p.motion;
    out.peak_motion.displacement = std::max(out.peak_motion.displacement, p.motion.displacement);
    out.peak_motion.rotation = std::max(out.peak_motion.rotation, p.motion.rotation);
    const bool go_on = spec.on_sample ? spec.on_sample(sim, p) : true;
    if (!out.decided)
      for (auto& rule : spec.rules)
        if (const std::optional<Verdict> v = rule->check(p)) {
          out.decided = true;
          out.collapsed = v->collapsed;
          out.reason = v->reason;
          out.decided_at = p.time;
          break;
        }
    if (!spec.quiet && spec.progress && ticker.wall() >= next_progress) {
      next_progress += spec.progress_period;
      spec.progress(p, ticker.wall());
    }
    if (!go_on || (out.decided && p.time >= spec.min_time)) break;
  }
  sync_rigid_nodes(sim.model);
  sim.ctx.contact_energy = true;
  note_solver_runs(sim.nscd_stats, solver_start);
  out.time = sim.ctx.time - t_start;
  out.steps = sim.step - step_start;
  out.wall_s = seconds_since(wall0);
  return out;
}

void check_finite(const Simulation& sim, const std::string& label) {
  const Nodes& n = sim.model.nodes;
  for (Index i = 0; i < n.size(); ++i) {
    const char* what = non_finite_quantity(n, i);
    if (!what) continue;
    throw RunError(std::string("non-finite ") + what + " " + where(sim, i, label) +
                   " (the time step may be too large for the contact penalty; try a smaller "
                   "solver.dt_safety)");
  }
  const EnergyLedger& l = sim.ledger;
  const std::pair<const char*, double> energies[] = {
      {"kinetic energy", l.kinetic},
      {"strain energy", l.strain},
      {"contact energy", l.contact},
      {"external work", l.external_work},
      {"damping dissipation", l.damping_dissipated},
      {"friction dissipation", l.friction_dissipated},
      {"impact dissipation", l.impact_dissipated},
      {"local damping dissipation", l.local_dissipated},
      {"peak energy", l.max_energy}};
  for (const auto& [name, e] : energies) {
    if (std::isfinite(e)) continue;
    throw RunError(std::string("non-finite ") + name + " " + where(sim, fastest_node(n), label) +
                   " (the fastest node; the loads or the material may be out of range)");
  }
}

void check_energy_balance(const Simulation& sim, double limit, const std::string& label) {
  const double err = sim.ledger.balance_error();
  if (!(err > limit)) return;
  const EnergyLedger& l = sim.ledger;
  std::ostringstream msg;
  msg << "energy balance error " << err << " above the limit " << limit << " "
      << where(sim, fastest_node(sim.model.nodes), label) << " (the fastest node): external work "
      << l.external_work << " J, kinetic " << l.kinetic << " J, strain " << l.strain
      << " J, contact " << l.contact << " J, dissipated " << l.dissipated()
      << " J (the time step may be too large; try a smaller solver.dt_safety)";
  throw RunError(msg.str());
}

}  // namespace voussoir

#include "drivers/capacity.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "drivers/run.hpp"
#include "drivers/setup.hpp"

namespace voussoir {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Largest speed of any free node [m/s].
double max_free_speed(const Nodes& n) {
  double v2 = 0.0;
  for (Index i = 0; i < n.size(); ++i)
    if (n.inv_mass[i] != 0.0) v2 = std::max(v2, n.vx[i] * n.vx[i] + n.vy[i] * n.vy[i]);
  return std::sqrt(v2);
}

double reference_length(const Model& model) {
  double a = std::numeric_limits<double>::infinity();
  for (const Block& b : model.blocks)
    if (!b.fixed) a = std::min(a, b.area);
  return std::isfinite(a) ? std::sqrt(a) : 1.0;
}

// Samples are taken every kSampleTime of simulated time: the criteria need no finer reading
// and a sample costs a pass over the nodes.
constexpr double kSampleTime = 1e-3;  // [s]

// Hinge thresholds for reports: a joint is open when its gap exceeds 1% of L_ref, sliding
// when its slip exceeds 1% of L_ref.
constexpr double kHingeFraction = 0.01;

}  // namespace

SettledState settle(const Config& config, const TrialCriteria& crit, bool quiet) {
  const auto t0 = Clock::now();
  SettledState s;
  s.sim = make_simulation(config);
  s.gravity = config.load.gravity;
  s.l_ref = reference_length(s.sim.model);
  Simulation& sim = s.sim;
  const double dt = sim.ctx.dt;
  const long long every = std::max(1LL, std::llround(kSampleTime / dt));
  const double v_rest = crit.rest_speed * std::sqrt(std::max(s.gravity, 1e-12) * s.l_ref);
  double rest_since = -1.0;
  while (sim.ctx.time < crit.settle_max_time) {
    const double ramp = std::min(1.0, sim.ctx.time / crit.ramp_time);
    set_static_load(sim, s.gravity * ramp, 0.0);
    advance(sim);
    if (sim.step % every != 0) continue;
    check_finite(sim);
    if (sim.ctx.time < crit.ramp_time) continue;
    if (max_free_speed(sim.model.nodes) < v_rest) {
      if (rest_since < 0.0) rest_since = sim.ctx.time;
      if (sim.ctx.time - rest_since >= crit.hold_time) {
        s.settled = true;
        break;
      }
    } else {
      rest_since = -1.0;
    }
  }
  set_static_load(sim, s.gravity, 0.0);
  s.settle_time = sim.ctx.time;
  s.steps = sim.step;
  s.wall_s = seconds_since(t0);
  if (!quiet)
    std::fprintf(stderr, "settled under gravity: %s after %.3f s (%lld steps, %.2f s wall)\n",
                 s.settled ? "at rest" : "NOT at rest", s.settle_time, s.steps, s.wall_s);
  return s;
}

TrialResult run_trial(const SettledState& settled, double lambda, const TrialCriteria& crit) {
  const auto t0 = Clock::now();
  Simulation sim = settled.sim;  // deep copy
  const double g = settled.gravity;
  const double t_start = sim.ctx.time;
  const long long step_start = sim.step;
  const long long every = std::max(1LL, std::llround(kSampleTime / sim.ctx.dt));
  const double v_rest = crit.rest_speed * std::sqrt(std::max(g, 1e-12) * settled.l_ref);
  const double d_collapse = crit.collapse_displacement * settled.l_ref;
  // Motions are measured from the settled state: re-reference the block centroids there.
  const std::vector<BlockMotion> base = block_motions(sim.model);

  TrialResult r;
  r.lambda = lambda;
  double rest_since = -1.0;
  // Motion measure m(t) = max over blocks of max(d / d_collapse, |rotation| / rot_collapse)
  // (1 = collapse) sampled in time, for the timeout decision.
  std::vector<double> measure;
  bool decided = false;
  while (!decided) {
    const double t = sim.ctx.time - t_start;
    set_static_load(sim, g, lambda * std::min(1.0, t / crit.ramp_time));
    advance(sim);
    if ((sim.step - step_start) % every != 0) continue;
    check_finite(sim);
    const double elapsed = sim.ctx.time - t_start;
    const std::vector<BlockMotion> now = block_motions(sim.model);
    double dmax = 0.0, rmax = 0.0;
    for (size_t b = 0; b < now.size(); ++b) {
      if (sim.model.blocks[b].fixed) continue;
      dmax = std::max(dmax, std::hypot(now[b].ux - base[b].ux, now[b].uy - base[b].uy));
      rmax = std::max(rmax, std::abs(now[b].rotation - base[b].rotation));
    }
    r.max_displacement = dmax;
    r.max_rotation = rmax;
    measure.push_back(std::max(dmax / d_collapse, rmax / crit.collapse_rotation));
    if (dmax > d_collapse || rmax > crit.collapse_rotation) {
      r.collapsed = true;
      r.reason = dmax > d_collapse ? "displacement" : "rotation";
      decided = true;
    } else if (elapsed >= crit.ramp_time) {
      const double v = max_free_speed(sim.model.nodes);
      if (v < v_rest) {
        if (rest_since < 0.0) rest_since = elapsed;
        if (elapsed - rest_since >= crit.hold_time) {
          r.reason = "rest";
          decided = true;
        }
      } else {
        rest_since = -1.0;
      }
      if (!decided && elapsed >= crit.max_time) {
        // Near lambda* the restoring stiffness of the mechanism vanishes, so motion decays
        // ever more slowly (critical slowing down) and neither criterion fires. Decide by the
        // trend: collapsed when the motion measure now exceeds by 10% its largest value over
        // the first two thirds of the trial (a mechanism that keeps opening), stable when it
        // stays bounded (an oscillation about a displaced equilibrium).
        const size_t cut = measure.size() * 2 / 3;
        const double earlier = *std::max_element(measure.begin(), measure.begin() + cut + 1);
        r.collapsed = measure.back() > 1.1 * earlier;
        r.reason = "timeout";
        decided = true;
      }
    }
  }
  r.sim_time = sim.ctx.time - t_start;
  r.steps = sim.step - step_start;
  r.energy_balance_error = sim.ledger.balance_error();
  if (r.collapsed) {
    const double tol = kHingeFraction * settled.l_ref;
    r.hinges = find_hinges(sim.model, tol, tol);
  }
  r.wall_s = seconds_since(t0);
  return r;
}

namespace {

// Runs the given lambdas (in parallel when cores allow) and returns results in input order.
std::vector<TrialResult> run_round(const SettledState& s, const std::vector<double>& lambdas,
                                   const TrialCriteria& crit) {
  std::vector<TrialResult> out(lambdas.size());
  const int n = static_cast<int>(lambdas.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(std::min(n, omp_get_max_threads()))
  for (int i = 0; i < n; ++i) out[i] = run_trial(s, lambdas[i], crit);
  return out;
}

void report(const TrialResult& r, bool quiet) {
  if (quiet) return;
  std::fprintf(stderr, "  lambda = %.5f  %-9s (%s, %.3f s simulated, %lld steps, %.2f s wall)\n",
               r.lambda, r.collapsed ? "collapsed" : "stable", r.reason.c_str(), r.sim_time,
               r.steps, r.wall_s);
}

}  // namespace

CapacityResult find_capacity(const Config& config, const TrialCriteria& crit, int points,
                             bool quiet) {
  const auto t0 = Clock::now();
  CapacityResult res;
  res.tolerance = config.capacity.tolerance;
  points = std::max(1, points);
  const SettledState settled = settle(config, crit, quiet);
  res.triangles = settled.sim.model.tris.size();
  res.dt = settled.sim.ctx.dt;
  if (!settled.settled)
    throw RunError("the structure does not come to rest under gravity alone within " +
                   std::to_string(crit.settle_max_time) +
                   " s: it has no gravity capacity (lambda* = 0) or needs a longer settle");

  double lo = config.capacity.lambda_min, hi = config.capacity.lambda_max;
  const TrialResult* hinge_source = nullptr;
  auto record = [&](const std::vector<TrialResult>& round) {
    for (const TrialResult& r : round) {
      report(r, quiet);
      res.trials.push_back(r);
    }
  };

  // Bracket: a given upper bound is checked; otherwise lambdas grow geometrically from
  // 0.125 until one collapses (cap 8: beyond that the structure is not a masonry mechanism).
  constexpr double kFirstGuess = 0.125, kCap = 8.0;
  bool have_hi = false;
  if (hi > lo) {
    const auto round = run_round(settled, {hi}, crit);
    record(round);
    have_hi = round[0].collapsed;
    if (!have_hi) lo = hi;
  }
  double next = std::max(kFirstGuess, 2.0 * lo);
  while (!have_hi && next <= kCap) {
    std::vector<double> lambdas;
    for (int i = 0; i < points && next <= kCap; ++i, next *= 2.0) lambdas.push_back(next);
    const auto round = run_round(settled, lambdas, crit);
    record(round);
    for (const TrialResult& r : round) {
      if (r.collapsed) {
        hi = r.lambda;
        have_hi = true;
        break;
      }
      lo = std::max(lo, r.lambda);
    }
  }
  res.bracketed = have_hi;
  if (!have_hi) {
    res.lo = lo;
    res.hi = lo;
    res.lambda_star = lo;
    res.wall_s = seconds_since(t0);
    return res;
  }

  // k-section: `points` interior lambdas per round.
  while (hi - lo > res.tolerance * hi) {
    std::vector<double> lambdas;
    for (int i = 1; i <= points; ++i) lambdas.push_back(lo + (hi - lo) * i / (points + 1));
    const auto round = run_round(settled, lambdas, crit);
    record(round);
    // The lowest collapse is the new upper bound and the highest stable trial below it the
    // new lower bound (a stable trial above a collapsed one, a non-monotone response near the
    // threshold, is ignored).
    for (const TrialResult& r : round)
      if (r.collapsed) hi = std::min(hi, r.lambda);
    for (const TrialResult& r : round)
      if (!r.collapsed && r.lambda < hi) lo = std::max(lo, r.lambda);
    if (!quiet) std::fprintf(stderr, "bracket [%.5f, %.5f]\n", lo, hi);
  }
  for (const TrialResult& r : res.trials)
    if (r.collapsed && r.lambda == hi) hinge_source = &r;
  if (hinge_source) res.hinges = hinge_source->hinges;
  res.lo = lo;
  res.hi = hi;
  res.lambda_star = 0.5 * (lo + hi);
  res.wall_s = seconds_since(t0);
  return res;
}

}  // namespace voussoir

#include "drivers/pushover.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <utility>

#include "drivers/commands.hpp"
#include "drivers/motion.hpp"
#include "drivers/setup.hpp"
#include "drivers/trial.hpp"
#include "limit/interfaces.hpp"
#include "limit/limit_analysis.hpp"

namespace voussoir {
namespace {

using Clock = std::chrono::steady_clock;

// x of block b's centroid now [m]: the body's for a rigid block, the nodes' mass centre for an
// elastic one (O(nodes of the block), read every step).
double centroid_x(const Model& m, int b) {
  if (m.is_rigid()) return m.rigid.cx0[b] + m.rigid.ux[b];
  const Block& blk = m.blocks[b];
  double mx = 0.0, mass = 0.0;
  for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i) {
    mx += m.nodes.mass[i] * m.nodes.x[i];
    mass += m.nodes.mass[i];
  }
  return mx / mass;
}

// Block b's reference centroid (its outline's) [m].
Vec2 reference_centroid(const Model& m, int b) {
  Vec2 c;
  polygon_centroid(m.blocks[std::size_t(b)].polygon, &c);
  return c;
}

// Sum over the free blocks of mass x centroid x [kg m] (true masses: the load's).
double mass_moment_x(const Model& m) {
  double s = 0.0;
  if (m.is_rigid()) {
    const RigidBodies& r = m.rigid;
    for (std::size_t b = 0; b < m.blocks.size(); ++b)
      if (!m.blocks[b].fixed) s += r.load_mass[b] * (r.cx0[b] + r.ux[b]);
    return s;
  }
  for (Index i = 0; i < m.nodes.size(); ++i)
    if (m.nodes.inv_mass[i] != 0.0) s += m.nodes.mass[i] * m.nodes.x[i];
  return s;
}

}  // namespace

int default_control_block(const Model& m) {
  const bool arch = std::any_of(m.blocks.begin(), m.blocks.end(),
                                [](const Block& b) { return !b.fixed && b.role == "voussoir"; });
  double xlo = std::numeric_limits<double>::infinity(), xhi = -xlo;
  for (const Block& b : m.blocks)
    if (!b.fixed)
      for (const Vec2& p : b.polygon) xlo = std::min(xlo, p.x), xhi = std::max(xhi, p.x);
  const double mid = 0.5 * (xlo + xhi);
  int best = -1;
  Vec2 cb{};
  for (int b = 0; b < static_cast<int>(m.blocks.size()); ++b) {
    const Block& blk = m.blocks[b];
    if (blk.fixed || (arch && blk.role != "voussoir")) continue;
    const Vec2 c = reference_centroid(m, b);
    // Equal heights to a part in 1e9 of the span are a tie (mirror blocks).
    const double tie = 1e-9 * (xhi - xlo);
    if (best < 0 || c.y > cb.y + tie ||
        (std::abs(c.y - cb.y) <= tie && std::abs(c.x - mid) < std::abs(cb.x - mid) - tie)) {
      best = b;
      cb = c;
    }
  }
  return best;
}

void validate_pushover(const Model& m, const PushoverSettings& s) {
  const int n = static_cast<int>(m.blocks.size());
  if (s.control != -1) {
    if (s.control < 0 || s.control >= n)
      throw DeckError("--control " + std::to_string(s.control) + ": no such block (the blocks " +
                      "are numbered 0 to " + std::to_string(n - 1) + "; see check --mesh-out)");
    if (m.blocks[s.control].fixed)
      throw DeckError("--control " + std::to_string(s.control) + ": block " +
                      std::to_string(s.control) + " is fixed (a support); the control block " +
                      "must be a free block");
  }
  auto positive = [](const char* option, double v) {
    if (!(v > 0.0) || !std::isfinite(v))
      throw DeckError(std::string(option) + " " + option_number(v) + ": must be a positive finite number");
  };
  // NaN: not given, the default.
  if (!std::isnan(s.rate)) positive("--rate", s.rate);
  if (!std::isnan(s.max_displacement)) positive("--max-displacement", s.max_displacement);
  if (!std::isnan(s.servo)) positive("--servo", s.servo);
  if (s.direction != 1.0 && s.direction != -1.0)
    throw DeckError("--direction " + option_number(s.direction) + ": must be +x or -x");
}

Sdof equivalent_sdof(const std::vector<double>& weights, const std::vector<double>& dx, int control,
                     const std::vector<PushoverPoint>& curve, double gravity, bool reached_zero,
                     double ultimate) {
  Sdof s;
  double sum_p = 0.0, sum_pd = 0.0, sum_pd2 = 0.0;
  for (std::size_t i = 0; i < weights.size(); ++i) {
    sum_p += weights[i];
    sum_pd += weights[i] * dx[i];
    sum_pd2 += weights[i] * dx[i] * dx[i];
  }
  if (!(sum_pd2 > 0.0) || !(sum_p > 0.0) || !(std::abs(dx[control]) > 0.0)) return s;
  s.valid = true;
  s.dx = dx;
  s.participating_mass = sum_pd * sum_pd / (gravity * sum_pd2);
  s.participating_mass_ratio = gravity * s.participating_mass / sum_p;
  s.factor = sum_pd2 / (dx[control] * sum_pd);
  for (const PushoverPoint& p : curve) {
    s.d_star.push_back(p.displacement * s.factor);
    s.a_star.push_back(p.lambda * gravity / s.participating_mass_ratio);
  }
  if (reached_zero) {
    s.d_star_0 = ultimate * s.factor;
    s.d_star_u = 0.4 * s.d_star_0;
  }
  return s;
}

PushoverResult run_pushover(const Config& config, const PushoverSettings& given, bool quiet) {
  const auto t0 = Clock::now();
  PushoverSettings set = given;
  PushoverResult r;
  // Limit analysis of the same blocks (towards -x: of their mirror image): lambda_ref for the
  // servo stiffness, and whether the mechanism slides. On the model as built; with [supports],
  // on the blocks where the support movement leaves them (limit_of_settled, as `capacity`).
  auto read_limit = [&](const LimitResult& la) {
    r.lambda_ref = 1.0;
    r.lambda_ref_from = "none (1)";
    bool slides = false;
    if (la.status == "optimal" && la.lambda_la > 0.0 && std::isfinite(la.lambda_la)) {
      r.lambda_ref = la.lambda_la;
      r.lambda_ref_from = "limit analysis";
      for (const MechanismJoint& j : la.mechanism) slides = slides || j.kind == "sliding";
    }
    return slides;
  };
  bool slides = false;
  {
    // The settings are checked on the model before the settle (exit 2 at once).
    const Simulation probe = make_simulation(config);
    validate_pushover(probe.model, set);
    slides = read_limit(limit_analysis(set.direction < 0.0 ? mirror_x(probe.model) : probe.model,
                                       config.contact.friction, config.load.gravity, false));
  }
  // The technique (header comment): quasi-static unless the mechanism slides.
  auto choose = [&](bool slide) {
    if (set.technique == "auto") {
      set.criteria.quasi_static = !slide;
      r.technique = slide ? "physical: the limit-analysis mechanism slides"
                          : "quasi-static: the limit-analysis mechanism does not slide";
    } else {
      set.criteria.quasi_static = set.technique == "quasi-static";
      r.technique = set.technique + " (asked)";
    }
  };
  choose(slides);
  SettledState settled = settle(config, set.criteria, quiet);
  if (!settled.settled) throw RunError(unsettled_message(settled, set.criteria));
  if (!config.supports.moves.empty()) {
    // The moved structure decides; a technique it changes is settled and moved again under it.
    const bool moved_slides =
        read_limit(limit_of_settled(settled, config.contact.friction, set.direction));
    if (moved_slides != slides && set.technique == "auto") {
      choose(moved_slides);
      settled = settle(config, set.criteria, quiet);
      if (!settled.settled) throw RunError(unsettled_message(settled, set.criteria));
      read_limit(limit_of_settled(settled, config.contact.friction, set.direction));
    }
  }

  r.settle_wall_s = settled.wall_s;
  r.quasi_static = set.criteria.quasi_static;
  Simulation sim = settled.sim;
  Model& model = sim.model;
  const double g = settled.gravity;
  const double l_ref = settled.l_ref;
  r.control = set.control >= 0 ? set.control : default_control_block(model);
  if (r.control < 0) throw DeckError("pushover: the model has no free block to control");
  r.control_point = reference_centroid(model, r.control);
  r.direction = set.direction;
  r.dt = sim.ctx.dt;
  r.gravity = g;
  r.servo = !std::isnan(set.servo) ? set.servo : kServoFactor * r.lambda_ref / l_ref;
  r.rate = !std::isnan(set.rate) ? set.rate : kRateFactor * std::sqrt(std::max(g, 1e-12) * l_ref);
  r.max_displacement = !std::isnan(set.max_displacement)
                           ? set.max_displacement
                           : kMaxDisplacementFraction * free_extent(model).height;
  // The quasi-static run: local damping as the settle, no kinetic damping (header comment).
  sim.ctx.kinetic_damping = 0.0;

  const int k = r.control;
  const double dir = set.direction;
  const double x_start = centroid_x(model, k);
  const double t_start = sim.ctx.time;
  const double servo = r.servo, rate = r.rate;
  double lambda = 0.0, target = 0.0;
  bool fast = true;
  // The fast rise ramps lambda_ref on no faster than the capacity trials' ramp.
  const double fast_rate =
      std::max(rate, std::min(kFastRate * rate, r.lambda_ref / (servo * set.criteria.ramp_time)));
  auto displacement = [&]() { return dir * (centroid_x(model, k) - x_start); };
  set_static_load(sim, g, 0.0);
  double total_mass = 0.0;
  for (const Block& b : model.blocks)
    if (!b.fixed) total_mass += b.mass;

  // The open window of the quasi-static load factor (header comment): its start, and the work
  // of the horizontal load over it.
  struct Window {
    double d = 0.0, lambda = 0.0, s = 0.0, rate_energy = 0.0, time = 0.0;
    double work = 0.0, lambda_sum = 0.0;
    long long steps = 0;
  };
  const double d_window = kWindowDisplacement * l_ref;
  const double lambda_window = kWindowLambda * r.lambda_ref;
  auto rate_energy = [](const EnergyLedger& e) {
    return e.kinetic + e.local_dissipated + e.damping_dissipated + e.impact_dissipated;
  };
  double s_prev = dir * mass_moment_x(model);
  Window win{0.0, 0.0, s_prev, rate_energy(sim.ledger), 0.0};
  r.curve.push_back({0.0, 0.0, 0.0, 0.0, true});

  // Per sample: each free block's horizontal centroid displacement (the mechanism of the SDOF
  // curve) and the time.
  const std::vector<BlockMotion> base = block_motions(model);
  std::vector<std::vector<double>> ux;
  std::vector<double> sample_time;
  std::set<int> seen;
  const double tol = kHingeFraction * l_ref;
  double peak_lambda = 0.0;
  std::size_t peak_point = 0;
  // Indices of the quasi-static windows in r.curve (the first point, at rest, is one).
  std::vector<std::size_t> qs_points = {0};
  bool grab_peak = false, stop = false;
  std::size_t peak_sample = 0;

  std::string ended = "time limit";
  RunSpec spec;
  spec.label = "the pushover";
  spec.limits = set.criteria.limits;
  spec.sample_at_start = true;
  spec.sample_last = true;
  spec.end_time = (r.max_displacement + 2.0 * r.lambda_ref / servo) / rate;
  spec.quiet = quiet;
  spec.on_step = [&](Simulation& sim_now, const StepInfo&) {
    // The step just taken ran under `lambda`; its horizontal load did lambda g dS of work.
    const double s_now = dir * mass_moment_x(sim_now.model);
    win.work += lambda * g * (s_now - s_prev);
    win.lambda_sum += lambda;
    ++win.steps;
    s_prev = s_now;
    const double run_time = sim_now.ctx.time - t_start;
    const double d = displacement();
    const double ds = s_now - win.s;
    // A window in which the masses moved on average less than kWindowMotion of the window's
    // displacement carries too little power to read: it stays open, up to kWindowMaxTime, after
    // which it reads its average load factor.
    const bool moved = std::abs(ds) >= kWindowMotion * total_mass * d_window;
    const bool full = std::abs(d - win.d) >= d_window ||
                      std::abs(lambda - win.lambda) >= lambda_window ||
                      run_time - win.time >= kWindowTime;
    // After the window that ends the run, none more: the engine stops at its next sample.
    if (!stop && ((full && moved) || run_time - win.time >= kWindowMaxTime)) {
      const double e_rate = rate_energy(sim_now.ledger);
      const double lambda_avg = win.lambda_sum / static_cast<double>(win.steps);
      const double lambda_qs =
          moved ? (win.work - (e_rate - win.rate_energy)) / (g * ds) : lambda_avg;
      const bool quasi_static = std::abs(lambda_qs - lambda_avg) <= kDynamicWindow * r.lambda_ref;
      r.curve.push_back({d, lambda_qs, run_time, lambda, quasi_static});
      if (quasi_static) {
        // The peak: the largest median of three consecutive quasi-static windows, at the
        // middle one (one window's spike is not a peak).
        qs_points.push_back(r.curve.size() - 1);
        const std::size_t m = qs_points.size();
        if (m >= 3) {
          const double a = r.curve[qs_points[m - 3]].lambda, b = r.curve[qs_points[m - 2]].lambda;
          const double median = std::max(std::min(a, b), std::min(std::max(a, b), lambda_qs));
          if (median > peak_lambda) {
            peak_lambda = median;
            peak_point = qs_points[m - 2];
            grab_peak = true;
          }
        }
      }
      const bool past_peak = peak_point + 1 < r.curve.size() && peak_lambda > 0.0;
      if (past_peak && quasi_static && lambda_qs <= 0.0) stop = true, ended = "lambda <= 0";
      if (past_peak && quasi_static && set.stop_fraction > 0.0 &&
          lambda_qs <= set.stop_fraction * peak_lambda && !stop)
        stop = true, ended = "fallen to " + option_number(set.stop_fraction) + " x peak";
      win = Window{d, lambda, s_now, e_rate, run_time};
    }
    // The target: fast while lambda is below kFastFraction lambda_ref, at the rate after.
    if (fast && lambda >= kFastFraction * r.lambda_ref) fast = false;
    target += (fast ? fast_rate : rate) * sim_now.ctx.dt;
    lambda = servo * (target - d);
    sim_now.ctx.body_ax = dir * lambda * g;
  };
  spec.on_sample = [&](const Simulation& s, const Probe& p) {
    const double d = displacement();
    r.energy_balance_error = std::max(r.energy_balance_error, s.ledger.balance_error());
    const std::vector<BlockMotion> now = block_motions(s.model);
    std::vector<double> row(now.size());
    for (std::size_t b = 0; b < now.size(); ++b) row[b] = now[b].ux - base[b].ux;
    ux.push_back(std::move(row));
    sample_time.push_back(p.time);
    if (grab_peak) {
      r.at_peak = s.model;
      peak_sample = ux.size() - 1;
      grab_peak = false;
    }
    for (const Hinge& h : find_hinges(s.model, tol, tol))
      if (seen.insert(h.joint).second) r.hinges.push_back({h, d, r.curve[qs_points.back()].lambda});
    if (stop) return false;
    if (d >= r.max_displacement) {
      ended = "max displacement";
      return false;
    }
    return true;
  };
  spec.progress = [&](const Probe& p, double wall) {
    std::fprintf(stderr,
                 "  pushover: %.3f s simulated, d = %.4g m, lambda = %.4f (peak %.4f), %zu "
                 "hinges (%.0f s wall)\n",
                 p.time, displacement(), r.curve.back().lambda, peak_lambda, r.hinges.size(), wall);
  };
  const Outcome o = run_engine(sim, spec);
  r.ended = ended;
  r.sim_time = o.time;
  r.steps = o.steps;
  r.at_end = model;
  if (r.at_peak.blocks.empty()) r.at_peak = model;
  r.hinges_at_end = find_hinges(model, tol, tol);
  r.peak = r.curve[peak_point];
  r.peak.lambda = peak_lambda;
  if (ended == "lambda <= 0") {  // the last two quasi-static windows bracket lambda = 0
    const std::size_t m = qs_points.size();
    const PushoverPoint &a = r.curve[qs_points[m - 2]], &b = r.curve[qs_points[m - 1]];
    r.reached_zero = true;
    r.ultimate_displacement =
        a.lambda > b.lambda
            ? a.displacement + (b.displacement - a.displacement) * a.lambda / (a.lambda - b.lambda)
            : b.displacement;
  }

  // The mechanism at the peak: each centroid's horizontal motion from the peak's sample to the
  // first sample kMechanismWindow of the way to the end (header comment), normalised at the
  // control block.
  const double t_end = sample_time.back();
  const double t_mech =
      sample_time[peak_sample] + kMechanismWindow * (t_end - sample_time[peak_sample]);
  std::size_t w = peak_sample;
  while (w + 1 < sample_time.size() && sample_time[w] < t_mech) ++w;
  std::vector<double> weights(model.blocks.size(), 0.0), dx(model.blocks.size(), 0.0);
  const double dk = ux[w][k] - ux[peak_sample][k];
  for (std::size_t b = 0; b < model.blocks.size(); ++b) {
    if (model.blocks[b].fixed) continue;
    weights[b] = model.blocks[b].mass * g;
    if (dk != 0.0) dx[b] = (ux[w][b] - ux[peak_sample][b]) / dk;
  }
  r.sdof = equivalent_sdof(weights, dx, k, r.curve, g, r.reached_zero, r.ultimate_displacement);
  r.wall_s = seconds_since(t0);
  return r;
}

namespace {

// The block outlines of `m` moved by each block's rigid motion, their reference outlines and
// which are fixed: what scripts/plot_pushover draws.
nlohmann::json outlines_json(const Model& m) {
  nlohmann::json fixed = nlohmann::json::array();
  for (const Block& b : m.blocks) fixed.push_back(b.fixed);
  const MovedOutlines o = moved_outlines(m);
  return {{"blocks", o.moved}, {"reference", o.reference}, {"fixed", fixed}};
}

}  // namespace

nlohmann::json pushover_json(const PushoverResult& r) {
  using nlohmann::json;
  const json none(nullptr);
  json curve = json::array(), dynamic = json::array();
  for (const PushoverPoint& p : r.curve)
    (p.quasi_static ? curve : dynamic)
        .push_back({{"displacement", p.displacement},
                    {"lambda", p.lambda},
                    {"lambda_applied", p.applied},
                    {"time", p.time}});
  json hinges = json::array();
  for (const HingeEvent& e : r.hinges) {
    json h = hinges_to_json({e.hinge})[0];
    h["displacement"] = e.displacement;
    h["lambda"] = e.lambda;
    hinges.push_back(h);
  }
  json sdof = none;
  if (r.sdof.valid) {
    json sc = json::array();
    for (std::size_t i = 0; i < r.sdof.d_star.size(); ++i)
      if (r.curve[i].quasi_static)
        sc.push_back({{"d_star", r.sdof.d_star[i]}, {"a_star", r.sdof.a_star[i]}});
    sdof = {{"participating_mass_ratio", r.sdof.participating_mass_ratio},
            {"participating_mass", r.sdof.participating_mass},
            {"e_star", r.sdof.participating_mass_ratio},
            {"d_star_factor", r.sdof.factor},
            {"a_star_0", r.peak.lambda > 0.0
                             ? json(r.peak.lambda * r.gravity / r.sdof.participating_mass_ratio)
                             : none},
            {"curve", sc},
            {"d_star_0", r.reached_zero ? json(r.sdof.d_star_0) : none},
            {"d_star_u", r.reached_zero ? json(r.sdof.d_star_u) : none},
            {"dx", r.sdof.dx}};
  }
  return {{"curve", curve},
          {"dynamic_windows", dynamic},
          {"peak", {{"lambda", r.peak.lambda}, {"displacement", r.peak.displacement}}},
          {"ultimate_displacement", r.reached_zero ? json(r.ultimate_displacement) : none},
          {"ended", r.ended},
          {"control", {{"block", r.control}, {"point", {r.control_point.x, r.control_point.y}}}},
          {"direction", r.direction > 0.0 ? "+x" : "-x"},
          {"rate", r.rate},
          {"servo", r.servo},
          {"lambda_ref", r.lambda_ref},
          {"lambda_ref_from", r.lambda_ref_from},
          {"max_displacement", r.max_displacement},
          {"quasi_static", r.quasi_static},
          {"technique", r.technique},
          {"sdof", sdof},
          {"hinges", hinges},
          {"energy_balance_error", r.energy_balance_error},
          {"sim_time", r.sim_time},
          {"steps", r.steps},
          {"dt", r.dt},
          {"settle_wall_s", r.settle_wall_s},
          {"wall_s", r.wall_s},
          {"mechanisms", {{"peak", outlines_json(r.at_peak)}, {"end", outlines_json(r.at_end)}}}};
}

}  // namespace voussoir

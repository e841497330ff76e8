// `voussoir pushover DECK`: the capacity curve and its equivalent SDOF curve.

#include "commands/pushover.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "commands/common.hpp"
#include "engine/kinematics.hpp"
#include "engine/motion.hpp"
#include "engine/setup.hpp"
#include "engine/trial.hpp"
#include "io/json.hpp"
#include "io/plot.hpp"
#include "limit/interfaces.hpp"
#include "limit/limit_analysis.hpp"

namespace voussoir {
namespace {

using Clock = std::chrono::steady_clock;

// Block b's reference centroid (its outline's) [m].
Vec2 reference_centroid(const Model& m, int b) {
  Vec2 c;
  polygon_centroid(m.blocks[std::size_t(b)].polygon, &c);
  return c;
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
      throw DeckError(std::string(option) + " " + option_number(v) +
                      ": must be a positive finite number");
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

// The limit analysis of the blocks (towards -x: of their mirror image), the technique it
// decides (header comment) and the settle under it; sets r.lambda_ref, r.lambda_ref_from,
// r.technique and set.criteria.quasi_static.
SettledState settle_for_pushover(const Config& config, PushoverSettings& set, PushoverResult& r,
                                 bool quiet) {
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

  return settled;
}

// The control block and point, the servo, the rate and the largest displacement of the run:
// given, or their defaults.
void size_pushover(PushoverResult& r, const PushoverSettings& set, const Model& model, double g,
                   double l_ref) {
  r.control = set.control >= 0 ? set.control : default_control_block(model);
  if (r.control < 0) throw DeckError("pushover: the model has no free block to control");
  r.control_point = reference_centroid(model, r.control);
  r.direction = set.direction;
  r.gravity = g;
  r.servo = !std::isnan(set.servo) ? set.servo : kServoFactor * r.lambda_ref / l_ref;
  r.rate = !std::isnan(set.rate) ? set.rate : kRateFactor * std::sqrt(std::max(g, 1e-12) * l_ref);
  r.max_displacement = !std::isnan(set.max_displacement)
                           ? set.max_displacement
                           : kMaxDisplacementFraction * free_extent(model).height;
}

// The peak of the curve: the largest median of three consecutive quasi-static windows, at the
// middle one (one window's spike is not a peak).
struct PeakTrack {
  // Indices of the quasi-static windows in the curve (the first point, at rest, is one).
  std::vector<std::size_t> qs_points = {0};
  double lambda = 0.0;    // the peak's load factor
  std::size_t point = 0;  // its window in the curve
  bool grab = false;      // a new peak: its state is to be kept at the next sample
  // Takes the quasi-static window just added to `curve`, at load factor lambda_qs.
  void add(const std::vector<PushoverPoint>& curve, double lambda_qs) {
    qs_points.push_back(curve.size() - 1);
    const std::size_t m = qs_points.size();
    if (m >= 3) {
      const double a = curve[qs_points[m - 3]].lambda, b = curve[qs_points[m - 2]].lambda;
      const double median = std::max(std::min(a, b), std::min(std::max(a, b), lambda_qs));
      if (median > lambda) {
        lambda = median;
        point = qs_points[m - 2];
        grab = true;
      }
    }
  }
};

// The open window of the quasi-static load factor (header comment): its start, and the work
// of the horizontal load over it.
struct Window {
  double d = 0.0, lambda = 0.0, s = 0.0, rate_energy = 0.0, time = 0.0;
  double work = 0.0, lambda_sum = 0.0;
  long long steps = 0;
};

// A run that ended at lambda <= 0: the last two quasi-static windows (`qs_points` in r.curve)
// bracket lambda = 0; the ultimate displacement is interpolated between them.
void read_zero_crossing(PushoverResult& r, const std::vector<std::size_t>& qs_points) {
  const std::size_t m = qs_points.size();
  const PushoverPoint &a = r.curve[qs_points[m - 2]], &b = r.curve[qs_points[m - 1]];
  r.reached_zero = true;
  r.ultimate_displacement =
      a.lambda > b.lambda
          ? a.displacement + (b.displacement - a.displacement) * a.lambda / (a.lambda - b.lambda)
          : b.displacement;
}

// The equivalent SDOF curve of the mechanism at the peak (`ux`: each block's horizontal
// centroid displacement per sample, at `sample_time`).
Sdof peak_sdof(const PushoverResult& r, const Model& model,
               const std::vector<std::vector<double>>& ux, const std::vector<double>& sample_time,
               std::size_t peak_sample, double g) {
  const int k = r.control;
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
  return equivalent_sdof(weights, dx, k, r.curve, g, r.reached_zero, r.ultimate_displacement);
}

PushoverResult run_pushover(const Config& config, const PushoverSettings& given, bool quiet) {
  const auto t0 = Clock::now();
  PushoverSettings set = given;
  PushoverResult r;
  const SettledState settled = settle_for_pushover(config, set, r, quiet);

  r.settle_wall_s = settled.wall_s;
  r.quasi_static = set.criteria.quasi_static;
  Simulation sim = settled.sim;
  Model& model = sim.model;
  const double g = settled.gravity;
  const double l_ref = settled.l_ref;
  size_pushover(r, set, model, g, l_ref);
  r.dt = sim.ctx.dt;
  // The quasi-static run: local damping as the settle, no kinetic damping (header comment).
  sim.ctx.kinetic_damping = 0.0;

  const int k = r.control;
  const double dir = set.direction;
  const double x_start = block_centroid_x(model, k);
  const double t_start = sim.ctx.time;
  const double servo = r.servo, rate = r.rate;
  double lambda = 0.0, target = 0.0;
  bool fast = true;
  // The fast rise ramps lambda_ref on no faster than the capacity trials' ramp.
  const double fast_rate =
      std::max(rate, std::min(kFastRate * rate, r.lambda_ref / (servo * set.criteria.ramp_time)));
  auto displacement = [&]() { return dir * (block_centroid_x(model, k) - x_start); };
  set_static_load(sim, g, 0.0);
  double total_mass = 0.0;
  for (const Block& b : model.blocks)
    if (!b.fixed) total_mass += b.mass;

  const double d_window = kWindowDisplacement * l_ref;
  const double lambda_window = kWindowLambda * r.lambda_ref;
  auto rate_energy = [](const EnergyLedger& e) {
    return e.kinetic + e.local_dissipated + e.damping_dissipated + e.impact_dissipated;
  };
  double s_prev = dir * free_mass_moment_x(model);
  Window win{0.0, 0.0, s_prev, rate_energy(sim.ledger), 0.0};
  r.curve.push_back({0.0, 0.0, 0.0, 0.0, true});

  // Per sample: each free block's horizontal centroid displacement (the mechanism of the SDOF
  // curve) and the time.
  const std::vector<BlockMotion> base = block_motions(model);
  std::vector<std::vector<double>> ux;
  std::vector<double> sample_time;
  std::set<int> seen;
  const double tol = kHingeFraction * l_ref;
  PeakTrack peak;
  double& peak_lambda = peak.lambda;
  std::size_t& peak_point = peak.point;
  std::vector<std::size_t>& qs_points = peak.qs_points;
  bool& grab_peak = peak.grab;
  bool stop = false;
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
    const double s_now = dir * free_mass_moment_x(sim_now.model);
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
      if (quasi_static) peak.add(r.curve, lambda_qs);
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
  if (ended == "lambda <= 0") read_zero_crossing(r, qs_points);

  r.sdof = peak_sdof(r, model, ux, sample_time, peak_sample, g);
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

namespace voussoir {
namespace {

void print_pushover(const PushoverResult& r, const std::string& deck) {
  std::printf("pushover of %s towards %s: control block %d, centroid (%.4f, %.4f)\n", deck.c_str(),
              r.direction > 0.0 ? "+x" : "-x", r.control, r.control_point.x, r.control_point.y);
  std::printf("peak lambda = %.4f at d = %.4g m\n", r.peak.lambda, r.peak.displacement);
  if (r.reached_zero)
    std::printf("ultimate displacement d0 = %.4g m (lambda falls to 0)\n", r.ultimate_displacement);
  else
    std::printf("lambda did not fall to 0: ended at %s, d = %.4g m, lambda = %.4f\n",
                r.ended.c_str(), r.curve.back().displacement, r.curve.back().lambda);
  if (r.sdof.valid) {
    std::printf("equivalent SDOF: e* = %.4f, M* = %.4g kg, a*0 = %.4g m/s2",
                r.sdof.participating_mass_ratio, r.sdof.participating_mass,
                r.peak.lambda * r.gravity / r.sdof.participating_mass_ratio);
    if (r.reached_zero)
      std::printf(", d*0 = %.4g m, d*u = %.4g m", r.sdof.d_star_0, r.sdof.d_star_u);
    std::printf("\n");
  }
  for (const HingeEvent& e : r.hinges) {
    const Hinge& h = e.hinge;
    std::printf("  %-7s joint %d (blocks %d-%d)", h.kind.c_str(), h.joint, h.block_a, h.block_b);
    if (std::isfinite(h.position_deg)) std::printf(" at %.1f deg", h.position_deg);
    if (!h.side.empty()) std::printf(", pivot at %s", h.side.c_str());
    std::printf(": opened at d = %.4g m, lambda = %.4f\n", e.displacement, e.lambda);
  }
  std::printf("technique: %s\n", r.technique.c_str());
  std::printf(
      "%zu points, %.3f s simulated in %lld steps, servo K = %.4g /m, rate %.4g m/s, "
      "energy balance error %.2g, %.1f s wall\n",
      r.curve.size(), r.sim_time, r.steps, r.servo, r.rate, r.energy_balance_error, r.wall_s);
}

void write_csv(const PushoverResult& r, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw OutputError(path + ": cannot write the pushover CSV");
  out.precision(9);
  out << "displacement,lambda,time,d_star,a_star\n";
  for (std::size_t i = 0; i < r.curve.size(); ++i) {
    const PushoverPoint& p = r.curve[i];
    if (!p.quasi_static) continue;  // a snap's window: in the JSON's "dynamic_windows"
    out << p.displacement << "," << p.lambda << "," << p.time << ",";
    if (r.sdof.valid)
      out << r.sdof.d_star[i] << "," << r.sdof.a_star[i];
    else
      out << ",";
    out << "\n";
  }
  if (!out) throw OutputError(path + ": cannot write the pushover CSV");
}

}  // namespace

int command_pushover(const Config& config, const CommonOptions& common,
                     const PushoverOptions& opts) {
  if (opts.direction != "+x" && opts.direction != "-x")
    throw DeckError("--direction " + opts.direction + ": must be +x or -x");
  PushoverSettings set;
  set.control = opts.control;
  set.direction = opts.direction == "-x" ? -1.0 : 1.0;
  set.rate = opts.rate;
  set.max_displacement = opts.max_displacement;
  set.servo = opts.servo;
  if (!(opts.stop_at >= 0.0 && opts.stop_at < 1.0)) {
    char v[32];
    std::snprintf(v, sizeof v, "%g", opts.stop_at);
    throw DeckError(std::string("--stop-at ") + v +
                    ": must be at least 0 and below 1 (a fraction of the peak)");
  }
  set.stop_fraction = opts.stop_at;
  if (opts.dynamic && opts.quasi_static)
    throw DeckError(
        "--dynamic and --quasi-static: give one of them, or neither (the default "
        "chooses by the limit-analysis mechanism)");
  set.technique = opts.dynamic ? "dynamic" : opts.quasi_static ? "quasi-static" : "auto";
  set.criteria.settle_max_time = opts.settle_time;
  set.criteria.limits = common.limits;
  const PushoverResult r = run_pushover(config, set, common.quiet);
  print_pushover(r, config.deck_path);

  const nlohmann::json j = pushover_json(r);
  if (!common.json_path.empty()) write_json(j, common.json_path);
  if (!opts.csv.empty()) write_csv(r, opts.csv);
  if (!opts.plot.empty()) {
    const std::string tmp = opts.plot + ".pushover.json";
    write_json(j, tmp);
    char title[200];
    std::snprintf(title, sizeof title, "%s towards %s, control block %d",
                  std::filesystem::path(config.deck_path).stem().c_str(),
                  r.direction > 0.0 ? "+x" : "-x", r.control);
    draw_with_script("plot_pushover", {tmp, "-o", opts.plot, "--title", title}, opts.plot);
    std::remove(tmp.c_str());
  }
  if (!opts.picture.empty()) {
    char title[200];
    std::snprintf(title, sizeof title, "%s: pushover end, d = %.4g m, lambda = %.4f",
                  std::filesystem::path(config.deck_path).stem().c_str(),
                  r.curve.back().displacement,
                  // no "-0.0000" for the small negative lambda that ends a curve
                  std::abs(r.curve.back().lambda) < 5e-5 ? 0.0 : r.curve.back().lambda);
    draw_geometry(failure_mode_json(r.at_end, r.hinges_at_end), opts.picture,
                  {"--no-mesh", "--title", title});
  }
  return 0;
}

// The options of `pushover` (docs/reference/commands.md).
CommandAction add_pushover_command(CLI::App& cmd, CommandLine& line) {
  auto opts = std::make_shared<PushoverOptions>();
  PushoverOptions& o = *opts;
  add_common(cmd, line);
  add_limit_options(&cmd, line.common.limits);
  cmd.add_option("--control", o.control,
                 "control block (its centroid); default: the crown block of an arch, the "
                 "top block otherwise");
  cmd.add_option("--direction", o.direction, "direction of the load: +x or -x")
      ->capture_default_str();
  cmd.add_option("--rate", o.rate,
                 "speed of the control target [m/s] (default " + option_number(kRateFactor) +
                     " sqrt(g L_ref))");
  cmd.add_option("--max-displacement", o.max_displacement,
                 "largest control displacement [m] (default half the structure's height)");
  cmd.add_option("--servo", o.servo,
                 "servo stiffness K [1/m]: lambda = K (target - d) (default 50 lambda_la "
                 "/ L_ref)");
  cmd.add_option("--stop-at", o.stop_at,
                 "end when lambda has fallen past the peak to this fraction of it (for "
                 "lambda* alone; default 0: down to lambda <= 0)");
  cmd.add_flag("--dynamic", o.dynamic,
               "physical settle and run: no quasi-static local damping (default when the "
               "limit-analysis mechanism slides)");
  cmd.add_flag("--quasi-static", o.quasi_static,
               "quasi-static settle and run even when the limit-analysis mechanism slides");
  cmd.add_option("--settle-time", o.settle_time,
                 "longest settle under gravity before the pushover [s]")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd.add_option("--csv", o.csv, "CSV of the curve and its SDOF curve");
  cmd.add_option("--plot", o.plot,
                 "PNG of the curve, the SDOF curve and the mechanism (scripts/plot_pushover)");
  cmd.add_option("--picture", o.picture,
                 "picture (PNG/SVG) of the state at the end with its hinges");
  CommandAction action;
  action.run = [&line, opts] {
    const Config config = load_command_deck(line);
    require_gravity(config, "pushover");
    return command_pushover(config, line.common, *opts);
  };
  return action;
}

}  // namespace voussoir

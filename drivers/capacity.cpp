#include "drivers/capacity.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>

#include "core/fnv.hpp"
#include "core/rigid.hpp"
#include "drivers/bracket.hpp"
#include "drivers/journal.hpp"
#include "drivers/motion.hpp"
#include "drivers/run.hpp"
#include "drivers/setup.hpp"
#include "drivers/trial.hpp"
#include "drivers/trial_pool.hpp"
#include "io/hdf5_output.hpp"
#include "limit/limit_analysis.hpp"

namespace voussoir {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

SettledState settle(const Config& given, const TrialCriteria& crit, bool quiet) {
  const auto t0 = Clock::now();
  SettledState s;
  // The quasi-static phases damp every motion themselves: rigid joints take no dashpot there
  // unless the deck gives one (contact/joint_stiffness.hpp kRigidDefaultRestitution).
  Config config = given;
  // Non-smooth contact dynamics needs no quasi-static technique: on rigid contacts a structure
  // that can stand stands still, and the plastic impacts at its contact points take the energy
  // out of a motion (docs/nscd.md "Capacity"); the trials are physical.
  const bool quasi_static = crit.quasi_static && config.solver.scheme != "nscd";
  if (quasi_static && !config.contact.has("restitution")) {
    config.contact.restitution = 1.0;
    config.contact.given.push_back("restitution");
  }
  s.sim = make_simulation(config);
  if (quasi_static) {
    s.sim.ctx.local_damping = config.capacity.local_damping;
    s.sim.ctx.local_damping_outgoing = config.capacity.local_damping_mode == "outgoing";
    s.sim.ctx.kinetic_damping = config.capacity.kinetic_damping;
    if (config.capacity.mass_scaling == "equalize") {
      const InertiaScaling scaled = equalize_rigid_inertia(s.sim);
      if (!quiet && scaled.blocks > 0)
        std::fprintf(stderr,
                     "quasi-static inertia: %d blocks lightened (down to x%.3g) to the step of "
                     "the fastest (capacity.mass_scaling = \"equalize\")\n",
                     scaled.blocks, scaled.smallest);
    }
  }
  s.gravity = config.load.gravity;
  s.l_ref = reference_length(s.sim.model);
  Simulation& sim = s.sim;
  const double v_rest = crit.rest_speed * std::sqrt(std::max(s.gravity, 1e-12) * s.l_ref);
  const double d_collapse = crit.collapse_displacement * s.l_ref;

  // Gravity ramped on, no horizontal load; ends at rest, at a collapse (no need to wait for the
  // time limit) or at settle_max_time.
  RunSpec spec;
  spec.label = "the settle under gravity";
  spec.loads = LoadProgram{};
  spec.loads->gravity = s.gravity;
  const double ramp = load_ramp(crit, sim);
  spec.loads->gravity_ramp = ramp;
  spec.limits = crit.limits;
  spec.end_time = crit.settle_max_time;
  spec.track_motion = true;
  spec.rules.push_back(std::make_unique<CollapseRule>(d_collapse, crit.collapse_rotation));
  spec.rules.push_back(std::make_unique<RestRule>(v_rest, crit.hold_time, ramp));
  spec.quiet = quiet;
  spec.progress = [&](const Probe& p, double wall) {
    std::fprintf(stderr,
                 "  settling: %.3f s simulated, largest block motion %.3g m, %.3g rad, speed "
                 "%.2g x the rest speed (%.0f s wall)\n",
                 p.time, p.motion.displacement, p.motion.rotation, p.speed / v_rest, wall);
  };
  const Outcome o = run_engine(sim, spec);
  s.settled = o.decided && !o.collapsed;
  s.collapsed = o.decided && o.collapsed;
  s.max_displacement = o.motion.displacement;
  s.max_rotation = o.motion.rotation;
  set_static_load(sim, s.gravity, 0.0);
  s.settle_time = sim.ctx.time;
  s.steps = sim.step;
  s.wall_s = seconds_since(t0);
  if (!quiet)
    std::fprintf(stderr,
                 "settled under gravity: %s after %.3f s (%lld steps of %.4g s, %.2f s wall; "
                 "energy balance error %.2g)\n",
                 s.settled ? "at rest" : (s.collapsed ? "COLLAPSED" : "NOT at rest"), s.settle_time,
                 s.steps, sim.ctx.dt, s.wall_s, sim.ledger.balance_error());
  if (s.settled && !sim.supports.empty()) move_supports_settled(s, config, crit, quiet);
  return s;
}

double load_ramp(const TrialCriteria& crit, const Simulation& sim) {
  return sim.ctx.nscd ? 0.0 : crit.ramp_time;
}

MotionExtent support_allowance(const SupportMotion& supports, double l_ref) {
  double reach = 0.0, turn = 0.0;
  for (const SupportMove& m : supports.moves) {
    reach = std::max(reach, std::hypot(m.dx, m.dy));
    turn = std::max(turn, std::abs(m.rotation));
  }
  return {3.0 * reach, 3.0 * reach / l_ref + turn};
}

Outcome run_support_movement(Simulation& sim, double gravity, double l_ref, double ramp,
                             const MotionExtent& allowed, const TrialCriteria& crit, bool quiet) {
  const double v_rest = crit.rest_speed * std::sqrt(std::max(gravity, 1e-12) * l_ref);
  const double d_collapse = crit.collapse_displacement * l_ref;
  auto phase = [&](const char* label, double end_time, bool hold) {
    RunSpec spec;
    spec.label = label;
    spec.loads = LoadProgram{};
    spec.loads->gravity = gravity;
    spec.limits = crit.limits;
    spec.end_time = end_time;
    spec.track_motion = true;
    const double widen = hold ? 0.0 : 1.0;
    spec.rules.push_back(
        std::make_unique<CollapseRule>(d_collapse + widen * allowed.displacement,
                                       crit.collapse_rotation + widen * allowed.rotation));
    if (hold) spec.rules.push_back(std::make_unique<RestRule>(v_rest, crit.hold_time, 0.0));
    spec.quiet = quiet;
    spec.progress = [label](const Probe& p, double wall) {
      std::fprintf(stderr, "  %s: %.3f s, largest block motion %.3g m, %.3g rad (%.0f s wall)\n",
                   label, p.time, p.motion.displacement, p.motion.rotation, wall);
    };
    return run_engine(sim, spec);
  };
  // The ramp without the quasi-static damping, which would hold back the blocks the supports
  // carry (docs/supports.md "Why the ramp is undamped").
  const double local = sim.ctx.local_damping, kinetic = sim.ctx.kinetic_damping;
  sim.ctx.local_damping = sim.ctx.kinetic_damping = 0.0;
  Outcome o = phase("moving the supports", ramp, false);
  sim.ctx.local_damping = local, sim.ctx.kinetic_damping = kinetic;
  std::fill(sim.local_damping_previous.begin(), sim.local_damping_previous.end(), 0.0);
  sim.kinetic_peak = 0.0;
  if (o.decided) return o;
  const Outcome held = phase("holding the moved supports", crit.settle_max_time, true);
  o.decided = held.decided, o.collapsed = held.collapsed, o.reason = held.reason;
  o.time += held.time;
  o.decided_at = o.time - held.time + held.decided_at;
  o.steps += held.steps;
  o.wall_s += held.wall_s;
  o.motion = held.motion;
  return o;
}

// The support movement after the settle ([supports], core/supports.hpp), by
// run_support_movement. Nothing to run when every move is zero.
void move_supports_settled(SettledState& s, const Config& config, const TrialCriteria& crit,
                           bool quiet) {
  const auto t0 = Clock::now();
  Simulation& sim = s.sim;
  const MotionExtent allowed = support_allowance(sim.supports, s.l_ref);
  const double ramp = config.supports.ramp;
  start_supports(config, sim);
  if (allowed.displacement == 0.0 && allowed.rotation == 0.0) return;
  const Outcome o = run_support_movement(sim, s.gravity, s.l_ref, ramp, allowed, crit, quiet);
  s.settled = o.decided && !o.collapsed;
  s.collapsed = o.decided && o.collapsed;
  s.supports_collapsed = s.collapsed;
  s.supports_time = o.time;
  s.max_displacement = o.motion.displacement;
  s.max_rotation = o.motion.rotation;
  set_static_load(sim, s.gravity, 0.0);
  s.settle_time = sim.ctx.time;
  s.steps = sim.step;
  s.wall_s += seconds_since(t0);
  if (!quiet)
    std::fprintf(stderr,
                 "supports moved (%zu, over %.3g s): %s after %.3f s (%lld steps in all, %.2f s "
                 "wall; energy balance error %.2g)\n",
                 sim.supports.moves.size(), ramp,
                 s.settled ? "at rest" : (s.collapsed ? "COLLAPSED" : "NOT at rest"), o.time,
                 s.steps, s.wall_s, sim.ledger.balance_error());
}

Model mirror_x(const Model& model) {
  Model m = model;
  for (Block& b : m.blocks) {
    for (Vec2& p : b.polygon) p.x = -p.x;
    std::reverse(b.polygon.begin(), b.polygon.end());  // counter-clockwise again
  }
  for (Joint& j : m.joints) {
    j.a.x = -j.a.x;
    j.b.x = -j.b.x;
  }
  return m;
}

MovedBlocks moved_blocks(const Simulation& sim, bool mirror, OpenJoints open) {
  MovedBlocks out;
  out.model = sim.model;
  sync_rigid_nodes(out.model);
  const std::vector<BlockMotion> motion = block_motions(out.model);
  if (open == OpenJoints::Points) {
    const double tol = kHingeFraction * reference_length(out.model);
    for (const Hinge& h : find_hinges(out.model, tol, tol))
      if (h.kind == "hinge") out.point_contacts.push_back(h);
  }
  for (std::size_t b = 0; b < motion.size(); ++b)
    for (Vec2& p : out.model.blocks[b].polygon) p = move_point(motion[b], p);
  auto carried = [&](Index a, Index b, Vec2 p) {
    return 0.5 * (move_point(motion[std::size_t(a)], p) + move_point(motion[std::size_t(b)], p));
  };
  for (Joint& j : out.model.joints) {
    j.a = carried(j.block_a, j.block_b, j.a);
    j.b = carried(j.block_a, j.block_b, j.b);
  }
  for (Interface f : find_interfaces(sim.model)) {
    const double turn =
        0.5 * (motion[std::size_t(f.block_a)].rotation + motion[std::size_t(f.block_b)].rotation);
    const double c = std::cos(turn), s = std::sin(turn);
    f.a = carried(f.block_a, f.block_b, f.a);
    f.b = carried(f.block_a, f.block_b, f.b);
    f.normal = {c * f.normal.x - s * f.normal.y, s * f.normal.x + c * f.normal.y};
    for (const Hinge& h : out.point_contacts)
      if (h.joint == f.joint) (h.side == "intrados" ? f.open_b : f.open_a) = true;
    out.interfaces.push_back(f);
  }
  if (mirror) {
    out.model = mirror_x(out.model);
    for (Interface& f : out.interfaces) f.a.x = -f.a.x, f.b.x = -f.b.x, f.normal.x = -f.normal.x;
  }
  return out;
}

LimitResult limit_of_settled(const SettledState& settled, double friction, double direction) {
  const Simulation& sim = settled.sim;
  if (sim.supports.empty())
    return limit_analysis(direction < 0.0 ? mirror_x(sim.model) : sim.model, friction,
                          settled.gravity, false);
  const MovedBlocks moved = moved_blocks(sim, direction < 0.0);
  LimitOptions options;
  options.interfaces = &moved.interfaces;
  return limit_analysis(moved.model, friction, settled.gravity, false, options);
}

std::string unsettled_message(const SettledState& s, const TrialCriteria& crit) {
  char buf[320];
  if (s.supports_collapsed)
    std::snprintf(buf, sizeof buf,
                  "the structure collapses while its supports move ([supports]): a block moved "
                  "%.3g m and rotated %.3g rad within %.3g s of the movement's start (no "
                  "capacity left, lambda* = 0)",
                  s.max_displacement, s.max_rotation, s.supports_time);
  else if (s.collapsed)
    std::snprintf(buf, sizeof buf,
                  "the structure collapses under gravity alone: a block moved %.3g m and "
                  "rotated %.3g rad within %.3g s of settling (no gravity capacity, "
                  "lambda* = 0)",
                  s.max_displacement, s.max_rotation, s.settle_time);
  else
    std::snprintf(buf, sizeof buf,
                  "the structure does not come to rest under gravity alone within %g s (largest "
                  "block motion %.3g m, %.3g rad): it creeps towards collapse or needs a longer "
                  "settle (--settle-time)",
                  crit.settle_max_time, s.max_displacement, s.max_rotation);
  return buf;
}

namespace {

// The run of one trial from a copy of `settled`: lambda g ramped on from the settled state,
// motions measured from there; collapse at any time, rest and the trend at the time limit
// once the ramp is over.
RunSpec trial_spec(const SettledState& settled, double lambda, const TrialCriteria& crit,
                   bool quiet) {
  const double g = settled.gravity;
  const double v_rest = crit.rest_speed * std::sqrt(std::max(g, 1e-12) * settled.l_ref);
  const double d_collapse = crit.collapse_displacement * settled.l_ref;
  char label[64];
  std::snprintf(label, sizeof label, "the capacity trial lambda = %.6g", lambda);
  RunSpec spec;
  spec.label = label;
  spec.loads = LoadProgram{};
  spec.loads->gravity = g;
  spec.loads->lambda = crit.direction * lambda;
  const double ramp = load_ramp(crit, settled.sim);
  spec.loads->lambda_ramp = ramp;
  spec.loads->start = settled.sim.ctx.time;
  spec.limits = crit.limits;
  spec.track_motion = true;
  spec.rules.push_back(std::make_unique<CollapseRule>(d_collapse, crit.collapse_rotation));
  auto rest = std::make_unique<RestRule>(v_rest, crit.hold_time, ramp);
  if (crit.quasi_static) rest->refuse_creep(d_collapse, crit.collapse_rotation, kCreepTolerance);
  spec.rules.push_back(std::move(rest));
  spec.rules.push_back(
      std::make_unique<TrendRule>(d_collapse, crit.collapse_rotation, 0.0, ramp, crit.max_time));
  spec.quiet = quiet;
  const double rot_limit = crit.collapse_rotation;
  spec.progress = [lambda, d_collapse, v_rest, rot_limit](const Probe& p, double wall) {
    std::fprintf(
        stderr,
        "  lambda = %.5f  running: %.3f s simulated, motion %.0f%% of the collapse "
        "criterion, speed %.2g x the rest speed (%.0f s wall)\n",
        lambda, p.time,
        100.0 * std::max(p.motion.displacement / d_collapse, p.motion.rotation / rot_limit),
        p.speed / v_rest, wall);
  };
  return spec;
}

}  // namespace

TrialResult run_trial(const SettledState& settled, double lambda, const TrialCriteria& crit,
                      bool quiet, const std::function<bool(double)>* sample) {
  const auto t0 = Clock::now();
  Simulation sim = settled.sim;  // deep copy
  RunSpec spec = trial_spec(settled, lambda, crit, quiet);
  if (sample)
    spec.on_sample = [sample](const Simulation&, const Probe& p) { return (*sample)(p.time); };
  const Outcome o = run_engine(sim, spec);

  TrialResult r;
  r.lambda = lambda;
  r.collapsed = o.collapsed;
  r.reason = o.reason;
  r.max_displacement = o.motion.displacement;
  r.max_rotation = o.motion.rotation;
  r.sim_time = o.time;
  r.steps = o.steps;
  r.energy_balance_error = sim.ledger.balance_error();
  r.kinetic_resets = sim.kinetic_resets - settled.sim.kinetic_resets;
  r.joints = joint_resultants(sim.model, sim.contact, sim.ctx.dt);
  if (r.collapsed) {
    const double tol = kHingeFraction * settled.l_ref;
    r.hinges = find_hinges(sim.model, tol, tol);
    r.final_x = sim.model.nodes.x;
    r.final_y = sim.model.nodes.y;
  }
  r.wall_s = seconds_since(t0);
  return r;
}

MovieReport record_trial(const SettledState& settled, double lambda, const TrialCriteria& crit,
                         double frame_every, const std::string& h5_path, bool quiet) {
  const auto t0 = Clock::now();
  Simulation sim = settled.sim;  // deep copy, as run_trial
  RunSpec spec = trial_spec(settled, lambda, crit, quiet);
  spec.label = "the movie of " + spec.label;
  // Past the collapse criterion: on to the end of the movie (on_sample below decides).
  spec.min_time = std::numeric_limits<double>::infinity();
  RunWriter writer;
  writer.open(h5_path, sim.model, {"position"});
  MovieReport m;
  const double d_end = kMovieDisplacement * settled.l_ref;
  double next_frame = 0.0;
  spec.sample_at_start = true;
  spec.on_sample = [&](const Simulation& s, const Probe& p) {
    if (p.time >= next_frame - 0.5 * s.ctx.dt) {
      const double ramp_time = load_ramp(crit, s);
      const double ramp = ramp_time > 0.0 ? std::min(1.0, p.time / ramp_time) : 1.0;
      writer.write_snapshot(p.time, s.model, {});
      write_snapshot_thrust(writer, s.model, s.contact, s.ctx.dt, lambda * ramp);
      next_frame += frame_every;
      ++m.frames;
      m.duration = p.time;
    }
    return m.frames < kMovieFrames && p.motion.rotation < kMovieRotation &&
           p.motion.displacement < d_end;
  };
  try {
    const Outcome o = run_engine(sim, spec);
    m.collapsed = o.collapsed;
    m.collapse_time = o.decided_at;
    writer.close_complete();
  } catch (const std::exception& e) {
    writer.close_incomplete(e.what());
    throw;
  }
  m.wall_s = seconds_since(t0);
  return m;
}

std::string settled_fingerprint(const SettledState& s, const TrialCriteria& c) {
  Fnv f;
  const Nodes& n = s.sim.model.nodes;
  f.array(n.x);
  f.array(n.y);
  f.array(n.vx);
  f.array(n.vy);
  for (double v : {s.sim.ctx.dt, s.sim.ctx.eta, s.gravity, c.ramp_time, c.collapse_displacement,
                   c.collapse_rotation, c.rest_speed, c.hold_time, c.max_time})
    f.value(v);
  if (s.sim.ctx.local_damping > 0.0) {
    f.value(s.sim.ctx.local_damping);
    f.value(s.sim.ctx.local_damping_outgoing ? 1.0 : 0.0);
  }
  if (s.sim.ctx.kinetic_damping > 0.0) f.value(s.sim.ctx.kinetic_damping);
  // The bodies' inertia (lowered by the quasi-static mass scaling).
  f.array(s.sim.model.rigid.mass);
  f.array(s.sim.model.rigid.inertia);
  if (c.direction != 1.0) f.value(c.direction);
  // The quasi-static trials' rest rule refuses a creep (RestRule::refuse_creep).
  if (c.quasi_static) f.value(kCreepTolerance);
  // The contact law: the settled positions need not show a change of friction or joint
  // stiffness (a block at rest under gravity alone sits the same at any friction).
  const ContactParams& cp = s.sim.contact.params();
  for (double v : {cp.penalty, cp.friction, cp.normal_stiffness, cp.joint_young, cp.shear_stiffness,
                   cp.restitution})
    f.value(v);
  // Non-smooth contact dynamics: its settings, which a block settled still on its ground need
  // not show (max_iterations never does when no step reaches it), as in the checkpoint's
  // fingerprint. The explicit scheme hashes without them: its journals stay valid.
  if (s.sim.ctx.nscd) {
    f.text("nscd");
    const NscdSettings& ns = s.sim.ctx.nscd_settings;
    for (double v : {ns.theta, ns.tolerance, double(ns.max_iterations)}) f.value(v);
  }
  return f.hex();
}

namespace {

void report(const TrialResult& r, bool quiet, bool resumed) {
  if (quiet) return;
  std::fprintf(stderr, "  lambda = %.5f  %-9s (%s, %.3f s simulated, %lld steps, %.2f s wall)%s\n",
               r.lambda, r.collapsed ? "collapsed" : "stable", r.reason.c_str(), r.sim_time,
               r.steps, r.wall_s, resumed ? " [journal]" : "");
  // A trial whose velocities the kinetic damping reset at most of its steps stood still
  // whatever the forces on it (docs/capacity.md, "The step of the quasi-static phases").
  if (4 * r.kinetic_resets > r.steps)
    std::fprintf(stderr,
                 "  warning: the kinetic damping reset the velocities at %lld of this trial's %lld "
                 "steps and may have held it still; check it with --dynamic\n",
                 r.kinetic_resets, r.steps);
}

}  // namespace

nlohmann::json trial_json(const TrialResult& r) {
  return {{"lambda", r.lambda},
          {"collapsed", r.collapsed},
          {"reason", r.reason},
          {"sim_time", r.sim_time},
          {"steps", r.steps},
          {"wall_s", r.wall_s},
          {"max_displacement", r.max_displacement},
          {"max_rotation", r.max_rotation},
          {"energy_balance_error", r.energy_balance_error},
          {"kinetic_resets", r.kinetic_resets},
          {"hinges", hinges_record(r.hinges)}};
}

TrialResult trial_from_json(const nlohmann::json& j) {
  TrialResult r;
  r.lambda = j.at("lambda");
  r.collapsed = j.at("collapsed");
  r.reason = j.at("reason");
  r.sim_time = j.at("sim_time");
  r.steps = j.at("steps");
  r.wall_s = j.at("wall_s");
  r.max_displacement = j.at("max_displacement");
  r.max_rotation = j.at("max_rotation");
  r.energy_balance_error = j.at("energy_balance_error");
  r.kinetic_resets = j.value("kinetic_resets", 0LL);  // older journals have none
  r.hinges = hinges_from_record(j.at("hinges"));
  return r;
}

int unseeded_trial_count(double lambda_star, double lambda_min, double tolerance, int points) {
  constexpr double kFirstGuess = 0.125, kCap = 8.0;
  int trials = 0;
  double lo = lambda_min, hi = 0.0;
  bool have_hi = false;
  double next = std::max(kFirstGuess, 2.0 * lo);
  while (!have_hi && next <= kCap) {
    for (int i = 0; i < points && next <= kCap; ++i, next *= 2.0) {
      ++trials;
      if (!have_hi && next > lambda_star) {
        hi = next;
        have_hi = true;
      } else if (!have_hi) {
        lo = next;
      }
    }
  }
  if (!have_hi) return trials;
  Bracket b{lo, hi};
  auto oracle = [lambda_star](const std::vector<double>& probes) {
    std::vector<bool> crossed;
    for (double l : probes) crossed.push_back(l > lambda_star);
    return crossed;
  };
  return trials + shrink_bracket(b, tolerance, points, ProbePlacement::KSection, oracle,
                                 [](const Bracket&) {});
}

CapacityResult find_capacity(const Config& config, const TrialCriteria& crit, int points,
                             bool quiet) {
  CapacitySearch search;
  search.points = points;
  search.quiet = quiet;
  return find_capacity(config, crit, search);
}

CapacityResult find_capacity(const Config& config, const TrialCriteria& crit,
                             const CapacitySearch& search) {
  const auto t0 = Clock::now();
  const bool quiet = search.quiet;
  const int points = std::max(1, search.points);
  CapacityResult res;
  res.tolerance = config.capacity.tolerance;
  std::optional<SettledState> own;
  if (!search.settled) own = settle(config, crit, quiet);
  const SettledState& settled = search.settled ? *search.settled : *own;
  res.triangles = settled.sim.model.tris.size();
  res.dt = settled.sim.ctx.dt;
  res.settle_time = settled.settle_time;
  res.settle_steps = settled.steps;
  res.settle_wall_s = settled.wall_s;
  if (!settled.settled) throw RunError(unsettled_message(settled, crit));
  res.joints_settled = joint_resultants(settled.sim.model, settled.sim.contact, settled.sim.ctx.dt);
  Journal journal(search.journal, settled_fingerprint(settled, crit));

  // Trials on a pool of workers (drivers/trial_pool.hpp): a round's trials side by side, and
  // idle workers running ahead the trials the search will most likely ask for next. One
  // worker inside an active parallel region (the cells of a sweep).
  const int workers = omp_in_parallel() ? 1 : std::max(1, omp_get_max_threads());
  TrialPool pool(
      workers,
      [&](double lambda, const TrialPool::Sample& sample) {
        return run_trial(settled, lambda, crit, quiet, &sample);
      },
      [&](const TrialResult& r) { journal.append(trial_json(r)); });
  // Rounds ahead that the planners list (bracket.hpp probes_ahead), and their guess of
  // lambda* (the middle of each bracket until limit analysis gives kAheadGuess x lambda_la).
  const int depth = 1 + (workers + points - 1) / points;
  double guess = std::numeric_limits<double>::quiet_NaN();
  // The journal's trials, known to the pool before anything runs (none is run ahead again).
  // Lambdas are written with 17 significant digits, so a resumed search that recomputes the
  // same lambdas finds them bit for bit; the first record of a lambda counts (preload).
  std::set<double> from_journal;
  for (const nlohmann::json& j : journal.records()) {
    if (!j.contains("lambda")) continue;
    try {
      pool.preload(trial_from_json(j));
    } catch (const std::exception&) {
      continue;  // a record without a trial's fields: that trial runs again
    }
    from_journal.insert(j.at("lambda").get<double>());
  }
  // Runs a round (trials of the journal taken from it); returns all results in input order.
  auto evaluate = [&](const std::vector<double>& lambdas,
                      TrialPool::Planner planner = TrialPool::nothing_ahead) {
    const std::vector<TrialResult> out = pool.run_round(lambdas, std::move(planner));
    for (const TrialResult& r : out) {
      const bool resumed = from_journal.count(r.lambda) != 0;
      if (resumed) ++res.resumed_trials;
      report(r, quiet, resumed);
      res.trials.push_back(r);
    }
    return out;
  };

  double lo = config.capacity.lambda_min, hi = config.capacity.lambda_max;
  bool have_hi = false;
  constexpr double kFirstGuess = 0.125, kCap = 8.0;
  // The seed's ends are presumed, not run: [s_lo, s_hi] is where the k-section starts, and an
  // end is run only when the search ends on it (below).
  double s_lo = 0.0, s_hi = 0.0;
  bool lo_presumed = false, hi_presumed = false;

  // A contradicted bracket (the seed's, or the deck's) widens geometrically: down from a low
  // end that collapsed (it becomes hi), up from a high end that stood (it becomes lo; no
  // collapse up to kCap leaves the search unbracketed).
  auto widen_down = [&](double from) {
    hi = from;
    double down = from;
    while (down > 1e-3) {
      ++res.seed.widenings;
      down *= kWidenDown;
      if (!quiet)
        std::fprintf(stderr, "bracket contradicted (collapse at %.5f): widening down\n", hi);
      if (!evaluate({down})[0].collapsed) {
        lo = down;
        return;
      }
      hi = down;
    }
    lo = 0.0;
  };
  auto widen_up = [&](double from) {
    if (!quiet) std::fprintf(stderr, "bracket contradicted (stable at %.5f): widening up\n", from);
    lo = from;
    have_hi = false;
    double up = from;
    while (!have_hi && up < kCap) {
      ++res.seed.widenings;
      up *= kWidenUp;
      if (evaluate({up})[0].collapsed) {
        hi = up;
        have_hi = true;
      } else {
        lo = up;
      }
    }
  };

  if (hi > lo) {
    // The deck's bracket: both ends are run, side by side (a lower end of 0 is not). A lower
    // end that collapses widens the bracket down, an upper end that stands widens it up.
    std::vector<double> ends;
    if (lo > 0.0) ends.push_back(lo);
    ends.push_back(hi);
    const auto round = evaluate(ends);
    have_hi = round.back().collapsed;
    if (lo > 0.0 && round.front().collapsed) {
      widen_down(lo);
      have_hi = true;
    } else if (!have_hi) {
      widen_up(hi);
    }
  } else if (search.seed_from_limit) {
    // Towards -x: limit analysis of the mirror image towards +x.
    const LimitResult la = limit_of_settled(settled, config.contact.friction, crit.direction);
    res.seed.status = la.status;
    if (la.status == "optimal" && la.lambda_la > lo) {
      res.seed.used = true;
      res.seed.held = true;  // until a presumed end that is run contradicts it
      res.seed.lambda_la = la.lambda_la;
      s_lo = std::max(lo, kSeedLow * la.lambda_la);
      s_hi = kSeedHigh * la.lambda_la;
      if (!quiet)
        std::fprintf(stderr, "limit analysis: lambda_la = %.5f, seeded bracket [%.5f, %.5f]\n",
                     la.lambda_la, s_lo, s_hi);
      lo = s_lo;
      hi = s_hi;
      have_hi = lo_presumed = hi_presumed = true;
      guess = kAheadGuess * la.lambda_la;
    }
  }

  // Unseeded bracket: lambdas grow geometrically from 0.125 until one collapses (cap 8: beyond
  // that the structure is not a masonry mechanism).
  double next = std::max(kFirstGuess, 2.0 * lo);
  while (!have_hi && next <= kCap) {
    std::vector<double> lambdas;
    for (int i = 0; i < points && next <= kCap; ++i, next *= 2.0) lambdas.push_back(next);
    const auto round = evaluate(lambdas);
    for (const TrialResult& r : round) {
      if (r.collapsed) {
        hi = r.lambda;
        have_hi = true;
        break;
      }
      lo = std::max(lo, r.lambda);
    }
  }

  // k-section (drivers/bracket.hpp): `points` interior lambdas per round, run in parallel. A
  // presumed seed end that is still an end of the bracket is also listed for idle workers,
  // after the rounds ahead.
  Bracket bracket{lo, hi};
  while (have_hi) {
    shrink_bracket(
        bracket, res.tolerance, points, ProbePlacement::KSection,
        [&](const std::vector<double>& lambdas) {
          const Bracket now = bracket;
          const double tol = res.tolerance;
          const bool check_lo = lo_presumed && now.lo == s_lo;
          const bool check_hi = hi_presumed && now.hi == s_hi;
          std::vector<bool> collapsed;
          for (const TrialResult& r : evaluate(lambdas, [=](const std::vector<Outcome3>&known,
                                                            const std::map<double, bool>&finished) {
                 std::vector<double> ahead =
                     probes_ahead(now, lambdas, known, tol, points, ProbePlacement::KSection, depth,
                                  guess, finished);
                 if (check_hi) ahead.push_back(s_hi);
                 if (check_lo) ahead.push_back(s_lo);
                 return ahead;
               }))
            collapsed.push_back(r.collapsed);
          return collapsed;
        },
        [&](const Bracket& b) {
          if (!quiet) std::fprintf(stderr, "bracket [%.5f, %.5f]\n", b.lo, b.hi);
        });
    lo = bracket.lo;
    hi = bracket.hi;
    // The seed's ends that the search ended on are run now (both in one round when it ended on
    // both: no probe fell between them). The bracket holds when they do as presumed.
    std::vector<double> ends;
    if (lo_presumed && lo == s_lo) ends.push_back(s_lo);
    if (hi_presumed && hi == s_hi) ends.push_back(s_hi);
    lo_presumed = hi_presumed = false;
    if (ends.empty()) break;
    res.seed.ends_run += static_cast<int>(ends.size());
    if (!quiet)
      for (double l : ends)
        std::fprintf(stderr, "the bracket ends on the seed's presumed %s end: running %.5f\n",
                     l == s_lo ? "low" : "high", l);
    bool lo_collapsed = false, hi_stood = false;
    for (const TrialResult& r : evaluate(ends)) {
      if (r.lambda == s_lo && r.collapsed) lo_collapsed = true;
      if (r.lambda == s_hi && !r.collapsed) hi_stood = true;
    }
    if (!lo_collapsed && !hi_stood) break;
    res.seed.held = false;
    if (lo_collapsed)
      widen_down(s_lo);
    else
      widen_up(s_hi);
    bracket = Bracket{lo, hi};
  }

  // The joint resultants of the trials at the bracket's ends (CapacityResult).
  auto keep_joints = [&](double at_lo, double at_hi, bool bracketed) {
    if (at_lo == 0.0) res.joints_stable = res.joints_settled, res.has_stable = true;
    for (const TrialResult& r : res.trials) {
      if (r.joints.empty()) continue;
      if (!r.collapsed && r.lambda == at_lo) res.joints_stable = r.joints, res.has_stable = true;
      if (bracketed && r.collapsed && r.lambda == at_hi)
        res.joints_collapsed = r.joints, res.has_collapsed = true;
    }
  };
  // The search is over: what still runs ahead is cancelled, and the pool's figures kept.
  pool.cancel_ahead();
  const PoolStats st = pool.stats();
  res.workers = st.workers;
  res.ahead = st.ahead;
  res.ahead_used = st.ahead_used;
  res.ahead_cancelled = st.cancelled;
  res.ahead_unused_s = st.unused_s;
  res.bracketed = have_hi;
  if (!have_hi) {
    keep_joints(lo, hi, false);
    res.lo = res.hi = res.lambda_star = lo;
    res.wall_s = seconds_since(t0);
    return res;
  }
  for (const TrialResult& r : res.trials) {
    if (!r.collapsed || r.lambda != hi) continue;
    res.hinges = r.hinges;
    if (!r.final_x.empty()) {
      res.has_mode = true;
      res.mode = settled.sim.model;
      res.mode.nodes.x = r.final_x;
      res.mode.nodes.y = r.final_y;
    }
  }
  keep_joints(lo, hi, true);
  // The movie: the collapsed trial at hi run again with snapshots (record_trial), about
  // kMovieFramesToCollapse frames until its collapse criterion fired.
  if (!search.movie.empty())
    for (const TrialResult& r : res.trials) {
      if (!r.collapsed || r.lambda != hi || res.has_movie) continue;
      if (!quiet) std::fprintf(stderr, "recording the trial lambda = %.5f for the movie\n", hi);
      const double every = std::max(res.dt, r.sim_time / kMovieFramesToCollapse);
      res.movie = record_trial(settled, hi, crit, every, search.movie, quiet);
      res.has_movie = true;
    }
  res.lo = lo;
  res.hi = hi;
  res.lambda_star = 0.5 * (lo + hi);
  if (res.seed.used)
    res.seed.unseeded_trials =
        unseeded_trial_count(res.lambda_star, config.capacity.lambda_min, res.tolerance, points);
  res.wall_s = seconds_since(t0);
  return res;
}

}  // namespace voussoir

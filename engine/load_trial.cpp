#include "engine/load_trial.hpp"

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
#include "engine/bracket.hpp"
#include "engine/journal.hpp"
#include "engine/motion.hpp"
#include "engine/run_loop.hpp"
#include "engine/setup.hpp"
#include "engine/trial.hpp"
#include "engine/trial_pool.hpp"
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
  return sim.scheme == StepScheme::RigidNscd ? 0.0 : crit.ramp_time;
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
  if (s.sim.scheme == StepScheme::RigidNscd) {
    f.text("nscd");
    const NscdSettings& ns = s.sim.ctx.nscd_settings;
    for (double v : {ns.theta, ns.tolerance, double(ns.max_iterations)}) f.value(v);
  }
  return f.hex();
}

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

}  // namespace voussoir

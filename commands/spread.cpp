// `voussoir spread`: the spreading study (procedure in commands/spread.hpp).

#include "commands/spread.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/rigid.hpp"
#include "core/supports.hpp"
#include "engine/motion.hpp"
#include "engine/thrust.hpp"
#include "engine/trial.hpp"
#include "io/json.hpp"
#include "limit/limit_analysis.hpp"
#include "mesh/scene.hpp"

namespace voussoir {

namespace {

using Clock = std::chrono::steady_clock;

// The study's block: --block, else the deck's first move, else the leftmost fixed block.
int study_block(const Config& config, const Model& model, const SpreadOptions& opts) {
  if (opts.block >= 0) return opts.block;
  if (!config.supports.moves.empty()) return config.supports.moves.front().block;
  int best = -1;
  double best_x = std::numeric_limits<double>::infinity();
  for (std::size_t b = 0; b < model.blocks.size(); ++b) {
    if (!model.blocks[b].fixed) continue;
    Vec2 c;
    polygon_centroid(model.blocks[b].polygon, &c);
    if (c.x < best_x) best_x = c.x, best = int(b);
  }
  return best;
}

// One step: the study's support from where it is to `target` (the deck's moves kept), held
// until rest; false when it collapsed or did not come to rest.
bool move_step(SettledState& s, const std::vector<SupportMove>& targets, double ramp,
               const TrialCriteria& crit, SpreadState& out) {
  const auto t0 = Clock::now();
  Simulation& sim = s.sim;
  SupportMotion step = sim.supports;  // the step's own movement, for its allowance
  for (std::size_t k = 0; k < targets.size(); ++k) {
    step.moves[k].dx = targets[k].dx - sim.supports.moves[k].dx;
    step.moves[k].dy = targets[k].dy - sim.supports.moves[k].dy;
    step.moves[k].rotation = targets[k].rotation - sim.supports.moves[k].rotation;
  }
  const MotionExtent allowed = support_allowance(step, s.l_ref);
  retarget_support_motion(sim.supports, targets, sim.ctx.time, ramp);
  const Outcome o = run_support_movement(sim, s.gravity, s.l_ref, ramp, allowed, crit, true);
  out.collapsed = !(o.decided && !o.collapsed);
  out.sim_time = o.time;
  if (!out.collapsed) {
    sync_rigid_nodes(sim.model);
    const SupportThrust h =
        support_thrust(sim.model, joint_resultants(sim.model, sim.contact, sim.ctx.dt));
    out.thrust_left = h.left, out.thrust_right = h.right, out.thrust = h.mean();
    const double tol = kHingeFraction * s.l_ref;
    out.hinges = find_hinges(sim.model, tol, tol);
  }
  out.wall_s = seconds_since(t0);
  return !out.collapsed;
}

std::string hinge_text(const std::vector<Hinge>& hinges) {
  std::string out;
  for (const Hinge& h : hinges) {
    if (!out.empty()) out += " ";
    out += std::to_string(h.joint) + (h.kind == "sliding" ? "s" : h.side == "intrados" ? "i" : "e");
  }
  return out;
}

}  // namespace

SpreadResult run_spread(const Config& given, const SpreadOptions& opts, bool quiet) {
  const auto t0 = Clock::now();
  SpreadResult res;
  const Model unmoved = build_model(scene_params(given));
  res.block = study_block(given, unmoved, opts);
  const bool exists = res.block >= 0 && std::size_t(res.block) < unmoved.blocks.size();
  if (!exists || !unmoved.blocks[std::size_t(res.block)].fixed)
    throw DeckError(given.deck_path + ": spread --block " + std::to_string(res.block) +
                    ": expected a fixed block (`voussoir check` lists the supports)");
  Vec2 c;
  polygon_centroid(unmoved.blocks[std::size_t(res.block)].polygon, &c);
  const double xg = free_weight_x(unmoved);
  Vec2 e{c.x < xg ? -1.0 : 1.0, 0.0};
  if (opts.direction.size() == 2) e = {opts.direction[0], opts.direction[1]};
  if (!(norm(e) > 0.0) || !std::isfinite(norm(e)))
    throw DeckError(given.deck_path +
                    ": spread --direction: expected two numbers DX,DY, not both 0");
  res.direction = (1.0 / norm(e)) * e;
  const double width = free_extent(unmoved).width;
  res.step = opts.step > 0.0 ? opts.step : 0.0025 * width;
  res.max_movement = opts.max_movement > 0.0 ? opts.max_movement : 0.25 * width;
  res.tolerance = opts.tolerance;
  const double turn_per_metre = opts.rotation * M_PI / 180.0;

  // The study's block among the deck's moves (a zero move when the deck does not move it), so
  // that it is a prescribed support from the start.
  Config config = given;
  std::size_t slot = config.supports.moves.size();
  for (std::size_t k = 0; k < config.supports.moves.size(); ++k)
    if (config.supports.moves[k].block == res.block) slot = k;
  if (slot == config.supports.moves.size())
    config.supports.moves.push_back({res.block, 0, 0, 0, ""});
  const SupportMoveConfig base = config.supports.moves[slot];

  for (const bool min : {true, false}) {
    const LimitResult la = limit_thrust(unmoved, config.contact.friction, config.load.gravity,
                                        min ? ThrustBound::Min : ThrustBound::Max);
    (min ? res.thrust_min : res.thrust_max) =
        la.status == "optimal" ? la.thrust : std::numeric_limits<double>::quiet_NaN();
  }

  TrialCriteria crit = opts.criteria;
  crit.quasi_static = true;
  SettledState s = settle(config, crit, quiet);
  res.settle_wall_s = s.wall_s;
  if (!s.settled) throw RunError(config.deck_path + ": " + unsettled_message(s, crit));
  {
    SpreadState start;
    const SupportThrust h =
        support_thrust(s.sim.model, joint_resultants(s.sim.model, s.sim.contact, s.sim.ctx.dt));
    start.thrust_left = h.left, start.thrust_right = h.right, start.thrust = h.mean();
    const double tol = kHingeFraction * s.l_ref;
    start.hinges = find_hinges(s.sim.model, tol, tol);
    res.states.push_back(start);
  }
  const double ramp = config.supports.ramp;
  auto targets_at = [&](double d) {
    std::vector<SupportMove> t = s.sim.supports.moves;
    t[slot].dx = base.dx + d * res.direction.x;
    t[slot].dy = base.dy + d * res.direction.y;
    t[slot].rotation = base.rotation * M_PI / 180.0 + d * turn_per_metre;
    return t;
  };
  auto report = [&](const SpreadState& st) {
    if (quiet) return;
    std::fprintf(stderr, "  movement %.5g m: %s", st.movement,
                 st.collapsed ? "COLLAPSED" : "at rest");
    if (!st.collapsed)
      std::fprintf(stderr, ", thrust %.6g N (left %.6g, right %.6g), hinges [%s]", st.thrust,
                   st.thrust_left, st.thrust_right, hinge_text(st.hinges).c_str());
    std::fprintf(stderr, " (%.3f s simulated, %.2f s wall)\n", st.sim_time, st.wall_s);
  };

  // Steps until a collapse or the largest movement.
  double lo = 0.0;
  SettledState last = s;
  for (int k = 1; !res.collapsed; ++k) {
    const double d = std::min(k * res.step, res.max_movement);
    SpreadState st;
    st.movement = d;
    if (move_step(s, targets_at(d), ramp, crit, st)) {
      lo = d;
      last = s;
    } else {
      res.collapsed = true;
      res.collapse_hi = d;
    }
    res.states.push_back(st);
    report(st);
    if (d >= res.max_movement) break;
  }
  // Bisection of the movement at collapse from the last state at rest.
  while (res.collapsed && res.collapse_hi - lo > res.tolerance * res.collapse_hi) {
    const double d = 0.5 * (lo + res.collapse_hi);
    SettledState trial = last;
    SpreadState st;
    st.movement = d;
    if (move_step(trial, targets_at(d), ramp, crit, st)) {
      lo = d;
      last = std::move(trial);
    } else {
      res.collapse_hi = d;
    }
    res.states.push_back(st);
    report(st);
  }
  res.collapse_lo = lo;
  res.wall_s = seconds_since(t0);
  return res;
}

int command_spread(const Config& config, const CommonOptions& common, const SpreadOptions& opts) {
  const SpreadResult r = run_spread(config, opts, common.quiet);
  std::printf("deck        %s\n", config.deck_path.c_str());
  std::printf("support     block %d moved along (%.4g, %.4g) in steps of %.4g m (at most %.4g m)\n",
              r.block, r.direction.x, r.direction.y, r.step, r.max_movement);
  std::printf("limit       thrust_min %.6g N, thrust_max %.6g N (unmoved structure)\n",
              r.thrust_min, r.thrust_max);
  std::printf("%12s %12s %12s %12s  %s\n", "movement [m]", "thrust [N]", "left [N]", "right [N]",
              "hinges (joint, i/e/s)");
  std::vector<const SpreadState*> rows;
  for (const SpreadState& st : r.states) rows.push_back(&st);
  std::stable_sort(rows.begin(), rows.end(), [](const SpreadState* a, const SpreadState* b) {
    return a->movement < b->movement;
  });
  for (const SpreadState* st : rows) {
    if (st->collapsed)
      std::printf("%12.6g %12s\n", st->movement, "collapsed");
    else
      std::printf("%12.6g %12.6g %12.6g %12.6g  %s\n", st->movement, st->thrust, st->thrust_left,
                  st->thrust_right, hinge_text(st->hinges).c_str());
  }
  if (r.collapsed)
    std::printf("collapse    at a movement in [%.6g, %.6g] m (bracket %.3g%% of its upper end)\n",
                r.collapse_lo, r.collapse_hi,
                100.0 * (r.collapse_hi - r.collapse_lo) / std::max(r.collapse_hi, 1e-300));
  else
    std::printf("collapse    none up to %.6g m\n", r.max_movement);
  std::printf("wall        %.2f s (settle %.2f s)\n", r.wall_s, r.settle_wall_s);

  std::ofstream csv(opts.csv);
  if (!csv) throw DeckError("spread --csv " + opts.csv + ": cannot write");
  csv << "movement,collapsed,thrust,thrust_left,thrust_right,hinges,sim_time,wall_s\n";
  for (const SpreadState* st : rows)
    csv << st->movement << "," << (st->collapsed ? 1 : 0) << "," << st->thrust << ","
        << st->thrust_left << "," << st->thrust_right << "," << hinge_text(st->hinges) << ","
        << st->sim_time << "," << st->wall_s << "\n";

  if (!common.json_path.empty()) {
    nlohmann::json states = nlohmann::json::array();
    for (const SpreadState* st : rows) {
      nlohmann::json j = {{"movement", st->movement},
                          {"collapsed", st->collapsed},
                          {"sim_time", st->sim_time},
                          {"wall_s", st->wall_s}};
      if (!st->collapsed) {
        j["thrust"] = st->thrust;
        j["thrust_left"] = st->thrust_left;
        j["thrust_right"] = st->thrust_right;
        j["hinges"] = hinges_to_json(st->hinges);
      }
      states.push_back(j);
    }
    nlohmann::json j = {{"block", r.block},
                        {"direction", {r.direction.x, r.direction.y}},
                        {"step", r.step},
                        {"max_movement", r.max_movement},
                        {"tolerance", r.tolerance},
                        {"states", states},
                        {"collapsed", r.collapsed},
                        {"thrust_min", std::isfinite(r.thrust_min) ? nlohmann::json(r.thrust_min)
                                                                   : nlohmann::json(nullptr)},
                        {"thrust_max", std::isfinite(r.thrust_max) ? nlohmann::json(r.thrust_max)
                                                                   : nlohmann::json(nullptr)},
                        {"settle_wall_s", r.settle_wall_s},
                        {"wall_s", r.wall_s}};
    if (r.collapsed) {
      j["collapse_movement"] = 0.5 * (r.collapse_lo + r.collapse_hi);
      j["collapse_bracket"] = {r.collapse_lo, r.collapse_hi};
    } else {
      j["collapse_movement"] = nullptr;
    }
    write_json(j, common.json_path);
  }
  return 0;
}

// The options of `spread` (docs/reference/commands.md).
CommandAction add_spread_command(CLI::App& cmd, CommandLine& line) {
  auto opts = std::make_shared<SpreadOptions>();
  SpreadOptions& o = *opts;
  add_common(cmd, line);
  add_limit_options(&cmd, line.common.limits);
  cmd.add_option("--block", o.block,
                 "fixed block to move (default: the deck's first move, else the leftmost)");
  cmd.add_option("--direction", o.direction,
                 "DX,DY of the movement (default: horizontal, away from the structure)")
      ->delimiter(',')
      ->expected(2);
  cmd.add_option("--rotation", o.rotation, "turn of the support [deg] per metre of movement");
  cmd.add_option("--step", o.step, "movement per step [m] (default 0.25% of width)")
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--max", o.max_movement,
                 "largest movement [m] (default 25% of the structure's width)")
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--tolerance", o.tolerance,
                 "relative width of the bracket on the movement at collapse")
      ->capture_default_str()
      ->check(CLI::Range(1e-4, 1.0));
  cmd.add_option("--csv", o.csv, "thrust and hinges per step")->capture_default_str();
  CommandAction action;
  action.run = [&line, opts] {
    const Config config = load_command_deck(line);
    require_gravity(config, "spread");
    return command_spread(config, line.common, *opts);
  };
  return action;
}

}  // namespace voussoir

// `voussoir limit DECK`: rigid-block limit analysis on the blocks of the deck's model — the
// collapse load factor lambda_la and its mechanism, or (--gravity-only) whether an admissible
// equilibrium exists under self-weight alone, or (--thrust min|max) the least or greatest
// horizontal thrust on the supports under self-weight ("thrust_min" / "thrust_max" in N per
// model.out_of_plane; --mechanism-out then carries that equilibrium's line of thrust, the
// centres of pressure of the interfaces, for scripts/draw). Friction: contact.friction
// (associative, so an upper bound where sliding governs); gravity: load.gravity. With
// [supports] moves, the blocks where the movement leaves them, their open joints closed or
// (--open-joints points) point contacts at their pivots.

#include "commands/limit.hpp"

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "commands/capacity.hpp"
#include "commands/common.hpp"
#include "io/deck.hpp"
#include "io/json.hpp"
#include "limit/limit_analysis.hpp"
#include "mesh/scene.hpp"

namespace voussoir {

// Meshed model geometry as written by `voussoir check --mesh-out` (commands/check.cpp).

namespace {

nlohmann::json number_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json mechanism_json(const LimitResult& res) {
  nlohmann::json out = nlohmann::json::array();
  for (const MechanismJoint& m : res.mechanism)
    out.push_back({{"joint", m.joint},
                   {"interface", m.interface},
                   {"blocks", {m.block_a, m.block_b}},
                   {"kind", m.kind},
                   {"side", m.side},
                   {"x", m.x},
                   {"y", m.y},
                   {"position_deg", number_or_null(m.position_deg)},
                   {"opening_a", m.opening_a},
                   {"opening_b", m.opening_b},
                   {"slip", m.slip}});
  return out;
}

// The line of thrust of the LP's equilibrium in the form of the joint resultants
// (engine/thrust.hpp) that scripts/draw reads: per interface with a compressive resultant, its
// blocks, normal force and centre of pressure (the end forces' normal components weighted).
nlohmann::json thrust_line_json(const LimitResult& res) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t k = 0; k < res.interfaces.size() && k < res.forces.size(); ++k) {
    const Interface& f = res.interfaces[k];
    const InterfaceForces& F = res.forces[k];
    const double n = F.normal_a + F.normal_b;
    nlohmann::json j = {
        {"joint", f.joint}, {"blocks", {f.block_a, f.block_b}}, {"normal_force", n}};
    if (n > 0.0)
      j["point"] = {(F.normal_a * f.a.x + F.normal_b * f.b.x) / n,
                    (F.normal_a * f.a.y + F.normal_b * f.b.y) / n};
    else
      j["point"] = nullptr;
    out.push_back(j);
  }
  return out;
}

nlohmann::json interfaces_json(const LimitResult& res) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t k = 0; k < res.interfaces.size(); ++k) {
    const Interface& f = res.interfaces[k];
    nlohmann::json j = {{"blocks", {f.block_a, f.block_b}},
                        {"joint", f.joint},
                        {"a", {f.a.x, f.a.y}},
                        {"b", {f.b.x, f.b.y}},
                        {"normal", {f.normal.x, f.normal.y}},
                        {"position_deg", number_or_null(f.position_deg)}};
    if (k < res.forces.size()) {
      const InterfaceForces& F = res.forces[k];
      j["forces"] = {{"normal_a", F.normal_a},
                     {"shear_a", F.shear_a},
                     {"normal_b", F.normal_b},
                     {"shear_b", F.shear_b}};
    }
    out.push_back(j);
  }
  return out;
}

}  // namespace

int command_limit(const Config& config, const CommonOptions& common,
                  const LimitCommandOptions& opts) {
  const auto t0 = std::chrono::steady_clock::now();
  require_gravity(config, "limit");
  if (opts.gravity_only && !opts.thrust.empty())
    throw DeckError("limit --thrust " + opts.thrust +
                    " with --gravity-only: give one of them (--thrust bounds the thrust under "
                    "gravity alone already)");
  const bool points = opts.open_joints == "points";
  if (points && config.supports.moves.empty())
    throw DeckError(
        "limit --open-joints points needs [supports] moves: without them the "
        "blocks stand as built, every joint closed");
  // [supports]: the blocks where the support movement leaves them (settled under gravity and
  // moved as `capacity` does it, then carried rigidly: commands/capacity.hpp moved_blocks).
  MovedBlocks moved;
  LimitOptions options;
  if (!config.supports.moves.empty()) {
    TrialCriteria crit;
    crit.quasi_static = true;
    const SettledState settled = settle(config, crit, common.quiet);
    if (!settled.settled)
      throw RunError(config.deck_path + ": " + unsettled_message(settled, crit));
    moved = moved_blocks(settled.sim, false, points ? OpenJoints::Points : OpenJoints::Closed);
    options.interfaces = &moved.interfaces;
  }
  const Model model = options.interfaces ? moved.model : build_model(scene_params(config));
  const double model_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double mu = config.contact.friction;
  const double g = config.load.gravity;
  if (!common.quiet)
    std::fprintf(stderr, "limit: %zu blocks, model built in %.2f s; solving the LP...\n",
                 model.blocks.size(), model_s);
  const bool thrust = !opts.thrust.empty();
  const std::string thrust_key = "thrust_" + opts.thrust;
  const LimitResult res =
      thrust ? limit_thrust(model, mu, g,
                            opts.thrust == "min" ? ThrustBound::Min : ThrustBound::Max, options)
             : limit_analysis(model, mu, g, opts.gravity_only, options);

  std::printf("deck        %s\n", config.deck_path.c_str());
  std::printf("model       %s: %d free blocks, %zu interfaces (mu = %.4g)\n", model.kind.c_str(),
              res.free_blocks, res.interfaces.size(), mu);
  if (options.interfaces) {
    std::printf("open joints %s", points ? "point contacts at their pivots:" : "closed");
    for (const Hinge& h : moved.point_contacts) std::printf(" %d (%s)", h.joint, h.side.c_str());
    std::printf("%s\n", points && moved.point_contacts.empty() ? " none opened" : "");
  }
  std::printf("LP          %d rows x %d columns, %d iterations, %s, %.3f s\n", res.rows,
              res.columns, res.iterations, res.exact ? "exact check passed" : "no exact check",
              res.wall_s);
  if (thrust) {
    if (res.status == "optimal")
      std::printf("%-11s %.6g N (per out_of_plane %.4g m; outward on each side, lambda = 0)\n",
                  thrust_key.c_str(), res.thrust, model.out_of_plane);
    else if (res.status == "unbounded")
      std::printf("%-11s unbounded: the supports can take any thrust (a flat arch)\n",
                  thrust_key.c_str());
    else
      std::printf("%-11s none: %s (no admissible equilibrium under self-weight)\n",
                  thrust_key.c_str(), res.status.c_str());
  } else if (opts.gravity_only) {
    std::printf("gravity     %s: %s\n", res.admissible ? "admissible" : "NOT admissible",
                res.admissible ? "an equilibrium with N >= 0 and |S| <= mu N exists"
                               : "no equilibrium under self-weight with N >= 0, |S| <= mu N");
  } else if (res.status == "optimal") {
    std::printf("lambda_la   %.6f  (rigid blocks, no tension, associative friction)\n",
                res.lambda_la);
    if (res.lambda_la < 0.0)
      std::printf("            negative: the model is not admissible under self-weight alone\n");
    for (const MechanismJoint& m : res.mechanism) {
      std::printf("  %-10s interface %d", m.kind.c_str(), m.interface);
      if (m.joint >= 0) std::printf(" (joint %d)", m.joint);
      std::printf(" blocks %d-%d", m.block_a, m.block_b);
      if (std::isfinite(m.position_deg)) std::printf(" at %.1f deg", m.position_deg);
      if (!m.side.empty()) std::printf(", pivot at %s", m.side.c_str());
      std::printf(" (%.4f, %.4f)\n", m.x, m.y);
    }
    bool sliding = false;
    for (const MechanismJoint& m : res.mechanism) sliding |= m.kind == "sliding";
    if (sliding)
      std::printf(
          "            the mechanism slides: with associative friction lambda_la is an\n"
          "            upper bound on the Coulomb (non-associative) collapse load\n");
  } else if (res.status == "unbounded") {
    std::printf("lambda_la   unbounded: no horizontal load factor collapses the model\n");
  } else {
    std::printf("lambda_la   none: %s (no admissible equilibrium at any lambda)\n",
                res.status.c_str());
  }

  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!common.json_path.empty()) {
    nlohmann::json j = {{"status", res.status},
                        {"admissible", res.admissible},
                        {"gravity_only", opts.gravity_only},
                        {"friction", mu},
                        {"free_blocks", res.free_blocks},
                        {"interfaces", res.interfaces.size()},
                        {"rows", res.rows},
                        {"columns", res.columns},
                        {"iterations", res.iterations},
                        {"exact", res.exact},
                        {"lp_wall_s", res.wall_s},
                        {"model_wall_s", model_s},
                        {"wall_s", wall_s}};
    if (options.interfaces) {
      nlohmann::json joints = nlohmann::json::array();
      for (const Hinge& h : moved.point_contacts)
        joints.push_back({{"joint", h.joint}, {"side", h.side}, {"opening", h.opening}});
      j["open_joints"] = opts.open_joints;
      j["point_contacts"] = joints;
    }
    if (thrust) {
      j[thrust_key] = number_or_null(res.thrust);
      j["out_of_plane"] = model.out_of_plane;
    } else if (!opts.gravity_only) {
      j["lambda_la"] = number_or_null(res.lambda_la);
      j["mechanism"] = mechanism_json(res);
    }
    write_json(j, common.json_path);
  }
  if (!opts.mechanism_out.empty()) {
    nlohmann::json geo = model_geometry_json(model);
    nlohmann::json vel = nlohmann::json::array();
    for (const BlockVelocity& v : res.velocities) vel.push_back({v.ux, v.uy, v.omega});
    geo["limit"] = {{"status", res.status},
                    {"gravity_only", opts.gravity_only},
                    {"lambda_la", number_or_null(res.lambda_la)},
                    {"friction", mu},
                    {"mechanism", mechanism_json(res)},
                    {"interfaces", interfaces_json(res)},
                    {"block_velocities", vel}};
    if (thrust) {
      geo["limit"][thrust_key] = number_or_null(res.thrust);
      char label[96];
      std::snprintf(label, sizeof label, "%s = %.4g N", thrust_key.c_str(), res.thrust);
      geo["thrust"] =
          nlohmann::json::array({{{"label", label}, {"joints", thrust_line_json(res)}}});
    }
    write_json(geo, opts.mechanism_out);
  }
  return 0;
}

// The options of `limit` (docs/reference/commands.md).
CommandAction add_limit_command(CLI::App& cmd, CommandLine& line) {
  auto opts = std::make_shared<LimitCommandOptions>();
  LimitCommandOptions& o = *opts;
  add_common(cmd, line);
  cmd.add_flag("--gravity-only", o.gravity_only,
               "only decide whether an admissible equilibrium exists under self-weight");
  cmd.add_option("--mechanism-out", o.mechanism_out,
                 "write the block polygons and the mechanism as JSON (scripts/draw)");
  cmd.add_option("--thrust", o.thrust,
                 "least (min) or greatest (max) horizontal support thrust under gravity")
      ->check(CLI::IsMember({"min", "max"}));
  cmd.add_option("--open-joints", o.open_joints,
                 "with [supports] moves: the joints that opened closed over their face "
                 "(default) or point contacts at their pivots")
      ->check(CLI::IsMember({"closed", "points"}));
  CommandAction action;
  action.run = [&line, opts] {
    const Config config = load_command_deck(line);
    return command_limit(config, line.common, *opts);
  };
  return action;
}

}  // namespace voussoir

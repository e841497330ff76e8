// `voussoir check DECK`: validate the deck, build the model, print its summary
// (docs/reference/commands.md section 2) and optionally the meshed geometry as JSON for
// scripts/draw.

#include "commands/check.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <vector>

#include "commands/common.hpp"
#include "contact/friction.hpp"
#include "contact/joint_stiffness.hpp"
#include "core/model.hpp"
#include "engine/setup.hpp"
#include "io/json.hpp"
#include "limit/interfaces.hpp"
#include "mesh/scene.hpp"

namespace voussoir {

nlohmann::json model_geometry_json(const Model& model) {
  using nlohmann::json;
  const Nodes& n = model.nodes;
  const Triangles& t = model.tris;
  json nodes = json::array(), tris = json::array(), tri_block = json::array();
  for (Index i = 0; i < n.size(); ++i) nodes.push_back({n.x[i], n.y[i]});
  for (Index e = 0; e < t.size(); ++e) {
    tris.push_back({t.n0[e], t.n1[e], t.n2[e]});
    tri_block.push_back(t.block[e]);
  }
  json blocks = json::array();
  for (const Block& b : model.blocks) {
    json poly = json::array();
    for (const Vec2& p : b.polygon) poly.push_back({p.x, p.y});
    blocks.push_back({{"fixed", b.fixed}, {"role", b.role}, {"name", b.name}, {"polygon", poly}});
    if (b.prescribed) blocks.back()["moves"] = true;  // a support that [supports] moves
  }
  json joints = json::array();
  for (const Joint& j : model.joints)
    joints.push_back({{"blocks", {j.block_a, j.block_b}},
                      {"a", {j.a.x, j.a.y}},
                      {"b", {j.b.x, j.b.y}},
                      {"position_deg", j.position_deg}});
  return {{"kind", model.kind},     {"nodes", nodes},   {"triangles", tris},
          {"tri_block", tri_block}, {"blocks", blocks}, {"joints", joints}};
}

MovedOutlines moved_outlines(const Model& model) {
  MovedOutlines out;
  out.motions = block_motions(model);
  out.moved = nlohmann::json::array();
  out.reference = nlohmann::json::array();
  for (size_t b = 0; b < model.blocks.size(); ++b) {
    nlohmann::json moved = nlohmann::json::array(), ref = nlohmann::json::array();
    for (const Vec2& p : model.blocks[b].polygon) {
      const Vec2 q = move_point(out.motions[b], p);
      moved.push_back({q.x, q.y});
      ref.push_back({p.x, p.y});
    }
    out.moved.push_back(moved);
    out.reference.push_back(ref);
  }
  return out;
}

nlohmann::json failure_mode_json(const Model& model, const std::vector<Hinge>& hinges) {
  using nlohmann::json;
  json geo = model_geometry_json(model);
  const MovedOutlines outlines = moved_outlines(model);
  const std::vector<BlockMotion>& motions = outlines.motions;
  for (size_t b = 0; b < model.blocks.size(); ++b) geo["blocks"][b]["polygon"] = outlines.moved[b];
  geo["reference_blocks"] = outlines.reference;
  json marks = hinges_to_json(hinges);
  for (size_t k = 0; k < hinges.size(); ++k) {
    const Vec2 q = move_point(motions[hinges[k].block_a], Vec2{hinges[k].x, hinges[k].y});
    marks[k]["x_deformed"] = q.x;
    marks[k]["y_deformed"] = q.y;
  }
  geo["hinges"] = marks;
  return geo;
}

int command_check(const Config& config, const CommonOptions& common, const CheckOptions& opts) {
  SetupInfo info;
  Simulation sim = make_simulation(config, &info);
  const Model& m = sim.model;
  int free_blocks = 0;
  for (const Block& b : m.blocks) free_blocks += b.fixed ? 0 : 1;
  const double worst = worst_triangle_angle_deg(m);

  std::printf("deck        %s\n", config.deck_path.c_str());
  std::printf("model       %s\n", m.kind.c_str());
  std::printf("blocks      %zu (%d free, %zu fixed)\n", m.blocks.size(), free_blocks,
              m.blocks.size() - free_blocks);
  // Blocks read from a gmsh file: which physical surface became which block index (the
  // numbers model.fixed takes).
  bool named = false;
  for (const Block& b : m.blocks) named = named || !b.name.empty();
  if (named)
    for (std::size_t b = 0; b < m.blocks.size(); ++b)
      std::printf("  block %-4zu %-5s \"%s\"\n", b, m.blocks[b].fixed ? "fixed" : "free",
                  m.blocks[b].name.c_str());
  // Which block number is which support (the numbers [supports] moves take), and the moves.
  std::printf("supports   ");
  for (std::size_t b = 0; b < m.blocks.size(); ++b)
    if (m.blocks[b].fixed) {
      Vec2 c;
      polygon_centroid(m.blocks[b].polygon, &c);
      std::printf(" %zu (%s at %.3g, %.3g)", b, m.blocks[b].role.c_str(), c.x, c.y);
    }
  std::printf("\n");
  for (const SupportMove& mv : sim.supports.moves)
    std::printf(
        "  move block %d (%s): dx = %.6g m, dy = %.6g m, rotation = %.6g deg, over %.4g s "
        "after the settle\n",
        mv.block, m.blocks[std::size_t(mv.block)].role.c_str(), mv.dx, mv.dy,
        mv.rotation * 180.0 / M_PI, config.supports.ramp);
  std::printf("triangles   %d\n", m.tris.size());
  std::printf("nodes       %d\n", m.nodes.size());
  std::printf("free area   %.6g m2\n", free_area(m));
  std::printf("mass        %.6g kg (free blocks, out-of-plane %.4g m)\n", free_mass(m),
              m.out_of_plane);
  std::printf("worst angle %.2f deg\n", worst);
  std::printf("blocks are  %s\n", info.rigid ? "rigid (one body each; no strain energy, no stress "
                                               "field)"
                                             : "elastic (constant-strain triangles)");
  const bool nscd = sim.scheme == StepScheme::RigidNscd;
  if (nscd) {
    // Non-smooth contact dynamics: no stiffness, no stable limit (docs/nscd.md).
    std::printf(
        "scheme      nscd: Moreau-Jean theta = %g, rigid contact points, Gauss-Seidel to "
        "%g (at most %d sweeps a step)\n",
        config.solver.theta, config.solver.tolerance, config.solver.max_iterations);
    std::printf("dt          %.4g s (set by the %s)\n", info.dt, info.dt_set_by.c_str());
    std::printf("restitution %.3g (%s)\n", sim.contact.params().restitution,
                config.contact.has("restitution") ? "contact.restitution"
                                                  : "plastic impacts, the nscd default");
  } else {
    std::printf("dt          %.4g s (stable limit %.4g s, set by the %s)\n", info.dt,
                info.dt_stable, info.dt_set_by.c_str());
  }
  // Rigid blocks: how far the blocks' own stable limits spread. The step is the smallest; a
  // narrow spread means that no mass scaling of a few fast blocks could lengthen it much.
  const std::vector<double> each_body = rigid_body_stable_steps(sim);
  std::vector<double> body_steps;
  for (double s : each_body)
    if (std::isfinite(s)) body_steps.push_back(s);
  std::sort(body_steps.begin(), body_steps.end());
  const std::size_t fastest =
      std::size_t(std::min_element(each_body.begin(), each_body.end()) - each_body.begin());
  if (!body_steps.empty() && !nscd) {
    std::printf(
        "body steps  min %.4g s (block %zu), median %.4g s, max %.4g s: each free block "
        "alone on its joints\n",
        body_steps.front(), fastest, body_steps[body_steps.size() / 2], body_steps.back());
  }
  if (nscd) {
    // no joint stiffness, no penalty, no impact dashpot
  } else if (info.joint_stiffness) {
    if (config.contact.normal_stiffness > 0.0)
      std::printf("joints      kn = %.4g N/m3, ks = %.4g N/m3\n", config.contact.normal_stiffness,
                  config.contact.shear_stiffness > 0.0
                      ? config.contact.shear_stiffness
                      : kTangentialStiffnessRatio * config.contact.normal_stiffness);
    else
      std::printf("joints      kn = %g E / L per joint (L: the joint's length), ks = %s\n",
                  kRigidJointFactor,
                  config.contact.shear_stiffness > 0.0 ? "contact.shear_stiffness" : "kn / 4");
  } else {
    std::printf("penalty     %.4g Pa\n", info.penalty);
  }
  if (sim.contact.params().restitution < 1.0 && !nscd)
    std::printf("restitution %.3g (impact damping%s)\n", sim.contact.params().restitution,
                config.contact.has("restitution")
                    ? ""
                    : "; rigid blocks' default in the physical runs, none in the quasi-static "
                      "capacity trials");
  std::printf("damping eta %.4g Pa s\n", info.eta);

  if (!common.json_path.empty()) {
    nlohmann::json j = {{"blocks", m.blocks.size()},
                        {"free_blocks", free_blocks},
                        {"triangles", m.tris.size()},
                        {"nodes", m.nodes.size()},
                        {"free_area", free_area(m)},
                        {"mass", free_mass(m)},
                        {"dt", info.dt},
                        {"dt_stable", info.dt_stable},
                        {"penalty", info.penalty},
                        {"eta", info.eta},
                        {"worst_angle_deg", worst},
                        {"joints", m.joints.size()},
                        {"block_model", info.rigid ? "rigid" : "elastic"},
                        {"dt_set_by", info.dt_set_by}};
    if (!body_steps.empty())
      j["body_steps"] = {{"min", body_steps.front()},
                         {"min_block", fastest},
                         {"median", body_steps[body_steps.size() / 2]},
                         {"max", body_steps.back()}};
    nlohmann::json moves = nlohmann::json::array();
    for (const SupportMove& mv : sim.supports.moves)
      moves.push_back({{"block", mv.block},
                       {"dx", mv.dx},
                       {"dy", mv.dy},
                       {"rotation", mv.rotation * 180.0 / M_PI}});
    j["supports"] = {{"moves", moves}, {"ramp", config.supports.ramp}};
    if (named) {
      nlohmann::json names = nlohmann::json::array();
      for (const Block& b : m.blocks) names.push_back(b.name);
      j["block_names"] = names;
    }
    write_json(j, common.json_path);
  }
  if (!opts.mesh_out.empty()) write_json(model_geometry_json(m), opts.mesh_out);
  return 0;
}

// The options of `check` (docs/reference/commands.md).
CommandAction add_check_command(CLI::App& cmd, CommandLine& line) {
  auto opts = std::make_shared<CheckOptions>();
  CheckOptions& o = *opts;
  add_common(cmd, line);
  cmd.add_option("--mesh-out", o.mesh_out, "write the meshed model as JSON");
  CommandAction action;
  action.run = [&line, opts] {
    const Config config = load_command_deck(line);
    return command_check(config, line.common, *opts);
  };
  return action;
}

}  // namespace voussoir

// `voussoir stability DECK --param KEY=V1,... --param KEY=start:stop:step`: gravity-only
// stability maps. One cell = one deck run from rest under gravity, classified stable or
// collapsed; the criteria, the kinetic-energy normalisation and the limit-analysis cross-check
// are described at the top of commands/stability.hpp. One CSV row per cell in grid order (last
// axis fastest), the JSON summary, the collapse-mode outlines of collapsed cells (--mode-out
// DIR, one JSON per cell) and the picture (--plot, drawn by scripts/plot_stability).

#include "commands/stability.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands/capacity.hpp"
#include "commands/common.hpp"
#include "core/fnv.hpp"
#include "core/scene_kinds.hpp"
#include "engine/dealer.hpp"
#include "engine/motion.hpp"
#include "engine/run_loop.hpp"
#include "engine/setup.hpp"
#include "engine/solver_report.hpp"
#include "engine/trial.hpp"
#include "io/deck.hpp"
#include "io/json.hpp"
#include "io/plot.hpp"
#include "limit/limit_analysis.hpp"
#include "mesh/scene.hpp"

namespace voussoir {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

double stability_ke_length(const Config& config, const Model& model) {
  if (is_arch_kind(config.model.kind)) return config.model.radius;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Block& b : model.blocks)
    if (!b.fixed)
      for (const Vec2& p : b.polygon) {
        lo = std::min(lo, p.y);
        hi = std::max(hi, p.y);
      }
  return hi > lo ? hi - lo : 1.0;
}

StabilityCell run_stability_cell(const Config& deck, const StabilityCriteria& crit, bool keep_mode,
                                 const std::string& cell_label) {
  const auto t0 = Clock::now();
  Config config = deck;
  config.load.lambda = 0.0;  // gravity only
  config.load.base.signal = "none";
  config.output.file.clear();
  Simulation sim = make_simulation(config);
  const TrialCriteria& tc = crit.trial;

  StabilityCell c;
  c.thickness = config.model.thickness;
  c.radius = config.model.radius;
  c.friction = config.contact.friction;
  c.triangles = sim.model.tris.size();
  c.dt = sim.ctx.dt;
  c.l_ref = reference_length(sim.model);
  c.free_mass = free_mass(sim.model);
  c.ke_length = stability_ke_length(config, sim.model);
  const double g = config.load.gravity;
  const double ke_scale = c.free_mass * g * c.ke_length;
  const double v_rest = tc.rest_speed * std::sqrt(std::max(g, 1e-12) * c.l_ref);
  const double d_collapse = tc.collapse_displacement * c.l_ref;

  // Gravity ramped on from rest; motions measured from the unloaded geometry. A decided cell
  // runs on to ke_time, when its kinetic energy is read. [supports]: the supports move once
  // the gravity ramp is on, over supports.ramp; rest is judged and the kinetic energy read
  // that much later, and the collapse limits widen by what the movement imposes.
  double moved_by = 0.0;  // [s] the support movement's share of the cell's time
  MotionExtent allowed;
  const double ramp = load_ramp(tc, sim);  // none under nscd (commands/capacity.hpp)
  if (!sim.supports.empty()) {
    start_support_motion(sim.supports, ramp, config.supports.ramp);
    moved_by = config.supports.ramp;
    allowed = support_allowance(sim.supports, c.l_ref);
  }
  const double ke_time = crit.ke_time + moved_by;
  RunSpec spec;
  spec.label = "the stability cell " + cell_label;
  spec.loads = LoadProgram{};
  spec.loads->gravity = g;
  spec.loads->gravity_ramp = ramp;
  spec.limits = tc.limits;
  spec.track_motion = true;
  spec.min_time = ke_time;
  spec.rules.push_back(std::make_unique<CollapseRule>(d_collapse + allowed.displacement,
                                                      tc.collapse_rotation + allowed.rotation));
  spec.rules.push_back(std::make_unique<RestRule>(v_rest, tc.hold_time, ramp + moved_by));
  spec.rules.push_back(std::make_unique<TrendRule>(d_collapse, tc.collapse_rotation,
                                                   moved_by > 0.0 ? ramp + moved_by : 0.0,
                                                   ramp + moved_by, tc.max_time + moved_by));
  bool ke_read = false;
  spec.on_sample = [&](const Simulation& s, const Probe& p) {
    if (!ke_read && p.time >= ke_time) {
      c.kinetic_energy = s.ledger.kinetic;
      c.ke_time = p.time;
      ke_read = true;
    }
    return true;
  };
  const Outcome o = run_engine(sim, spec);
  c.stable = !o.collapsed;
  c.reason = o.reason;
  c.decision_time = o.decided_at;
  c.max_displacement = o.motion.displacement;
  c.max_rotation = o.motion.rotation;
  c.normalised_kinetic_energy = ke_scale > 0.0 ? c.kinetic_energy / ke_scale : 0.0;
  c.sim_time = sim.ctx.time;
  c.steps = sim.step;
  if (!c.stable) {
    const double tol = kHingeFraction * c.l_ref;
    c.hinges = find_hinges(sim.model, tol, tol);
  }
  if (keep_mode) {
    const std::vector<BlockMotion> m = block_motions(sim.model);
    for (size_t b = 0; b < sim.model.blocks.size(); ++b) {
      const Block& blk = sim.model.blocks[b];
      std::vector<Vec2> moved;
      moved.reserve(blk.polygon.size());
      for (const Vec2& p : blk.polygon) moved.push_back(blk.fixed ? p : move_point(m[b], p));
      c.outlines.push_back(std::move(moved));
      c.outlines0.push_back(blk.polygon);
      c.fixed.push_back(blk.fixed);
    }
  }
  c.wall_s = seconds_since(t0);
  return c;
}

void check_limit_admissibility(const Config& config, StabilityCell& cell) {
  try {
    const Model model = build_model(scene_params(config));
    const LimitResult r = limit_analysis(model, config.contact.friction, config.load.gravity, true);
    cell.la_admissible = r.admissible;
    cell.la_status = r.status;
  } catch (const std::exception& e) {
    cell.la_admissible = false;
    cell.la_status = std::string("error: ") + e.what();
  }
}

nlohmann::json outlines_record(const std::vector<std::vector<Vec2>>& polys) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& poly : polys) {
    nlohmann::json p = nlohmann::json::array();
    for (const Vec2& v : poly) p.push_back({v.x, v.y});
    out.push_back(p);
  }
  return out;
}

namespace {

std::vector<std::vector<Vec2>> outlines_from_record(const nlohmann::json& j) {
  std::vector<std::vector<Vec2>> out;
  for (const auto& poly : j) {
    out.emplace_back();
    for (const auto& v : poly) out.back().push_back(Vec2{v[0], v[1]});
  }
  return out;
}

// The fields of a cell that the journal record and the JSON summary share, under the names of
// docs/reference/output.md ("stability").
nlohmann::json stability_cell_fields(const StabilityCell& r) {
  return {{"thickness", r.thickness},
          {"friction", r.friction},
          {"stable", r.stable},
          {"reason", r.reason},
          {"kinetic_energy", r.kinetic_energy},
          {"normalised_kinetic_energy", r.normalised_kinetic_energy},
          {"ke_time", r.ke_time},
          {"ke_length", r.ke_length},
          {"free_mass", r.free_mass},
          {"max_displacement", r.max_displacement},
          {"max_rotation", r.max_rotation},
          {"decision_time", r.decision_time},
          {"sim_time", r.sim_time},
          {"steps", r.steps},
          {"wall_s", r.wall_s},
          {"triangles", r.triangles},
          {"dt", r.dt}};
}

}  // namespace

nlohmann::json stability_cell_record(const StabilityCell& r) {
  nlohmann::json j = stability_cell_fields(r);
  j["values"] = r.values;
  j["radius"] = r.radius;
  j["l_ref"] = r.l_ref;
  j["error"] = r.error;
  j["hinges"] = hinges_record(r.hinges);
  j["outlines"] = outlines_record(r.outlines);
  j["outlines0"] = outlines_record(r.outlines0);
  j["fixed"] = r.fixed;
  return j;
}

StabilityCell stability_cell_from_record(const nlohmann::json& j) {
  StabilityCell r;
  r.values = j.at("values").get<std::vector<std::string>>();
  r.thickness = j.at("thickness");
  r.radius = j.at("radius");
  r.friction = j.at("friction");
  r.stable = j.at("stable");
  r.reason = j.at("reason");
  r.kinetic_energy = j.at("kinetic_energy");
  r.normalised_kinetic_energy = j.at("normalised_kinetic_energy");
  r.ke_time = j.at("ke_time");
  r.ke_length = j.at("ke_length");
  r.free_mass = j.at("free_mass");
  r.max_displacement = j.at("max_displacement");
  r.max_rotation = j.at("max_rotation");
  r.decision_time = j.at("decision_time");
  r.sim_time = j.at("sim_time");
  r.steps = j.at("steps");
  r.wall_s = j.at("wall_s");
  r.triangles = j.at("triangles");
  r.dt = j.at("dt");
  r.l_ref = j.at("l_ref");
  r.error = j.at("error");
  r.hinges = hinges_from_record(j.at("hinges"));
  r.outlines = outlines_from_record(j.at("outlines"));
  r.outlines0 = outlines_from_record(j.at("outlines0"));
  r.fixed = j.at("fixed").get<std::vector<bool>>();
  return r;
}

std::vector<StabilityCell> run_stability_map(const Grid& grid, const StabilityCriteria& crit,
                                             int threads, bool keep_modes, bool quiet,
                                             Journal* journal) {
  const size_t cells = grid.configs.size();
  const bool dealer = is_dealer_rank();
  // Limit-analysis cross-checks first, serially (a few ms each; GLPK is not assumed to be
  // thread-safe), so progress lines can flag disagreements; on rank 0, which gathers.
  std::vector<StabilityCell> la(cells);
  if (dealer)
    for (size_t c = 0; c < cells; ++c) check_limit_admissibility(grid.configs[c], la[c]);

  // A cell's record (journal and ranks, engine/dealer.hpp) into the map.
  std::vector<StabilityCell> out(cells);
  auto take_record = [&](size_t c, const nlohmann::json& j) {
    if (c >= cells || j.at("values") != nlohmann::json(grid.values[c]))
      throw RunError("the stability journal belongs to another grid (cell " + std::to_string(c) +
                     ")");
    out[c] = stability_cell_from_record(j);
    out[c].la_admissible = la[c].la_admissible;
    out[c].la_status = la[c].la_status;
  };
  CellWork work;
  work.cells = cells;
  work.finished.assign(cells, 0);
  if (journal)
    for (const nlohmann::json& j : journal->records()) {
      const long c = j.value("cell", -1L);
      take_record(c < 0 ? cells : size_t(c), j);
      work.finished[c] = 1;
    }
  work.run = [&](size_t c, const nlohmann::json&) {
    StabilityCell r;
    try {
      std::string label;
      for (size_t k = 0; k < grid.axes.size(); ++k)
        label += (k ? " " : "") + grid.axes[k].key + "=" + grid.values[c][k];
      r = run_stability_cell(grid.configs[c], crit, keep_modes, label);
      if (r.stable) {  // outlines are only wanted for collapse modes
        r.outlines.clear();
        r.outlines0.clear();
        r.fixed.clear();
      }
    } catch (const std::exception& e) {
      r.error = e.what();
      r.reason = "error";
      r.thickness = grid.configs[c].model.thickness;
      r.radius = grid.configs[c].model.radius;
      r.friction = grid.configs[c].contact.friction;
    }
    r.values = grid.values[c];
    nlohmann::json record = stability_cell_record(r);
    record["cell"] = c;
    return record;
  };
  const auto t0 = Clock::now();
  int done = 0;
  work.take = [&](size_t c, const nlohmann::json& record) {
    take_record(c, record);
    const StabilityCell& r = out[c];
    if (journal) journal->append(record);
    ++done;
    if (!quiet) {
      std::fprintf(stderr, "[%d/%zu]", done, cells);
      for (size_t k = 0; k < grid.axes.size(); ++k)
        std::fprintf(stderr, " %s=%s", grid.axes[k].key.c_str(), grid.values[c][k].c_str());
      if (r.error.empty())
        std::fprintf(stderr,
                     "  %-9s (%s at %.3f s) KE/MgL = %.3g at %.3f s; LA %s%s; %.1f s wall, "
                     "%.0f s elapsed\n",
                     r.stable ? "stable" : "collapsed", r.reason.c_str(), r.decision_time,
                     r.normalised_kinetic_energy, r.ke_time,
                     r.la_admissible ? "admissible" : "not admissible",
                     r.disagrees() ? " (DISAGREES)" : "", r.wall_s, seconds_since(t0));
      else
        std::fprintf(stderr, "  failed: %s\n", r.error.c_str());
    }
  };
  deal_cells(work, threads, quiet);
  return out;
}

}  // namespace voussoir

namespace voussoir {

namespace {

// A cell of the JSON summary (docs/reference/output.md, stability).
nlohmann::json stability_cell_summary(const StabilityCell& r, const nlohmann::json& params) {
  nlohmann::json j = stability_cell_fields(r);
  j["params"] = params;
  j["la_admissible"] = r.la_admissible;
  j["la_status"] = r.la_status;
  j["disagree"] = r.disagrees();
  j["hinges"] = hinges_to_json(r.hinges);
  if (!r.error.empty()) j["error"] = r.error;
  return j;
}

// Collapse modes: one JSON per collapsed cell, FOLDER/cell_NNNN.json, with the cell's
// parameters as in the summary's `jcells`.
void write_collapse_modes(const std::string& folder, const std::vector<StabilityCell>& cells,
                          const nlohmann::json& jcells) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) throw OutputError("cannot create " + folder + ": " + ec.message());
  for (size_t c = 0; c < cells.size(); ++c) {
    const StabilityCell& r = cells[c];
    if (r.outlines.empty()) continue;
    char name[32];
    std::snprintf(name, sizeof name, "cell_%04zu.json", c);
    nlohmann::json fixed = nlohmann::json::array();
    for (bool f : r.fixed) fixed.push_back(f);
    write_json({{"cell", c},
                {"params", jcells[c]["params"]},
                {"thickness", r.thickness},
                {"radius", r.radius},
                {"friction", r.friction},
                {"reason", r.reason},
                {"time", r.sim_time},
                {"l_ref", r.l_ref},
                {"max_displacement", r.max_displacement},
                {"max_rotation", r.max_rotation},
                {"fixed", fixed},
                {"reference", outlines_record(r.outlines0)},
                {"deformed", outlines_record(r.outlines)},
                {"hinges", hinges_to_json(r.hinges)}},
               (std::filesystem::path(folder) / name).string());
  }
}

}  // namespace

int command_stability(const std::string& deck_path, const std::vector<std::string>& sets,
                      const CommonOptions& common, const StabilityOptions& opts) {
  const auto t0 = std::chrono::steady_clock::now();
  if (opts.params.empty())
    throw DeckError("stability needs at least one --param KEY=V1,V2,... or KEY=start:stop:step");
  if (!(opts.ke_time > 0.0) || !(opts.max_time > 0.0))
    throw DeckError("--ke-time and --max-time must be positive seconds");
  std::vector<GridAxis> axes;
  for (const std::string& p : opts.params) axes.push_back(parse_grid_param(p));
  const Grid grid = make_grid(deck_path, sets, axes);
  for (const Config& c : grid.configs) require_gravity(c, "stability");
  StabilityCriteria crit;
  crit.ke_time = opts.ke_time;
  crit.trial.limits = common.limits;
  crit.trial.max_time = opts.max_time;
  if (!common.quiet && is_dealer_rank())
    std::fprintf(stderr,
                 "stability map: %zu cells, gravity only, KE read at %.3g s, "
                 "undecided cells decided at %.3g s\n",
                 grid.configs.size(), crit.ke_time, crit.trial.max_time);
  const bool keep_modes = !opts.mode_out.empty();
  // Resume (engine/journal.hpp): one record per finished cell under the fingerprint of the
  // deck, its overrides, the axes, the criteria and whether modes are kept.
  Fnv print;
  fingerprint_grid(print, deck_path, sets, axes);
  for (double v : {crit.ke_time, crit.trial.max_time, common.limits.drift_limit,
                   double(common.limits.max_steps), keep_modes ? 1.0 : 0.0})
    print.value(v);
  Journal journal(is_dealer_rank() ? opts.resume : std::string(), print.hex());
  const std::vector<StabilityCell> cells =
      run_stability_map(grid, crit, common.threads, keep_modes, common.quiet,
                        opts.resume.empty() ? nullptr : &journal);
  if (!is_dealer_rank()) return 0;  // rank 0 writes the outputs (engine/dealer.hpp)

  // CSV, written to a temporary name and renamed when complete.
  const std::string csv_path = opts.csv.empty() ? "stability.csv" : opts.csv;
  GridCsv grid_csv(csv_path, 10, axes);
  std::ostream& csv = grid_csv.out();
  csv << "thickness,radius,friction,stable,reason,kinetic_energy,normalised_ke,ke_time,"
         "ke_length,free_mass,max_displacement,max_rotation,decision_time,sim_time,steps,"
         "triangles,dt,wall_s,la_admissible,disagree,error\n";
  nlohmann::json jcells = nlohmann::json::array();
  int n_stable = 0, n_disagree = 0, n_error = 0;
  for (size_t c = 0; c < cells.size(); ++c) {
    const StabilityCell& r = cells[c];
    const nlohmann::json params = grid_csv.cell(r.values);
    csv << r.thickness << ',' << r.radius << ',' << r.friction << ',' << (r.stable ? 1 : 0) << ','
        << r.reason << ',' << r.kinetic_energy << ',' << r.normalised_kinetic_energy << ','
        << r.ke_time << ',' << r.ke_length << ',' << r.free_mass << ',' << r.max_displacement << ','
        << r.max_rotation << ',' << r.decision_time << ',' << r.sim_time << ',' << r.steps << ','
        << r.triangles << ',' << r.dt << ',' << r.wall_s << ',' << (r.la_admissible ? 1 : 0) << ','
        << (r.disagrees() ? 1 : 0) << ',' << csv_quote(r.error) << '\n';
    n_stable += r.error.empty() && r.stable;
    n_disagree += r.disagrees();
    n_error += !r.error.empty();
    jcells.push_back(stability_cell_summary(r, params));
  }
  grid_csv.finish();

  if (keep_modes) write_collapse_modes(opts.mode_out, cells, jcells);

  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf(
      "stability map of %zu cells: %d stable, %zu collapsed, %d disagree with limit "
      "analysis, %d failed; written to %s (%.1f s wall)\n",
      cells.size(), n_stable, cells.size() - n_stable - n_error, n_disagree, n_error,
      csv_path.c_str(), wall);
  for (const StabilityCell& r : cells)
    if (!r.error.empty()) std::fprintf(stderr, "voussoir: run failed: %s\n", r.error.c_str());
  if (!common.json_path.empty()) {
    nlohmann::json jaxes = nlohmann::json::array();
    for (const GridAxis& a : axes) {
      nlohmann::json vals = nlohmann::json::array();
      for (const std::string& v : a.values) vals.push_back(param_value(v));
      jaxes.push_back({{"key", a.key}, {"values", vals}});
    }
    write_json({{"cells", jcells},
                {"axes", jaxes},
                {"solver", solver_json(grid.configs.front(), solver_record())},
                {"criteria",
                 {{"ramp_time", crit.trial.ramp_time},
                  {"collapse_displacement", crit.trial.collapse_displacement},
                  {"collapse_rotation", crit.trial.collapse_rotation},
                  {"rest_speed", crit.trial.rest_speed},
                  {"hold_time", crit.trial.hold_time},
                  {"max_time", crit.trial.max_time},
                  {"ke_time", crit.ke_time}}},
                {"csv", csv_path},
                {"stable", n_stable},
                {"disagree", n_disagree},
                {"ranks", rank_count()},
                {"wall_s", wall}},
               common.json_path);
  }
  if (!opts.plot.empty()) {
    std::vector<std::string> args = {csv_path, "-o", opts.plot};
    if (keep_modes) args.insert(args.end(), {"--modes", opts.mode_out});
    draw_with_script("plot_stability", args, opts.plot);
  }
  return n_error > 0 ? 1 : 0;
}

// The options of `stability` (docs/reference/commands.md).
CommandAction add_stability_command(CLI::App& cmd, CommandLine& line) {
  auto opts = std::make_shared<StabilityOptions>();
  StabilityOptions& o = *opts;
  add_common(cmd, line);
  add_limit_options(&cmd, line.common.limits);
  cmd.add_option("--param", o.params,
                 "KEY=V1,V2,... or KEY=start:stop:step (repeat for a grid); "
                 "model.thickness_ratio=R sets model.thickness = R x model.radius")
      ->required();
  cmd.add_option("--csv", o.csv, "CSV output (default stability.csv)");
  cmd.add_option("--plot", o.plot, "PNG map (scripts/plot_stability)");
  cmd.add_option("--mode-out", o.mode_out,
                 "folder for the block outlines of every collapsed cell (JSON)");
  cmd.add_option("--ke-time", o.ke_time,
                 "time at which the kinetic energy is read [s] (default 1)");
  cmd.add_option("--resume", o.resume,
                 "journal of finished cells: created, or resumed after a kill");
  cmd.add_option("--max-time", o.max_time,
                 "simulated time after which undecided cells are decided [s] (default 3)");
  CommandAction action;
  action.run = [&line, opts] {
    return command_stability(line.deck, line.sets, line.common, *opts);
  };
  action.dealt = [] { return true; };
  return action;
}

}  // namespace voussoir

// `voussoir stability DECK --param KEY=V1,... --param KEY=start:stop:step`: the gravity-only
// stability map (drivers/stability.hpp). One CSV row per cell in grid order (last axis
// fastest), the JSON summary, the collapse-mode outlines of collapsed cells (--mode-out DIR,
// one JSON per cell) and the picture (--plot, drawn by scripts/plot_stability).

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/fnv.hpp"
#include "drivers/solver_report.hpp"
#include "drivers/commands.hpp"
#include "drivers/dealer.hpp"
#include "drivers/plot.hpp"
#include "drivers/stability.hpp"
#include "io/deck.hpp"
#include "io/json.hpp"

namespace voussoir {

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
  // Resume (drivers/journal.hpp): one record per finished cell under the fingerprint of the
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
  if (!is_dealer_rank()) return 0;  // rank 0 writes the outputs (drivers/dealer.hpp)

  // CSV, written to a temporary name and renamed when complete.
  const std::string csv_path = opts.csv.empty() ? "stability.csv" : opts.csv;
  std::ofstream csv(csv_path + ".tmp");
  if (!csv) throw OutputError("cannot write " + csv_path);
  csv.precision(10);
  for (const GridAxis& a : axes) csv << a.key << ',';
  csv << "thickness,radius,friction,stable,reason,kinetic_energy,normalised_ke,ke_time,"
         "ke_length,free_mass,max_displacement,max_rotation,decision_time,sim_time,steps,"
         "triangles,dt,wall_s,la_admissible,disagree,error\n";
  nlohmann::json jcells = nlohmann::json::array();
  int n_stable = 0, n_disagree = 0, n_error = 0;
  for (size_t c = 0; c < cells.size(); ++c) {
    const StabilityCell& r = cells[c];
    nlohmann::json params = nlohmann::json::object();
    for (size_t k = 0; k < axes.size(); ++k) {
      csv << r.values[k] << ',';
      params[axes[k].key] = param_value(r.values[k]);
    }
    csv << r.thickness << ',' << r.radius << ',' << r.friction << ',' << (r.stable ? 1 : 0) << ','
        << r.reason << ',' << r.kinetic_energy << ',' << r.normalised_ke << ',' << r.ke_read_time
        << ',' << r.ke_length << ',' << r.free_mass << ',' << r.max_displacement << ','
        << r.max_rotation << ',' << r.decision_time << ',' << r.sim_time << ',' << r.steps << ','
        << r.triangles << ',' << r.dt << ',' << r.wall_s << ',' << (r.la_admissible ? 1 : 0) << ','
        << (r.disagrees() ? 1 : 0) << ',' << csv_quote(r.error) << '\n';
    n_stable += r.error.empty() && r.stable;
    n_disagree += r.disagrees();
    n_error += !r.error.empty();
    nlohmann::json j = {{"params", params},
                        {"stable", r.stable},
                        {"reason", r.reason},
                        {"kinetic_energy", r.kinetic_energy},
                        {"normalised_kinetic_energy", r.normalised_ke},
                        {"ke_time", r.ke_read_time},
                        {"ke_length", r.ke_length},
                        {"free_mass", r.free_mass},
                        {"max_displacement", r.max_displacement},
                        {"max_rotation", r.max_rotation},
                        {"decision_time", r.decision_time},
                        {"sim_time", r.sim_time},
                        {"steps", r.steps},
                        {"triangles", r.triangles},
                        {"dt", r.dt},
                        {"thickness", r.thickness},
                        {"friction", r.friction},
                        {"wall_s", r.wall_s},
                        {"la_admissible", r.la_admissible},
                        {"la_status", r.la_status},
                        {"disagree", r.disagrees()},
                        {"hinges", hinges_to_json(r.hinges)}};
    if (!r.error.empty()) j["error"] = r.error;
    jcells.push_back(j);
  }
  csv.close();
  if (!csv || std::rename((csv_path + ".tmp").c_str(), csv_path.c_str()) != 0)
    throw OutputError("cannot write " + csv_path);

  // Collapse modes: one JSON per collapsed cell, DIR/cell_NNNN.json.
  if (keep_modes) {
    std::error_code ec;
    std::filesystem::create_directories(opts.mode_out, ec);
    if (ec) throw OutputError("cannot create " + opts.mode_out + ": " + ec.message());
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
                 (std::filesystem::path(opts.mode_out) / name).string());
    }
  }

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

}  // namespace voussoir

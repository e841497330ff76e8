// `voussoir sweep DECK --param KEY=V1,V2,...`: capacity over a grid of deck values, cells in
// parallel, one CSV row per cell (written as each finishes, in grid order at the end).

#include "commands/sweep.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands/capacity.hpp"
#include "commands/common.hpp"
#include "core/fnv.hpp"
#include "engine/dealer.hpp"
#include "engine/grid.hpp"
#include "engine/journal.hpp"
#include "engine/setup.hpp"
#include "engine/solver_report.hpp"
#include "io/deck.hpp"
#include "io/json.hpp"
#include "io/plot.hpp"

namespace voussoir {
namespace {

// The joint indices of the hinges of one kind, as a JSON array.
nlohmann::json joint_indices(const std::vector<Hinge>& hinges, const std::string& kind) {
  nlohmann::json out = nlohmann::json::array();
  for (const Hinge& h : hinges)
    if (h.kind == kind) out.push_back(h.joint);
  return out;
}

// A cell's record: the journal's and the one sent between ranks (engine/dealer.hpp), one code
// path for the resumed, the local and the remote cells.
nlohmann::json sweep_cell_record(size_t c, const std::vector<std::string>& values,
                                 const CapacityResult& r, const std::string& error) {
  return nlohmann::json{{"cell", c},
                        {"values", values},
                        {"lambda_star", r.lambda_star},
                        {"lo", r.lo},
                        {"hi", r.hi},
                        {"bracketed", r.bracketed},
                        {"trials", r.trials.size()},
                        {"wall_s", r.wall_s},
                        {"hinge_joints", joint_indices(r.hinges, "hinge")},
                        {"sliding_joints", joint_indices(r.hinges, "sliding")},
                        {"error", error}};
}

// The result of a cell from its record (sweep_cell_record); `error` gets the cell's error.
CapacityResult sweep_cell_from_record(const nlohmann::json& j, std::string& error) {
  CapacityResult r;
  r.lambda_star = j["lambda_star"];
  r.lo = j["lo"];
  r.hi = j["hi"];
  r.bracketed = j["bracketed"];
  r.trials.resize(j["trials"].get<size_t>());
  r.wall_s = j["wall_s"];
  // The failure mode's joints (only their kind and index are tabulated).
  for (const char* kind : {"hinge", "sliding"})
    for (const nlohmann::json& jt :
         j.value(std::string(kind) + "_joints", nlohmann::json::array())) {
      Hinge h;
      h.kind = kind;
      h.joint = jt.get<int>();
      r.hinges.push_back(h);
    }
  error = j["error"];
  return r;
}

// Writes the CSV of the sweep, one row per cell in grid order, and returns the cells of the
// JSON summary.
nlohmann::json write_sweep_csv(const std::string& csv_path, const std::vector<GridAxis>& axes,
                               const std::vector<std::vector<std::string>>& cell_values,
                               const std::vector<CapacityResult>& results,
                               const std::vector<std::string>& errors) {
  GridCsv grid_csv(csv_path, 17, axes);
  std::ostream& csv = grid_csv.out();
  // One row per cell: the swept values, the result and its failure mode (hinge_joints and
  // sliding_joints: joint indices of check --mesh-out, space separated), the trials and the
  // cell's wall time. A cell taken from a --resume journal keeps its journalled wall time, so
  // a resumed sweep differs from an uninterrupted one in the wall_s of the cells it re-ran
  // only. lambda_star is empty when no trial collapsed (failure_mode says kNoCollapse; lo is
  // then the highest lambda that stood) or the cell failed (error).
  csv << "lambda_star,lo,hi,bracketed,failure_mode,hinge_joints,sliding_joints,trials,wall_s,"
         "error\n";
  nlohmann::json jcells = nlohmann::json::array();
  const nlohmann::json none(nullptr);
  for (size_t c = 0; c < results.size(); ++c) {
    const CapacityResult& r = results[c];
    const bool ok = errors[c].empty();
    const nlohmann::json params = grid_csv.cell(cell_values[c]);
    const std::string mode = ok ? failure_mode_text(r) : std::string();
    if (ok && r.bracketed) csv << r.lambda_star;
    csv << ',' << r.lo << ',';
    if (r.bracketed) csv << r.hi;
    csv << ',' << (r.bracketed ? 1 : 0) << ',' << mode << ',' << joint_list(r.hinges, "hinge")
        << ',' << joint_list(r.hinges, "sliding") << ',' << r.trials.size() << ',' << r.wall_s
        << ',' << csv_quote(errors[c]) << '\n';
    jcells.push_back({{"params", params},
                      {"lambda_star", ok && r.bracketed ? nlohmann::json(r.lambda_star) : none},
                      {"bracket", {r.lo, r.bracketed ? nlohmann::json(r.hi) : none}},
                      {"bracketed", r.bracketed},
                      {"failure_mode", mode},
                      {"hinge_joints", joint_indices(r.hinges, "hinge")},
                      {"sliding_joints", joint_indices(r.hinges, "sliding")},
                      {"trials", r.trials.size()},
                      {"wall_s", r.wall_s},
                      {"error", errors[c]}});
  }
  grid_csv.finish();
  return jcells;
}

}  // namespace

int command_sweep(const std::string& deck_path, const std::vector<std::string>& sets,
                  const CommonOptions& common, const SweepOptions& opts) {
  const auto t0 = std::chrono::steady_clock::now();
  if (opts.params.empty()) throw DeckError("sweep needs at least one --param KEY=V1,V2,...");
  std::vector<GridAxis> axes;
  for (const std::string& p : opts.params) axes.push_back(parse_grid_param(p));
  // Every cell's deck validated up front, so a bad value stops the sweep before any work.
  const Grid grid = make_grid(deck_path, sets, axes);
  for (const Config& c : grid.configs) require_gravity(c, "sweep");
  const auto loosest = std::max_element(
      grid.configs.begin(), grid.configs.end(),
      [](const Config& a, const Config& b) { return a.solver.tolerance < b.solver.tolerance; });
  warn_loose_tolerance(*loosest, "sweep", common.quiet || !is_dealer_rank());
  const size_t cells = grid.configs.size();
  const std::vector<std::vector<std::string>>& cell_values = grid.values;
  const std::vector<Config>& configs = grid.configs;

  std::vector<CapacityResult> results(cells);
  std::vector<std::string> errors(cells);
  TrialCriteria criteria = opts.criteria;
  criteria.limits = common.limits;
  criteria.quasi_static = !opts.dynamic;
  // Resume (engine/journal.hpp): one record per finished cell ({"cell": i, "values": [...],
  // result}) under the fingerprint of the deck, overrides, axes and criteria; cells found
  // there are not run again.
  Fnv print;
  fingerprint_grid(print, deck_path, sets, axes);
  print.value(opts.points);
  print.value(criteria.settle_max_time);
  if (criteria.quasi_static) print.text("quasi-static");
  Journal journal(is_dealer_rank() ? opts.resume : std::string(), print.hex());
  // A cell's record (the journal's and the one sent between ranks) and back: one code path for
  // the resumed, the local and the remote cells (engine/dealer.hpp).
  auto take_record = [&](size_t c, const nlohmann::json& j) {
    if (c >= cells || j["values"] != nlohmann::json(cell_values[c]))
      throw DeckError("--resume " + opts.resume + ": the journal belongs to another sweep");
    results[c] = sweep_cell_from_record(j, errors[c]);
  };
  CellWork work;
  work.cells = cells;
  work.finished.assign(cells, 0);
  for (const nlohmann::json& j : journal.records()) {
    if (!j.contains("cell")) continue;
    const size_t c = j["cell"];
    take_record(c, j);
    work.finished[c] = 1;
  }
  work.run = [&](size_t c, const nlohmann::json&) {
    CapacityResult r;
    std::string error;
    try {
      r = find_capacity(configs[c], criteria, opts.points, true);
    } catch (const std::exception& e) {
      error = e.what();
    }
    return sweep_cell_record(c, cell_values[c], r, error);
  };
  int done = 0;
  work.take = [&](size_t c, const nlohmann::json& record) {
    journal.append(record);
    take_record(c, record);
    const CapacityResult& r = results[c];
    ++done;
    if (!common.quiet) {
      std::fprintf(stderr, "[%d/%zu]", done, cells);
      for (size_t k = 0; k < axes.size(); ++k)
        std::fprintf(stderr, " %s=%s", axes[k].key.c_str(), cell_values[c][k].c_str());
      if (!errors[c].empty())
        std::fprintf(stderr, "  failed: %s\n", errors[c].c_str());
      else if (!r.bracketed)
        std::fprintf(stderr, "  %s = %.4f (%zu trials, %.1f s)\n", kNoCollapse, r.lo,
                     r.trials.size(), r.wall_s);
      else
        std::fprintf(stderr, "  lambda* = %.4f, %s (%zu trials, %.1f s)\n", r.lambda_star,
                     failure_mode_text(r).c_str(), r.trials.size(), r.wall_s);
    }
  };
  deal_cells(work, common.threads, common.quiet);
  if (!is_dealer_rank()) return 0;  // rank 0 writes the outputs (engine/dealer.hpp)

  const std::string csv_path = opts.csv.empty() ? "sweep.csv" : opts.csv;
  const nlohmann::json jcells = write_sweep_csv(csv_path, axes, cell_values, results, errors);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("sweep of %zu cells written to %s (%.1f s wall)\n", cells, csv_path.c_str(), wall);
  if (!common.json_path.empty())
    write_json({{"cells", jcells},
                {"csv", csv_path},
                {"ranks", rank_count()},
                {"wall_s", wall},
                {"solver", solver_json(grid.configs.front(), solver_record())}},
               common.json_path);
  if (!opts.plot.empty()) {
    draw_with_script("plot_sweep", {csv_path, "-o", opts.plot}, opts.plot);
  }
  int failed = 0;
  for (const std::string& e : errors)
    if (!e.empty()) {
      std::fprintf(stderr, "voussoir: run failed: %s\n", e.c_str());
      ++failed;
    }
  return failed > 0 ? 1 : 0;
}

// The options of `sweep` (docs/reference/commands.md).
CommandAction add_sweep_command(CLI::App& cmd, CommandLine& line) {
  auto opts = std::make_shared<SweepOptions>();
  SweepOptions& o = *opts;
  add_common(cmd, line);
  add_limit_options(&cmd, line.common.limits);
  cmd.add_option("--param", o.params, "KEY=V1,V2,... (repeat for a grid)")->required();
  cmd.add_option("--csv", o.csv, "CSV output (default sweep.csv)");
  cmd.add_option("--plot", o.plot, "PNG plot of lambda* over the grid");
  cmd.add_option("--settle-time", o.criteria.settle_max_time,
                 "longest settle under gravity before each cell's trials [s]")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd.add_flag("--dynamic", o.dynamic, "physical settle and trials: no quasi-static local damping");
  cmd.add_option("--resume", o.resume,
                 "journal of finished cells: created, or resumed after a kill");
  cmd.add_option("--points", o.points, "trial lambdas per round (default 2)")
      ->check(CLI::Range(1, 64));
  CommandAction action;
  action.run = [&line, opts] { return command_sweep(line.deck, line.sets, line.common, *opts); };
  action.dealt = [] { return true; };
  return action;
}

}  // namespace voussoir

// `voussoir sweep DECK --param KEY=V1,V2,...`: capacity over a grid of deck values, cells in
// parallel, one CSV row per cell (written as each finishes, in grid order at the end).

#include <omp.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/fnv.hpp"
#include "drivers/capacity.hpp"
#include "drivers/commands.hpp"
#include "drivers/plot.hpp"
#include "drivers/grid.hpp"
#include "drivers/journal.hpp"
#include "drivers/setup.hpp"
#include "io/deck.hpp"
#include "io/json.hpp"

namespace voussoir {

int command_sweep(const std::string& deck_path, const std::vector<std::string>& sets,
                  const CommonOptions& common, const SweepOptions& opts) {
  const auto t0 = std::chrono::steady_clock::now();
  if (opts.params.empty()) throw DeckError("sweep needs at least one --param KEY=V1,V2,...");
  std::vector<GridAxis> axes;
  for (const std::string& p : opts.params) axes.push_back(parse_grid_param(p));
  // Every cell's deck validated up front, so a bad value stops the sweep before any work.
  const Grid grid = make_grid(deck_path, sets, axes);
  const size_t cells = grid.configs.size();
  const std::vector<std::vector<std::string>>& cell_values = grid.values;
  const std::vector<Config>& configs = grid.configs;

  std::vector<CapacityResult> results(cells);
  std::vector<std::string> errors(cells);
  TrialCriteria criteria = opts.criteria;
  criteria.limits = common.limits;
  criteria.quasi_static = !opts.dynamic;
  // Resume (drivers/journal.hpp): one record per finished cell ({"cell": i, "values": [...],
  // result}) under the fingerprint of the deck, overrides, axes and criteria; cells found
  // there are not run again.
  Fnv print;
  print.text(deck_path);
  for (const std::string& set : sets) print.text(set);
  for (const GridAxis& a : axes) {
    print.text(a.key);
    for (const std::string& v : a.values) print.text(v);
  }
  print.value(opts.points);
  print.value(criteria.settle_max_time);
  if (criteria.quasi_static) print.text("quasi-static");
  Journal journal(opts.resume, print.hex());
  std::vector<bool> finished(cells, false);
  for (const nlohmann::json& j : journal.records()) {
    if (!j.contains("cell")) continue;
    const size_t c = j["cell"];
    if (c >= cells || j["values"] != nlohmann::json(cell_values[c]))
      throw DeckError("--resume " + opts.resume + ": the journal belongs to another sweep");
    CapacityResult& r = results[c];
    r.lambda_star = j["lambda_star"];
    r.lo = j["lo"];
    r.hi = j["hi"];
    r.bracketed = j["bracketed"];
    r.trials.resize(j["trials"].get<size_t>());
    r.wall_s = j["wall_s"];
    errors[c] = j["error"];
    finished[c] = true;
  }
  int done = 0;
#pragma omp parallel for schedule(dynamic, 1)
  for (long c = 0; c < static_cast<long>(cells); ++c) {
    if (finished[c]) continue;
    try {
      results[c] = find_capacity(configs[c], criteria, opts.points, true);
    } catch (const std::exception& e) {
      errors[c] = e.what();
    }
#pragma omp critical
    {
      const CapacityResult& r = results[c];
      journal.append({{"cell", c},
                      {"values", cell_values[c]},
                      {"lambda_star", r.lambda_star},
                      {"lo", r.lo},
                      {"hi", r.hi},
                      {"bracketed", r.bracketed},
                      {"trials", r.trials.size()},
                      {"wall_s", r.wall_s},
                      {"error", errors[c]}});
      ++done;
      if (!common.quiet) {
        std::fprintf(stderr, "[%d/%zu]", done, cells);
        for (size_t k = 0; k < axes.size(); ++k)
          std::fprintf(stderr, " %s=%s", axes[k].key.c_str(), cell_values[c][k].c_str());
        if (errors[c].empty())
          std::fprintf(stderr, "  lambda* = %.4f (%zu trials, %.1f s)\n", results[c].lambda_star,
                       results[c].trials.size(), results[c].wall_s);
        else
          std::fprintf(stderr, "  failed: %s\n", errors[c].c_str());
      }
    }
  }

  const std::string csv_path = opts.csv.empty() ? "sweep.csv" : opts.csv;
  std::ofstream csv(csv_path + ".tmp");
  csv.precision(17);
  if (!csv) throw OutputError("cannot write " + csv_path);
  for (const GridAxis& a : axes) csv << a.key << ',';
  // The CSV holds results only (no wall times), so a resumed sweep writes the same file as an
  // uninterrupted one; wall times are in the JSON and on stderr.
  csv << "lambda_star,lo,hi,bracketed,trials,error\n";
  nlohmann::json jcells = nlohmann::json::array();
  for (size_t c = 0; c < cells; ++c) {
    const CapacityResult& r = results[c];
    nlohmann::json params = nlohmann::json::object();
    for (size_t k = 0; k < axes.size(); ++k) {
      csv << cell_values[c][k] << ',';
      params[axes[k].key] = cell_values[c][k];
    }
    csv << r.lambda_star << ',' << r.lo << ',' << r.hi << ',' << (r.bracketed ? 1 : 0) << ','
        << r.trials.size() << ',' << '"' << errors[c] << '"' << '\n';
    jcells.push_back({{"params", params},
                      {"lambda_star", r.lambda_star},
                      {"bracket", {r.lo, r.hi}},
                      {"trials", r.trials.size()},
                      {"wall_s", r.wall_s},
                      {"error", errors[c]}});
  }
  csv.close();
  if (std::rename((csv_path + ".tmp").c_str(), csv_path.c_str()) != 0)
    throw OutputError("cannot write " + csv_path);
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("sweep of %zu cells written to %s (%.1f s wall)\n", cells, csv_path.c_str(), wall);
  if (!common.json_path.empty())
    write_json({{"cells", jcells}, {"csv", csv_path}, {"wall_s", wall}}, common.json_path);
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

}  // namespace voussoir

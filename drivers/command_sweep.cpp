// `voussoir sweep DECK --param KEY=V1,V2,...`: capacity over a grid of deck values, cells in
// parallel, one CSV row per cell (written as each finishes, in grid order at the end).

#include <omp.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "drivers/capacity.hpp"
#include "drivers/commands.hpp"
#include "drivers/setup.hpp"
#include "io/deck.hpp"
#include "io/json.hpp"

namespace voussoir {
namespace {

struct Axis {
  std::string key;
  std::vector<std::string> values;
};

Axis parse_param(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw DeckError("--param '" + text + "': expected KEY=V1,V2,...");
  Axis a;
  a.key = text.substr(0, eq);
  std::stringstream ss(text.substr(eq + 1));
  std::string v;
  while (std::getline(ss, v, ',')) {
    if (v.empty()) throw DeckError("--param '" + text + "': empty value in the list");
    a.values.push_back(v);
  }
  return a;
}

}  // namespace

int command_sweep(const std::string& deck_path, const std::vector<std::string>& sets,
                  const CommonOptions& common, const SweepOptions& opts) {
  const auto t0 = std::chrono::steady_clock::now();
  if (opts.params.empty()) throw DeckError("sweep needs at least one --param KEY=V1,V2,...");
  std::vector<Axis> axes;
  for (const std::string& p : opts.params) axes.push_back(parse_param(p));

  // The grid, row-major with the last axis fastest; every cell's deck validated up front so
  // a bad value stops the sweep before any work.
  size_t cells = 1;
  for (const Axis& a : axes) cells *= a.values.size();
  std::vector<std::vector<std::string>> cell_values(cells);
  std::vector<Config> configs;
  for (size_t c = 0; c < cells; ++c) {
    size_t rest = c;
    std::vector<std::string> cell_sets = sets;
    std::vector<std::string> vals(axes.size());
    for (size_t k = axes.size(); k-- > 0;) {
      vals[k] = axes[k].values[rest % axes[k].values.size()];
      rest /= axes[k].values.size();
      cell_sets.push_back(axes[k].key + "=" + vals[k]);
    }
    cell_values[c] = vals;
    configs.push_back(load_deck(deck_path, cell_sets));
  }

  std::vector<CapacityResult> results(cells);
  std::vector<std::string> errors(cells);
  TrialCriteria criteria = opts.criteria;
  criteria.limits = common.limits;
  // Resume: the journal holds one JSON line per finished cell ({"cell": i, "values": [...],
  // result}); cells found there with the same values are not run again.
  std::vector<bool> finished(cells, false);
  if (!opts.resume.empty()) {
    std::ifstream in(opts.resume);
    for (std::string line; std::getline(in, line);) {
      const auto j = nlohmann::json::parse(line, nullptr, false);
      if (j.is_discarded() || !j.contains("cell")) continue;  // cut by a kill: run it again
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
  }
  std::ofstream journal;
  if (!opts.resume.empty()) journal.open(opts.resume, std::ios::app);
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
      if (journal.is_open()) {
        const CapacityResult& r = results[c];
        journal << nlohmann::json{{"cell", c},
                                  {"values", cell_values[c]},
                                  {"lambda_star", r.lambda_star},
                                  {"lo", r.lo},
                                  {"hi", r.hi},
                                  {"bracketed", r.bracketed},
                                  {"trials", r.trials.size()},
                                  {"wall_s", r.wall_s},
                                  {"error", errors[c]}}
                       .dump()
                << '\n'
                << std::flush;
      }
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
  for (const Axis& a : axes) csv << a.key << ',';
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
    const std::string cmd = std::string("/usr/bin/python3 ") + VOUSSOIR_SOURCE_DIR +
                            "/scripts/plot_sweep '" + csv_path + "' -o '" + opts.plot + "'";
    if (std::system(cmd.c_str()) != 0)
      std::fprintf(stderr, "voussoir: warning: the plot %s could not be drawn\n",
                   opts.plot.c_str());
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

#include "engine/solver_report.hpp"

#include <cstdio>
#include <mutex>

namespace voussoir {

namespace {

std::mutex g_mutex;
NscdStats g_record;

}  // namespace

void note_solver_runs(const NscdStats& end, const NscdStats& start) {
  if (end.steps == start.steps) return;
  const std::lock_guard<std::mutex> lock(g_mutex);
  // The run's largest values are those of the whole simulation, whose history before this
  // run (a copied settled state) is part of the command's record anyway.
  g_record.add_run(end, start);
}

nlohmann::json solver_runs_since(const NscdStats& start) {
  return {{"start", start.numbers()}, {"end", solver_record().numbers()}};
}

void note_solver_runs(const nlohmann::json& runs) {
  note_solver_runs(NscdStats::from_numbers(runs.at("end").get<std::vector<double>>()),
                   NscdStats::from_numbers(runs.at("start").get<std::vector<double>>()));
}

NscdStats solver_record() {
  const std::lock_guard<std::mutex> lock(g_mutex);
  return g_record;
}

void reset_solver_record() {
  const std::lock_guard<std::mutex> lock(g_mutex);
  g_record = NscdStats{};
}

nlohmann::json solver_json(const Config& config, const NscdStats& r) {
  if (config.solver.scheme != "nscd") return {{"scheme", config.solver.scheme}};
  const double share = r.steps > 0 ? double(r.unconverged_steps) / double(r.steps) : 0.0;
  return {{"scheme", "nscd"},
          {"theta", config.solver.theta},
          {"tolerance", config.solver.tolerance},
          {"max_iterations", config.solver.max_iterations},
          {"steps", r.steps},
          {"iterations_mean", r.steps > 0 ? double(r.iterations) / double(r.steps) : 0.0},
          {"iterations_max", r.max_iterations},
          {"cone_steps", r.cone_steps},
          {"cone_products", r.cone_products},
          {"factorisations", r.factorisations},
          {"unconverged_steps", r.unconverged_steps},
          {"unconverged_share", share},
          {"max_residual", r.max_residual},
          {"max_interpenetration", r.max_penetration},
          {"converged", !(share > kUnconvergedShare)}};
}

bool warn_unconverged(const Config& config, const NscdStats& r, bool quiet) {
  if (config.solver.scheme != "nscd" || r.steps == 0) return false;
  const double share = double(r.unconverged_steps) / double(r.steps);
  if (!(share > kUnconvergedShare)) return false;
  if (!quiet)
    std::fprintf(stderr,
                 "warning: the contact solver stopped at solver.max_iterations = %d before "
                 "solver.tolerance = %g on %lld of %lld steps (%.1f%%, more than %.0f%%; largest "
                 "residual %.3g): raise solver.max_iterations or solver.tolerance, or shorten "
                 "solver.dt\n",
                 config.solver.max_iterations, config.solver.tolerance, r.unconverged_steps,
                 r.steps, 100.0 * share, 100.0 * kUnconvergedShare, r.max_residual);
  return true;
}

bool tolerance_too_loose_for_rest(const Config& config) {
  return config.solver.scheme == "nscd" && config.solver.tolerance > SolverConfig{}.tolerance;
}

bool warn_loose_tolerance(const Config& config, const char* command, bool quiet) {
  if (!tolerance_too_loose_for_rest(config)) return false;
  const double converged = SolverConfig{}.tolerance;
  if (!quiet)
    std::fprintf(stderr,
                 "warning: %s: solver.tolerance = %g is looser than the default %g: a stable "
                 "structure can creep at it, and a trial that neither comes to rest nor falls "
                 "counts as a collapse, so lambda* can come out low\n",
                 command, config.solver.tolerance, converged);
  return true;
}

}  // namespace voussoir

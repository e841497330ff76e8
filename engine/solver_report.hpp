#pragma once
// What the non-smooth contact solver did over a command's runs (docs/nscd.md "Never silent"):
// its record in the JSON, and a warning on stderr when too many steps stopped unconverged.
//
// Every run of the engine (engine/trial.hpp run_engine) adds the record of its own steps to
// one record of the process (note_solver_runs), which the commands write: the settle, each
// trial, pulse run and cell alike. Sums and largest values do not depend on the order in which
// threads add them. Under MPI each rank keeps its own, and each of ranks 1 to N-1 sends rank 0
// what its cells added (solver_runs_since) when it stops (engine/dealer.cpp): the JSON of
// rank 0 holds every rank's cells.

#include <nlohmann/json.hpp>
#include <string>

#include "contact/nscd.hpp"
#include "core/schema.hpp"

namespace voussoir {

// Share of a command's steps that may stop at solver.max_iterations before it says so (on
// stderr and as "converged": false in the JSON's "solver").
inline constexpr double kUnconvergedShare = 0.01;

// Adds the steps of one run (its record at the end less the one at its start).
void note_solver_runs(const NscdStats& end, const NscdStats& start);
// What the runs since the record `start` added, as JSON ({"start": ..., "end": ...}, the
// records' fields), and its addition to this process's record (the message of an MPI rank).
nlohmann::json solver_runs_since(const NscdStats& start);
void note_solver_runs(const nlohmann::json& runs);
// The process's record so far, and its reset (tests, and commands that run twice).
NscdStats solver_record();
void reset_solver_record();

// {"scheme": "nscd", "theta", "tolerance", "max_iterations", "steps", "iterations_mean",
//  "iterations_max", "cone_steps", "cone_products", "factorisations", "unconverged_steps",
//  "unconverged_share", "max_residual", "max_interpenetration", "converged"}; {"scheme":
//  "explicit"} for the explicit scheme.
nlohmann::json solver_json(const Config& config, const NscdStats& record);

// Prints the warning on stderr when more than kUnconvergedShare of the steps stopped at the
// cap (unless quiet); true when they did.
bool warn_unconverged(const Config& config, const NscdStats& record, bool quiet);

// Under nscd a solver.tolerance above the default lets a stable structure creep, and a
// capacity trial that neither comes to rest nor falls counts as a collapse, so lambda* can come
// out low (docs/nscd.md, "Capacity, sweeps, maps and pulses"). True when `config` is so.
bool tolerance_too_loose_for_rest(const Config& config);
// Prints a warning on stderr for the capacity searches of `command` when it is (unless quiet);
// true when the tolerance is looser.
bool warn_loose_tolerance(const Config& config, const char* command, bool quiet);

}  // namespace voussoir

#pragma once
// Gravity-only stability maps (docs/reference/commands.md, `voussoir stability`; docs/stability.md
// "Gilbert arch stability map").
//
// A cell of the map is one deck (the base deck with the cell's `--param` values applied) run
// from rest under gravity alone (load.lambda and any base motion switched off):
//   1. gravity is ramped from 0 to g over `ramp_time` (a ramp, not a step, as in capacity's
//      settle: a step overshoots the static contact response and would open joints);
//   2. the cell is classified with the thresholds of a capacity trial (commands/capacity.hpp,
//      TrialCriteria defaults, measured from the initial, unloaded geometry):
//        collapsed as soon as any free block's centroid has moved more than
//          collapse_displacement x L_ref (0.05 L_ref) or rotated more than collapse_rotation
//          (0.05 rad), L_ref = square root of the smallest free block area;
//        stable as soon as, after the ramp, the largest free-node speed has stayed below
//          rest_speed x sqrt(g L_ref) for hold_time and the kinetic energy has not grown over
//          that window (capacity's rest rule: peak of its second half <= peak of its first);
//        otherwise at `max_time` (3 s of simulated time from the start): collapsed if the motion
//          measure max(d / d_collapse, |rotation| / rot_collapse) at the end exceeds by 10% its
//          largest value over the first two thirds of the run, stable otherwise ("timeout").
//   3. the normalised kinetic energy KE / (M g L) is read at `ke_time` (1 s by default, from the
//      start of the gravity ramp), M the free mass and L the reference length of the scene
//      (`ke_length`: the centreline radius Rc for arches, the height of the free blocks'
//      bounding box for other scenes). It is the fraction of the potential energy of a drop
//      of L that has turned into motion. Every cell runs at least to `ke_time`, whenever it
//      was classified (a collapsed cell runs on after crossing the threshold, a cell found at
//      rest is followed to ke_time), so the energies of all cells are read at the same time.
//   4. cross-check: rigid-block limit analysis (limit/limit_analysis.hpp, gravity only) on the
//      same blocks says whether an admissible equilibrium exists; `disagree` flags cells where
//      the FDEM classification differs from it. Limit analysis assumes associative friction and
//      rigid blocks, so near the friction threshold (sliding) it may call admissible a cell that
//      collapses by non-associative sliding.
//
// Cells run in parallel (OpenMP over cells, dynamic schedule); each cell is a serial
// simulation, so results do not depend on the thread count.

#include <string>
#include <vector>

#include "commands/capacity.hpp"
#include "commands/common.hpp"
#include "core/model.hpp"
#include "core/schema.hpp"
#include "engine/grid.hpp"
#include "engine/journal.hpp"
#include "engine/kinematics.hpp"

namespace voussoir {

struct StabilityCriteria {
  TrialCriteria trial;   // thresholds shared with capacity (ramp, collapse, rest, max_time)
  double ke_time = 1.0;  // [s] from the start of the gravity ramp
};

struct StabilityCell {
  std::vector<std::string> values;  // per axis, as in GridAxis::values
  double thickness = 0.0;           // model.thickness of the cell [m]
  double radius = 0.0;              // model.radius of the cell [m]
  double friction = 0.0;            // contact.friction of the cell
  bool stable = false;
  std::string reason;                      // "rest", "displacement", "rotation", "timeout", "error"
  double kinetic_energy = 0.0;             // [J per out_of_plane] at ke_time
  double normalised_kinetic_energy = 0.0;  // kinetic_energy / (M g L)
  double ke_time = 0.0;                    // [s] when the kinetic energy was read
  double ke_length = 0.0;                  // L [m]
  double free_mass = 0.0;                  // M [kg]
  double max_displacement = 0.0;           // largest block centroid displacement at the end [m]
  double max_rotation = 0.0;               // largest block rotation at the end [rad]
  double decision_time = 0.0;              // [s] simulated when the classification was made
  double sim_time = 0.0;                   // [s] simulated in total
  long long steps = 0;
  double wall_s = 0.0;
  Index triangles = 0;
  double dt = 0.0;             // [s]
  double l_ref = 0.0;          // [m]
  bool la_admissible = false;  // limit analysis: admissible equilibrium under gravity
  std::string la_status;       // limit analysis status ("optimal"/"infeasible"/...)
  std::string error;           // non-empty when the cell failed
  std::vector<Hinge> hinges;   // collapsed cells: joints open or sliding at the end
  // Kept when asked (mode pictures): block outlines at the end of the run (reference polygon
  // moved by the block's rigid motion) and the reference outlines.
  std::vector<std::vector<Vec2>> outlines, outlines0;
  std::vector<bool> fixed;  // per block
  bool disagrees() const { return error.empty() && stable != la_admissible; }
};

// Length L of the kinetic-energy normalisation for this deck (see the top of this file).
double stability_ke_length(const Config& config, const Model& model);

// Runs one cell (the deck as given, lambda and base motion ignored); `keep_mode` keeps the
// block outlines at the end. Throws RunError from the engine's guards (non-finite state,
// energy balance), naming the cell by `cell_label` (its --param values).
StabilityCell run_stability_cell(const Config& config, const StabilityCriteria& criteria,
                                 bool keep_mode, const std::string& cell_label = "");

// The limit-analysis cross-check of one cell (fills la_admissible and la_status). GLPK is not
// assumed thread-safe: call it outside parallel regions.
void check_limit_admissibility(const Config& config, StabilityCell& cell);

// Runs every cell of the grid, in parallel over cells on `threads` threads (0 = OpenMP
// default), then the limit-analysis cross-checks. `keep_modes` keeps the outlines of
// collapsed cells. Progress lines on stderr unless quiet. A failing cell is reported in its
// `error`, the others still run.
// With a `journal` (engine/journal.hpp; `stability --resume FILE`), cells found there are
// taken from it, bit for bit, and each cell run is appended as it finishes.
std::vector<StabilityCell> run_stability_map(const Grid& grid, const StabilityCriteria& criteria,
                                             int threads, bool keep_modes, bool quiet,
                                             Journal* journal = nullptr);

// Block outlines as JSON: one array of [x, y] per block (journal records and --mode-out).
nlohmann::json outlines_record(const std::vector<std::vector<Vec2>>& outlines);

// A cell as a journal record and back (every field, 17 significant digits).
nlohmann::json stability_cell_record(const StabilityCell& cell);
StabilityCell stability_cell_from_record(const nlohmann::json& record);

struct StabilityOptions {
  std::vector<std::string> params;  // --param KEY=V1,V2,... or KEY=start:stop:step
  std::string csv;                  // --csv FILE (default stability.csv)
  std::string plot;                 // --plot FILE.png (scripts/plot_stability)
  std::string mode_out;             // --mode-out DIR: outlines of every collapsed cell
  double ke_time = 1.0;             // --ke-time [s]
  double max_time = 3.0;            // --max-time [s]
  std::string resume;               // --resume FILE: journal of finished cells
};

int command_stability(const std::string& deck_path, const std::vector<std::string>& sets,
                      const CommonOptions& common, const StabilityOptions& opts);

// Registers the options of `stability` on `cmd` (commands/table.cpp).
CommandAction add_stability_command(CLI::App& cmd, CommandLine& line);

}  // namespace voussoir

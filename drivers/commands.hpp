#pragma once
// The subcommands of the voussoir program (SPEC.md section 2). Each takes the validated deck
// and its options, prints a human summary on stdout, progress on stderr, and writes the JSON
// summary when asked. Errors: DeckError (exit 2), RunError (exit 1).

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/model.hpp"
#include "drivers/capacity.hpp"
#include "drivers/kinematics.hpp"
#include "core/schema.hpp"

namespace voussoir {

struct CommonOptions {
  std::string json_path;     // --json FILE ("" = none, "-" = stdout)
  int threads = 0;           // --threads N (0 = OpenMP default)
  bool quiet = false;        // no progress on stderr
  RunLimits limits;          // the engine's limits (add_limit_options, drivers/trial.hpp)
};

struct CheckOptions {
  std::string mesh_out;      // --mesh-out FILE: model geometry as JSON (for scripts/draw)
};

// The meshed model as JSON for scripts/draw: nodes (current positions), triangles, tri_block,
// blocks (fixed, role, name: the gmsh physical name or "", polygon), joints.
nlohmann::json model_geometry_json(const Model& model);

// The deformed model for pictures of a failure mode: model_geometry_json of the current state
// with every block outline moved by its rigid motion, the reference outlines under
// "reference_blocks", and the hinges (pivot moved with its block) under "hinges".
nlohmann::json failure_mode_json(const Model& model, const std::vector<Hinge>& hinges);

nlohmann::json hinges_to_json(const std::vector<Hinge>& hinges);

// Every block outline moved by its block's rigid motion (block_motions) and as drawn in the
// reference configuration, as JSON polygons [[x, y], ...], block by block.
struct MovedOutlines {
  std::vector<BlockMotion> motions;
  nlohmann::json moved, reference;
};
MovedOutlines moved_outlines(const Model& model);

// --picture of `run` and `pulse`: the blocks of `sim` as they are (true displacements), the
// reference outlines dashed, the line of thrust of this state, and the hinges (joints opened by
// more than kHingeFraction x L_ref that still carry a force: blocks that have fallen apart are
// not hinged), under `title`. A drawing that fails is a warning (drivers/plot.hpp).
void draw_current_state(const Simulation& sim, const std::string& title,
                        const std::string& picture);

// A capacity search in which no trial collapsed has no lambda*: the commands say so in these
// words (text, JSON "result", sweep CSV "failure_mode"), with the highest lambda that stood.
inline constexpr const char* kNoCollapse = "no collapse up to lambda_max";

// The failure mode of a finished capacity search in words: "hinging", "sliding",
// "hinging and sliding", kNoCollapse, or "none found" (a collapse without an open or slid
// joint at the end of the trial).
std::string failure_mode_text(const CapacityResult& result);

// The joint indices of the hinges of one kind ("hinge" or "sliding"), space separated.
std::string joint_list(const std::vector<Hinge>& hinges, const std::string& kind);

// The analyses whose loads are multiples of the blocks' weight (lambda g, a base amplitude in g,
// the friction that the weight presses into the joints) refuse load.gravity = 0 by name
// (exit 2): `command` would find nothing to measure. `check` and `run` accept it (a weightless
// run: a base record in m/s2 still drives it).
inline void require_gravity(const Config& config, const std::string& command) {
  if (!(config.load.gravity > 0.0))
    throw DeckError(config.deck_path + ": load.gravity = " + option_number(config.load.gravity) +
                    ": `" + command +
                    "` needs gravity > 0 (its loads are multiples of the blocks' weight; only "
                    "`check` and `run` take a weightless deck)");
}

int command_check(const Config& config, const CommonOptions& common, const CheckOptions& opts);

struct RunOptions {
  std::string output;        // -o FILE: HDF5 output (overrides output.file)
  // Checkpoint and restart (io/checkpoint.hpp, docs/robustness.md):
  double checkpoint_every = 0.0;  // --checkpoint-every T: every T s of simulated time; 0 = never
  std::string checkpoint;    // --checkpoint FILE (default OUTPUT.ckpt, else DECKNAME.ckpt)
  std::string restart;       // --restart FILE: continue the run saved in FILE
  std::string picture;       // --picture FILE.png|svg: the final state with its line of thrust
};

int command_run(const Config& config, const CommonOptions& common, const RunOptions& opts);

struct Simulation;
struct SetupInfo;
// The body of command_run on a simulation already built by make_simulation(config, &info)
// (tests inject a state or a time step here).
int run_simulation(Simulation& sim, const SetupInfo& info, const Config& config,
                   const CommonOptions& common, const RunOptions& opts);

}  // namespace voussoir

namespace voussoir {

struct CapacityOptions {
  int points = 2;            // trial lambdas per bisection round (k-section with k = points+1)
  bool no_seed = false;      // --no-seed: do not start from the limit-analysis bracket
  std::string resume;        // --resume FILE: journal of finished trials (created if absent)
  std::string mode_out;      // --mode-out FILE.json: deformed state of the collapse with hinges
  std::string picture;       // --picture FILE.png|svg: the same drawn by scripts/draw
  std::string movie;         // --movie FILE.gif|mp4: the collapsed trial at the upper bound
  TrialCriteria criteria;    // --ramp-time, --rest-speed, ... (docs/capacity.md)
  bool dynamic = false;      // --dynamic: no quasi-static damping (the physical trials)
  std::string direction = "+x";  // --direction +x | -x | both
};

int command_capacity(const Config& config, const CommonOptions& common,
                     const CapacityOptions& opts);

}  // namespace voussoir

namespace voussoir {

struct SweepOptions {
  std::vector<std::string> params;   // --param KEY=V1,V2,... (several make a grid)
  std::string csv;                   // --csv FILE (default: sweep.csv)
  std::string plot;                  // --plot FILE.png (drawn by scripts/plot_sweep)
  std::string resume;                // --resume FILE: journal of finished cells
  int points = 2;
  TrialCriteria criteria;            // --settle-time (the other trial criteria: defaults)
  bool dynamic = false;              // --dynamic, as for capacity
};

// Runs capacity over the grid; `deck_path` and `sets` rebuild the deck per cell.
int command_sweep(const std::string& deck_path, const std::vector<std::string>& sets,
                  const CommonOptions& common, const SweepOptions& opts);

}  // namespace voussoir

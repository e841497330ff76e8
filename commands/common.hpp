#pragma once
// What the subcommands of the voussoir program share (docs/reference/commands.md): the common
// options, the command table that app/main.cpp reads, and the drawings and JSON pieces several
// commands write. Each command takes the validated deck and its options, prints a human summary
// on stdout, progress on stderr, and writes the JSON summary when asked. Errors: DeckError
// (exit 2), RunError (exit 1).

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/model.hpp"
#include "core/schema.hpp"
#include "engine/kinematics.hpp"
#include "engine/trial.hpp"

namespace CLI {
class App;
}

namespace voussoir {

struct CommonOptions {
  std::string json_path;  // --json FILE ("" = none, "-" = stdout)
  int threads = 0;        // --threads N (0 = OpenMP default)
  bool quiet = false;     // no progress on stderr
  RunLimits limits;       // the engine's limits (add_limit_options, engine/trial.hpp)
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
// not hinged), under `title`. A drawing that fails is a warning (io/plot.hpp).
void draw_current_state(const Simulation& sim, const std::string& title,
                        const std::string& picture);

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

// The deck a command reads and its --set overrides, then the options every deck command
// takes (add_common), filled by the parse.
struct CommandLine {
  std::string deck;
  std::vector<std::string> sets;
  CommonOptions common;
};

// Registers on `cmd` the options every deck command takes: the deck, --set, --threads, --json,
// --quiet.
void add_common(CLI::App& cmd, CommandLine& line);

// The validated deck of `line` (io/deck.hpp load_deck with the --set overrides).
Config load_command_deck(const CommandLine& line);

// The folders of the output files named on the command line, created before the command
// runs: a missing folder then neither fails a search at its end, with its results lost, nor
// asks for a `mkdir` first. A folder that cannot be made is bad input (DeckError, exit 2)
// naming the option and the path.
void make_output_folders(const CLI::App& cmd);

// How a parsed command runs: `run` does the work and returns the exit status; `dealt` says
// whether it deals its cells to the ranks of mpirun (then every rank runs it; otherwise rank 0
// alone). Empty `dealt`: rank 0 alone.
struct CommandAction {
  std::function<int()> run;
  std::function<bool()> dealt;
};

// One subcommand: its name and help line, and `add`, which registers its options on the CLI11
// subcommand `cmd` (bound to storage the returned action owns) and returns the action.
struct Command {
  const char* name;
  const char* help;
  CommandAction (*add)(CLI::App& cmd, CommandLine& line);
};

// Runs a parsed command (`cmd` its CLI11 subcommand, `line` and `action` what its `add`
// filled): makes the folders of its output files, sets the OpenMP threads of --threads, starts
// the solver's record afresh (the JSON's "solver" is this command's) and returns the action's
// exit status. The program (app/main.cpp) and the Python module (python/module.cpp) alike.
int run_parsed_command(const CLI::App& cmd, const CommandLine& line, const CommandAction& action);

// Every subcommand, in the order of `voussoir --help` (commands/table.cpp).
const std::vector<Command>& command_table();

}  // namespace voussoir

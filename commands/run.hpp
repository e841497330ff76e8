#pragma once
// `voussoir run DECK` (docs/reference/commands.md): one simulation, its HDF5 output and JSON
// summary, checkpoints and restart.

#include <string>
#include <vector>

#include "commands/common.hpp"
#include "core/schema.hpp"

namespace voussoir {

struct RunOptions {
  std::string output;  // -o FILE: HDF5 output (overrides output.file)
  // Checkpoint and restart (engine/checkpoint.hpp, docs/robustness.md):
  double checkpoint_every = 0.0;  // --checkpoint-every T: every T s of simulated time; 0 = never
  std::string checkpoint;         // --checkpoint FILE (default OUTPUT.ckpt, else DECKNAME.ckpt)
  std::string restart;            // --restart FILE: continue the run saved in FILE
  std::string picture;            // --picture FILE.png|svg: the final state with its line of thrust
};

int command_run(const Config& config, const CommonOptions& common, const RunOptions& opts);

struct Simulation;
struct SetupInfo;
// The body of command_run on a simulation already built by make_simulation(config, &info)
// (tests inject a state or a time step here).
int run_simulation(Simulation& sim, const SetupInfo& info, const Config& config,
                   const CommonOptions& common, const RunOptions& opts);

// Registers the options of `run` on `cmd` (commands/table.cpp).
CommandAction add_run_command(CLI::App& cmd, CommandLine& line);

}  // namespace voussoir

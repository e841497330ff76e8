#pragma once
// `voussoir sweep DECK --param KEY=V1,V2,...` (docs/reference/commands.md): the capacity search
// of commands/capacity.hpp over a grid of deck values, one CSV row per cell.

#include <string>
#include <vector>

#include "commands/common.hpp"
#include "core/schema.hpp"
#include "engine/load_trial.hpp"

namespace voussoir {

struct SweepOptions {
  std::vector<std::string> params;  // --param KEY=V1,V2,... (several make a grid)
  std::string csv;                  // --csv FILE (default: sweep.csv)
  std::string plot;                 // --plot FILE.png (drawn by scripts/plot_sweep)
  std::string resume;               // --resume FILE: journal of finished cells
  int points = 2;
  TrialCriteria criteria;  // --settle-time (the other trial criteria: defaults)
  bool dynamic = false;    // --dynamic, as for capacity
};

// Runs capacity over the grid; `deck_path` and `sets` rebuild the deck per cell.
int command_sweep(const std::string& deck_path, const std::vector<std::string>& sets,
                  const CommonOptions& common, const SweepOptions& opts);

// Registers the options of `sweep` on `cmd` (commands/table.cpp).
CommandAction add_sweep_command(CLI::App& cmd, CommandLine& line);

}  // namespace voussoir

#pragma once
// `voussoir check DECK` (docs/reference/commands.md): validates the deck and prints the model
// summary; --mesh-out writes the meshed model as JSON.

#include <string>
#include <vector>

#include "commands/common.hpp"
#include "core/schema.hpp"

namespace voussoir {

struct CheckOptions {
  std::string mesh_out;  // --mesh-out FILE: model geometry as JSON (for scripts/draw)
};

int command_check(const Config& config, const CommonOptions& common, const CheckOptions& opts);

// Registers the options of `check` on `cmd` (commands/table.cpp).
CommandAction add_check_command(CLI::App& cmd, CommandLine& line);

}  // namespace voussoir

#pragma once
// `voussoir limit DECK`: rigid-block limit analysis of the deck's model (limit/).

#include <string>

#include "commands/common.hpp"
#include "core/schema.hpp"

namespace voussoir {

struct LimitCommandOptions {
  bool gravity_only = false;  // --gravity-only: admissibility under self-weight alone
  std::string mechanism_out;  // --mechanism-out FILE: geometry + mechanism JSON (scripts/draw)
  std::string thrust;         // --thrust min|max: the least / greatest support thrust ("": off)
  // --open-joints closed|points: with [supports] moves, the joints that opened taken as closed
  // over their face, or as point contacts at their pivots (commands/capacity.hpp OpenJoints)
  std::string open_joints = "closed";
};

int command_limit(const Config& config, const CommonOptions& common,
                  const LimitCommandOptions& opts);

// Registers the options of `limit` on `cmd` (commands/table.cpp).
CommandAction add_limit_command(CLI::App& cmd, CommandLine& line);

}  // namespace voussoir

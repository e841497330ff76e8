// voussoir: the command-line program. Registers every subcommand of the command table
// (commands/table.cpp) with CLI11, parses the arguments and runs the parsed command. Exit
// status (docs/reference/commands.md): 0 success, 2 bad deck or arguments, 1 failure during a
// run.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <optional>
#include <utility>
#include <vector>

#include "commands/common.hpp"
#include "engine/dealer.hpp"
#include "voussoir/config.hpp"

int main(int argc, char** argv) {
  // MPI, when launched by mpirun or srun (engine/dealer.hpp): for the life of main().
  std::optional<voussoir::Ranks> ranks;
  try {
    ranks.emplace(argc, argv);
  } catch (const std::exception& e) {
    if (voussoir::is_dealer_rank()) std::fprintf(stderr, "voussoir: error: %s\n", e.what());
    return 1;
  }
  // Under mpirun only rank 0 prints (messages and errors alike).
  const bool speaks = voussoir::is_dealer_rank();
  CLI::App app{"voussoir " VOUSSOIR_VERSION
               " - collapse capacity of dry-joint masonry arches by FDEM"};
  app.require_subcommand(1);
  app.set_version_flag("--version", VOUSSOIR_VERSION);

  voussoir::CommandLine line;
  std::vector<std::pair<CLI::App*, voussoir::CommandAction>> commands;
  for (const voussoir::Command& command : voussoir::command_table()) {
    CLI::App* cmd = app.add_subcommand(command.name, command.help);
    commands.emplace_back(cmd, command.add(*cmd, line));
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (!speaks) return e.get_exit_code() == 0 ? 0 : 2;
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }

  try {
    for (const auto& [cmd, action] : commands) {
      if (!cmd->parsed()) continue;
      // Under mpirun the commands that deal their cells run on every rank; the others on
      // rank 0 alone.
      const bool dealt = action.dealt && action.dealt();
      if (!dealt && !speaks) return 0;
      return voussoir::run_parsed_command(*cmd, line, action);
    }
  } catch (const voussoir::DeckError& e) {
    if (speaks) std::fprintf(stderr, "voussoir: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {  // RunError and the rest: a failure during a run
    if (speaks) std::fprintf(stderr, "voussoir: run failed: %s\n", e.what());
    return 1;
  }
  return 2;
}

// `voussoir keys`: the deck reference on stdout (commands/keys.hpp).

#include "commands/keys.hpp"

#include <CLI/CLI.hpp>
#include <cstdio>

#include "io/deck_reference.hpp"

namespace voussoir {

CommandAction add_keys_command(CLI::App& cmd, CommandLine& line) {
  CommandAction action;
  action.run = [] {
    std::fputs(deck_reference_markdown().c_str(), stdout);
    return 0;
  };
  return action;
}

}  // namespace voussoir

#pragma once
// `voussoir keys` (docs/reference/commands.md): prints the deck reference, every key with its
// type, unit, default and allowed values (io/deck_reference.hpp; docs/reference/deck.md).

#include <string>
#include <vector>

#include "commands/common.hpp"
#include "core/schema.hpp"

namespace voussoir {

// Registers the options of `keys` on `cmd` (commands/table.cpp).
CommandAction add_keys_command(CLI::App& cmd, CommandLine& line);

}  // namespace voussoir

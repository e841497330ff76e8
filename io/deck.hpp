#pragma once
// Deck reading and validation (the keys: docs/reference/deck.md). Every failure throws
// DeckError with one line naming the key, the value and what is allowed (or the file, line and
// column of a TOML syntax error); the program turns it into exit status 2.

#include <stdexcept>
#include <string>
#include <vector>

#include "core/schema.hpp"

namespace voussoir {

// (DeckError: core/schema.hpp.)

// Reads the deck file, applies the `--set KEY=VALUE` overrides (dotted paths, same
// validation as the file), validates every key and returns the result.
Config load_deck(const std::string& path, const std::vector<std::string>& overrides = {});

// Same from text already in memory; `source` names it in messages; `deck_dir` resolves
// relative paths.
Config parse_deck(const std::string& text, const std::string& source,
                  const std::vector<std::string>& overrides = {},
                  const std::string& deck_dir = ".");

// Every dotted key the deck accepts (model.kind, load.base.signal, ...), in the reader's
// order.
const std::vector<std::string>& known_keys();

// One deck key as the reference shows it, all from the key's row of the key table
// (io/deck.cpp): what its reader accepts, as its error messages say it: type ("number",
// "integer", "string", "array", ...), unit ("m", "Pa", ... or empty) and the allowed values ("a
// number in (0, 360)", "one of \"strain\", \"stress\"", ...); its default, the field of a
// default-constructed Config (core/schema.hpp) as a deck writes it, or "required", "required by
// kind ...", "none"; and one line of meaning. Throws std::invalid_argument for an unknown key.
// The deck reference (io/deck_reference.hpp) is built from it.
struct KeyRule {
  std::string type, unit, allowed;
  std::string default_value;
  std::string meaning;
};
KeyRule describe_key(const std::string& key);

}  // namespace voussoir

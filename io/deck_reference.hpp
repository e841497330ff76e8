#pragma once
// The deck reference for users (docs/reference/deck.md, printed by `voussoir keys`): every key
// the deck reader accepts with its type, unit, default, allowed values and one line of meaning.
//
// Every column comes from the key table of the deck reader (io/deck.cpp, through
// known_keys and describe_key), so the reference cannot drift from the code:
//   - the keys, types, units, allowed values: each key's reader, run on a value it refuses;
//   - the defaults: the key's field of a default-constructed Config (core/schema.hpp);
//   - which kinds need a key: the scene-kind registry (core/scene_kinds.hpp);
//   - the meaning: the line of the key's row.
// The DeckReference tests fail naming a key without a meaning, default, type or rule, and when
// docs/reference/deck.md differs from `voussoir keys`.

#include <string>
#include <vector>

namespace voussoir {

struct KeyReference {
  std::string key;            // dotted: model.radius
  std::string type;           // "number", "integer", "string", "array", ...
  std::string unit;           // "m", "Pa", ... or empty
  std::string default_value;  // as a deck would write it, or "required" / "none"
  std::string allowed;        // the reader's rule, as its error message states it
  std::string meaning;        // one line
};

// One entry per key the deck reader accepts, in the reader's order.
std::vector<KeyReference> deck_reference();

// docs/reference/deck.md: the reference as Markdown, one table per section.
std::string deck_reference_markdown();

}  // namespace voussoir

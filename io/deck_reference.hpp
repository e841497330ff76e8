#pragma once
// The deck reference for users (docs/reference/deck.md, printed by `voussoir keys`): every key
// the deck reader accepts with its type, unit, default, allowed values and one line of meaning.
//
// Where each column comes from, so the reference cannot drift from the code:
//   - the keys, types, units and allowed values: the deck reader itself (io/deck.hpp
//     known_keys and describe_key: each key's reader run on a value it refuses);
//   - the defaults: a default-constructed Config (core/schema.hpp), printed per key;
//   - which kinds need a key: the scene-kind registry (core/scene_kinds.hpp);
//   - the meaning: one line per key in io/deck_reference.cpp, the only hand-written column.
// The DeckReference tests (tests/unit/test_tools.cpp) fail naming any key the reader accepts
// without a line there, and when docs/reference/deck.md differs from `voussoir keys`.

#include <string>
#include <vector>

namespace voussoir {

struct KeyReference {
  std::string key;            // dotted: "model.radius"
  std::string type;           // "number", "integer", "string", "array", ...
  std::string unit;           // "m", "Pa", ... or empty
  std::string default_value;  // as a deck would write it, or "required" / "none"
  std::string allowed;        // the reader's rule, as its error message states it
  std::string meaning;        // one line; empty when io/deck_reference.cpp has none
};

// One entry per key the deck reader accepts, in the reader's order.
std::vector<KeyReference> deck_reference();

// Keys that have a line of meaning in io/deck_reference.cpp but that the reader does not
// accept (a key renamed or removed in the reader and not here).
std::vector<std::string> stale_reference_keys();

// docs/reference/deck.md: the reference as Markdown, one table per section.
std::string deck_reference_markdown();

}  // namespace voussoir

// Deck reading and validation: the key table (every deck key, its reader, its default and its
// meaning; printed as docs/reference/deck.md by `voussoir keys`) and the walk of a deck.
//
// How a deck becomes a Config:
//   1. the text is parsed by toml++ (a syntax error becomes "FILE:LINE:COL: TOML syntax error");
//   2. each `--set KEY=VALUE` is parsed as a TOML value (a bare word that is not valid TOML is
//      taken as a string) and inserted at its dotted path, replacing what the file said, so the
//      overrides go through exactly the same validation as the file;
//   3. the table is walked: every key must be a row of key_table() below (an unknown one is
//      reported with the nearest known key by edit distance); each key's reader checks the
//      type and the range and stores the value;
//   4. cross-key checks run last (required keys, lambda_min < lambda_max, input files exist).
// The first problem found throws DeckError with one line: where (file:line:column, or
// "--set"), the dotted key, the value as written and what is allowed.
//
// Decisions:
//   - integers are accepted where a number is expected; a float (even 3.0) is refused where an
//     integer is required, because a fractional count is almost always a typing slip;
//   - nan and inf are refused everywhere;
//   - relative `model.file` and `load.base.file` from the deck file are resolved against the
//     deck's folder; the same keys given with `--set` are typed on the command line and are
//     taken relative to the current directory, as a shell user expects;
//   - keys that the chosen model kind does not use are accepted (a deck can be switched between
//     kinds with `--set model.kind=...`), and recorded in ModelConfig::given all the same.

#include "io/deck.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "core/scene_kinds.hpp"

namespace voussoir {

// Whether `key` (embrace or model.embrace) is among the keys of `section` the deck gave.
static bool section_has(const std::vector<std::string>& given, const std::string& section,
                        const std::string& key) {
  const std::string prefix = section + ".";
  const std::string leaf = key.rfind(prefix, 0) == 0 ? key.substr(prefix.size()) : key;
  return std::find(given.begin(), given.end(), leaf) != given.end();
}

bool ContactConfig::has(const std::string& key) const {
  return section_has(given, "contact", key);
}

bool ModelConfig::has(const std::string& key) const {
  return section_has(given, "model", key);
}

namespace {

namespace fs = std::filesystem;

constexpr double kInf = std::numeric_limits<double>::infinity();

// An allowed interval for a number; open or closed at each end; +-inf = unbounded.
struct Range {
  double lo = -kInf;
  bool lo_open = false;
  double hi = kInf;
  bool hi_open = false;
};
Range above(double lo) {
  return {lo, true, kInf, false};
}  // (lo, inf)
Range at_least(double lo) {
  return {lo, false, kInf, false};
}  // [lo, inf)
Range any_finite() {
  return {};
}

std::string format_number(double v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

std::string describe(const Range& r, const char* what) {
  std::string s = what;
  const bool has_lo = std::isfinite(r.lo), has_hi = std::isfinite(r.hi);
  if (has_lo && has_hi) {
    s += std::string(" in ") + (r.lo_open ? "(" : "[") + format_number(r.lo) + ", " +
         format_number(r.hi) + (r.hi_open ? ")" : "]");
  } else if (has_lo) {
    s += std::string(r.lo_open ? " > " : " >= ") + format_number(r.lo);
  } else if (has_hi) {
    s += std::string(r.hi_open ? " < " : " <= ") + format_number(r.hi);
  }
  return s;
}

bool inside(const Range& r, double v) {
  if (!std::isfinite(v)) return false;
  if (r.lo_open ? !(v > r.lo) : !(v >= r.lo)) return false;
  if (r.hi_open ? !(v < r.hi) : !(v <= r.hi)) return false;
  return true;
}

// The value as the user wrote it, on one line.
std::string value_text(const toml::node& n) {
  if (const auto* s = n.as_string()) return "\"" + s->get() + "\"";
  if (const auto* i = n.as_integer()) return std::to_string(i->get());
  if (const auto* f = n.as_floating_point()) {
    // Show 11.0 as "11.0", so "expected an integer" makes sense next to it.
    std::string s = format_number(f->get());
    if (s.find_first_of(".eEni") == std::string::npos) s += ".0";
    return s;
  }
  if (const auto* b = n.as_boolean()) return b->get() ? "true" : "false";
  if (const auto* a = n.as_array()) {
    std::string s = "[";
    for (std::size_t k = 0; k < a->size(); ++k) {
      if (k) s += ", ";
      s += value_text(*a->get(k));
    }
    return s + "]";
  }
  if (n.is_table()) return "{...} (a table)";
  return "(a date/time)";
}

std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  std::replace(s.begin(), s.end(), '\r', ' ');
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

std::string join(const std::vector<std::string>& items, const char* sep = ", ") {
  std::string s;
  for (std::size_t k = 0; k < items.size(); ++k) s += (k ? sep : "") + items[k];
  return s;
}

// Optimal-string-alignment edit distance (Levenshtein plus adjacent transpositions, so the
// common slip "frictoin" is one edit from "friction").
std::size_t edit_distance(const std::string& a, const std::string& b) {
  const std::size_t n = a.size(), m = b.size();
  std::vector<std::vector<std::size_t>> d(n + 1, std::vector<std::size_t>(m + 1));
  for (std::size_t i = 0; i <= n; ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= m; ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= n; ++i) {
    for (std::size_t j = 1; j <= m; ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[n][m];
}

// ---------------------------------------------------------------------------------------------
// The reader: knows where the current value came from and turns every refusal into one line.

// What a key's reader allows, found by handing it a value no reader accepts (a table) in
// probing mode: the deck reference (io/deck_reference.cpp, `voussoir keys`, docs/reference/deck.md)
// is thus the reader's own rule, never a copy of it.
struct KeyProbe {
  std::string type, unit, allowed;
};

struct Reader {
  bool probing = false;                           // fail() throws KeyProbe (describe_key)
  mutable std::string probe_type, probe_unit;     // what the typed reader being run expects
  std::string source;                             // deck file name (or the text's label)
  std::string deck_dir;                           // for relative input files
  std::map<std::string, std::string> set_raw;     // dotted key -> raw VALUE of its --set
  std::map<std::string, const toml::node*> seen;  // dotted key -> node, for every key given
  std::string key;                                // dotted key being read
  // Input-file keys read so far -> the resolved path (input_file), checked once the whole
  // deck says which of them the run will read.
  mutable std::map<std::string, std::string> input_files;

  bool from_set(const std::string& k) const { return set_raw.count(k) != 0; }

  // "deck.toml:7:11: " or "deck.toml: --set ".
  std::string where(const std::string& k, const toml::node* n) const {
    if (from_set(k)) return source + ": --set ";
    if (n != nullptr) {
      const auto& b = n->source().begin;
      if (b.line > 0)
        return source + ":" + std::to_string(b.line) + ":" + std::to_string(b.column) + ": ";
    }
    return source + ": ";
  }

  // Notes the type (and unit) a typed reader expects, for probing.
  void expects(const char* type, const char* unit = nullptr) const {
    if (!probing) return;
    probe_type = type;
    probe_unit = unit ? unit : "";
  }

  [[noreturn]] void fail(const toml::node& n, const std::string& allowed) const {
    if (probing) throw KeyProbe{probe_type, probe_unit, allowed};
    throw DeckError(
        one_line(where(key, &n) + key + " = " + value_text(n) + ": expected " + allowed));
  }

  double number(const toml::node& n, const Range& r, const char* unit = nullptr) const {
    expects("number", unit);
    const std::string u = unit ? std::string(" [") + unit + "]" : std::string();
    const std::string allowed = describe(r, "a number") + u;
    double v = 0.0;
    if (const auto* i = n.as_integer()) {
      v = static_cast<double>(i->get());
    } else if (const auto* f = n.as_floating_point()) {
      v = f->get();
      if (!std::isfinite(v)) fail(n, describe(r, "a finite number") + u);
    } else {
      fail(n, allowed);
    }
    if (!inside(r, v)) fail(n, allowed);
    return v;
  }

  int integer(const toml::node& n, std::int64_t lo, std::int64_t hi) const {
    expects("integer");
    const std::string allowed =
        "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    const auto* i = n.as_integer();
    if (i == nullptr) fail(n, allowed);
    if (i->get() < lo || i->get() > hi) fail(n, allowed);
    return static_cast<int>(i->get());
  }

  std::string string(const toml::node& n) const {
    if (probe_type.empty()) expects("string");
    if (const auto* s = n.as_string()) return s->get();
    // `--set output.file=2024` parses as an integer; for a string key take the text typed.
    if (auto it = set_raw.find(key); it != set_raw.end() && !n.is_array() && !n.is_table())
      return it->second;
    fail(n, "a string");
  }

  std::string choice(const toml::node& n, const std::vector<std::string>& allowed) const {
    expects("string");
    const std::string what = "one of \"" + join(allowed, "\", \"") + "\"";
    if (!n.is_string() && !from_set(key)) fail(n, what);
    const std::string s = n.is_string() ? n.as_string()->get() : set_raw.at(key);
    if (std::find(allowed.begin(), allowed.end(), s) == allowed.end()) fail(n, what);
    return s;
  }

  const toml::array& array(const toml::node& n, const std::string& what) const {
    expects("array");
    const auto* a = n.as_array();
    if (a == nullptr) fail(n, what);
    return *a;
  }

  // A file the run will read: resolved against the deck folder (file keys) or the current
  // directory (--set), and it must be readable.
  std::string input_file(const toml::node& n) const {
    expects("string (file name)");
    if (probing) fail(n, "a readable file; a relative name is taken from the deck's folder");
    const std::string s = string(n);
    if (s.empty()) fail(n, "a file name");
    fs::path p(s);
    if (p.is_relative() && !from_set(key)) p = (fs::path(deck_dir) / p).lexically_normal();
    input_files[key] = p.string();
    return p.string();
  }
};

// ---------------------------------------------------------------------------------------------
// The key table: one row per deck key, the only place a key's name is written. A row gives
//   - the dotted name;
//   - the Config field the key fills (core/schema.hpp: the field's initialiser is the default
//     of a deck that omits the key);
//   - its rule: the reader that checks the value and stores it (Number, Integer, Choice, ...).
//     The rule also states the type, unit and allowed values (describe_key runs it in probing
//     mode) and shows the field as a deck writes it (the default column, from a
//     default-constructed Config);
//   - one line of meaning.
// `voussoir keys` and docs/reference/deck.md (io/deck_reference.cpp) print these rows; the
// cross-key checks (check_together) name a key by its field (key_of). Adding a key: its field
// and initialiser in core/schema.hpp, its row here, then `build/voussoir keys >
// docs/reference/deck.md`.
//
// A rule reads a TOML value into a field of type T, `read(Reader, node, T&)`, and shows a value
// of the field, `show(const T&)`.

std::string quoted(const std::string& s) {
  return "\"" + s + "\"";
}

template <typename List, typename F>
std::string list(const List& items, F show) {
  std::string s = "[";
  for (std::size_t k = 0; k < items.size(); ++k) s += (k ? ", " : "") + show(items[k]);
  return s + "]";
}

// A number in `range`. `unit`: "m", or the unit and what a value means ("m, 0 = automatic").
// A field the rule would refuse (a stiffness of 0: not given) shows as "none".
struct Number {
  Range range;
  const char* unit = nullptr;
  void read(const Reader& r, const toml::node& n, double& v) const { v = r.number(n, range, unit); }
  std::string show(double v) const { return inside(range, v) ? format_number(v) : "none"; }
};

// An integer in [lo, hi].
struct Integer {
  std::int64_t lo, hi;
  void read(const Reader& r, const toml::node& n, int& v) const { v = r.integer(n, lo, hi); }
  std::string show(int v) const { return std::to_string(v); }
};

// One of `allowed`.
struct Choice {
  std::vector<std::string> allowed;
  void read(const Reader& r, const toml::node& n, std::string& v) const {
    v = r.choice(n, allowed);
  }
  std::string show(const std::string& v) const { return quoted(v); }
};

// A key without a default: a deck must give it (check_together).
template <typename Rule>
struct Required : Rule {
  template <typename T>
  std::string show(const T&) const {
    return "required";
  }
};

// Any string; empty (the default): none.
struct Text {
  void read(const Reader& r, const toml::node& n, std::string& v) const { v = r.string(n); }
  std::string show(const std::string& v) const { return v.empty() ? "none" : quoted(v); }
};

// A file the run reads (Reader::input_file); empty (the default): none.
struct InputFile {
  void read(const Reader& r, const toml::node& n, std::string& v) const { v = r.input_file(n); }
  std::string show(const std::string& v) const { return v.empty() ? "none" : quoted(v); }
};

// model.spans: a non-empty array of numbers > 0.
struct Spans {
  void read(const Reader& r, const toml::node& n, std::vector<double>& spans) const {
    const char* what = "a non-empty array of spans > 0 [m]";
    const toml::array& a = r.array(n, what);
    if (a.empty()) r.fail(n, what);
    spans.clear();
    for (const toml::node& e : a) {
      const double v = e.is_number() ? e.value<double>().value_or(0.0) : 0.0;
      if (!e.is_number() || !inside(above(0), v)) r.fail(n, what);
      spans.push_back(v);
    }
  }
  std::string show(const std::vector<double>& spans) const { return list(spans, format_number); }
};

// model.fixed: distinct block indices.
struct BlockIndices {
  void read(const Reader& r, const toml::node& n, std::vector<int>& fixed) const {
    const char* what = "an array of distinct block indices (integers >= 0)";
    const toml::array& a = r.array(n, what);
    fixed.clear();
    for (const toml::node& e : a) {
      const auto* i = e.as_integer();
      if (i == nullptr || i->get() < 0 || i->get() > std::numeric_limits<int>::max())
        r.fail(n, what);
      const int v = static_cast<int>(i->get());
      if (std::find(fixed.begin(), fixed.end(), v) != fixed.end()) r.fail(n, what);
      fixed.push_back(v);
    }
  }
  std::string show(const std::vector<int>& fixed) const {
    return list(fixed, [](int v) { return std::to_string(v); });
  }
};

// solver.dt: "auto" (stored as 0) or a time step > 0.
struct TimeStep {
  void read(const Reader& r, const toml::node& n, double& dt) const {
    const char* what = "\"auto\" or a time step > 0 [s]";
    r.expects("\"auto\" or number", "s");
    if (n.is_string() || (r.from_set(r.key) && !n.is_number())) {
      if (r.string(n) != "auto") r.fail(n, what);
      dt = 0.0;
      return;
    }
    if (!n.is_number()) r.fail(n, what);
    const double v = n.value<double>().value_or(0.0);
    if (!inside(above(0), v)) r.fail(n, what);
    dt = v;
  }
  std::string show(double dt) const { return dt == 0.0 ? quoted("auto") : format_number(dt); }
};

// load.base.band: [low, high] in Hz, or [0, 0].
struct Band {
  void read(const Reader& r, const toml::node& n, std::array<double, 2>& band) const {
    const char* what = "[low, high] in Hz with 0 <= low < high, or [0, 0] for no filter";
    const toml::array& a = r.array(n, what);
    if (a.size() != 2 || !a[0].is_number() || !a[1].is_number()) r.fail(n, what);
    const double lo = a[0].value<double>().value_or(0.0), hi = a[1].value<double>().value_or(0.0);
    if (!std::isfinite(lo) || !std::isfinite(hi)) r.fail(n, what);
    if (!(lo == 0.0 && hi == 0.0) && !(lo >= 0.0 && lo < hi)) r.fail(n, what);
    band = {lo, hi};
  }
  std::string show(const std::array<double, 2>& band) const { return list(band, format_number); }
};

// supports.moves: an array of {block, dx, dy, rotation}; a bad field is named by its entry
// ("supports.moves[1].dx").
struct SupportMoves {
  void read(const Reader& r, const toml::node& n, std::vector<SupportMoveConfig>& moves) const {
    const char* what =
        "an array of {block = B, dx = X, dy = Y, rotation = R} (B: a fixed block's index, "
        "X, Y in m, R in degrees, |R| <= 90; dx, dy, rotation optional, 0 by default), each "
        "block once";
    const toml::array& a = r.array(n, what);
    moves.clear();
    for (std::size_t k = 0; k < a.size(); ++k) {
      const toml::node& e = *a.get(k);
      const auto* t = e.as_table();
      if (t == nullptr) r.fail(n, what);
      const std::string entry = "supports.moves[" + std::to_string(k) + "].";
      auto bad = [&](const std::string& field, const toml::node& v, const std::string& allowed) {
        throw DeckError(one_line(r.where(r.key, &v) + entry + field + " = " + value_text(v) +
                                 ": expected " + allowed));
      };
      SupportMoveConfig m;
      if (!t->contains("block")) r.fail(n, what);
      for (auto&& [name, v] : *t) {
        const std::string field(name.str());
        if (field == "block") {
          const auto* i = v.as_integer();
          if (i == nullptr || i->get() < 0 || i->get() > std::numeric_limits<int>::max())
            bad(field, v, "a block index (an integer >= 0)");
          m.block = static_cast<int>(i->get());
          m.where = r.where(r.key, &v);
          for (const SupportMoveConfig& o : moves)
            if (o.block == m.block) bad(field, v, "each block at most once");
          continue;
        }
        double* out = field == "dx"         ? &m.dx
                      : field == "dy"       ? &m.dy
                      : field == "rotation" ? &m.rotation
                                            : nullptr;
        if (out == nullptr) bad(field, v, "one of the fields block, dx, dy, rotation");
        const auto* i = v.as_integer();
        const auto* f = v.as_floating_point();
        const double x = i ? static_cast<double>(i->get()) : f ? f->get() : NAN;
        const bool angle = field == "rotation";
        if (!std::isfinite(x) || (angle && !(std::abs(x) <= 90.0)))
          bad(field, v, angle ? "a finite number of degrees in [-90, 90]" : "a finite number [m]");
        *out = x;
      }
      moves.push_back(m);
    }
  }
  std::string show(const std::vector<SupportMoveConfig>& moves) const {
    return moves.empty() ? "[] (none)" : std::to_string(moves.size()) + " moves";
  }
};

// output.fields: distinct names among "position", "velocity", "stress".
struct OutputFields {
  void read(const Reader& r, const toml::node& n, std::vector<std::string>& fields) const {
    const char* what = "an array of distinct names among \"position\", \"velocity\", \"stress\"";
    static const std::vector<std::string> allowed = {"position", "velocity", "stress"};
    const toml::array& a = r.array(n, what);
    fields.clear();
    for (const toml::node& e : a) {
      const auto* s = e.as_string();
      if (s == nullptr || std::find(allowed.begin(), allowed.end(), s->get()) == allowed.end())
        r.fail(n, what);
      if (std::find(fields.begin(), fields.end(), s->get()) != fields.end()) r.fail(n, what);
      fields.push_back(s->get());
    }
  }
  std::string show(const std::vector<std::string>& fields) const { return list(fields, quoted); }
};

struct KeySpec {
  // `field`: a generic lambda giving the address of the key's field in a Config (const or not).
  template <typename Field, typename Rule>
  KeySpec(const char* name, Field field, Rule rule, const char* what)
      : key(name),
        meaning(what),
        read([=](Reader& r, const toml::node& n, Config& c) { rule.read(r, n, *field(c)); }),
        show([=](const Config& c) { return rule.show(*field(c)); }),
        address([=](const Config& c) -> const void* { return field(c); }) {}
  const char* key;
  const char* meaning;
  std::function<void(Reader&, const toml::node&, Config&)> read;  // checks and stores a value
  // The key's value in a Config, as a deck writes it.
  std::function<std::string(const Config&)> show;
  // Where the key's field is in a Config (key_of).
  std::function<const void*(const Config&)> address;
};

const std::vector<std::string> kKinds = scene_kind_names();  // core/scene_kinds.hpp

// Every key of the deck in the reader's order (the order of the reference). Ranges are
// engineering limits: a value outside them is a typing slip or a unit error (kPa for Pa,
// radians for degrees), never a real structure. A data table: one row per key.
const std::vector<KeySpec>& key_table() {
  static const std::vector<KeySpec> table = {
      // [model]
      {"model.kind", [](auto& c) { return &c.model.kind; }, Required<Choice>{{kKinds}},
       "scene: which structure the deck builds (the kinds: core/scene_kinds.hpp)"},
      {"model.radius", [](auto& c) { return &c.model.radius; }, Number{above(0), "m"},
       "arches: centreline radius Rc (basket: of the reference circle)"},
      {"model.thickness", [](auto& c) { return &c.model.thickness; }, Number{above(0), "m"},
       "arches and church: ring thickness t normal to the centreline (church default 0.5)"},
      {"model.embrace", [](auto& c) { return &c.model.embrace; },
       Number{{0, true, 360, true}, "deg"}, "arches: embrace angle beta of the arch"},
      {"model.voussoirs", [](auto& c) { return &c.model.voussoirs; }, Integer{1, 100000},
       "arches: number of voussoirs (blocks of equal centreline length)"},
      {"model.offset", [](auto& c) { return &c.model.offset; }, Number{at_least(0), "m"},
       "basket arch: offset d of the large arc's centre below O"},
      {"model.small_radius", [](auto& c) { return &c.model.small_radius; }, Number{above(0), "m"},
       "basket arch: radius r of the two small arcs"},
      {"model.shape", [](auto& c) { return &c.model.shape; }, Choice{{"circular", "basket"}},
       "buttressed arch: shape of the arch between the buttresses"},
      {"model.buttress_width", [](auto& c) { return &c.model.buttress_width; },
       Number{above(0), "m"}, "buttressed arch: buttress width B"},
      {"model.base_depth", [](auto& c) { return &c.model.base_depth; }, Number{above(0), "m"},
       "buttressed arch: depth H1 of the ground line below the centre O"},
      {"model.courses", [](auto& c) { return &c.model.courses; },
       Number{at_least(0), "m, 0 = monolithic"},
       "buttressed arch and church: course height of the supports (0 = monolithic)"},
      {"model.spans", [](auto& c) { return &c.model.spans; }, Spans{},
       "church: clear spans of the three arches, left to right"},
      {"model.height", [](auto& c) { return &c.model.height; }, Number{above(0), "m"},
       "church: support height; block: block height (block default 1.0)"},
      {"model.pier_width", [](auto& c) { return &c.model.pier_width; }, Number{above(0), "m"},
       "church: width of the two inner piers"},
      {"model.outer_width", [](auto& c) { return &c.model.outer_width; }, Number{above(0), "m"},
       "church: width of the two outer buttresses"},
      {"model.eccentricity", [](auto& c) { return &c.model.eccentricity; },
       Number{{0, false, 2, false}},
       "church: centre offset c of each pointed half-arch, as a fraction of half the span"},
      {"model.voussoir_angle", [](auto& c) { return &c.model.voussoir_angle; },
       Number{{0, true, 90, true}, "deg"},
       "church: angle of the polar voussoirs about their centre"},
      {"model.width", [](auto& c) { return &c.model.width; }, Number{above(0), "m"},
       "block: block width"},
      {"model.incline", [](auto& c) { return &c.model.incline; },
       Number{{0, false, 90, true}, "deg"}, "block: incline of the fixed ground"},
      {"model.stack", [](auto& c) { return &c.model.stack; }, Integer{1, 1000},
       "block: number of blocks stacked on the ground"},
      {"model.file", [](auto& c) { return &c.model.file; }, InputFile{},
       "polygons: polygon text file or gmsh MSH 4.1 file of the blocks (docs/gmsh.md); a text "
       "file's block must be a simple polygon with no corner sharper than 1 degree and no notch "
       "narrower (refused naming the file's line, the block and the vertex; format: "
       "mesh/scenes_polygons.cpp)"},
      {"model.fixed", [](auto& c) { return &c.model.fixed; }, BlockIndices{},
       "polygons: indices of the fixed blocks (file order; gmsh: physical tag order); other kinds: "
       "blocks fixed besides the scene's supports (a pier to settle with [supports]); at least one "
       "block must stay free"},
      {"model.out_of_plane", [](auto& c) { return &c.model.out_of_plane; }, Number{above(0), "m"},
       "out-of-plane thickness: masses and forces scale with it"},
      // [mesh]
      {"mesh.chord_tolerance", [](auto& c) { return &c.mesh.chord_tolerance; },
       Number{{0, false, 1, false}, "x the block's thickness (rigid blocks)"},
       "rigid blocks: an outline point is dropped when its chord stays within this fraction of the "
       "block's thickness"},
      {"mesh.max_triangles", [](auto& c) { return &c.mesh.max_triangles; }, Integer{1, 1000000000},
       "the most triangles a model may have; a deck whose mesh would exceed it is refused (exit 2) "
       "before or while it is meshed"},
      {"mesh.size", [](auto& c) { return &c.mesh.size; },
       Number{at_least(0), "m, 0 = use mesh.through_thickness"},
       "target element size (0: from mesh.through_thickness)"},
      {"mesh.through_thickness", [](auto& c) { return &c.mesh.through_thickness; },
       Integer{1, 1000}, "elements across the arch thickness (or the smallest block)"},
      // [material]
      {"material.density", [](auto& c) { return &c.material.density; }, Number{above(0), "kg/m3"},
       "mass density rho of the blocks"},
      {"material.young", [](auto& c) { return &c.material.young; }, Number{above(0), "Pa"},
       "Young's modulus E of the blocks"},
      {"material.poisson", [](auto& c) { return &c.material.poisson; },
       Number{{0, false, 0.5, true}}, "Poisson's ratio nu of the blocks"},
      {"material.plane", [](auto& c) { return &c.material.plane; }, Choice{{"strain", "stress"}},
       "plane strain or plane stress"},
      {"material.model", [](auto& c) { return &c.material.model; }, Choice{{"elastic", "rigid"}},
       "elastic: constant-strain triangles; rigid: one rigid body per block (docs/rigid.md)"},
      // [contact]
      {"contact.friction", [](auto& c) { return &c.contact.friction; }, Number{at_least(0)},
       "Coulomb friction coefficient mu of the joints"},
      {"contact.penalty_factor", [](auto& c) { return &c.contact.penalty_factor; },
       Number{above(0), "x Lame's first constant"},
       "contact penalty Ep as a multiple of Lame's first constant"},
      {"contact.penalty", [](auto& c) { return &c.contact.penalty; },
       Number{at_least(0), "Pa, 0 = use contact.penalty_factor"},
       "contact penalty Ep as a value (0: from contact.penalty_factor)"},
      {"contact.buffer", [](auto& c) { return &c.contact.buffer; },
       Number{at_least(0), "m, 0 = automatic"}, "NBS contact search buffer (0: automatic)"},
      {"contact.normal_stiffness", [](auto& c) { return &c.contact.normal_stiffness; },
       Number{above(0), "N/m3"},
       "joint normal stiffness kn, replaces the penalty (not given: penalty, or 100 E / L for "
       "rigid blocks, L the joint's length)"},
      {"contact.shear_stiffness", [](auto& c) { return &c.contact.shear_stiffness; },
       Number{above(0), "N/m3"}, "joint shear stiffness ks (not given: kn / 4)"},
      {"contact.restitution", [](auto& c) { return &c.contact.restitution; },
       Number{{0, false, 1, false}, "coefficient of restitution"},
       "impact restitution of rigid blocks (1: no impact damping; below 1 needs material.model = "
       "\"rigid\"; not given: 0.5 for rigid blocks in run, pulse, stability and capacity "
       "--dynamic, none in the quasi-static capacity trials; nscd: 0, plastic impacts)"},
      // [solver]
      {"solver.dt", [](auto& c) { return &c.solver.dt; }, TimeStep{},
       "time step: \"auto\" (explicit: stable limit x solver.dt_safety; nscd: 1e-3 s, or a "
       "record's sampling interval if shorter) or a value"},
      {"solver.dt_safety", [](auto& c) { return &c.solver.dt_safety; }, Number{{0, true, 1, false}},
       "fraction of the stable time step that \"auto\" uses"},
      {"solver.damping_factor", [](auto& c) { return &c.solver.damping_factor; },
       Number{at_least(0)}, "scales the element viscosity eta = 2 h sqrt(E rho)"},
      {"solver.end_time", [](auto& c) { return &c.solver.end_time; }, Number{above(0), "s"},
       "simulated time of `run`"},
      {"solver.scheme", [](auto& c) { return &c.solver.scheme; }, Choice{{"explicit", "nscd"}},
       "time scheme: explicit central difference, or nscd: rigid blocks by non-smooth contact "
       "dynamics, rigid joints (needs material.model = \"rigid\"; docs/nscd.md)"},
      {"solver.theta", [](auto& c) { return &c.solver.theta; }, Number{{0.5, false, 1, false}},
       "nscd: Moreau-Jean's theta (0.5: no numerical dissipation)"},
      {"solver.tolerance", [](auto& c) { return &c.solver.tolerance; },
       Number{above(0), "x the step's velocity scale"},
       "nscd: the Gauss-Seidel stops when a sweep changes no body's velocity by more than this "
       "times h |a| or the fastest approach; above the default a stable structure can creep, "
       "which `capacity` and `sweep` warn of (docs/nscd.md)"},
      {"solver.max_iterations", [](auto& c) { return &c.solver.max_iterations; },
       Integer{1, 100000000},
       "nscd: most Gauss-Seidel sweeps a step (a step that reaches it is counted unconverged)"},
      // [load]
      {"load.gravity", [](auto& c) { return &c.load.gravity; }, Number{at_least(0), "m/s2"},
       "gravity g, downward (0: a weightless deck, which only `check` and `run` take)"},
      {"load.lambda", [](auto& c) { return &c.load.lambda; }, Number{any_finite(), "x gravity"},
       "horizontal body load factor of `run` (x gravity)"},
      {"load.gravity_ramp", [](auto& c) { return &c.load.gravity_ramp; }, Number{at_least(0), "s"},
       "`run`: gravity and lambda g brought on together, linearly, over this time (0: from t = 0; "
       "a structure loaded over a time long against its slowest mode starts its history at rest: "
       "docs/rigid.md)"},
      // [load.base]
      {"load.base.signal", [](auto& c) { return &c.load.base.signal; },
       Choice{{"none", "windowed_sine", "sine_pulse", "file"}},
       "base acceleration history of `pulse` (`run` does not apply it)"},
      {"load.base.amplitude", [](auto& c) { return &c.load.base.amplitude; },
       Number{any_finite(), "g"}, "peak base acceleration A"},
      {"load.base.frequency", [](auto& c) { return &c.load.base.frequency; },
       Number{above(0), "Hz"}, "pulse frequency f"},
      {"load.base.cycles", [](auto& c) { return &c.load.base.cycles; }, Integer{1, 1000},
       "windowed sine: number of cycles"},
      {"load.base.file", [](auto& c) { return &c.load.base.file; }, InputFile{},
       "signal = \"file\": two-column accelerogram (time, acceleration) or PEER NGA .AT2 record "
       "(docs/records.md)"},
      {"load.base.units", [](auto& c) { return &c.load.base.units; }, Choice{{"g", "m/s2"}},
       "units of the accelerogram's acceleration column"},
      {"load.base.baseline", [](auto& c) { return &c.load.base.baseline; },
       Choice{{"none", "constant", "linear", "quadratic"}},
       "baseline correction of the accelerogram before the band-pass: the degree of the polynomial "
       "removed from the acceleration, fitted to the displacement (docs/records.md)"},
      {"load.base.band", [](auto& c) { return &c.load.base.band; }, Band{},
       "band-pass filter of the accelerogram [low, high] ([0, 0]: none)"},
      // [capacity]
      {"capacity.lambda_min", [](auto& c) { return &c.capacity.lambda_min; }, Number{at_least(0)},
       "lower end of the starting bracket of `capacity` (stable); above 0, checked by a trial "
       "beside lambda_max's (a collapse there widens the bracket down)"},
      {"capacity.lambda_max", [](auto& c) { return &c.capacity.lambda_max; }, Number{at_least(0)},
       "upper end of the starting bracket (both 0: from limit analysis); checked by a trial"},
      {"capacity.local_damping", [](auto& c) { return &c.capacity.local_damping; },
       Number{{0, false, 1, true}, "local damping coefficient of the quasi-static trials"},
       "coefficient of the local damping of the quasi-static settle and trials of `capacity` and "
       "`sweep` (0: none; `--dynamic`: off; docs/capacity.md)"},
      {"capacity.local_damping_mode", [](auto& c) { return &c.capacity.local_damping_mode; },
       Choice{{"outgoing", "full"}},
       "outgoing: damp only while the force opposes the motion (a mechanism is not slowed); full: "
       "Cundall's rule at every step"},
      {"capacity.kinetic_damping", [](auto& c) { return &c.capacity.kinetic_damping; },
       Number{{0, false, 1, true}, "fraction of the peak kinetic energy"},
       "kinetic damping of the same phases: every velocity set to zero once the kinetic energy has "
       "fallen this fraction below its peak (0: none; `--dynamic`: off; docs/capacity.md)"},
      {"capacity.mass_scaling", [](auto& c) { return &c.capacity.mass_scaling; },
       Choice{{"equalize", "none"}},
       "rigid blocks in the same phases: equalize lowers the mass and inertia of each block until "
       "its own stable step is the model's (loads keep the true masses); none: true inertia "
       "(`--dynamic`: none; docs/capacity.md)"},
      {"capacity.tolerance", [](auto& c) { return &c.capacity.tolerance; },
       Number{{0, true, 1, true}, "relative bracket width"},
       "relative width of the final bracket: (hi - lo) / hi"},
      // [supports]
      {"supports.moves", [](auto& c) { return &c.supports.moves; }, SupportMoves{},
       "prescribed movements of fixed blocks: block (its number in `check`, which lists the "
       "supports), dx, dy [m] and rotation [deg, counter-clockwise about its centroid]; every "
       "command settles under gravity, moves them over `ramp`, then runs on the moved structure "
       "(`run`: from t = 0; docs/supports.md)"},
      {"supports.ramp", [](auto& c) { return &c.supports.ramp; }, Number{above(0), "s"},
       "time over which the moves are reached, by a ramp with zero velocity and acceleration at "
       "both ends (docs/supports.md)"},
      // [output]
      {"output.file", [](auto& c) { return &c.output.file; }, Text{},
       "HDF5 file of `run` / `pulse` (XDMF beside it); empty: none"},
      {"output.every", [](auto& c) { return &c.output.every; }, Number{above(0), "s"},
       "snapshot interval"},
      {"output.fields", [](auto& c) { return &c.output.fields; }, OutputFields{},
       "snapshot fields: position (with displacement), velocity, stress (elastic blocks)"},
  };
  return table;
}

const KeySpec* find_key(const std::string& dotted) {
  for (const KeySpec& k : key_table())
    if (dotted == k.key) return &k;
  return nullptr;
}

// Sections are the prefixes of the known keys: model, mesh, ..., load, load.base, ...
const std::set<std::string>& sections() {
  static const std::set<std::string> s = [] {
    std::set<std::string> out;
    for (const KeySpec& k : key_table()) {
      const std::string key = k.key;
      for (std::size_t p = key.find('.'); p != std::string::npos; p = key.find('.', p + 1))
        out.insert(key.substr(0, p));
    }
    return out;
  }();
  return s;
}

std::string leaf_of(const std::string& dotted) {
  const std::size_t p = dotted.rfind('.');
  return p == std::string::npos ? dotted : dotted.substr(p + 1);
}

std::string section_of(const std::string& dotted) {
  const std::size_t p = dotted.rfind('.');
  return p == std::string::npos ? std::string() : dotted.substr(0, p);
}

// The known key (or section) nearest to an unknown one, or "" when nothing is close.
// Score of a candidate: the edit distance of the whole dotted path, or, for a key of another
// section, the distance of the key names plus one (so model.frction finds contact.friction). Close
// enough to be a slip: at most one edit per four characters of the name, and two edits are always
// allowed.
std::string suggest(const std::string& unknown) {
  const std::string leaf = leaf_of(unknown), section = section_of(unknown);
  std::string best;
  std::size_t best_score = std::numeric_limits<std::size_t>::max();
  auto consider = [&](const std::string& cand, bool is_key) {
    std::size_t score = edit_distance(unknown, cand);
    if (is_key && section_of(cand) != section)
      score = std::min(score, edit_distance(leaf, leaf_of(cand)) + 1);
    if (score < best_score) best_score = score, best = cand;
  };
  for (const KeySpec& k : key_table()) consider(k.key, true);
  for (const std::string& s : sections()) consider(s, false);
  const std::size_t limit = std::max<std::size_t>(2, leaf.size() / 4);
  return best_score <= limit ? best : std::string();
}

[[noreturn]] void fail_unknown(const Reader& r, const std::string& dotted, const toml::node& n,
                               bool is_section) {
  std::string msg;
  const std::string what =
      is_section ? "unknown section [" + dotted + "]" : "unknown key '" + dotted + "'";
  // The --set that brought it: the key itself, or a key below an unknown section.
  auto origin = r.set_raw.find(dotted);
  if (origin == r.set_raw.end()) {
    origin = r.set_raw.lower_bound(dotted + ".");
    if (origin != r.set_raw.end() && origin->first.rfind(dotted + ".", 0) != 0)
      origin = r.set_raw.end();
  }
  if (origin != r.set_raw.end()) {
    msg = r.source + ": " + what + " in --set " + origin->first + "=" + origin->second;
  } else {
    msg = r.where(dotted, &n) + what;
  }
  const std::string s = suggest(dotted);
  if (!s.empty()) msg += " (did you mean '" + s + "'?)";
  throw DeckError(one_line(msg));
}

// A --set inside a table that came only from --set: the keys below it carry its origin.
void mark_set_subtree(Reader& r, const std::string& prefix, const toml::node& n,
                      const std::string& raw) {
  if (const auto* t = n.as_table()) {
    for (auto&& [k, v] : *t) mark_set_subtree(r, prefix + "." + std::string(k.str()), v, raw);
  } else {
    r.set_raw[prefix] = raw;
  }
}

void walk(Reader& r, const toml::table& table, const std::string& prefix, Config& config) {
  // In the order of the file (toml++ keeps keys sorted by name), so the first problem reported
  // is the first one a reader of the deck meets.
  std::vector<std::pair<std::string, const toml::node*>> entries;
  for (auto&& [k, v] : table) entries.emplace_back(std::string(k.str()), &v);
  std::stable_sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) {
    const auto &sa = a.second->source().begin, &sb = b.second->source().begin;
    return sa.line != sb.line ? sa.line < sb.line : sa.column < sb.column;
  });
  for (const auto& [name, node] : entries) {
    const toml::node& v = *node;
    const std::string dotted = prefix.empty() ? name : prefix + "." + name;
    const KeySpec* spec = find_key(dotted);
    if (spec != nullptr) {
      r.key = dotted;
      r.seen[dotted] = &v;
      spec->read(r, v, config);
      continue;
    }
    if (sections().count(dotted) != 0) {
      const auto* sub = v.as_table();
      if (sub == nullptr)
        throw DeckError(one_line(r.where(dotted, &v) + "'" + dotted + "' is a section [" + dotted +
                                 "], not a value (got " + value_text(v) + ")"));
      walk(r, *sub, dotted, config);
      continue;
    }
    fail_unknown(r, dotted, v, v.is_table());
  }
}

std::vector<std::string> split_dots(const std::string& s) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (true) {
    const std::size_t p = s.find('.', start);
    parts.push_back(s.substr(start, p == std::string::npos ? std::string::npos : p - start));
    if (p == std::string::npos) break;
    start = p + 1;
  }
  return parts;
}

std::string trim(const std::string& s) {
  const std::size_t b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const std::size_t e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

// Inserts one `--set KEY=VALUE` into the parsed deck.
void apply_override(Reader& r, toml::table& root, const std::string& text) {
  const std::size_t eq = text.find('=');
  const std::string example = " (for example --set model.embrace=135)";
  if (eq == std::string::npos)
    throw DeckError("--set '" + text + "': expected KEY=VALUE" + example);
  const std::string key = trim(text.substr(0, eq));
  const std::string raw = trim(text.substr(eq + 1));
  const std::vector<std::string> parts = split_dots(key);
  for (const std::string& p : parts)
    if (p.empty() || p.find_first_of(" \t\"'[]") != std::string::npos)
      throw DeckError("--set '" + text + "': '" + key + "' is not a dotted key path" + example);

  // VALUE as a TOML value; anything that is not one (a bare word, a path) is a string.
  toml::table parsed;
  bool is_toml = false;
  try {
    parsed = toml::parse("v = " + raw + "\n", std::string_view("--set"));
    is_toml = parsed.size() == 1 && parsed.contains("v");
  } catch (const toml::parse_error&) {
    is_toml = false;
  }
  if (!is_toml) {
    parsed = toml::table{};
    parsed.insert("v", raw);
  }
  const toml::node& value = *parsed.get("v");

  toml::table* t = &root;
  std::string path;
  for (std::size_t k = 0; k + 1 < parts.size(); ++k) {
    path += (k ? "." : "") + parts[k];
    toml::node* existing = t->get(parts[k]);
    if (existing == nullptr) {
      t->insert(parts[k], toml::table{});
      existing = t->get(parts[k]);
    } else if (!existing->is_table()) {
      throw DeckError("--set '" + text + "': '" + path + "' is a value, not a section");
    }
    t = existing->as_table();
  }
  if (const toml::node* existing = t->get(parts.back());
      existing != nullptr && existing->is_table())
    throw DeckError("--set '" + text + "': '" + key + "' is a section; set a key inside it (" +
                    key + ".KEY=VALUE)");
  value.visit([&](auto&& v) { t->insert_or_assign(parts.back(), v); });
  mark_set_subtree(r, key, value, raw);
}

// The key whose field is at `field` in `c` (a field of one row of key_table()). The cross-key
// checks below name a key by its field, so that its name is written in its row only.
std::string key_of(const Config& c, const void* field) {
  for (const KeySpec& k : key_table())
    if (k.address(c) == field) return k.key;
  throw std::logic_error("key_of: a Config field that no row of the key table reads");
}

// Cross-key checks, after every key has been read.
void check_together(const Reader& r, Config& c) {
  auto key = [&](const auto& field) { return key_of(c, &field); };
  auto given = [&](const std::string& k) { return r.seen.count(k) != 0; };
  const std::string kind_key = key(c.model.kind);
  if (!given(kind_key))
    throw DeckError(r.source + ": missing required key '" + kind_key + "' (one of " + join(kKinds) +
                    ")");
  const SceneKind* kind = find_scene_kind(c.model.kind);  // known: read by r.choice(kKinds)
  for (const RequiredKey& req : kind ? kind->required : std::vector<RequiredKey>{})
    if (!given(req.key))
      throw DeckError(r.where(kind_key, r.seen.at(kind_key)) + "missing required key '" + req.key +
                      "' (" + kind_key + " = \"" + c.model.kind + "\" " + req.why + ")");
  const std::string signal = key(c.load.base.signal), record = key(c.load.base.file);
  if (c.load.base.signal == "file" && !given(record))
    throw DeckError(r.where(signal, r.seen.at(signal)) + "missing required key '" + record + "' (" +
                    signal + " = \"file\" reads a two-column or PEER .AT2 accelerogram from it)");
  // Input files the run will read must be there now, not an hour into a sweep.
  auto readable = [&](const std::string& k, const std::string& path) {
    std::error_code ec;
    std::string why;
    if (!fs::exists(path, ec)) {
      why = "no such file";
    } else if (fs::is_directory(path, ec)) {
      why = "is a directory";
    } else {
      std::ifstream in(path);
      if (!in) why = std::strerror(errno);
    }
    if (!why.empty()) {
      const toml::node* n = r.seen.at(k);
      throw DeckError(one_line(r.where(k, n) + k + " = " + value_text(*n) + ": cannot read '" +
                               path + "' (" + why + ")"));
    }
  };
  // A joint stiffness replaces the penalty: both at once is a contradiction.
  for (const std::string& stiff :
       {key(c.contact.normal_stiffness), key(c.contact.shear_stiffness)}) {
    if (!given(stiff)) continue;
    for (const std::string& pen : {key(c.contact.penalty), key(c.contact.penalty_factor)}) {
      if (!given(pen)) continue;
      const toml::node* n = r.seen.at(stiff);
      throw DeckError(one_line(r.where(stiff, n) + stiff + " = " + value_text(*n) + " and " + pen +
                               " = " + value_text(*r.seen.at(pen)) +
                               ": give the joint stiffness (N/m3) or the penalty, not both"));
    }
  }
  if (c.solver.scheme == "nscd" && c.material.model != "rigid") {
    const std::string scheme = key(c.solver.scheme);
    const toml::node* n = r.seen.at(scheme);
    throw DeckError(one_line(r.where(scheme, n) + scheme + " = " + value_text(*n) +
                             ": non-smooth contact dynamics needs material.model = \"rigid\" "
                             "(material.model = \"" +
                             c.material.model + "\")"));
  }
  const std::string restitution = key(c.contact.restitution);
  if (given(restitution) && c.contact.restitution < 1.0 && c.material.model != "rigid") {
    const toml::node* n = r.seen.at(restitution);
    throw DeckError(one_line(r.where(restitution, n) + restitution + " = " + value_text(*n) +
                             ": impact damping needs material.model = \"rigid\" (elastic blocks "
                             "allow only 1)"));
  }
  // The input files this deck's run reads: its kind's required keys (core/scene_kinds.hpp)
  // and the accelerogram of a "file" signal. A file key that the run ignores is not opened.
  std::vector<std::string> reads;
  for (const RequiredKey& req : kind ? kind->required : std::vector<RequiredKey>{})
    reads.emplace_back(req.key);
  if (c.load.base.signal == "file") reads.emplace_back(record);
  for (const std::string& k : reads) {
    const auto it = r.input_files.find(k);
    if (it != r.input_files.end()) readable(k, it->second);
  }
  const std::string lo = key(c.capacity.lambda_min), hi = key(c.capacity.lambda_max);
  if (given(lo) && given(hi) && !(c.capacity.lambda_min == 0.0 && c.capacity.lambda_max == 0.0) &&
      !(c.capacity.lambda_min < c.capacity.lambda_max)) {
    const toml::node* n = r.seen.at(lo);
    throw DeckError(one_line(r.where(lo, n) + lo + " = " + value_text(*n) +
                             ": expected a number < " + hi + " = " + value_text(*r.seen.at(hi))));
  }
}

}  // namespace

KeyRule describe_key(const std::string& key) {
  const KeySpec* spec = find_key(key);
  if (spec == nullptr) throw std::invalid_argument("describe_key: unknown deck key " + key);
  KeyRule rule;
  rule.meaning = spec->meaning;
  static const Config defaults;
  rule.default_value = spec->show(defaults);
  // Keys a scene kind cannot do without (core/scene_kinds.hpp).
  for (const SceneKind& k : scene_kinds())
    for (const RequiredKey& req : k.required)
      if (key == req.key) rule.default_value = "required by kind \"" + std::string(k.name) + "\"";
  Reader r;
  r.probing = true;
  r.source = "(probe)";
  r.key = key;
  const toml::table probe;
  Config scratch;
  try {
    spec->read(r, probe, scratch);
  } catch (const KeyProbe& p) {
    rule.type = p.type;
    rule.unit = p.unit;
    rule.allowed = p.allowed;
    // "a number > 0 [m, 0 = automatic]" -> allowed "a number > 0; 0 = automatic", unit "m".
    const std::string suffix = " [" + p.unit + "]";
    if (!p.unit.empty() && rule.allowed.size() >= suffix.size() &&
        rule.allowed.compare(rule.allowed.size() - suffix.size(), suffix.size(), suffix) == 0)
      rule.allowed.resize(rule.allowed.size() - suffix.size());
    if (const std::size_t comma = p.unit.find(", "); comma != std::string::npos) {
      rule.allowed += "; " + p.unit.substr(comma + 2);
      rule.unit = p.unit.substr(0, comma);
    }
  }
  // A reader that took a table leaves type and allowed empty (the reference tests refuse it).
  return rule;
}

const std::vector<std::string>& known_keys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> out;
    for (const KeySpec& k : key_table()) out.emplace_back(k.key);
    return out;
  }();
  return keys;
}

Config parse_deck(const std::string& text, const std::string& source,
                  const std::vector<std::string>& overrides, const std::string& deck_dir) {
  Reader r;
  r.source = source;
  r.deck_dir = deck_dir.empty() ? "." : deck_dir;

  toml::table root;
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    throw DeckError(one_line(source + ":" + std::to_string(b.line) + ":" +
                             std::to_string(b.column) +
                             ": TOML syntax error: " + std::string(e.description())));
  }
  for (const std::string& o : overrides) apply_override(r, root, o);

  Config config;
  config.deck_path = source;
  config.deck_dir = r.deck_dir;
  walk(r, root, "", config);
  check_together(r, config);
  // Rigid blocks carry no element stress: the field is not written (`check` says so).
  if (config.material.model == "rigid") std::erase(config.output.fields, std::string("stress"));
  for (const auto& [k, n] : r.seen) {
    if (k.rfind("model.", 0) == 0) config.model.given.push_back(k.substr(6));
    if (k.rfind("contact.", 0) == 0) config.contact.given.push_back(k.substr(8));
  }
  return config;
}

Config load_deck(const std::string& path, const std::vector<std::string>& overrides) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw DeckError("cannot read deck '" + path + "': no such file");
  if (fs::is_directory(path, ec))
    throw DeckError("cannot read deck '" + path + "': is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw DeckError("cannot read deck '" + path + "': " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw DeckError("cannot read deck '" + path + "': read error");
  std::string dir = fs::path(path).parent_path().string();
  if (dir.empty()) dir = ".";
  return parse_deck(text.str(), path, overrides, dir);
}

}  // namespace voussoir

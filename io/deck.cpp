// Deck reading and validation (SPEC.md "Deck keys").
//
// How a deck becomes a Config:
//   1. the text is parsed by toml++ (a syntax error becomes "FILE:LINE:COL: TOML syntax error");
//   2. each `--set KEY=VALUE` is parsed as a TOML value (a bare word that is not valid TOML is
//      taken as a string) and inserted at its dotted path, replacing what the file said, so the
//      overrides go through exactly the same validation as the file;
//   3. the table is walked: every key must be one of the `kKeys` below (an unknown one is
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
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "core/scene_kinds.hpp"

namespace voussoir {

// Whether `key` ("embrace" or "model.embrace") is among the keys of `section` the deck gave.
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

using Apply = void (*)(Reader&, const toml::node&, Config&);
struct KeySpec {
  const char* key;
  Apply apply;
};

const std::vector<std::string> kKinds = scene_kind_names();  // core/scene_kinds.hpp

// Every key of the deck with its reader. Ranges are engineering limits: a value outside them
// is a typing slip or a unit error (kPa for Pa, radians for degrees), never a real structure.
const std::vector<KeySpec>& key_table() {
  static const std::vector<KeySpec> table = {
      // [model]
      {"model.kind", [](Reader& r, const toml::node& n, Config& c) { c.model.kind = r.choice(n, kKinds); }},
      {"model.radius", [](Reader& r, const toml::node& n, Config& c) { c.model.radius = r.number(n, above(0), "m"); }},
      {"model.thickness", [](Reader& r, const toml::node& n, Config& c) { c.model.thickness = r.number(n, above(0), "m"); }},
      {"model.embrace", [](Reader& r, const toml::node& n, Config& c) { c.model.embrace = r.number(n, {0, true, 360, true}, "deg"); }},
      {"model.voussoirs", [](Reader& r, const toml::node& n, Config& c) { c.model.voussoirs = r.integer(n, 1, 100000); }},
      {"model.offset", [](Reader& r, const toml::node& n, Config& c) { c.model.offset = r.number(n, at_least(0), "m"); }},
      {"model.small_radius", [](Reader& r, const toml::node& n, Config& c) { c.model.small_radius = r.number(n, above(0), "m"); }},
      {"model.shape", [](Reader& r, const toml::node& n, Config& c) { c.model.shape = r.choice(n, {"circular", "basket"}); }},
      {"model.buttress_width", [](Reader& r, const toml::node& n, Config& c) { c.model.buttress_width = r.number(n, above(0), "m"); }},
      {"model.base_depth", [](Reader& r, const toml::node& n, Config& c) { c.model.base_depth = r.number(n, above(0), "m"); }},
      {"model.courses", [](Reader& r, const toml::node& n, Config& c) { c.model.courses = r.number(n, at_least(0), "m, 0 = monolithic"); }},
      {"model.spans", [](Reader& r, const toml::node& n, Config& c) {
         const char* what = "a non-empty array of spans > 0 [m]";
         const toml::array& a = r.array(n, what);
         if (a.empty()) r.fail(n, what);
         c.model.spans.clear();
         for (const toml::node& e : a) {
           const double v = e.is_number() ? e.value<double>().value_or(0.0) : 0.0;
           if (!e.is_number() || !inside(above(0), v)) r.fail(n, what);
           c.model.spans.push_back(v);
         }
       }},
      {"model.height", [](Reader& r, const toml::node& n, Config& c) { c.model.height = r.number(n, above(0), "m"); }},
      {"model.pier_width", [](Reader& r, const toml::node& n, Config& c) { c.model.pier_width = r.number(n, above(0), "m"); }},
      {"model.outer_width", [](Reader& r, const toml::node& n, Config& c) { c.model.outer_width = r.number(n, above(0), "m"); }},
      {"model.eccentricity", [](Reader& r, const toml::node& n, Config& c) { c.model.eccentricity = r.number(n, {0, false, 2, false}); }},
      {"model.voussoir_angle", [](Reader& r, const toml::node& n, Config& c) { c.model.voussoir_angle = r.number(n, {0, true, 90, true}, "deg"); }},
      {"model.width", [](Reader& r, const toml::node& n, Config& c) { c.model.width = r.number(n, above(0), "m"); }},
      {"model.incline", [](Reader& r, const toml::node& n, Config& c) { c.model.incline = r.number(n, {0, false, 90, true}, "deg"); }},
      {"model.stack", [](Reader& r, const toml::node& n, Config& c) { c.model.stack = r.integer(n, 1, 1000); }},
      {"model.file", [](Reader& r, const toml::node& n, Config& c) { c.model.file = r.input_file(n); }},
      {"model.fixed", [](Reader& r, const toml::node& n, Config& c) {
         const char* what = "an array of distinct block indices (integers >= 0)";
         const toml::array& a = r.array(n, what);
         c.model.fixed.clear();
         for (const toml::node& e : a) {
           const auto* i = e.as_integer();
           if (i == nullptr || i->get() < 0 || i->get() > std::numeric_limits<int>::max())
             r.fail(n, what);
           const int v = static_cast<int>(i->get());
           if (std::find(c.model.fixed.begin(), c.model.fixed.end(), v) != c.model.fixed.end())
             r.fail(n, what);
           c.model.fixed.push_back(v);
         }
       }},
      {"model.out_of_plane", [](Reader& r, const toml::node& n, Config& c) { c.model.out_of_plane = r.number(n, above(0), "m"); }},
      // [mesh]
      {"mesh.chord_tolerance", [](Reader& r, const toml::node& n, Config& c) { c.mesh.chord_tolerance = r.number(n, {0, false, 1, false}, "x the block's thickness (rigid blocks)"); }},
      {"mesh.max_triangles", [](Reader& r, const toml::node& n, Config& c) { c.mesh.max_triangles = r.integer(n, 1, 1000000000); }},
      {"mesh.size", [](Reader& r, const toml::node& n, Config& c) { c.mesh.size = r.number(n, at_least(0), "m, 0 = use mesh.through_thickness"); }},
      {"mesh.through_thickness", [](Reader& r, const toml::node& n, Config& c) { c.mesh.through_thickness = r.integer(n, 1, 1000); }},
      // [material]
      {"material.density", [](Reader& r, const toml::node& n, Config& c) { c.material.density = r.number(n, above(0), "kg/m3"); }},
      {"material.young", [](Reader& r, const toml::node& n, Config& c) { c.material.young = r.number(n, above(0), "Pa"); }},
      {"material.poisson", [](Reader& r, const toml::node& n, Config& c) { c.material.poisson = r.number(n, {0, false, 0.5, true}); }},
      {"material.plane", [](Reader& r, const toml::node& n, Config& c) { c.material.plane = r.choice(n, {"strain", "stress"}); }},
      {"material.model", [](Reader& r, const toml::node& n, Config& c) { c.material.model = r.choice(n, {"elastic", "rigid"}); }},
      // [contact]
      {"contact.friction", [](Reader& r, const toml::node& n, Config& c) { c.contact.friction = r.number(n, at_least(0)); }},
      {"contact.penalty_factor", [](Reader& r, const toml::node& n, Config& c) { c.contact.penalty_factor = r.number(n, above(0), "x Lame's first constant"); }},
      {"contact.penalty", [](Reader& r, const toml::node& n, Config& c) { c.contact.penalty = r.number(n, at_least(0), "Pa, 0 = use contact.penalty_factor"); }},
      {"contact.buffer", [](Reader& r, const toml::node& n, Config& c) { c.contact.buffer = r.number(n, at_least(0), "m, 0 = automatic"); }},
      {"contact.normal_stiffness", [](Reader& r, const toml::node& n, Config& c) { c.contact.normal_stiffness = r.number(n, above(0), "N/m3"); }},
      {"contact.shear_stiffness", [](Reader& r, const toml::node& n, Config& c) { c.contact.shear_stiffness = r.number(n, above(0), "N/m3"); }},
      {"contact.restitution", [](Reader& r, const toml::node& n, Config& c) { c.contact.restitution = r.number(n, {0, false, 1, false}, "coefficient of restitution"); }},
      // [solver]
      {"solver.dt", [](Reader& r, const toml::node& n, Config& c) {
         const char* what = "\"auto\" or a time step > 0 [s]";
         r.expects("\"auto\" or number", "s");
         if (n.is_string() || (r.from_set(r.key) && !n.is_number())) {
           if (r.string(n) != "auto") r.fail(n, what);
           c.solver.dt = 0.0;
           return;
         }
         if (!n.is_number()) r.fail(n, what);
         const double v = n.value<double>().value_or(0.0);
         if (!inside(above(0), v)) r.fail(n, what);
         c.solver.dt = v;
       }},
      {"solver.dt_safety", [](Reader& r, const toml::node& n, Config& c) { c.solver.dt_safety = r.number(n, {0, true, 1, false}); }},
      {"solver.damping_factor", [](Reader& r, const toml::node& n, Config& c) { c.solver.damping_factor = r.number(n, at_least(0)); }},
      {"solver.end_time", [](Reader& r, const toml::node& n, Config& c) { c.solver.end_time = r.number(n, above(0), "s"); }},
      {"solver.scheme", [](Reader& r, const toml::node& n, Config& c) { c.solver.scheme = r.choice(n, {"explicit", "nscd"}); }},
      {"solver.theta", [](Reader& r, const toml::node& n, Config& c) { c.solver.theta = r.number(n, {0.5, false, 1, false}); }},
      {"solver.tolerance", [](Reader& r, const toml::node& n, Config& c) { c.solver.tolerance = r.number(n, above(0), "x the step's velocity scale"); }},
      {"solver.max_iterations", [](Reader& r, const toml::node& n, Config& c) { c.solver.max_iterations = r.integer(n, 1, 100000000); }},
      // [load]
      {"load.gravity", [](Reader& r, const toml::node& n, Config& c) { c.load.gravity = r.number(n, at_least(0), "m/s2"); }},
      {"load.lambda", [](Reader& r, const toml::node& n, Config& c) { c.load.lambda = r.number(n, any_finite(), "x gravity"); }},
      {"load.gravity_ramp", [](Reader& r, const toml::node& n, Config& c) { c.load.gravity_ramp = r.number(n, at_least(0), "s"); }},
      // [load.base]
      {"load.base.signal", [](Reader& r, const toml::node& n, Config& c) { c.load.base.signal = r.choice(n, {"none", "windowed_sine", "sine_pulse", "file"}); }},
      {"load.base.amplitude", [](Reader& r, const toml::node& n, Config& c) { c.load.base.amplitude = r.number(n, any_finite(), "g"); }},
      {"load.base.frequency", [](Reader& r, const toml::node& n, Config& c) { c.load.base.frequency = r.number(n, above(0), "Hz"); }},
      {"load.base.cycles", [](Reader& r, const toml::node& n, Config& c) { c.load.base.cycles = r.integer(n, 1, 1000); }},
      {"load.base.file", [](Reader& r, const toml::node& n, Config& c) { c.load.base.file = r.input_file(n); }},
      {"load.base.units", [](Reader& r, const toml::node& n, Config& c) { c.load.base.units = r.choice(n, {"g", "m/s2"}); }},
      {"load.base.baseline", [](Reader& r, const toml::node& n, Config& c) { c.load.base.baseline = r.choice(n, {"none", "constant", "linear", "quadratic"}); }},
      {"load.base.band", [](Reader& r, const toml::node& n, Config& c) {
         const char* what = "[low, high] in Hz with 0 <= low < high, or [0, 0] for no filter";
         const toml::array& a = r.array(n, what);
         if (a.size() != 2 || !a[0].is_number() || !a[1].is_number()) r.fail(n, what);
         const double lo = a[0].value<double>().value_or(0.0), hi = a[1].value<double>().value_or(0.0);
         if (!std::isfinite(lo) || !std::isfinite(hi)) r.fail(n, what);
         if (!(lo == 0.0 && hi == 0.0) && !(lo >= 0.0 && lo < hi)) r.fail(n, what);
         c.load.base.band = {lo, hi};
       }},
      // [capacity]
      {"capacity.lambda_min", [](Reader& r, const toml::node& n, Config& c) { c.capacity.lambda_min = r.number(n, at_least(0)); }},
      {"capacity.lambda_max", [](Reader& r, const toml::node& n, Config& c) { c.capacity.lambda_max = r.number(n, at_least(0)); }},
      {"capacity.local_damping", [](Reader& r, const toml::node& n, Config& c) { c.capacity.local_damping = r.number(n, {0, false, 1, true}, "local damping coefficient of the quasi-static trials"); }},
      {"capacity.local_damping_mode", [](Reader& r, const toml::node& n, Config& c) { c.capacity.local_damping_mode = r.choice(n, {"outgoing", "full"}); }},
      {"capacity.kinetic_damping", [](Reader& r, const toml::node& n, Config& c) { c.capacity.kinetic_damping = r.number(n, {0, false, 1, true}, "fraction of the peak kinetic energy"); }},
      {"capacity.mass_scaling", [](Reader& r, const toml::node& n, Config& c) { c.capacity.mass_scaling = r.choice(n, {"equalize", "none"}); }},
      {"capacity.tolerance", [](Reader& r, const toml::node& n, Config& c) { c.capacity.tolerance = r.number(n, {0, true, 1, true}, "relative bracket width"); }},
      // [supports]
      {"supports.moves", [](Reader& r, const toml::node& n, Config& c) {
         const char* what =
             "an array of {block = B, dx = X, dy = Y, rotation = R} (B: a fixed block's index, "
             "X, Y in m, R in degrees, |R| <= 90; dx, dy, rotation optional, 0 by default), each block once";
         const toml::array& a = r.array(n, what);
         c.supports.moves.clear();
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
               for (const SupportMoveConfig& o : c.supports.moves)
                 if (o.block == m.block) bad(field, v, "each block at most once");
               continue;
             }
             double* out = field == "dx" ? &m.dx : field == "dy" ? &m.dy
                                        : field == "rotation" ? &m.rotation : nullptr;
             if (out == nullptr) bad(field, v, "one of the fields block, dx, dy, rotation");
             const auto* i = v.as_integer();
             const auto* f = v.as_floating_point();
             const double x = i ? static_cast<double>(i->get()) : f ? f->get() : NAN;
             const bool angle = field == "rotation";
             if (!std::isfinite(x) || (angle && !(std::abs(x) <= 90.0)))
               bad(field, v, angle ? "a finite number of degrees in [-90, 90]"
                                   : "a finite number [m]");
             *out = x;
           }
           c.supports.moves.push_back(m);
         }
       }},
      {"supports.ramp", [](Reader& r, const toml::node& n, Config& c) { c.supports.ramp = r.number(n, above(0), "s"); }},
      // [output]
      {"output.file", [](Reader& r, const toml::node& n, Config& c) { c.output.file = r.string(n); }},
      {"output.every", [](Reader& r, const toml::node& n, Config& c) { c.output.every = r.number(n, above(0), "s"); }},
      {"output.fields", [](Reader& r, const toml::node& n, Config& c) {
         const char* what = "an array of distinct names among \"position\", \"velocity\", \"stress\"";
         static const std::vector<std::string> allowed = {"position", "velocity", "stress"};
         const toml::array& a = r.array(n, what);
         c.output.fields.clear();
         for (const toml::node& e : a) {
           const auto* s = e.as_string();
           if (s == nullptr || std::find(allowed.begin(), allowed.end(), s->get()) == allowed.end())
             r.fail(n, what);
           if (std::find(c.output.fields.begin(), c.output.fields.end(), s->get()) != c.output.fields.end())
             r.fail(n, what);
           c.output.fields.push_back(s->get());
         }
       }},
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
// section, the distance of the key names plus one (so "model.frction" finds
// "contact.friction"). Close enough to be a slip: at most one edit per four characters of the
// name, and two edits are always allowed.
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
      spec->apply(r, v, config);
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

// Cross-key checks, after every key has been read.
void check_together(const Reader& r, Config& c) {
  auto given = [&](const std::string& k) { return r.seen.count(k) != 0; };
  if (!given("model.kind"))
    throw DeckError(r.source + ": missing required key 'model.kind' (one of " + join(kKinds) + ")");
  const SceneKind* kind = find_scene_kind(c.model.kind);  // known: read by r.choice(kKinds)
  for (const RequiredKey& req : kind ? kind->required : std::vector<RequiredKey>{})
    if (!given(req.key))
      throw DeckError(r.where("model.kind", r.seen.at("model.kind")) + "missing required key '" +
                      req.key + "' (model.kind = \"" + c.model.kind + "\" " + req.why + ")");
  if (c.load.base.signal == "file" && !given("load.base.file"))
    throw DeckError(r.where("load.base.signal", r.seen.at("load.base.signal")) +
                    "missing required key 'load.base.file' (load.base.signal = \"file\" reads a "
                    "two-column or PEER .AT2 accelerogram from it)");
  // Input files the run will read must be there now, not an hour into a sweep.
  auto readable = [&](const std::string& key, const std::string& path) {
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
      const toml::node* n = r.seen.at(key);
      throw DeckError(one_line(r.where(key, n) + key + " = " + value_text(*n) + ": cannot read '" +
                               path + "' (" + why + ")"));
    }
  };
  // A joint stiffness replaces the penalty: both at once is a contradiction.
  for (const char* stiff : {"contact.normal_stiffness", "contact.shear_stiffness"}) {
    if (!given(stiff)) continue;
    for (const char* pen : {"contact.penalty", "contact.penalty_factor"}) {
      if (!given(pen)) continue;
      const toml::node* n = r.seen.at(stiff);
      throw DeckError(one_line(r.where(stiff, n) + stiff + " = " + value_text(*n) + " and " + pen +
                               " = " + value_text(*r.seen.at(pen)) +
                               ": give the joint stiffness (N/m3) or the penalty, not both"));
    }
  }
  if (c.solver.scheme == "nscd" && c.material.model != "rigid") {
    const toml::node* n = r.seen.at("solver.scheme");
    throw DeckError(one_line(r.where("solver.scheme", n) + "solver.scheme = " + value_text(*n) +
                             ": non-smooth contact dynamics needs material.model = \"rigid\" "
                             "(material.model = \"" + c.material.model + "\")"));
  }
  if (given("contact.restitution") && c.contact.restitution < 1.0 && c.material.model != "rigid") {
    const toml::node* n = r.seen.at("contact.restitution");
    throw DeckError(one_line(r.where("contact.restitution", n) + "contact.restitution = " +
                             value_text(*n) +
                             ": impact damping needs material.model = \"rigid\" (elastic blocks "
                             "allow only 1)"));
  }
  // The input files this deck's run reads: its kind's required keys (core/scene_kinds.hpp)
  // and the accelerogram of a "file" signal. A file key that the run ignores is not opened.
  std::vector<std::string> reads;
  for (const RequiredKey& req : kind ? kind->required : std::vector<RequiredKey>{})
    reads.emplace_back(req.key);
  if (c.load.base.signal == "file") reads.emplace_back("load.base.file");
  for (const std::string& key : reads) {
    const auto it = r.input_files.find(key);
    if (it != r.input_files.end()) readable(key, it->second);
  }
  if (given("capacity.lambda_min") && given("capacity.lambda_max") &&
      !(c.capacity.lambda_min == 0.0 && c.capacity.lambda_max == 0.0) &&
      !(c.capacity.lambda_min < c.capacity.lambda_max)) {
    const toml::node* n = r.seen.at("capacity.lambda_min");
    throw DeckError(one_line(r.where("capacity.lambda_min", n) + "capacity.lambda_min = " +
                             value_text(*n) + ": expected a number < capacity.lambda_max = " +
                             value_text(*r.seen.at("capacity.lambda_max"))));
  }
}

}  // namespace

KeyRule describe_key(const std::string& key) {
  const KeySpec* spec = find_key(key);
  if (spec == nullptr) throw std::invalid_argument("describe_key: unknown deck key " + key);
  Reader r;
  r.probing = true;
  r.source = "(probe)";
  r.key = key;
  const toml::table probe;
  Config scratch;
  try {
    spec->apply(r, probe, scratch);
  } catch (const KeyProbe& p) {
    KeyRule rule{p.type, p.unit, p.allowed};
    // "a number > 0 [m, 0 = automatic]" -> allowed "a number > 0; 0 = automatic", unit "m".
    const std::string suffix = " [" + p.unit + "]";
    if (!p.unit.empty() && rule.allowed.size() >= suffix.size() &&
        rule.allowed.compare(rule.allowed.size() - suffix.size(), suffix.size(), suffix) == 0)
      rule.allowed.resize(rule.allowed.size() - suffix.size());
    if (const std::size_t comma = p.unit.find(", "); comma != std::string::npos) {
      rule.allowed += "; " + p.unit.substr(comma + 2);
      rule.unit = p.unit.substr(0, comma);
    }
    return rule;
  }
  return {};  // the reader took a table: no rule to show (the reference test refuses this)
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
  if (config.material.model == "rigid")
    std::erase(config.output.fields, std::string("stress"));
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

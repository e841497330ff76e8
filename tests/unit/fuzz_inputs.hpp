#pragma once
// Bad-input fuzzing of the voussoir program (docs/reference/commands.md, exit statuses):
// deterministic mutations of the shipped decks (cases/*.toml) and of the polygon and gmsh files of
// tests/data, fed to `voussoir check` and `voussoir run` in a child process with a wall-clock, CPU
// and memory limit (tests/unit/subprocess.hpp). Shared by tests/unit/test_fuzz.cpp (the default
// share) and tests/slow/test_fuzz_slow.cpp (the full set).
//
// Contract checked for every input (docs/reference/commands.md, exit status):
//   check: exit 0, or exit 2 with a "voussoir: error:" message;
//   run:   the same, or exit 1 with a "voussoir: run failed:" message naming the step (a run
//          that a guard stopped: engine/run_loop.hpp; the deck was valid but its numbers were not
//          runnable, e.g. lambda = 1e300);
//   never a signal (crash, abort, sanitizer report), never the time limit (hang), never the
//   memory limit (std::bad_alloc would surface as exit 1 without a step: refused as well).
// The work of an input is bounded by counts, so that a loaded machine never decides an outcome:
// every command gets mesh.max_triangles = kFuzzMaxTriangles (a mutation that makes a larger mesh
// is refused by name, exit 2, before or while it is meshed) and `run` gets --max-steps
// kFuzzMaxSteps (a run still going then fails naming the step, exit 1). The wall-clock limit
// stays, as the net for a hang.
// Every failing input is kept under <tmp>/voussoir_fuzz_failures/ with a line to reproduce it.

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "io/deck.hpp"
#include "subprocess.hpp"

namespace voussoir::testing {

namespace fuzz_fs = std::filesystem;

// The shipped decks have 24 to 630 triangles and take 1e-4 s in 3 to 200 steps; a mutation
// that scales the mesh (mesh.through_thickness = 3) stays far below these bounds. Above them:
// `check` of a 1.7 million triangle block (model.width = 2000, a swap of two values) took 15 to
// 30 s of a 20 s limit on a loaded machine, and a rigid church with a 1e4 times smaller step
// (material.density = 1e-4) ran 1e6 steps for minutes. At the bounds: meshing 20 000
// triangles, or a block's runaway quality mesh stopped there, takes under a second; 5000 steps
// of 20 000 triangles are 1e8 triangle-steps, about 3 s at the 28 ns a triangle-step of the
// elastic block measured on this machine.
inline constexpr int kFuzzMaxTriangles = 20000;
inline constexpr int kFuzzMaxSteps = 5000;

inline std::string source_path(const std::string& rel) {
  return std::string(VOUSSOIR_SOURCE_DIR) + "/" + rel;
}

// Numbers at and beyond the edges of every range: zero, signs, overflow and underflow of
// double and of 32/64-bit integers, NaN and infinities, huge counts.
inline const std::vector<std::string>& extreme_values() {
  static const std::vector<std::string> v = {"0",
                                             "-0.0",
                                             "-1",
                                             "1e308",
                                             "-1e308",
                                             "1e-308",
                                             "5e-324",
                                             "nan",
                                             "inf",
                                             "-inf",
                                             "+inf",
                                             "-nan",
                                             "9223372036854775807",
                                             "-9223372036854775808",
                                             "2147483648",
                                             "4294967296",
                                             "1e9",
                                             "100000",
                                             "1000",
                                             "1e-9",
                                             "1e15",
                                             "0.5",
                                             "3",
                                             "360",
                                             "180.0000001",
                                             "1e6",
                                             "-1e-300",
                                             "0.0001",
                                             "65536",
                                             "0x7fffffff",
                                             "1e19",
                                             "123456789012345678901234567890"};
  return v;
}

// Values of another type than a key expects.
inline const std::vector<std::string>& other_types() {
  static const std::vector<std::string> v = {"\"text\"",
                                             "true",
                                             "false",
                                             "[1, 2]",
                                             "{ a = 1 }",
                                             "[]",
                                             "1979-05-27T07:32:00Z",
                                             "\"\"",
                                             "[[1], [2]]",
                                             "'single'",
                                             "\"auto\"",
                                             "[\"position\", \"position\"]",
                                             "07:32:00",
                                             "[1e308, -1e308]",
                                             "{}",
                                             "\"1.0\"",
                                             "[0, 0]",
                                             "[nan, 1]",
                                             "\"circular_arch\""};
  return v;
}

class Mutator {
 public:
  explicit Mutator(std::uint64_t seed) : rng_(seed) {}

  std::size_t pick(std::size_t n) {
    return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_);
  }
  bool coin(double p) { return std::uniform_real_distribution<double>(0.0, 1.0)(rng_) < p; }

  // One to three mutations of a TOML deck; `what` describes them.
  std::string deck(std::string text, std::string& what) {
    const int count = 1 + static_cast<int>(pick(3));
    for (int k = 0; k < count; ++k) text = deck_once(text, what);
    return text;
  }

  // One to three mutations of a polygon text file or a gmsh file (numbers and lines).
  std::string geometry(std::string text, std::string& what) {
    const int count = 1 + static_cast<int>(pick(3));
    for (int k = 0; k < count; ++k) text = geometry_once(text, what);
    return text;
  }

 private:
  std::mt19937_64 rng_;

  static std::vector<std::string> lines_of(const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string l; std::getline(in, l);) lines.push_back(l);
    return lines;
  }
  static std::string join_lines(const std::vector<std::string>& lines) {
    std::string s;
    for (const std::string& l : lines) s += l + "\n";
    return s;
  }
  // Lines holding `key = value` (not comments, not section headers).
  static std::vector<std::size_t> key_lines(const std::vector<std::string>& lines) {
    std::vector<std::size_t> out;
    for (std::size_t i = 0; i < lines.size(); ++i) {
      const std::string& l = lines[i];
      const std::size_t b = l.find_first_not_of(" \t");
      if (b == std::string::npos || l[b] == '#' || l[b] == '[') continue;
      if (l.find('=') != std::string::npos) out.push_back(i);
    }
    return out;
  }
  static std::string set_value(const std::string& line, const std::string& value) {
    return line.substr(0, line.find('=') + 1) + " " + value;
  }

  std::string garbage(std::string text, std::string& what) {
    const std::size_t at = text.empty() ? 0 : pick(text.size() + 1);
    const std::size_t n = 1 + pick(16);
    std::string bytes;
    for (std::size_t k = 0; k < n; ++k) bytes.push_back(static_cast<char>(pick(256)));
    text.insert(at, bytes);
    what += "garbage(" + std::to_string(n) + "@" + std::to_string(at) + ") ";
    return text;
  }
  std::string truncate(const std::string& text, std::string& what) {
    const std::size_t at = text.empty() ? 0 : pick(text.size());
    what += "truncate@" + std::to_string(at) + " ";
    return text.substr(0, at);
  }

  std::string deck_once(const std::string& text, std::string& what) {
    std::vector<std::string> lines = lines_of(text);
    const std::vector<std::size_t> keys = key_lines(lines);
    const std::size_t op = pick(10);
    if (keys.empty() && op <= 2) return garbage(text, what);
    switch (op) {
      case 0: {  // delete a key
        const std::size_t i = keys[pick(keys.size())];
        what += "delete[" + lines[i].substr(0, lines[i].find('=')) + "] ";
        lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(i));
        return join_lines(lines);
      }
      case 1: {  // another type
        const std::size_t i = keys[pick(keys.size())];
        const std::string& v = other_types()[pick(other_types().size())];
        lines[i] = set_value(lines[i], v);
        what += "type[" + lines[i] + "] ";
        return join_lines(lines);
      }
      case 2: {  // an extreme number
        const std::size_t i = keys[pick(keys.size())];
        lines[i] = set_value(lines[i], extreme_values()[pick(extreme_values().size())]);
        what += "extreme[" + lines[i] + "] ";
        return join_lines(lines);
      }
      case 3:
        return garbage(text, what);
      case 4:
        return truncate(text, what);
      case 5: {  // a known key (maybe absent from this deck) with an extreme or odd value
        const std::vector<std::string>& known = known_keys();
        const std::string key = known[pick(known.size())];
        const std::string value = coin(0.7) ? extreme_values()[pick(extreme_values().size())]
                                            : other_types()[pick(other_types().size())];
        const std::size_t dot = key.rfind('.');
        const std::string section = key.substr(0, dot), leaf = key.substr(dot + 1);
        // Into its section if the deck has it, else as a new section at the end.
        std::size_t at = lines.size();
        bool found = false;
        for (std::size_t i = 0; i < lines.size(); ++i)
          if (lines[i] == "[" + section + "]") {
            at = i + 1;
            found = true;
          }
        if (found) {
          lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(at), leaf + " = " + value);
        } else {
          lines.push_back("[" + section + "]");
          lines.push_back(leaf + " = " + value);
        }
        what += "add[" + key + " = " + value + "] ";
        return join_lines(lines);
      }
      case 6: {  // duplicate a line (duplicate key or section)
        if (lines.empty()) return garbage(text, what);
        const std::size_t i = pick(lines.size());
        lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(i), lines[i]);
        what += "dup[" + lines[i] + "] ";
        return join_lines(lines);
      }
      case 7: {  // an unknown key or section
        static const std::vector<std::string> unknown = {"frobnicate = 1", "[nonsense]",
                                                         "radius_ = 2",    "[model.sub]",
                                                         "kind.x = 1",     "\"quoted key\" = 3"};
        const std::size_t i = lines.empty() ? 0 : pick(lines.size() + 1);
        const std::string& u = unknown[pick(unknown.size())];
        lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(i), u);
        what += "unknown[" + u + "] ";
        return join_lines(lines);
      }
      case 8: {  // break or remove a section header
        std::vector<std::size_t> headers;
        for (std::size_t i = 0; i < lines.size(); ++i)
          if (!lines[i].empty() && lines[i][0] == '[') headers.push_back(i);
        if (headers.empty()) return garbage(text, what);
        const std::size_t i = headers[pick(headers.size())];
        static const std::vector<std::string> broken = {
            "", "[", "[]", "[[model]]", "[model", "[ model ]", "[contact.friction]"};
        const std::string& b = broken[pick(broken.size())];
        what += "header[" + lines[i] + " -> " + b + "] ";
        lines[i] = b;
        return join_lines(lines);
      }
      default: {  // swap the values of two keys
        if (keys.size() < 2) return garbage(text, what);
        const std::size_t i = keys[pick(keys.size())], j = keys[pick(keys.size())];
        const std::string vi = lines[i].substr(lines[i].find('=') + 1);
        const std::string vj = lines[j].substr(lines[j].find('=') + 1);
        lines[i] = set_value(lines[i], vj);
        lines[j] = set_value(lines[j], vi);
        what += "swap[" + std::to_string(i) + "," + std::to_string(j) + "] ";
        return join_lines(lines);
      }
    }
  }

  std::string geometry_once(const std::string& text, std::string& what) {
    std::vector<std::string> lines = lines_of(text);
    const std::size_t op = pick(8);
    if (lines.empty() && op != 3 && op != 4) return garbage(text, what);
    switch (op) {
      case 0: {  // a number token becomes an extreme value
        for (int attempt = 0; attempt < 20; ++attempt) {
          const std::size_t i = pick(lines.size());
          std::istringstream in(lines[i]);
          std::vector<std::string> tokens;
          for (std::string t; in >> t;) tokens.push_back(t);
          if (tokens.empty()) continue;
          const std::size_t k = pick(tokens.size());
          if (tokens[k].find_first_of("0123456789") == std::string::npos) continue;
          tokens[k] = extreme_values()[pick(extreme_values().size())];
          std::string l;
          for (const std::string& t : tokens) l += (l.empty() ? "" : " ") + t;
          lines[i] = l;
          what += "number[" + std::to_string(i) + ": " + l + "] ";
          break;
        }
        return join_lines(lines);
      }
      case 1: {  // delete a line
        const std::size_t i = pick(lines.size());
        what += "delete[" + lines[i] + "] ";
        lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(i));
        return join_lines(lines);
      }
      case 2: {  // duplicate a line
        const std::size_t i = pick(lines.size());
        lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(i), lines[i]);
        what += "dup[" + lines[i] + "] ";
        return join_lines(lines);
      }
      case 3:
        return garbage(text, what);
      case 4:
        return truncate(text, what);
      case 5: {  // an odd line: a block marker, a section marker, words, a lone number
        static const std::vector<std::string> odd = {
            "block", "$EndNodes", "$Nodes",      "1 2",     "x y", "0 0 0 0 0 0",
            "-1",    "$Elements", "1e308 1e308", "nan nan", ","};
        const std::size_t i = pick(lines.size() + 1);
        const std::string& o = odd[pick(odd.size())];
        lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(i), o);
        what += "odd[" + o + "@" + std::to_string(i) + "] ";
        return join_lines(lines);
      }
      case 6: {  // move a vertex far away or onto another (overlaps, self-intersection)
        const std::size_t i = pick(lines.size()), j = pick(lines.size());
        what += "copy[" + std::to_string(j) + "->" + std::to_string(i) + "] ";
        lines[i] = lines[j];
        return join_lines(lines);
      }
      default: {  // swap two lines
        const std::size_t i = pick(lines.size()), j = pick(lines.size());
        std::swap(lines[i], lines[j]);
        what += "swap[" + std::to_string(i) + "," + std::to_string(j) + "] ";
        return join_lines(lines);
      }
    }
  }
};

struct FuzzTally {
  std::map<std::string, int> outcomes;  // "check exit 0", "run exit 1", ...
  int inputs = 0;
  int failures = 0;

  std::string summary() const {
    std::ostringstream s;
    s << inputs << " inputs:";
    for (const auto& [k, n] : outcomes) s << " " << k << " x" << n << ";";
    return s.str();
  }
};

inline std::string fuzz_dir() {
  const fuzz_fs::path d = fuzz_fs::temp_directory_path() /
                          ("voussoir_fuzz_" + std::to_string(static_cast<long long>(::getpid())));
  fuzz_fs::create_directories(d);
  return d.string();
}

inline void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// Feeds the deck at `deck_path` to `command` ("check" or "run") and checks the contract in the
// header; on failure the deck (and `extra_file`, if any) is copied to the failure folder.
inline void fuzz_one(const std::string& command, const std::string& deck_path,
                     const std::string& what, FuzzTally& tally, const std::string& label,
                     const std::string& extra_file = "") {
  const std::string dir = fuzz_fs::path(deck_path).parent_path().string();
  std::vector<std::string> args = {
      VOUSSOIR_BINARY, command,
      deck_path,       "-q",
      "--set",         "mesh.max_triangles=" + std::to_string(kFuzzMaxTriangles)};
  // Within the bounds above an input checks in under a second and runs in a few; 20 and 40 s
  // leave room for a loaded machine and sanitizer builds.
  Limits limits;
  limits.wall_s = command == "run" ? 40 : 20;
  limits.cpu_s = 2 * limits.wall_s;
  if (command == "run") {
    // A short end time, whatever the deck says; output into the scratch folder.
    args.insert(args.end(), {"--set", "solver.end_time=1e-4", "--max-steps",
                             std::to_string(kFuzzMaxSteps), "-o", dir + "/fuzz_run.h5"});
  }
  const ProcessResult r = run_process(args, limits, dir + "/child");
  ++tally.inputs;
  std::string outcome = command + (r.exited ? " exit " + std::to_string(r.status)
                                            : " signal " + std::to_string(r.signal));
  bool ok = false;
  if (r.exited && r.status == 0) ok = true;
  if (r.exited && r.status == 2) ok = r.err.find("voussoir: error:") != std::string::npos;
  if (r.exited && r.status == 1 && command == "run")
    ok = r.err.find("run failed:") != std::string::npos &&
         r.err.find("at step") != std::string::npos;
  ++tally.outcomes[outcome];
  if (ok) return;
  ++tally.failures;
  const fuzz_fs::path keep = fuzz_fs::temp_directory_path() / "voussoir_fuzz_failures";
  fuzz_fs::create_directories(keep);
  const std::string name = label + "_" + std::to_string(tally.inputs);
  std::error_code ec;
  fuzz_fs::copy_file(deck_path, keep / (name + ".toml"), fuzz_fs::copy_options::overwrite_existing,
                     ec);
  if (!extra_file.empty())
    fuzz_fs::copy_file(extra_file, keep / (name + fuzz_fs::path(extra_file).extension().string()),
                       fuzz_fs::copy_options::overwrite_existing, ec);
  ADD_FAILURE() << command << " on mutated " << label << " (" << what << "): " << r.describe()
                << "\nstderr: " << r.err.substr(0, 2000) << "\nkept as "
                << (keep / (name + ".toml")).string();
}

// `count` mutated versions of the shipped deck `case_name`, each fed to `check`; every
// `run_every`-th one also to `run` (0 = never).
inline FuzzTally fuzz_deck(const std::string& case_name, int count, int run_every,
                           std::uint64_t seed) {
  const std::string original = read_text_file(source_path("cases/" + case_name + ".toml"));
  Mutator m(seed);
  FuzzTally tally;
  const std::string dir = fuzz_dir();
  const std::string deck = dir + "/" + case_name + ".toml";
  for (int k = 0; k < count; ++k) {
    std::string what;
    write_text(deck, m.deck(original, what));
    fuzz_one("check", deck, what, tally, case_name);
    if (run_every > 0 && k % run_every == 0) fuzz_one("run", deck, what, tally, case_name);
  }
  std::error_code ec;
  fuzz_fs::remove_all(dir, ec);
  return tally;
}

// `count` mutated versions of a polygon text or gmsh file of tests/data (`data_file`), each
// read through a `kind = "polygons"` deck (block 1 fixed) by `check`, every `run_every`-th
// also by `run`.
inline FuzzTally fuzz_geometry(const std::string& data_file, int count, int run_every,
                               std::uint64_t seed) {
  const std::string original = read_text_file(source_path("tests/data/" + data_file));
  Mutator m(seed);
  FuzzTally tally;
  const std::string dir = fuzz_dir();
  const std::string geometry = dir + "/" + data_file;
  const std::string deck = dir + "/polygons.toml";
  write_text(deck, "[model]\nkind = \"polygons\"\nfile = \"" + data_file +
                       "\"\nfixed = [1]\n\n[contact]\nfriction = 0.6\n");
  for (int k = 0; k < count; ++k) {
    std::string what;
    write_text(geometry, m.geometry(original, what));
    fuzz_one("check", deck, what, tally, data_file, geometry);
    if (run_every > 0 && k % run_every == 0)
      fuzz_one("run", deck, what, tally, data_file, geometry);
  }
  std::error_code ec;
  fuzz_fs::remove_all(dir, ec);
  return tally;
}

}  // namespace voussoir::testing

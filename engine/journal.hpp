#pragma once
// The one journal format (capacity's trials, sweep's cells, stability's cells, the pulse
// curve's runs: `--resume FILE` of each command): a file of JSON lines, the first
// {"fingerprint": "<16 hex digits>"} (core/fnv.hpp over what the records depend on), then one
// record a line, appended and flushed as each finishes, so a killed command resumes from the
// records already there. A journal of another fingerprint is refused, never mixed; a line cut
// by the kill is dropped (its work is done again) and the file rewritten without it.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/kinematics.hpp"

namespace voussoir {

// The hinges of a record: one array [joint, block_a, block_b, kind, side, position_deg, x, y,
// opening, slip] per hinge, NaN written as null (a joint without an angular position).
nlohmann::json hinges_record(const std::vector<Hinge>& hinges);
std::vector<Hinge> hinges_from_record(const nlohmann::json& record);

class Journal {
 public:
  // An empty path: no journal (nothing read or written). Throws RunError when the file holds
  // another fingerprint or cannot be written.
  Journal(const std::string& path, const std::string& fingerprint);
  // Records held in memory only (a cell's share of rank 0's journal, sent with the cell under
  // mpirun: engine/dealer.hpp): read, appends dropped.
  explicit Journal(std::vector<nlohmann::json> records) : records_(std::move(records)) {}
  const std::vector<nlohmann::json>& records() const { return records_; }
  // Appends one record (not thread-safe: callers serialise).
  void append(const nlohmann::json& record);

 private:
  std::string path_;
  std::vector<nlohmann::json> records_;
};

}  // namespace voussoir

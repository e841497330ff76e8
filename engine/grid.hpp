#pragma once
// Grids of deck values for `voussoir sweep` and `voussoir stability`: the `--param` axes
// (lists and ranges), and the grid of validated decks, row-major with the last axis fastest.

#include <fstream>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "core/fnv.hpp"
#include "core/schema.hpp"

namespace voussoir {

// One axis of a grid, from `--param KEY=V1,V2,...` or `--param KEY=start:stop:step`.
// The key `model.thickness_ratio` is a convenience: the cell's model.thickness becomes
// ratio x model.radius (the radius of the cell's deck).
struct GridAxis {
  std::string key;
  std::vector<std::string> values;  // as written to the deck override
};

inline constexpr const char* kThicknessRatioKey = "model.thickness_ratio";

// Expands "start:stop:step" into decimal strings start, start + step, ... up to stop included
// when stop lies on the grid (within 1e-9 of a step). Each value is computed as
// start + i x step and printed with the number of decimals of the inputs, so 0.2:0.8:0.05
// gives exactly "0.20", "0.25", ..., "0.80" (13 values, no floating drift). Throws DeckError
// for a non-positive step, stop < start or text that is not three numbers.
std::vector<std::string> expand_range(const std::string& spec);

// Parses one --param; throws DeckError naming the text when malformed.
GridAxis parse_grid_param(const std::string& text);

struct Grid {
  std::vector<GridAxis> axes;
  std::vector<Config> configs;                   // row-major, last axis fastest
  std::vector<std::vector<std::string>> values;  // per cell, per axis
};

// Builds every cell's deck (validated up front, so a bad value stops the map before any
// work) from the deck file, the --set overrides and the axes.
Grid make_grid(const std::string& deck_path, const std::vector<std::string>& sets,
               const std::vector<GridAxis>& axes);

// A grid value (as written to the deck override) for a JSON summary: a number when the text
// is one ("0.3" -> 0.3), else the text.
nlohmann::json param_value(const std::string& text);

// Adds to `print` (core/fnv.hpp) what a grid of runs depends on: the deck path, its overrides
// and the axes with their values (the journals of `sweep` and `stability`).
void fingerprint_grid(Fnv& print, const std::string& deck_path,
                      const std::vector<std::string>& sets, const std::vector<GridAxis>& axes);

// The CSV of a grid (sweep, stability): written to PATH.tmp and renamed to PATH when complete,
// so a partial file is never taken for a finished one; each row opens with the cell's swept
// values, the header with the axes' keys.
class GridCsv {
 public:
  // Opens PATH.tmp at `precision` digits and writes the axes' keys, each followed by a comma
  // (the caller writes the rest of the header). Throws OutputError when it cannot.
  GridCsv(const std::string& path, int precision, const std::vector<GridAxis>& axes);
  std::ostream& out() { return csv_; }
  // Writes the swept values of one cell, each followed by a comma, and returns them for the
  // JSON summary ({key: param_value}).
  nlohmann::json cell(const std::vector<std::string>& values);
  // Closes and renames the file; throws OutputError when it could not be written.
  void finish();

 private:
  std::string path_;
  const std::vector<GridAxis>& axes_;
  std::ofstream csv_;
};

// A CSV field in double quotes (quotes inside doubled), for free text such as error messages.
std::string csv_quote(const std::string& text);

}  // namespace voussoir

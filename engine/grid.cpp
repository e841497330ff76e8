// Grids of deck values (grid.hpp).

#include "engine/grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "io/deck.hpp"
#include "io/json.hpp"

namespace voussoir {
namespace {

// Whole text parsed as a finite number.
bool parse_number(const std::string& s, double& v) {
  if (s.empty()) return false;
  char* end = nullptr;
  v = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size() && std::isfinite(v);
}

// Digits after the decimal point of a plain decimal ("0.05" -> 2, "3" -> 0); -1 when the
// number has an exponent (printed with %.12g then).
int decimals_of(const std::string& s) {
  if (s.find_first_of("eE") != std::string::npos) return -1;
  const auto dot = s.find('.');
  return dot == std::string::npos ? 0 : static_cast<int>(s.size() - dot - 1);
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

std::string format_number(double v, int decimals) {
  char buf[64];
  if (decimals >= 0)
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  else
    std::snprintf(buf, sizeof buf, "%.12g", v);
  std::string s = buf;
  if (s == "-0" || s.rfind("-0.", 0) == 0) {  // no negative zero from rounding
    double z = 0.0;
    if (parse_number(s, z) && z == 0.0) s = s.substr(1);
  }
  return s;
}

}  // namespace

std::vector<std::string> expand_range(const std::string& spec) {
  std::vector<std::string> parts;
  std::stringstream ss(spec);
  std::string p;
  while (std::getline(ss, p, ':')) parts.push_back(trim(p));
  double start = 0.0, stop = 0.0, step = 0.0;
  if (parts.size() != 3 || !parse_number(parts[0], start) || !parse_number(parts[1], stop) ||
      !parse_number(parts[2], step))
    throw DeckError("range '" + spec + "': expected start:stop:step (three numbers)");
  if (!(step > 0.0)) throw DeckError("range '" + spec + "': the step must be positive");
  if (stop < start) throw DeckError("range '" + spec + "': stop is below start");
  // Count by integer steps with a tolerance of 1e-9 step, so a stop on the grid is included
  // whatever the rounding of (stop - start) / step.
  const double span = (stop - start) / step;
  if (span > 1e6) throw DeckError("range '" + spec + "': more than a million values");
  const long n = static_cast<long>(std::floor(span + 1e-9)) + 1;
  int decimals = -1;
  const int d0 = decimals_of(parts[0]), d2 = decimals_of(parts[2]);
  if (d0 >= 0 && d2 >= 0) decimals = std::max(d0, d2);
  std::vector<std::string> out;
  out.reserve(n);
  for (long i = 0; i < n; ++i) out.push_back(format_number(start + i * step, decimals));
  return out;
}

GridAxis parse_grid_param(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw DeckError("--param '" + text + "': expected KEY=V1,V2,... or KEY=start:stop:step");
  GridAxis a;
  a.key = trim(text.substr(0, eq));
  std::stringstream ss(text.substr(eq + 1));
  std::string item;
  while (std::getline(ss, item, ',')) {
    item = trim(item);
    if (item.empty()) throw DeckError("--param '" + text + "': empty value in the list");
    if (item.find(':') != std::string::npos) {
      for (std::string& v : expand_range(item)) a.values.push_back(std::move(v));
    } else {
      a.values.push_back(item);
    }
  }
  if (a.key == kThicknessRatioKey)
    for (const std::string& v : a.values) {
      double r = 0.0;
      if (!parse_number(v, r) || !(r > 0.0))
        throw DeckError("--param '" + text +
                        "': model.thickness_ratio must be positive numbers, "
                        "got '" +
                        v + "'");
    }
  return a;
}

Grid make_grid(const std::string& deck_path, const std::vector<std::string>& sets,
               const std::vector<GridAxis>& axes) {
  Grid grid;
  grid.axes = axes;
  size_t cells = 1;
  for (const GridAxis& a : axes) {
    if (a.values.empty()) throw DeckError("--param " + a.key + ": no values");
    cells *= a.values.size();
  }
  for (size_t c = 0; c < cells; ++c) {
    size_t rest = c;
    std::vector<std::string> vals(axes.size());
    for (size_t k = axes.size(); k-- > 0;) {
      vals[k] = axes[k].values[rest % axes[k].values.size()];
      rest /= axes[k].values.size();
    }
    std::vector<std::string> cell_sets = sets;
    const GridAxis* ratio = nullptr;
    std::string ratio_value;
    for (size_t k = 0; k < axes.size(); ++k) {
      if (axes[k].key == kThicknessRatioKey) {
        ratio = &axes[k];
        ratio_value = vals[k];
      } else {
        cell_sets.push_back(axes[k].key + "=" + vals[k]);
      }
    }
    if (ratio) {
      // thickness = ratio x radius of this cell's deck (after every other override).
      const Config partial = load_deck(deck_path, cell_sets);
      const double t = std::strtod(ratio_value.c_str(), nullptr) * partial.model.radius;
      cell_sets.push_back("model.thickness=" + format_number(t, -1));
    }
    grid.configs.push_back(load_deck(deck_path, cell_sets));
    grid.values.push_back(std::move(vals));
  }
  return grid;
}

nlohmann::json param_value(const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (!text.empty() && end == text.c_str() + text.size() && std::isfinite(v)) return v;
  return text;
}

std::string csv_quote(const std::string& text) {
  std::string q = "\"";
  for (char ch : text) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return q + "\"";
}

void fingerprint_grid(Fnv& print, const std::string& deck_path,
                      const std::vector<std::string>& sets, const std::vector<GridAxis>& axes) {
  print.text(deck_path);
  for (const std::string& set : sets) print.text(set);
  for (const GridAxis& a : axes) {
    print.text(a.key);
    for (const std::string& v : a.values) print.text(v);
  }
}

GridCsv::GridCsv(const std::string& path, int precision, const std::vector<GridAxis>& axes)
    : path_(path), axes_(axes), csv_(path + ".tmp") {
  if (!csv_) throw OutputError("cannot write " + path_);
  csv_.precision(precision);
  for (const GridAxis& a : axes_) csv_ << a.key << ',';
}

nlohmann::json GridCsv::cell(const std::vector<std::string>& values) {
  nlohmann::json params = nlohmann::json::object();
  for (std::size_t k = 0; k < axes_.size(); ++k) {
    csv_ << values[k] << ',';
    params[axes_[k].key] = param_value(values[k]);
  }
  return params;
}

void GridCsv::finish() {
  csv_.close();
  if (!csv_ || std::rename((path_ + ".tmp").c_str(), path_.c_str()) != 0)
    throw OutputError("cannot write " + path_);
}

}  // namespace voussoir

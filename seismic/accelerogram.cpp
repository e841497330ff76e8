// Accelerogram files and the deck's base signal (contract in accelerogram.hpp).

#include "seismic/accelerogram.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "io/json.hpp"

namespace voussoir {

namespace {

// `token` as a finite number (strtod: the whole token, no overflow), or false.
bool to_finite(const std::string& token, double& value) {
  const char* s = token.c_str();
  char* end = nullptr;
  errno = 0;
  value = std::strtod(s, &end);
  return !(end == s || *end != '\0' || errno == ERANGE || !std::isfinite(value));
}

std::string upper(std::string s) {
  for (char& ch : s) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  return s;
}

// The number after `NAME` and '=' in the upper-case header line `line` (NPTS=  5590, DT= .0050).
bool value_after(const std::string& line, const std::string& name, double& value) {
  std::size_t at = line.find(name);
  if (at == std::string::npos) return false;
  at = line.find_first_not_of(' ', at + name.size());
  if (at == std::string::npos || line[at] != '=') return false;
  const char* s = line.c_str() + at + 1;
  char* end = nullptr;
  errno = 0;
  value = std::strtod(s, &end);
  return end != s && errno != ERANGE && std::isfinite(value);
}

// Throws the DeckError of a bad line: "SOURCE:LINE: WHAT (HINT)".
[[noreturn]] void throw_at_line(const std::string& source, int line_no, const std::string& what,
                                const std::string& hint) {
  std::ostringstream msg;
  msg << source << ":" << line_no << ": " << what << " (" << hint << ")";
  throw DeckError(msg.str());
}

}  // namespace

Accelerogram parse_at2(const std::string& text, const std::string& source, double gravity) {
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  auto fail = [&](const std::string& what) {
    throw_at_line(source, line_no, what,
                  "PEER AT2: 4 header lines, the 4th 'NPTS= N, DT= D SEC' or 'N D NPTS, DT', then "
                  "N accelerations in g");
  };
  while (line_no < 4) {
    if (!std::getline(in, line)) {
      line_no = std::max(line_no, 1);
      fail("the file ends inside the 4-line header");
    }
    ++line_no;
  }
  // Line 4: the count and the time step.
  std::string head = upper(line);
  std::replace(head.begin(), head.end(), '\t', ' ');
  std::replace(head.begin(), head.end(), '\r', ' ');
  double npts = 0.0, dt = 0.0;
  if (head.find("NPTS") == std::string::npos || head.find("DT") == std::string::npos)
    fail("no NPTS and DT in the header line '" + line + "'");
  if (head.find('=') != std::string::npos) {
    if (!value_after(head, "NPTS", npts) || !value_after(head, "DT", dt))
      fail("cannot read 'NPTS= N' and 'DT= D' from '" + line + "'");
  } else {
    std::string fields = head;
    std::replace(fields.begin(), fields.end(), ',', ' ');
    std::istringstream f(fields);
    std::string t0, t1;
    if (!(f >> t0 >> t1) || !to_finite(t0, npts) || !to_finite(t1, dt))
      fail("cannot read the two numbers N D before 'NPTS, DT' in '" + line + "'");
  }
  if (!(npts >= 2.0 && npts == std::floor(npts) && npts < 1e9)) {
    std::ostringstream what;
    what << "NPTS = " << npts << " is not a whole number >= 2";
    fail(what.str());
  }
  if (!(dt > 0.0)) {
    std::ostringstream what;
    what << "DT = " << dt << " s is not > 0";
    fail(what.str());
  }
  const std::size_t n = static_cast<std::size_t>(npts);
  Accelerogram rec;
  rec.time.reserve(n);
  rec.accel.reserve(n);
  while (std::getline(in, line)) {
    ++line_no;
    std::string fields = line;
    std::replace(fields.begin(), fields.end(), ',', ' ');
    std::replace(fields.begin(), fields.end(), '\t', ' ');
    std::replace(fields.begin(), fields.end(), '\r', ' ');
    std::istringstream f(fields);
    for (std::string tok; f >> tok;) {
      std::replace(tok.begin(), tok.end(), 'D', 'E');  // Fortran double-precision exponent
      std::replace(tok.begin(), tok.end(), 'd', 'e');
      double v = 0.0;
      if (!to_finite(tok, v)) fail("'" + tok + "' is not a finite number");
      if (rec.accel.size() == n)
        fail("more values than NPTS = " + std::to_string(n) + " (value '" + tok + "')");
      rec.time.push_back(static_cast<double>(rec.accel.size()) * dt);
      rec.accel.push_back(v * gravity);
    }
  }
  if (rec.accel.size() != n)
    fail("found " + std::to_string(rec.accel.size()) +
         " values, the header says NPTS = " + std::to_string(n));
  return rec;
}

bool looks_like_at2(const std::string& path, const std::string& text) {
  if (path.size() >= 4 && upper(path.substr(path.size() - 4)) == ".AT2") return true;
  std::istringstream in(text);
  std::string line;
  for (int k = 0; k < 4; ++k)
    if (!std::getline(in, line)) return false;
  const std::string head = upper(line.substr(0, line.find('#')));
  return head.find("NPTS") != std::string::npos && head.find("DT") != std::string::npos;
}

Accelerogram parse_accelerogram(const std::string& text, const std::string& source,
                                const std::string& units, double gravity) {
  double scale = 1.0;
  if (units == "g") {
    scale = gravity;
  } else if (units != "m/s2") {
    throw DeckError(source + ": unknown acceleration units '" + units +
                    "' (allowed: \"g\", \"m/s2\")");
  }
  Accelerogram rec;
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  auto fail = [&](const std::string& what) {
    throw_at_line(source, line_no, what,
                  "expected two numbers per line: time [s], acceleration [" + units +
                      "], separated by a comma or spaces; '#' starts a comment");
  };
  while (std::getline(in, line)) {
    ++line_no;
    const std::size_t hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    std::replace(line.begin(), line.end(), ',', ' ');
    std::replace(line.begin(), line.end(), ';', ' ');
    std::replace(line.begin(), line.end(), '\t', ' ');
    std::replace(line.begin(), line.end(), '\r', ' ');
    if (line.find_first_not_of(' ') == std::string::npos) continue;
    std::istringstream fields(line);
    std::vector<std::string> tokens;
    for (std::string tok; fields >> tok;) tokens.push_back(tok);
    if (tokens.size() != 2)
      fail("found " + std::to_string(tokens.size()) + " values '" + line + "'");
    double v[2];
    for (int c = 0; c < 2; ++c)
      if (!to_finite(tokens[c], v[c])) fail("'" + tokens[c] + "' is not a finite number");
    if (!rec.time.empty() && !(v[0] > rec.time.back())) {
      std::ostringstream what;
      what << "time " << v[0] << " s does not increase (previous " << rec.time.back() << " s)";
      fail(what.str());
    }
    rec.time.push_back(v[0]);
    rec.accel.push_back(v[1] * scale);
  }
  if (rec.time.size() < 2) {
    line_no = std::max(line_no, 1);
    fail("an accelerogram needs at least two samples, found " + std::to_string(rec.time.size()));
  }
  if (rec.time.front() < 0.0) {
    line_no = 1;
    std::ostringstream what;
    what << "negative time " << rec.time.front() << " s (the signal starts at t = 0)";
    fail(what.str());
  }
  return rec;
}

Accelerogram read_accelerogram(const std::string& path, const std::string& units, double gravity) {
  std::ifstream in(path);
  if (!in) throw DeckError(path + ": cannot read the accelerogram (load.base.file)");
  std::ostringstream text;
  text << in.rdbuf();
  if (looks_like_at2(path, text.str())) {
    if (units != "g")
      throw DeckError(path + ": a PEER AT2 record is in g; load.base.units = \"" + units +
                      "\" does not apply to it (leave units at \"g\")");
    return parse_at2(text.str(), path, gravity);
  }
  return parse_accelerogram(text.str(), path, units, gravity);
}

std::string format_at2(const std::vector<double>& accel_g, double dt, const std::string& title,
                       const std::string& note) {
  auto one_line = [](std::string s) {
    std::replace(s.begin(), s.end(), '\n', ' ');
    std::replace(s.begin(), s.end(), '\r', ' ');
    return s;
  };
  // DT in the fewest significant digits that strtod reads back to the same double.
  char dt_text[40] = "";
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(dt_text, sizeof dt_text, "%.*g", digits, dt);
    if (std::strtod(dt_text, nullptr) == dt) break;
  }
  std::string text =
      one_line(title) + "\n" + one_line(note) +
      "\nACCELERATION TIME SERIES IN UNITS OF G\nNPTS= " + std::to_string(accel_g.size()) +
      ", DT= " + dt_text + " SEC\n";
  text.reserve(text.size() + 18 * accel_g.size());
  char value[40];
  for (std::size_t k = 0; k < accel_g.size(); ++k) {
    std::snprintf(value, sizeof value, " %16.9E", accel_g[k] + 0.0);  // -0 written as 0
    text += value;
    if (k % 5 == 4 || k + 1 == accel_g.size()) text += '\n';
  }
  return text;
}

void write_at2(const std::string& path, const std::vector<double>& accel_g, double dt,
               const std::string& title, const std::string& note) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw OutputError(path + ": cannot write the AT2 record: " + std::strerror(errno));
  out << format_at2(accel_g, dt, title, note);
  out.close();
  if (!out) throw OutputError(path + ": cannot write the AT2 record: write failed");
}

int baseline_degree(const std::string& baseline) {
  if (baseline == "constant") return 0;
  if (baseline == "linear") return 1;
  if (baseline == "quadratic") return 2;
  if (baseline == "none") return -1;
  throw DeckError("load.base.baseline = \"" + baseline +
                  "\" (allowed: none, constant, linear, quadratic)");
}

void correct_baseline(Accelerogram& rec, int degree) {
  const std::size_t n = rec.time.size();
  if (degree < 0 || n < 2) return;
  // Displacement from rest at the first sample (exact for the piecewise-linear record).
  std::vector<double> d(n, 0.0);
  double v = 0.0;
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const double h = rec.time[k + 1] - rec.time[k];
    d[k + 1] = d[k] + h * v + h * h * (2.0 * rec.accel[k] + rec.accel[k + 1]) / 6.0;
    v += h * (rec.accel[k] + rec.accel[k + 1]) / 2.0;
  }
  // Normal equations of d ~ sum_j b_j x^j, x = tau / tau_end, j = 2 .. degree + 2.
  const double span = rec.time.back() - rec.time.front();
  const int m = degree + 1;
  double ata[3][3] = {}, atd[3] = {};
  for (std::size_t k = 0; k < n; ++k) {
    const double x = (rec.time[k] - rec.time.front()) / span;
    double col[3];
    for (int j = 0; j < m; ++j) col[j] = std::pow(x, j + 2);
    for (int i = 0; i < m; ++i) {
      atd[i] += col[i] * d[k];
      for (int j = 0; j < m; ++j) ata[i][j] += col[i] * col[j];
    }
  }
  // Gaussian elimination with partial pivoting (m <= 3).
  double b[3] = {};
  for (int c = 0; c < m; ++c) {
    int piv = c;
    for (int r = c + 1; r < m; ++r)
      if (std::abs(ata[r][c]) > std::abs(ata[piv][c])) piv = r;
    std::swap(ata[c], ata[piv]);
    std::swap(atd[c], atd[piv]);
    for (int r = c + 1; r < m; ++r) {
      const double f = ata[r][c] / ata[c][c];
      for (int j = c; j < m; ++j) ata[r][j] -= f * ata[c][j];
      atd[r] -= f * atd[c];
    }
  }
  for (int c = m - 1; c >= 0; --c) {
    double sum = atd[c];
    for (int j = c + 1; j < m; ++j) sum -= ata[c][j] * b[j];
    b[c] = sum / ata[c][c];
  }
  // a <- a - P'': d^2 (b x^p) / dt^2 = b p (p - 1) x^(p-2) / span^2.
  for (std::size_t k = 0; k < n; ++k) {
    const double x = (rec.time[k] - rec.time.front()) / span;
    double corr = 0.0;
    for (int j = 0; j < m; ++j) {
      const int p = j + 2;
      corr += b[j] * p * (p - 1) * std::pow(x, p - 2);
    }
    rec.accel[k] -= corr / (span * span);
  }
}

BaseSignal make_base_signal(const BaseConfig& base, double amplitude_g, double frequency,
                            double gravity) {
  const bool band = !(base.band[0] == 0.0 && base.band[1] == 0.0);
  if (band && base.signal != "file")
    throw DeckError("load.base.band = [" + std::to_string(base.band[0]) + ", " +
                    std::to_string(base.band[1]) +
                    "] applies to signal = \"file\" only (signal is \"" + base.signal +
                    "\"; the analytic pulses are band-limited already)");
  if (base.baseline != "none" && base.signal != "file")
    throw DeckError("load.base.baseline = \"" + base.baseline +
                    "\" applies to signal = \"file\" only (signal is \"" + base.signal + "\")");
  if (base.signal == "none") return BaseSignal::none();
  if (base.signal == "windowed_sine")
    return BaseSignal::windowed(amplitude_g * gravity, frequency, base.cycles);
  if (base.signal == "sine_pulse") return BaseSignal::one_sine(amplitude_g * gravity, frequency);
  if (base.signal == "file") {
    Accelerogram rec = read_accelerogram(base.file, base.units, gravity);
    correct_baseline(rec, baseline_degree(base.baseline));
    if (band) {
      const double h = resample_spacing(rec, base.band[1]);
      if (!(base.band[1] < 0.5 / h)) {
        std::ostringstream msg;
        msg << base.file << ": load.base.band upper cut-off " << base.band[1]
            << " Hz is not below the Nyquist frequency " << 0.5 / h
            << " Hz of the record (too long to resample finely enough)";
        throw DeckError(msg.str());
      }
    }
    BaseSignal s = BaseSignal::table(rec, base.band[0], base.band[1]);
    // A given amplitude scales the record to that peak (PGA), sign included.
    if (amplitude_g != 0.0 && s.peak_acceleration() > 0.0)
      s.scale(amplitude_g * gravity / s.peak_acceleration());
    return s;
  }
  throw DeckError("load.base.signal = \"" + base.signal +
                  "\" (allowed: none, windowed_sine, sine_pulse, file)");
}

}  // namespace voussoir

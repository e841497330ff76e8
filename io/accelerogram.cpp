// Accelerogram files and the deck's base signal (contract in accelerogram.hpp).

#include "io/accelerogram.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace voussoir {

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
    std::ostringstream msg;
    msg << source << ":" << line_no << ": " << what
        << " (expected two numbers per line: time [s], acceleration [" << units
        << "], separated by a comma or spaces; '#' starts a comment)";
    throw DeckError(msg.str());
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
    for (int c = 0; c < 2; ++c) {
      const char* s = tokens[c].c_str();
      char* end = nullptr;
      errno = 0;
      v[c] = std::strtod(s, &end);
      if (end == s || *end != '\0' || errno == ERANGE || !std::isfinite(v[c]))
        fail("'" + tokens[c] + "' is not a finite number");
    }
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
  return parse_accelerogram(text.str(), path, units, gravity);
}

BaseSignal make_base_signal(const BaseConfig& base, double amplitude_g, double frequency,
                            double gravity) {
  const bool band = !(base.band[0] == 0.0 && base.band[1] == 0.0);
  if (band && base.signal != "file")
    throw DeckError("load.base.band = [" + std::to_string(base.band[0]) + ", " +
                    std::to_string(base.band[1]) +
                    "] applies to signal = \"file\" only (signal is \"" + base.signal +
                    "\"; the analytic pulses are band-limited already)");
  if (base.signal == "none") return BaseSignal::none();
  if (base.signal == "windowed_sine")
    return BaseSignal::windowed(amplitude_g * gravity, frequency, base.cycles);
  if (base.signal == "sine_pulse") return BaseSignal::one_sine(amplitude_g * gravity, frequency);
  if (base.signal == "file") {
    const Accelerogram rec = read_accelerogram(base.file, base.units, gravity);
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

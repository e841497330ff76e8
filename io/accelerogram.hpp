#pragma once
// Accelerograms from files and the base signal of a deck's [load.base] (SPEC.md section 4):
// the edge between the deck and core/base_motion.hpp. This file reads and checks the record
// (DeckError naming the file, the line and what is wrong), checks the band against it and
// hands BaseSignal::table the samples; the resampling, the band-pass filter and the table
// motion are core's (core/base_motion.hpp, with their math and decisions).

#include <string>

#include "core/base_motion.hpp"
#include "core/schema.hpp"

namespace voussoir {

// Parses the text of an accelerogram: one sample per line, two numbers (time, acceleration)
// separated by a comma and/or whitespace; '#' starts a comment; blank lines are skipped.
// `units` is "g" (multiplied by `gravity`) or "m/s2". Throws DeckError naming `source`, the
// line and what is wrong (not two numbers, non-finite, time not increasing, fewer than two
// samples).
Accelerogram parse_accelerogram(const std::string& text, const std::string& source,
                                const std::string& units, double gravity);

// Reads and parses the file (DeckError if it cannot be read).
Accelerogram read_accelerogram(const std::string& path, const std::string& units, double gravity);

// The signal of a deck's [load.base] with amplitude `amplitude_g` [g] and frequency [Hz] (the
// deck values unless a driver overrides them, e.g. `pulse --curve`); `gravity` [m/s2] converts
// g to m/s2. A file record is used as read when the amplitude is 0 (the deck default) and
// otherwise scaled to that peak |a_g| (its PGA), sign included; frequency does not apply to it.
// Reads and filters the file for signal = "file". Throws DeckError for a band given with an
// analytic signal, a band above the Nyquist frequency of the resampled record, or a bad file.
BaseSignal make_base_signal(const BaseConfig& base, double amplitude_g, double frequency,
                            double gravity);
inline BaseSignal make_base_signal(const BaseConfig& base, double gravity) {
  return make_base_signal(base, base.amplitude, base.frequency, gravity);
}

}  // namespace voussoir

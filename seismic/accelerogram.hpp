#pragma once
// Accelerograms from files and the base signal of a deck's [load.base] (docs/reference/deck.md,
// [load.base]): the edge between the deck and seismic/base_motion.hpp. This file reads and checks
// the record (DeckError naming the file, the line and what is wrong), checks the band against it
// and hands BaseSignal::table the samples; the resampling, the band-pass filter and the table
// motion are core's (seismic/base_motion.hpp, with their math and decisions).
//
// Two file formats (docs/records.md):
//   two-column  time [s], acceleration [g or m/s2] per line (parse_accelerogram);
//   PEER AT2    the PEER NGA strong-motion format (parse_at2): 4 header lines, the 4th giving
//               the count and the step, as `NPTS=  5590, DT= .0050 SEC` (NGA-West2) or
//               `5590    0.0050    NPTS, DT` (older NGA); then NPTS accelerations in g, any
//               count per line, Fortran numbers (`.1234E-02`, `-1.234D-03`); sample k at k DT.
// A file is read as AT2 when its name ends in .AT2 (any case) or its 4th line names NPTS and
// DT (looks_like_at2); anything else by the two-column reader, unchanged. write_at2 writes the
// NGA-West2 form (`voussoir synth`).

#include <string>
#include <vector>

#include "core/schema.hpp"
#include "seismic/base_motion.hpp"

namespace voussoir {

// Parses the text of an accelerogram: one sample per line, two numbers (time, acceleration)
// separated by a comma and/or whitespace; '#' starts a comment; blank lines are skipped.
// `units` is "g" (multiplied by `gravity`) or "m/s2". Throws DeckError naming `source`, the
// line and what is wrong (not two numbers, non-finite, time not increasing, fewer than two
// samples).
Accelerogram parse_accelerogram(const std::string& text, const std::string& source,
                                const std::string& units, double gravity);

// Parses the text of a PEER AT2 record (header comment); accelerations in g are multiplied by
// `gravity`. Throws DeckError naming `source`, the line and what is wrong: no NPTS/DT on line
// 4, NPTS < 2, DT not > 0 or not finite, a value that is not a finite number, more or fewer
// values than NPTS.
Accelerogram parse_at2(const std::string& text, const std::string& source, double gravity);

// Whether a file is a PEER AT2 record: its name ends in .AT2 (any case), or the 4th line of
// `text` names both NPTS and DT (not after a '#').
bool looks_like_at2(const std::string& path, const std::string& text);

// Reads and parses the file, as AT2 when looks_like_at2 says so (then `units` must be "g":
// AT2 values are in g), two-column otherwise. DeckError if it cannot be read.
Accelerogram read_accelerogram(const std::string& path, const std::string& units, double gravity);

// The text of a PEER AT2 record (NGA-West2 header) that parse_at2 reads back: line 1 `title`,
// line 2 `note` (line breaks in either become spaces), line 3 "ACCELERATION TIME SERIES IN
// UNITS OF G", line 4 "NPTS= N, DT= D SEC" with D written in the fewest digits that read back
// to the same double; then the N values of `accel_g` [g] (sample k at t = k dt [s]) as
// " %16.9E", five a line: 10 significant digits, a relative rounding of at most 5e-10, and a
// value read back from such a file is written again to the same text.
std::string format_at2(const std::vector<double>& accel_g, double dt, const std::string& title,
                       const std::string& note);

// Writes format_at2 to `path`; OutputError (io/json.hpp) naming the path if it cannot.
void write_at2(const std::string& path, const std::vector<double>& accel_g, double dt,
               const std::string& title, const std::string& note);

// Baseline correction (deck load.base.baseline; docs/records.md). A record with an offset or
// a slow drift in its acceleration (instrument tilt, a shifted zero) integrates to a table
// velocity that does not return to zero and a displacement that grows like t^2 or faster. The
// standard correction: integrate the record twice (exactly, as piecewise linear, from rest at
// its first sample t_0),
//     v_{k+1} = v_k + h_k (a_k + a_{k+1}) / 2,
//     d_{k+1} = d_k + h_k v_k + h_k^2 (2 a_k + a_{k+1}) / 6,
// fit the displacement by least squares (every sample weighted alike) with the polynomial
//     P(t) = sum_{j=2}^{m+2} c_j tau^j,   tau = t - t_0,
// (no constant and linear terms: the corrected motion still starts at rest at d = 0), and
// subtract its second derivative from the acceleration:
//     a_k <- a_k - P''(t_k) = a_k - sum_{j=2}^{m+2} j (j - 1) c_j tau_k^(j-2).
// m, the degree of the acceleration correction, is 0 ("constant": removes an offset, the
// displacement fit a parabola), 1 ("linear") or 2 ("quadratic"). The corrected displacement is
// then d - P, the least-squares residual (exactly so up to the linear interpolation of P''
// between samples): its drift is gone and its end, with the end velocity, close to zero, not
// exactly zero (no end condition is imposed). The fit is solved in tau / tau_end (normal
// equations of at most 3 unknowns, conditioned well enough). Applied before the band-pass.
void correct_baseline(Accelerogram& record, int degree);

// The degree m of the correction for a deck's load.base.baseline ("none": -1).
int baseline_degree(const std::string& baseline);

// The signal of a deck's [load.base] with amplitude `amplitude_g` [g] and frequency [Hz] (the
// deck values unless a driver overrides them, e.g. `pulse --curve`); `gravity` [m/s2] converts
// g to m/s2. A file record is used as read when the amplitude is 0 (the deck default) and
// otherwise scaled to that peak |a_g| (its PGA), sign included; frequency does not apply to it.
// Reads, baseline-corrects (load.base.baseline) and filters the file for signal = "file".
// Throws DeckError for a band or a baseline given with an analytic signal, a band above the
// Nyquist frequency of the resampled record, or a bad file.
BaseSignal make_base_signal(const BaseConfig& base, double amplitude_g, double frequency,
                            double gravity);
inline BaseSignal make_base_signal(const BaseConfig& base, double gravity) {
  return make_base_signal(base, base.amplitude, base.frequency, gravity);
}

}  // namespace voussoir

#pragma once
// Base-excitation signals (docs/reference/deck.md, [load.base]): the horizontal
// acceleration a_g(t) of the shaking table / ground, and the table velocity and displacement
// obtained by integrating it.
//
// How it enters the step. The simulation runs in the frame of the fixed supports (the table),
// which accelerates by a_g(t); every free node feels the inertial (d'Alembert) body force
// -m a_g(t). The driver sets, before each advance(),
//     ctx.body_ax = lambda g - a_g(t_n),        ctx.body_ay = -g,
// so node displacements are displacements relative to the table, and the energy ledger
// (core/loads.hpp) books the work of the inertial force on the relative motion, for which the
// balance W = K + U + C + D holds exactly as for any body load.
//
// Signals (all accelerations in m/s2 here; decks give A in g):
//   windowed_sine  a_g(t) = A w(2t/T - 1) sin(2 pi f t),  0 <= t <= T = cycles / f, 0 after,
//                  Bohman window w(x) = (1 - |x|) cos(pi |x|) + sin(pi |x|) / pi, |x| <= 1.
//                  Table velocity at T is zero for any integer number of cycles: w is even
//                  about t = T/2 and sin(2 pi f (T - t)) = -sin(2 pi f t), so a_g is odd about
//                  T/2 and its integral over [0, T] vanishes. The displacement at T,
//                  -int t a_g dt, vanishes too for an odd number of cycles >= 3 (the Fourier
//                  transform of the Bohman window has double zeros there), not otherwise
//                  (1 cycle, even cycles): then the table ends displaced, at rest.
//   sine_pulse     a_g(t) = A sin(2 pi f t) for 0 <= t <= 1/f (one full cycle), 0 after;
//                  v(t) = A / (2 pi f) (1 - cos 2 pi f t): v(1/f) = 0, d(1/f) = A / (2 pi f^2).
//   file           two columns (time [s], acceleration [g or m/s2]), read by seismic/accelerogram;
//                  linear interpolation between samples, zero before the first and after
//                  the last sample.
//
// Evaluation cost. The analytic signals are evaluated from their formula at every step (two
// sines and a cosine: nothing next to a step of the element and contact stages, and exact at
// any dt). A file signal is resampled once onto a uniform grid of spacing h (the smallest time
// increment of the file, finer if the band-pass needs it) and read by linear interpolation.
//
// Table velocity and displacement (for recording only; the step never uses them) come from a
// uniform table of accelerations (the resampled record, or the analytic signal sampled at
// kSamplesPerCycle per cycle), integrated exactly as a piecewise-linear acceleration:
//     v_{k+1} = v_k + h (a_k + a_{k+1}) / 2,   d_{k+1} = d_k + h v_k + h^2 (2 a_k + a_{k+1}) / 6,
// and read between samples by the same cubic. For the analytic signals this is the trapezoid
// rule: relative error ~ (2 pi / kSamplesPerCycle)^2 / 12 ~ 1e-6 of A / (2 pi f).
//
// Band-pass filter (`band = [lo, hi]` Hz; lo = 0 gives a low-pass only). Choice: Butterworth
// of order 4 for each side (a high-pass at lo and a low-pass at hi, each two second-order
// sections made digital by the bilinear transform with pre-warped cut-off), run forward then
// backward over the record ("filtfilt"): zero phase, magnitude |H|^2, i.e. the gain at the
// cut-offs is 1/2 and the roll-off 16th-order in power. Check numbers (band [1, 50]):
// 10 Hz passes with gain 0.9999, 0.2 Hz is cut to 2.6e-6, 100 Hz to 3.9e-3. Rejected: an FFT
// brick-wall (zero phase too, but it rings over the whole record — Gibbs — and smears
// the onset of a pulse before it happens); a single forward pass (phase shift distorts the
// pulse shape and delays it). Edges: the record is zero outside its span, so it is padded with
// zeros after its end by 6 / lo seconds (6 / hi without high-pass), long enough for the slowest
// pole of the filter to decay below 1e-6 of its start, before the backward pass; the filtered
// signal keeps that tail (it is part of the zero-phase response) and starts at t = 0 (what the
// backward pass puts before t = 0 is dropped: records start with a quiet pre-event memory).
// Only file signals are filtered (the analytic pulses are already band-limited); a band given
// with an analytic signal is refused by make_base_signal (seismic/accelerogram.hpp).
//
// This file is signal math on arrays only: it reads no file and throws nothing. Reading the
// record, checking the deck's [load.base] and the band against the record are io/'s
// (seismic/accelerogram.hpp), which hands BaseSignal::table the samples.

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace voussoir {

// Bohman window w(x) for |x| <= 1, 0 outside. w(0) = 1, w(1/2) = 1/pi, w(+-1) = 0.
inline double bohman_window(double x) {
  const double ax = std::abs(x);
  if (ax > 1.0) return 0.0;
  return (1.0 - ax) * std::cos(std::numbers::pi * ax) +
         std::sin(std::numbers::pi * ax) / std::numbers::pi;
}

// Windowed-sine acceleration at time t [s]; `amplitude` in the unit of the result.
inline double windowed_sine(double t, double amplitude, double frequency, int cycles) {
  const double duration = cycles / frequency;
  if (t < 0.0 || t > duration) return 0.0;
  return amplitude * bohman_window(2.0 * t / duration - 1.0) *
         std::sin(2.0 * std::numbers::pi * frequency * t);
}

// One full sine cycle of the given amplitude and frequency, zero outside [0, 1/f].
inline double sine_pulse(double t, double amplitude, double frequency) {
  if (t < 0.0 || t * frequency > 1.0) return 0.0;
  return amplitude * std::sin(2.0 * std::numbers::pi * frequency * t);
}

// Zero-phase band-pass of uniform samples (spacing dt [s]) by forward-backward 4th-order
// Butterworth sections (header comment). lo = 0: low-pass only; hi must lie below the Nyquist
// frequency 1 / (2 dt). Returns the filtered samples on the same grid, extended by the padded
// tail of `tail_samples` (out) samples after the input's end.
std::vector<double> bandpass_zero_phase(const std::vector<double>& samples, double dt, double lo,
                                        double hi, std::size_t* tail_samples = nullptr);

// Second-order digital section y = (b0 x + b1 x' + b2 x'') - a1 y' - a2 y'' (a0 = 1).
struct Biquad {
  double b0 = 1.0, b1 = 0.0, b2 = 0.0, a1 = 0.0, a2 = 0.0;
};

// The two sections of a 4th-order Butterworth low-pass (high_pass = false) or high-pass at
// cut-off fc [Hz] for sampling interval dt [s] (bilinear transform, pre-warped).
std::vector<Biquad> butterworth4(double fc, double dt, bool high_pass);

// Gain |H| of a cascade of sections at frequency f [Hz] (one pass, not forward-backward).
double cascade_gain(const std::vector<Biquad>& sections, double f, double dt);

// An accelerogram: times [s] strictly increasing, accelerations [m/s2] (read from a file by
// seismic/accelerogram.hpp).
struct Accelerogram {
  std::vector<double> time;
  std::vector<double> accel;
};

// Uniform resampling interval [s] of a record for BaseSignal::table: its smallest time
// increment, at most 1 / (10 band_hi) when filtering (band_hi > 0), and coarse enough for
// the largest table (4e6 samples).
double resample_spacing(const Accelerogram& record, double band_hi);

// The base acceleration a_g(t) [m/s2] of one run, with the table velocity and displacement.
class BaseSignal {
 public:
  enum class Kind { None, WindowedSine, SinePulse, Table };

  BaseSignal() = default;
  static BaseSignal none();
  // amplitude in m/s2
  static BaseSignal windowed(double amplitude, double frequency, int cycles);
  static BaseSignal one_sine(double amplitude, double frequency);
  // Accelerations [m/s2] at times [s] (strictly increasing), optionally band-passed
  // (lo = hi = 0: none).
  static BaseSignal table(const Accelerogram& record, double band_lo = 0.0, double band_hi = 0.0);

  // Multiplies the signal by `factor`.
  void scale(double factor);

  Kind kind() const { return kind_; }
  // Time after which a_g = 0 [s] (T for the pulses, the end of the (filtered) record).
  double duration() const { return duration_; }
  // Largest |a_g| over the tabulated samples [m/s2].
  double peak_acceleration() const { return peak_; }

  // a_g(t) [m/s2]: formula for the pulses, linear interpolation of the table otherwise.
  double acceleration(double t) const {
    switch (kind_) {
      case Kind::WindowedSine:
        return windowed_sine(t, amplitude_, frequency_, cycles_);
      case Kind::SinePulse:
        return sine_pulse(t, amplitude_, frequency_);
      case Kind::Table:
        return interpolate_table(t);
      case Kind::None:
        break;
    }
    return 0.0;
  }
  double velocity(double t) const;      // table velocity [m/s], v(0) = 0
  double displacement(double t) const;  // table displacement [m], d(0) = 0

  // Uniform samples of a_g used for the motion table (spacing sample_dt()).
  const std::vector<double>& samples() const { return acc_; }
  double sample_dt() const { return h_; }

  static constexpr int kSamplesPerCycle = 4000;  // analytic pulses, for v and d only

 private:
  double interpolate_table(double t) const {
    if (!(t >= 0.0)) return 0.0;
    const double s = t / h_;
    const std::size_t i = static_cast<std::size_t>(s);
    if (i + 1 >= acc_.size()) return (i + 1 == acc_.size() && s == double(i)) ? acc_[i] : 0.0;
    const double u = s - double(i);
    return (1.0 - u) * acc_[i] + u * acc_[i + 1];
  }
  void integrate_motion();

  Kind kind_ = Kind::None;
  double amplitude_ = 0.0, frequency_ = 1.0;
  int cycles_ = 0;
  double duration_ = 0.0;
  double peak_ = 0.0;
  double h_ = 1.0;                  // sample spacing [s]
  std::vector<double> acc_;         // a_g at t_k = k h [m/s2]
  std::vector<double> vel_, disp_;  // table velocity and displacement at t_k
};

}  // namespace voussoir

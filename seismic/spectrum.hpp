#pragma once
// Elastic response spectra of a base acceleration record (docs/reference/deck.md, [load.base];
// `voussoir pulse
// --spectrum`, docs/records.md).
//
// The oscillator. A linear single-degree-of-freedom oscillator of natural circular frequency
// w = 2 pi / T and damping ratio z (< 1) on a base accelerating by a_g(t); its displacement
// relative to the base u(t) obeys
//     u'' + 2 z w u' + w^2 u = p(t),   p = -a_g,          u(0) = u'(0) = 0.
// The pseudo-acceleration spectrum is Sa(T) = w^2 max_t |u(t)| (in the unit of a_g).
//
// Exact integration (Nigam & Jennings 1969; Chopra, Dynamics of Structures, 5.2). Between
// samples t_i and t_i + h the record is taken linear, p(t_i + s) = p_i + r s with
// r = (p_{i+1} - p_i) / h. The equation is then solved exactly over the step:
//     particular  u_p(s) = alpha + beta s,  beta = r / w^2,  alpha = (p_i - 2 z w beta) / w^2;
//     free part   e^{-z w s} (X cos w_d s + Y sin w_d s),    w_d = w sqrt(1 - z^2),
//                 X = u_i - alpha,  Y = (u'_i - beta + z w X) / w_d;
//     u_{i+1}  = alpha + beta h + E (X c + Y s_),                        E = e^{-z w h},
//     u'_{i+1} = beta + E ((w_d Y - z w X) c - (w_d X + z w Y) s_),  c, s_ = cos, sin (w_d h).
// The step map is linear in (u_i, u'_i, p_i, p_{i+1}):
//     [u, u']_{i+1} = A [u, u']_i + B [p_i, p_{i+1}],
// the Nigam-Jennings recurrence with its 2x2 matrices A and B constant for a given (T, z, h).
// They are computed once per period by applying the exact step above to the four unit
// vectors (SdofStep), so the formulas are written once and not transcribed in expanded form.
// No stability or accuracy limit on h: the only error is the linear interpolation of the
// record between its samples (the record's own definition here, as in seismic/base_motion.hpp)
// and reading max|u| at the samples only (relative error below (w h)^2 / 8 of the peak).
//
// After the record. The response peak can come after the last sample (long periods): the
// oscillator is followed in free vibration for one more period T (p ramps to 0 over one step
// then stays 0). Free damped vibration reaches its largest |u| within its first half period,
// the envelope decaying after, so one period is enough.
//
// Short periods. As T -> 0 the oscillator follows the base quasi-statically, u -> p / w^2, and
// Sa -> the peak |a_g| (PGA); the recurrence stays exact there (E -> 0).
//
// This file is math on arrays: no I/O, no exceptions; periods must be > 0 and z in [0, 1).

#include <cstddef>
#include <vector>

namespace voussoir {

// The constant matrices of the exact step of length h (header comment):
//     u_{i+1}  = a00 u_i + a01 v_i + b00 p_i + b01 p_{i+1},
//     v_{i+1}  = a10 u_i + a11 v_i + b10 p_i + b11 p_{i+1}   (v = u').
struct SdofStep {
  double a00 = 0.0, a01 = 0.0, a10 = 0.0, a11 = 0.0;
  double b00 = 0.0, b01 = 0.0, b10 = 0.0, b11 = 0.0;
};

// The step matrices for circular frequency omega [rad/s], damping ratio zeta in [0, 1) and
// step h [s].
SdofStep make_sdof_step(double omega, double zeta, double h);

// Largest |u| [m for a_g in m/s2] of the oscillator of period T [s] and damping ratio zeta under
// the base acceleration `accel` (uniform samples, spacing dt [s], linear between samples), over
// the steps k in [from, to): k < accel.size() are the record's samples, the steps after it
// the free vibration of one period (the default `to` takes the whole of it; to = accel.size()
// stops at the end of the record, for tests of steady or ramped excitation).
inline constexpr std::size_t kWholeResponse = static_cast<std::size_t>(-1);
double sdof_peak_displacement(const std::vector<double>& accel, double dt, double period,
                              double zeta, std::size_t from = 0, std::size_t to = kWholeResponse);

// The damping ratio of the codes' elastic spectra (EN 1998-1 3.2.2.2: 5%, eta = 1).
inline constexpr double kCodeDamping = 0.05;

// Pseudo-acceleration spectrum Sa(T) = (2 pi / T)^2 max|u| at each period [s] (unit of
// `accel`), damping ratio zeta.
std::vector<double> response_spectrum(const std::vector<double>& accel, double dt,
                                      const std::vector<double>& periods,
                                      double zeta = kCodeDamping);

// `count` >= 2 periods from `first` to `last` [s], evenly spaced in log T (both ends included).
std::vector<double> log_spaced_periods(double first, double last, int count);

// The periods of every spectrum voussoir writes (`pulse --spectrum`, `synth`'s spectra.csv):
// 100 log-spaced from 0.02 to 4 s, where the EN 1998-1 elastic spectrum is defined.
inline std::vector<double> written_spectrum_periods() {
  return log_spaced_periods(0.02, 4.0, 100);
}

}  // namespace voussoir

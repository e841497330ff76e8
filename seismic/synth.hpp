#pragma once
// Spectrum-compatible artificial accelerograms (`voussoir synth`, docs/reference/commands.md;
// docs/records.md "Artificial records").
//
// The target: the Eurocode 8 Type 1 horizontal elastic spectrum (EN 1998-1:2004 3.2.2.2 (1)P,
// Table 3.2), 5% damping (eta = 1), ag the design ground acceleration on type A ground [g]:
//     0  <= T <= TB   Se = ag S (1 + T / TB (2.5 eta - 1))
//     TB <= T <= TC   Se = 2.5 eta ag S
//     TC <= T <= TD   Se = 2.5 eta ag S TC / T
//     TD <= T         Se = 2.5 eta ag S TC TD / T^2     (the code's branch stops at 4 s)
//   soil    S     TB [s]  TC [s]  TD [s]
//     A    1.00   0.15    0.40    2.0
//     B    1.20   0.15    0.50    2.0
//     C    1.15   0.20    0.60    2.0
//     D    1.35   0.20    0.80    2.0
//     E    1.40   0.15    0.50    2.0
//
// The method: SIMQKE (Gasparini & Vanmarcke 1976, "Simulated earthquake motions compatible with
// prescribed response spectra", MIT R76-4; Vanmarcke & Gasparini 1977). A record is a
// stationary Gaussian process shaped by a deterministic envelope,
//     a(t) = I(t) sum_k A_k sin(w_k t + phi_k),
// the phases phi_k independent and uniform in [0, 2 pi), the amplitudes from a one-sided power
// spectral density G(w): A_k^2 / 2 = G(w_k) dw (the variance of the sum is the area under G).
//
// 1. Frequencies. w_k = 2 pi f_k, f_k = k df with df = 1 / (2 D) (D the duration: half the
//    spacing of the record's own harmonics, so that the 5%-damped oscillators at long periods,
//    of half-power bandwidth 2 zeta f, each see more components), from kMinFrequency = 0.2 Hz
//    (T = 5 s, past the longest control period of 4 s) to f_max = min(25 Hz, 1 / (4 dt))
//    (T = 0.04 s at dt = 0.01 s: at least 4 samples a cycle). Measured on 35 records (ag = 0.25
//    g, soil B, seeds 1 to 5 of 7 records each, range 0.05-3 s; "least mean ratio": the least
//    ratio of a set's mean spectrum to the target over the range): 0.957 to 0.978 as chosen;
//    with df = 1 / D 0.944 to 0.978 and single records up to 38% off the target (24% as
//    chosen); from 0.1 Hz 0.919 to 0.974, and twice the ground displacement (PGD 0.28 m against
//    0.14 m on average, the largest 0.79 m against 0.27 m).
//
// 2. The envelope (Jennings, Housner & Tsai 1968, "Simulated earthquake motions", EERL):
//    quadratic rise, stationary strong part, exponential decay,
//        I(t) = (t / t1)^2              0  <= t < t1,
//             = 1                       t1 <= t <= t2,
//             = exp(-c (t - t2))        t2 <  t <= D,    c = ln(1 / kEnvelopeEnd) / (D - t2),
//    t1 = kEnvelopeRise = 2 s, t2 = t1 + 0.6 (D - t1), the decay ending at kEnvelopeEnd = 0.05.
//    D = 20 s gives a strong part of 10.8 s: EN 1998-1 3.2.3.1.2 (3) asks for at least 10 s.
//
// 3. The starting density (Vanmarcke 1976; Gasparini & Vanmarcke 1976): the median peak of an
//    oscillator (w, zeta) under a stationary process of duration Ts (the strong part, t2 - t1)
//    is r(w) sigma(w), sigma^2 ~ G(w) w (pi / (4 zeta_s) - 1) + int_0^w G(u) du, with the
//    time-dependent damping zeta_s = zeta / (1 - exp(-2 zeta w Ts)); setting r sigma = Sa(w)
//    gives, frequency by frequency from the lowest,
//        G(w_k) = (Sa(w_k)^2 / r_k^2 - sum_{j<k} G(w_j) dw) / (w_k (pi / (4 zeta_s) - 1)).
//    The peak factor r is Vanmarcke's median (p = 0.5) for n = w Ts / (2 pi) / ln 2 crossings:
//        r = sqrt(2 ln(2 n (1 - exp(-delta^1.2 sqrt(pi ln(2 n)))))),
//        delta = sqrt(1 - (1 - (2 / pi) atan(zeta_s / sqrt(1 - zeta_s^2)))^2 / (1 - zeta_s^2)),
//    floored at 1 (at the lowest frequencies the formula, made for many crossings, falls below).
//    The bracket can turn negative where the target falls faster than the accumulated area
//    (short periods); G is then floored at kDensityFloor of its largest value so far, so that no
//    component is lost: the iterations below only multiply amplitudes and could not revive one.
//    This density is a start only: the iterations correct it.
//
// 4. Iterations (SIMQKE's spectrum smoothing). Synthesise a(t). Correct its baseline so that
//    it ends at rest: subtract c1 I(t) + c2 I(t) t / D with the two constants that make the end
//    velocity and displacement zero (a 2 x 2 system, exact for the piecewise-linear record;
//    |c1| <= 0.0036 g and |c2| <= 0.0066 g on the 35 records, every iterate). The envelope's
//    shape keeps a(0) = 0 (the record starts from rest without a jump) and adds nothing where
//    the record is quiet. Rejected: the least-squares polynomial correction of
//    load.base.baseline (seismic/accelerogram.hpp correct_baseline, degree 2) before it: a(0)
//    became up to 0.004 g and the ground displacement grew (PGD 0.19 m against 0.14 m on average,
//    the largest 0.44 m against 0.27 m) for the same match. Compute the 5%-damped spectrum Sa_i at
//    the control periods (seismic/spectrum.hpp, exact for the piecewise-linear record) and multiply
//    each amplitude by the ratio target / Sa_i at its period (interpolated in log T between the
//    control periods, the end ratios beyond them), each ratio clamped to [1/2, 2]; the phases
//    stay. The correction is inside the loop, so the record written is the one measured. Stop
//    when every control period within the range lies within `tolerance` of the target, or after
//    `max_iterations`; the record kept is the iterate with the smallest largest deviation over
//    the range. A record's largest deviation levels off at 7 to 22% (long periods, where a 20 s
//    record holds few cycles); the least mean ratio of the 35 records was 0.939 after 8
//    iterations, 0.957 after 12, 0.959 after 20 (the default). Tried and
//    rejected: damping the update (ratio^0.5, ^0.7: 0.934, 0.948) or over-correcting
//    (ratio^1.3: 0.941).
//
// The set (EN 1998-1 3.2.3.1.2 (4), the rules for a suite of artificial records): at least 3
// records; the mean of their zero-period spectral values (their PGAs) not below ag S; and "in
// the range of periods between 0.2 T1 and 2 T1" (T1 the fundamental period of the structure)
// no value of their mean 5% spectrum below 90% of the target. The range is the caller's
// (`voussoir synth --range`, default 0.05 to 3 s, argued in docs/records.md); the matching aims
// at the target over the whole control grid, 0.02 to 4 s. A matched record's PGA is close to
// ag S (Sa(T -> 0) = PGA, and matching the plateau does not pin it), so a mean PGA below ag S
// is possible: synthesize_set then scales the whole set up by ag S / mean PGA (a few per
// cent), which raises the mean spectrum by the same factor.
//
// Reproducibility. Record `index` of seed K draws its phases from std::mt19937_64 seeded by
// std::seed_seq{K low 32 bits, K high 32 bits, index}; a phase is 2 pi (x >> 11) 2^-53 from
// one 64-bit draw x. Both generators and seed_seq are specified bit for bit by the C++
// standard (the std:: distributions are not, so none is used): the phases are the same on any
// standard library, the records too up to the last bits of the maths library's sin, cos and
// exp. Record i does not depend on how many are asked for, nor on the thread count.
//
// Cost. The sum of sines is evaluated by rotating each component's (cos, sin) by its step
// angle (four multiplications per sample and component, no sin() calls: the rotation drifts by
// ~1e-16 a step, 1e-13 over a record); ~990 components x 2001 samples per iterate, then the
// spectrum at 102 periods.
//
// This file is math on arrays: no I/O, no exceptions; the caller checks its input.

#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "seismic/spectrum.hpp"

namespace voussoir {

// EN 1998-1 Table 3.2 (Type 1) parameters of a ground type.
struct Ec8Soil {
  char name = 'B';
  double s = 1.2;    // soil factor S
  double tb = 0.15;  // [s]
  double tc = 0.5;   // [s]
  double td = 2.0;   // [s]
};

// The Type 1 parameters of soil class 'A'..'E' (upper case), or nothing for another letter.
std::optional<Ec8Soil> ec8_type1_soil(char name);

// EC8 horizontal elastic spectrum Se(T) [unit of ag] at period T >= 0 [s], 5% damping (eta = 1).
double ec8_elastic_spectrum(double period, double ag, const Ec8Soil& soil);

// The envelope of step 2 (header): times [s].
struct SynthEnvelope {
  double rise = 2.0;         // t1
  double strong_end = 12.8;  // t2
  double duration = 20.0;    // D
  double decay = 0.0;        // c [1/s]

  double at(double t) const;
  double strong_length() const { return strong_end - rise; }
};

// Rise of the envelope [s] and the level at its end.
inline constexpr double kEnvelopeRise = 2.0;
inline constexpr double kEnvelopeEnd = 0.05;
// Fraction of D - t1 taken by the strong part (the rest decays).
inline constexpr double kStrongFraction = 0.6;
// Shortest duration the envelope accepts [s]: the rise and 3 s after it.
inline constexpr double kMinDuration = kEnvelopeRise + 3.0;

// The envelope for duration D >= kMinDuration [s].
SynthEnvelope make_synth_envelope(double duration);

// Settings of the generation. Typical values are the defaults of `voussoir synth`.
struct SynthSettings {
  double dt = 0.01;               // sampling interval [s]
  double duration = 20.0;         // D [s]
  double damping = kCodeDamping;  // zeta of the spectra
  double range_lo = 0.05;         // matching and check range [s]
  double range_hi = 3.0;
  int max_iterations = 20;  // SIMQKE cycles (header step 4)
  double tolerance = 0.05;  // stop when |Sa / target - 1| <= this over the range
};

// Lowest component frequency [Hz], highest (at most) [Hz] (step 1), floor of the starting
// density relative to its largest value so far (step 3).
inline constexpr double kMinFrequency = 0.2;
inline constexpr double kMaxFrequency = 25.0;
inline constexpr double kDensityFloor = 0.01;

// The control periods of the iterations and of the reported spectra: 100 log-spaced from
// 0.02 s to 4 s (as `pulse --spectrum`) with range_lo and range_hi added, ascending.
std::vector<double> synth_periods(const SynthSettings& settings);

// One record: accelerations [unit of the target] at t = k dt, k = 0 .. round(D / dt); its
// spectrum at `periods` (synth_periods); the iterations run and the one kept (1-based); its
// largest |a|.
struct SynthRecord {
  std::vector<double> accel;
  std::vector<double> sa;
  int iterations = 0;
  int kept = 0;
  double pga = 0.0;
};

// Record `index` (0-based) of seed `seed` matched to `target` (Sa at a period [s], the unit of
// the result) over `periods`.
SynthRecord synthesize_record(const SynthSettings& settings,
                              const std::function<double(double)>& target,
                              const std::vector<double>& periods, std::uint64_t seed, int index);

// A set of records 0 .. count - 1 (on OpenMP threads; the same on any thread count), scaled
// together by `scale` >= 1 when their mean PGA falls below `pga_floor` (ag S: EN 1998-1
// 3.2.3.1.2 (4); header "The set"); `mean` is their mean spectrum at `periods`.
struct SynthSet {
  std::vector<SynthRecord> records;
  std::vector<double> mean;
  double mean_pga = 0.0;
  double scale = 1.0;
};
SynthSet synthesize_set(const SynthSettings& settings, const std::function<double(double)>& target,
                        const std::vector<double>& periods, std::uint64_t seed, int count,
                        double pga_floor);

// The ground velocity and displacement of `accel` (spacing dt, linear between samples, from
// rest at the first sample; v += dt (a_k + a_{k+1}) / 2, d += dt v + dt^2 (2 a_k + a_{k+1}) / 6):
// at the last sample and their largest magnitudes (PGV, PGD), in the unit of accel x s, x s^2.
struct GroundMotion {
  double end_velocity = 0.0, end_displacement = 0.0;
  double peak_velocity = 0.0, peak_displacement = 0.0;
};
GroundMotion ground_motion(const std::vector<double>& accel, double dt);

}  // namespace voussoir

#pragma once
// Lognormal fragility of collapse from an incremental dynamic analysis (`voussoir ida`,
// commands/ida.hpp; docs/ida.md).
//
// An IDA gives, for each ground-motion record i, the intensity x_i (PGA or Sa(T), in g) at which
// the structure first collapses. The fragility function is the probability of collapse at
// intensity x,
//     P(collapse | x) = Phi( ln(x / theta) / beta ),
// the lognormal CDF of the records' collapse intensities, with median theta and logarithmic
// standard deviation beta (Baker, "Efficient analytical fragility function fitting using dynamic
// structural analysis", Earthquake Spectra 31(1), 2015, section "IDA"). Both are fitted by
// maximum likelihood. With y_i = ln x_i, mu = ln theta and z_i = (y_i - mu) / beta, the
// log-likelihood is, up to a constant,
//     ln L(mu, beta) = sum over collapsed records [ -ln beta - z_i^2 / 2 ]
//                    + sum over censored records  ln( 1 - Phi(z_i) ).
// A censored record is one that did not collapse up to the largest intensity it was run at,
// x_i (the search's cap): all that is known is that its collapse intensity exceeds x_i. A
// record censored below collapsed at every intensity tried, down to the smallest, x_i
// (commands/pulse.hpp kMinAmplitude): its collapse intensity is at most x_i, and its term is
// ln Phi(z_i) = ln(1 - Phi(-z_i)).
//   - Without censored records the maximum is in closed form: mu = mean of y_i and
//     beta^2 = mean of (y_i - mu)^2 (the 1/n variance: the maximum-likelihood estimate; Baker's
//     method-of-moments estimate divides by n - 1 and is larger by sqrt(n / (n - 1)), 8% for 7
//     records).
//   - With censored records: for a fixed beta, ln L is concave in mu (the normal density and
//     its survival function are log-concave), so the profile max_mu ln L(mu, beta) is found by
//     Brent's method in mu, and its maximum over ln beta by Brent's method again (Boost.Math's
//     brent_find_minima, to full double precision in the bracket).
// A fit needs two collapsed records of different intensity (otherwise beta = 0 or the median is
// unbounded); `ok` says whether there was one.
//
// The confidence interval of the median is a percentile bootstrap (Efron & Tibshirani, "An
// Introduction to the Bootstrap", 1993, ch. 13): `resamples` sets of n records drawn with
// replacement from the n records, each fitted as above; the interval is the (1 - c)/2 and
// (1 + c)/2 empirical quantiles (linear interpolation between order statistics) of the resampled
// medians. Every resample counts (leaving out those without a fit would bias the interval
// towards the resamples that happen to hold two distinct collapses: 11% of them are left out
// with 3 records): one without a fit (fewer than two distinct collapse intensities) enters at
// its median's limit -- the geometric mean of its collapse intensities (one value v: the fit's
// limit as beta -> 0 without censored records), +infinity when none of its records collapsed
// and one is censored above (its median lies above every intensity run), 0 when all collapse
// at every intensity tried. An end of the interval may therefore be +infinity (written null in
// JSON): the records do not bound the median from above. The draws come from std::mt19937_64 seeded
// by `seed`, turned into indices by hand (the standard distributions differ between standard
// libraries), so an interval is the same on every machine, thread count and MPI rank count.

#include <cstdint>
#include <string>
#include <vector>

namespace voussoir {

// One record's result: its collapse intensity, or (censored) the largest intensity it survived.
struct IntensitySample {
  double im = 0.0;        // [g], > 0
  bool censored = false;  // no collapse up to im: the collapse intensity lies above
  bool below = false;     // a collapse at every intensity tried, im the smallest: it lies below
};

struct LognormalFit {
  bool ok = false;
  std::string why;      // when !ok: what is missing
  double median = 0.0;  // theta [g]
  double beta = 0.0;    // logarithmic standard deviation
  int samples = 0;      // records fitted
  int censored = 0;     // of which censored (above or below)
};

// Maximum-likelihood lognormal fit (header comment). Throws std::invalid_argument for an
// intensity that is not a positive finite number.
LognormalFit fit_lognormal(const std::vector<IntensitySample>& samples);

struct MedianInterval {
  double lo = 0.0, hi = 0.0;  // [g]; hi (or both) +infinity when the records leave it unbounded
  double confidence = 0.0;    // c
  int resamples = 0;          // resamples drawn (0: none, no interval)
  int without_fit = 0;        // of which without a fit, entered at their limit
};

// Percentile-bootstrap interval of the median (header comment); `confidence` in (0, 1),
// `resamples` >= 1. No interval (resamples = 0) without samples.
MedianInterval bootstrap_median(const std::vector<IntensitySample>& samples, int resamples,
                                std::uint64_t seed, double confidence = 0.95);

// ln(1 - Phi(z)) of the standard normal, finite for every finite z (erfc underflows past
// z ~ 38; Mills' ratio from z = 30 on).
double log_normal_survival(double z);

// P(collapse | im) of a fit: Phi(ln(im / median) / beta).
double collapse_probability(const LognormalFit& fit, double im);

}  // namespace voussoir

#pragma once
// Lognormal fragility of collapse from an incremental dynamic analysis (`voussoir ida`,
// drivers/ida.hpp; docs/ida.md).
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
// x_i (the search's cap): all that is known is that its collapse intensity exceeds x_i.
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
// medians. Resamples without a fit (fewer than two distinct collapse intensities) are left out
// and counted. The draws come from std::mt19937_64 seeded by `seed`, turned into indices by hand
// (the standard distributions differ between standard libraries), so an interval is the same on
// every machine, thread count and MPI rank count.

#include <cstdint>
#include <string>
#include <vector>

namespace voussoir {

// One record's result: its collapse intensity, or (censored) the largest intensity it survived.
struct IntensitySample {
  double im = 0.0;  // [g], > 0
  bool censored = false;
};

struct LognormalFit {
  bool ok = false;
  std::string why;      // when !ok: what is missing
  double median = 0.0;  // theta [g]
  double beta = 0.0;    // logarithmic standard deviation
  int samples = 0;      // records fitted
  int censored = 0;     // of which censored
};

// Maximum-likelihood lognormal fit (header comment). Throws std::invalid_argument for an
// intensity that is not a positive finite number.
LognormalFit fit_lognormal(const std::vector<IntensitySample>& samples);

struct MedianInterval {
  double lo = 0.0, hi = 0.0;  // [g]
  double confidence = 0.0;    // c
  int resamples = 0;          // fitted resamples used
  int without_fit = 0;        // resamples left out (no fit)
};

// Percentile-bootstrap interval of the median (header comment); `confidence` in (0, 1),
// `resamples` >= 1. An interval with lo = hi = 0 when no resample had a fit.
MedianInterval bootstrap_median(const std::vector<IntensitySample>& samples, int resamples,
                                std::uint64_t seed, double confidence = 0.95);

// P(collapse | im) of a fit: Phi(ln(im / median) / beta).
double collapse_probability(const LognormalFit& fit, double im);

}  // namespace voussoir

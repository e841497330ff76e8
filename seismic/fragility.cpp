// Lognormal fragility by maximum likelihood and its bootstrap interval (math in fragility.hpp).

#include "seismic/fragility.hpp"

#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/tools/minima.hpp>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace voussoir {

double log_normal_survival(double z) {
  // erfc(z / sqrt 2) underflows past z ~ 38 (1 - Phi(38) ~ 3e-316); from kTail on, Mills'
  // ratio: 1 - Phi(z) = phi(z) R(z), R(z) = (1/z)(1 - 1/z^2 + 3/z^4 - 15/z^6 + 105/z^8 - ...),
  // the next term 945/z^10 < 2e-12 of the sum there (Abramowitz & Stegun 26.2.12).
  constexpr double kTail = 30.0;
  if (z < kTail) return std::log(0.5 * std::erfc(z / std::sqrt(2.0)));
  const double w = 1.0 / (z * z);
  const double series = 1.0 + w * (-1.0 + w * (3.0 + w * (-15.0 + w * 105.0)));
  return -0.5 * z * z - std::log(z * std::sqrt(2.0 * M_PI)) + std::log(series);
}

namespace {

constexpr int kBrentBits = std::numeric_limits<double>::digits;
constexpr char kCollapsed = 0, kAbove = 1, kBelow = 2;  // a record's sample kind

// ln L(mu, beta) of the header comment (without its constant).
double log_likelihood(const std::vector<double>& y, const std::vector<char>& censored, double mu,
                      double beta) {
  double sum = 0.0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    const double z = (y[i] - mu) / beta;
    // Censored above x_i: ln(1 - Phi(z)); below it (a collapse at every intensity tried, the
    // smallest x_i): ln Phi(z) = ln(1 - Phi(-z)).
    sum += censored[i] == kAbove   ? log_normal_survival(z)
           : censored[i] == kBelow ? log_normal_survival(-z)
                                   : -std::log(beta) - 0.5 * z * z;
  }
  return sum;
}

}  // namespace

LognormalFit fit_lognormal(const std::vector<IntensitySample>& samples) {
  LognormalFit fit;
  fit.samples = static_cast<int>(samples.size());
  std::vector<double> y;
  std::vector<char> censored;
  std::vector<double> collapsed;
  for (const IntensitySample& s : samples) {
    if (!(s.im > 0.0) || !std::isfinite(s.im))
      throw std::invalid_argument("fragility: an intensity must be a positive number of g");
    if (s.censored && s.below)
      throw std::invalid_argument("fragility: a record is censored above or below, not both");
    y.push_back(std::log(s.im));
    censored.push_back(s.censored ? kAbove : s.below ? kBelow : kCollapsed);
    if (s.censored || s.below)
      ++fit.censored;
    else
      collapsed.push_back(y.back());
  }
  std::sort(collapsed.begin(), collapsed.end());
  if (collapsed.size() < 2 || collapsed.front() == collapsed.back()) {
    fit.why = "a fit needs two records that collapse at different intensities";
    return fit;
  }
  double mu = 0.0, beta = 0.0;
  if (fit.censored == 0) {
    for (double v : y) mu += v;
    mu /= static_cast<double>(y.size());
    for (double v : y) beta += (v - mu) * (v - mu);
    beta = std::sqrt(beta / static_cast<double>(y.size()));
  } else {
    const double lo = *std::min_element(y.begin(), y.end()) - 5.0;
    const double hi = *std::max_element(y.begin(), y.end()) + 5.0;
    auto best_mu = [&](double b) {
      return boost::math::tools::brent_find_minima(
                 [&](double m) { return -log_likelihood(y, censored, m, b); }, lo, hi, kBrentBits)
          .first;
    };
    const double log_beta = boost::math::tools::brent_find_minima(
                                [&](double lb) {
                                  const double b = std::exp(lb);
                                  return -log_likelihood(y, censored, best_mu(b), b);
                                },
                                std::log(1e-3), std::log(10.0), kBrentBits)
                                .first;
    beta = std::exp(log_beta);
    mu = best_mu(beta);
  }
  fit.ok = true;
  fit.median = std::exp(mu);
  fit.beta = beta;
  return fit;
}

MedianInterval bootstrap_median(const std::vector<IntensitySample>& samples, int resamples,
                                std::uint64_t seed, double confidence) {
  MedianInterval out;
  out.confidence = confidence;
  if (samples.empty() || resamples < 1) return out;
  std::mt19937_64 draw(seed);
  const std::size_t n = samples.size();
  std::vector<double> medians;
  std::vector<IntensitySample> set(n);
  for (int r = 0; r < resamples; ++r) {
    for (IntensitySample& s : set) {
      // A uniform in [0, 1) from the top 53 bits, then an index.
      const double u = static_cast<double>(draw() >> 11) * 0x1.0p-53;
      s = samples[std::min(n - 1, static_cast<std::size_t>(u * static_cast<double>(n)))];
    }
    const LognormalFit fit = fit_lognormal(set);
    if (fit.ok) {
      medians.push_back(fit.median);
      continue;
    }
    // Without a fit, the resample's median at its limit (header comment).
    ++out.without_fit;
    double sum = 0.0;
    int collapsed = 0;
    bool above = false;
    for (const IntensitySample& s : set) {
      if (!s.censored && !s.below) sum += std::log(s.im), ++collapsed;
      above = above || s.censored;
    }
    medians.push_back(collapsed > 0 ? std::exp(sum / collapsed)
                      : above       ? std::numeric_limits<double>::infinity()
                                    : 0.0);
  }
  out.resamples = static_cast<int>(medians.size());
  std::sort(medians.begin(), medians.end());
  auto quantile = [&](double p) {
    const double h = p * static_cast<double>(medians.size() - 1);
    const std::size_t k = static_cast<std::size_t>(std::floor(h));
    if (k + 1 >= medians.size()) return medians.back();
    const double f = h - static_cast<double>(k);
    if (f == 0.0) return medians[k];
    // Between a median and an infinite one the quantile is unbounded (inf x 0 is no number).
    if (std::isinf(medians[k + 1])) return medians[k + 1];
    return medians[k] + f * (medians[k + 1] - medians[k]);
  };
  out.lo = quantile(0.5 * (1.0 - confidence));
  out.hi = quantile(0.5 * (1.0 + confidence));
  return out;
}

double collapse_probability(const LognormalFit& fit, double im) {
  if (!fit.ok || !(im > 0.0)) return 0.0;
  return boost::math::cdf(boost::math::normal(), std::log(im / fit.median) / fit.beta);
}

}  // namespace voussoir

// Lognormal fragility by maximum likelihood and its bootstrap interval (math in fragility.hpp).

#include "core/fragility.hpp"

#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/tools/minima.hpp>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace voussoir {

namespace {

constexpr int kBrentBits = std::numeric_limits<double>::digits;

// ln(1 - Phi(z)), accurate far in the upper tail.
double log_survival(double z) {
  return std::log(0.5 * std::erfc(z / std::sqrt(2.0)));
}

// ln L(mu, beta) of the header comment (without its constant).
double log_likelihood(const std::vector<double>& y, const std::vector<char>& censored, double mu,
                      double beta) {
  double sum = 0.0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    const double z = (y[i] - mu) / beta;
    sum += censored[i] ? log_survival(z) : -std::log(beta) - 0.5 * z * z;
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
    y.push_back(std::log(s.im));
    censored.push_back(s.censored ? 1 : 0);
    if (s.censored)
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
    if (fit.ok)
      medians.push_back(fit.median);
    else
      ++out.without_fit;
  }
  out.resamples = static_cast<int>(medians.size());
  if (medians.empty()) return out;
  std::sort(medians.begin(), medians.end());
  auto quantile = [&](double p) {
    const double h = p * static_cast<double>(medians.size() - 1);
    const std::size_t k = static_cast<std::size_t>(std::floor(h));
    if (k + 1 >= medians.size()) return medians.back();
    return medians[k] + (h - static_cast<double>(k)) * (medians[k + 1] - medians[k]);
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

// Response spectra by exact integration of the piecewise-linear record (math in spectrum.hpp).

#include "seismic/spectrum.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>

namespace voussoir {

namespace {

// One exact step of length h from (u, v) under p linear from p0 to p1 (header comment).
void exact_step(double omega, double zeta, double h, double u, double v, double p0, double p1,
                double& u1, double& v1) {
  const double wd = omega * std::sqrt(1.0 - zeta * zeta);
  const double zw = zeta * omega;
  const double beta = (p1 - p0) / h / (omega * omega);
  const double alpha = (p0 - 2.0 * zw * beta) / (omega * omega);
  const double x = u - alpha;
  const double y = (v - beta + zw * x) / wd;
  const double e = std::exp(-zw * h), c = std::cos(wd * h), s = std::sin(wd * h);
  u1 = alpha + beta * h + e * (x * c + y * s);
  v1 = beta + e * ((wd * y - zw * x) * c - (wd * x + zw * y) * s);
}

}  // namespace

SdofStep make_sdof_step(double omega, double zeta, double h) {
  assert(omega > 0.0 && zeta >= 0.0 && zeta < 1.0 && h > 0.0);
  SdofStep m;
  exact_step(omega, zeta, h, 1.0, 0.0, 0.0, 0.0, m.a00, m.a10);
  exact_step(omega, zeta, h, 0.0, 1.0, 0.0, 0.0, m.a01, m.a11);
  exact_step(omega, zeta, h, 0.0, 0.0, 1.0, 0.0, m.b00, m.b10);
  exact_step(omega, zeta, h, 0.0, 0.0, 0.0, 1.0, m.b01, m.b11);
  return m;
}

double sdof_peak_displacement(const std::vector<double>& accel, double dt, double period,
                              double zeta, std::size_t from, std::size_t to) {
  assert(period > 0.0 && dt > 0.0);
  const double omega = 2.0 * std::numbers::pi / period;
  const SdofStep m = make_sdof_step(omega, zeta, dt);
  const std::size_t n = accel.size();
  // The record, then one step down to 0, then one period of free vibration (header).
  const std::size_t free_steps = static_cast<std::size_t>(std::ceil(period / dt)) + 1;
  const std::size_t total = std::min(n + free_steps, to);
  double u = 0.0, v = 0.0, peak = 0.0;
  double p0 = n > 0 ? -accel[0] : 0.0;
  for (std::size_t k = 1; k < total; ++k) {
    const double p1 = k < n ? -accel[k] : 0.0;
    const double u1 = m.a00 * u + m.a01 * v + m.b00 * p0 + m.b01 * p1;
    v = m.a10 * u + m.a11 * v + m.b10 * p0 + m.b11 * p1;
    u = u1;
    p0 = p1;
    if (k >= from) peak = std::max(peak, std::abs(u));
  }
  return peak;
}

std::vector<double> response_spectrum(const std::vector<double>& accel, double dt,
                                      const std::vector<double>& periods, double zeta) {
  std::vector<double> sa(periods.size());
  for (std::size_t i = 0; i < periods.size(); ++i) {
    const double omega = 2.0 * std::numbers::pi / periods[i];
    sa[i] = omega * omega * sdof_peak_displacement(accel, dt, periods[i], zeta);
  }
  return sa;
}

std::vector<double> log_spaced_periods(double first, double last, int count) {
  assert(first > 0.0 && last > first && count >= 2);
  std::vector<double> t(static_cast<std::size_t>(count));
  const double ratio = std::log(last / first) / (count - 1);
  for (int i = 0; i < count; ++i) t[static_cast<std::size_t>(i)] = first * std::exp(ratio * i);
  t.back() = last;
  return t;
}

}  // namespace voussoir

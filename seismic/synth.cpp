// Spectrum-compatible artificial accelerograms by SIMQKE iterations (method in synth.hpp).

#include "seismic/synth.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "seismic/spectrum.hpp"

namespace voussoir {

namespace {

constexpr double kPi = std::numbers::pi;

// Vanmarcke's median peak factor of an oscillator (omega, zeta_s) over Ts seconds (header
// step 3), floored at 1.
double peak_factor(double omega, double zeta_s, double ts) {
  const double n = omega * ts / (2.0 * kPi) / std::log(2.0);
  if (!(2.0 * n > 1.0)) return 1.0;
  const double z = std::min(zeta_s, 0.99);
  const double q = 1.0 - (2.0 / kPi) * std::atan(z / std::sqrt(1.0 - z * z));
  const double delta = std::sqrt(std::max(0.0, 1.0 - q * q / (1.0 - z * z)));
  const double arg =
      2.0 * n * (1.0 - std::exp(-std::pow(delta, 1.2) * std::sqrt(kPi * std::log(2.0 * n))));
  if (!(arg > 1.0)) return 1.0;
  return std::max(1.0, std::sqrt(2.0 * std::log(arg)));
}

// `values` given at ascending `periods`, linear in log T between them, the end values beyond.
double interpolate_log(const std::vector<double>& periods, const std::vector<double>& values,
                       double period) {
  if (period <= periods.front()) return values.front();
  if (period >= periods.back()) return values.back();
  const std::size_t hi = static_cast<std::size_t>(
      std::upper_bound(periods.begin(), periods.end(), period) - periods.begin());
  const std::size_t lo = hi - 1;
  const double w = std::log(period / periods[lo]) / std::log(periods[hi] / periods[lo]);
  return values[lo] + w * (values[hi] - values[lo]);
}

// a(t_n) = I(t_n) sum_k amp_k sin(w_k t_n + phi_k), n = 0 .. count - 1, by rotating each
// component's (cos, sin) by w_k dt per sample (header "Cost"). The sum over k is split over four
// accumulators (a fixed order: the same result on every run).
std::vector<double> sum_of_sines(const std::vector<double>& amp, const std::vector<double>& omega,
                                 const std::vector<double>& phase, const SynthEnvelope& env,
                                 double dt, std::size_t count) {
  const std::size_t m = amp.size();
  std::vector<double> c(m), s(m), rc(m), rs(m);
  for (std::size_t k = 0; k < m; ++k) {
    c[k] = std::cos(phase[k]);
    s[k] = std::sin(phase[k]);
    rc[k] = std::cos(omega[k] * dt);
    rs[k] = std::sin(omega[k] * dt);
  }
  std::vector<double> a(count);
  for (std::size_t n = 0; n < count; ++n) {
    double acc[4] = {0.0, 0.0, 0.0, 0.0};
    std::size_t k = 0;
    for (; k + 4 <= m; k += 4)
      for (std::size_t j = 0; j < 4; ++j) acc[j] += amp[k + j] * s[k + j];
    for (; k < m; ++k) acc[0] += amp[k] * s[k];
    a[n] = env.at(static_cast<double>(n) * dt) * ((acc[0] + acc[1]) + (acc[2] + acc[3]));
    for (std::size_t q = 0; q < m; ++q) {
      const double c1 = c[q] * rc[q] - s[q] * rs[q];
      s[q] = s[q] * rc[q] + c[q] * rs[q];
      c[q] = c1;
    }
  }
  return a;
}

// The baseline correction of step 4: subtracts c1 I(t) + c2 I(t) t / D from `accel` with c1, c2
// such that the record ends at rest: velocity and displacement zero (ground_motion).
void bring_to_rest(std::vector<double>& accel, double dt, const SynthEnvelope& env) {
  const std::size_t n = accel.size();
  std::vector<double> phi1(n), phi2(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * dt;
    phi1[k] = env.at(t);
    phi2[k] = phi1[k] * t / env.duration;
  }
  const GroundMotion m0 = ground_motion(accel, dt), m1 = ground_motion(phi1, dt),
                     m2 = ground_motion(phi2, dt);
  const double v0 = m0.end_velocity, d0 = m0.end_displacement;
  const double v1 = m1.end_velocity, d1 = m1.end_displacement;
  const double v2 = m2.end_velocity, d2 = m2.end_displacement;
  const double det = v1 * d2 - v2 * d1;
  if (det == 0.0) return;
  const double c1 = (v0 * d2 - v2 * d0) / det, c2 = (v1 * d0 - v0 * d1) / det;
  for (std::size_t k = 0; k < n; ++k) accel[k] -= c1 * phi1[k] + c2 * phi2[k];
}

}  // namespace

GroundMotion ground_motion(const std::vector<double>& accel, double dt) {
  GroundMotion m;
  double v = 0.0, d = 0.0;
  for (std::size_t k = 0; k + 1 < accel.size(); ++k) {
    d += dt * v + dt * dt * (2.0 * accel[k] + accel[k + 1]) / 6.0;
    v += dt * (accel[k] + accel[k + 1]) / 2.0;
    m.peak_velocity = std::max(m.peak_velocity, std::abs(v));
    m.peak_displacement = std::max(m.peak_displacement, std::abs(d));
  }
  m.end_velocity = v;
  m.end_displacement = d;
  return m;
}

std::optional<Ec8Soil> ec8_type1_soil(char name) {
  switch (name) {
    case 'A':
      return Ec8Soil{'A', 1.00, 0.15, 0.40, 2.0};
    case 'B':
      return Ec8Soil{'B', 1.20, 0.15, 0.50, 2.0};
    case 'C':
      return Ec8Soil{'C', 1.15, 0.20, 0.60, 2.0};
    case 'D':
      return Ec8Soil{'D', 1.35, 0.20, 0.80, 2.0};
    case 'E':
      return Ec8Soil{'E', 1.40, 0.15, 0.50, 2.0};
    default:
      return std::nullopt;
  }
}

double ec8_elastic_spectrum(double period, double ag, const Ec8Soil& soil) {
  constexpr double eta = 1.0;  // 5% damping
  const double plateau = 2.5 * eta * ag * soil.s;
  if (period <= soil.tb) return ag * soil.s * (1.0 + period / soil.tb * (2.5 * eta - 1.0));
  if (period <= soil.tc) return plateau;
  if (period <= soil.td) return plateau * soil.tc / period;
  return plateau * soil.tc * soil.td / (period * period);
}

double SynthEnvelope::at(double t) const {
  if (t < 0.0 || t > duration) return 0.0;
  if (t < rise) return (t / rise) * (t / rise);
  if (t <= strong_end) return 1.0;
  return std::exp(-decay * (t - strong_end));
}

SynthEnvelope make_synth_envelope(double duration) {
  assert(duration >= kMinDuration);
  SynthEnvelope e;
  e.rise = kEnvelopeRise;
  e.strong_end = kEnvelopeRise + kStrongFraction * (duration - kEnvelopeRise);
  e.duration = duration;
  e.decay = std::log(1.0 / kEnvelopeEnd) / (duration - e.strong_end);
  return e;
}

std::vector<double> synth_periods(const SynthSettings& settings) {
  std::vector<double> t = written_spectrum_periods();
  for (double end : {settings.range_lo, settings.range_hi})
    if (std::find(t.begin(), t.end(), end) == t.end()) t.push_back(end);
  std::sort(t.begin(), t.end());
  return t;
}

SynthRecord synthesize_record(const SynthSettings& settings,
                              const std::function<double(double)>& target,
                              const std::vector<double>& periods, std::uint64_t seed, int index) {
  const double dt = settings.dt, zeta = settings.damping;
  const SynthEnvelope env = make_synth_envelope(settings.duration);
  const std::size_t count = static_cast<std::size_t>(std::llround(settings.duration / dt)) + 1;

  // Components (step 1) and their random phases.
  const double df = 1.0 / (2.0 * settings.duration);
  const double f_max = std::min(kMaxFrequency, 0.25 / dt);
  std::vector<double> omega, phase;
  std::seed_seq seq{static_cast<std::uint32_t>(seed & 0xffffffffu),
                    static_cast<std::uint32_t>(seed >> 32), static_cast<std::uint32_t>(index)};
  std::mt19937_64 rng(seq);
  for (int k = static_cast<int>(std::ceil(kMinFrequency / df)); k * df <= f_max; ++k) {
    omega.push_back(2.0 * kPi * k * df);
    phase.push_back(2.0 * kPi * static_cast<double>(rng() >> 11) * 0x1.0p-53);
  }
  const std::size_t m = omega.size();
  const double dw = 2.0 * kPi * df;

  // Starting density (step 3), from the lowest frequency up.
  const double ts = env.strong_length();
  std::vector<double> amp(m);
  double area = 0.0, g_top = 0.0;
  for (std::size_t k = 0; k < m; ++k) {
    const double w = omega[k];
    const double zeta_s = zeta / (1.0 - std::exp(-2.0 * zeta * w * ts));
    const double r = peak_factor(w, zeta_s, ts);
    const double sa = target(2.0 * kPi / w);
    double g = (sa * sa / (r * r) - area) / (w * (kPi / (4.0 * zeta_s) - 1.0));
    g = std::max(g, kDensityFloor * g_top);
    g_top = std::max(g_top, g);
    area += g * dw;
    amp[k] = std::sqrt(2.0 * g * dw);
  }

  // Iterations (step 4).
  std::vector<double> goal(periods.size());
  for (std::size_t j = 0; j < periods.size(); ++j) goal[j] = target(periods[j]);
  std::vector<double> ratio(periods.size());
  SynthRecord best;
  double best_dev = std::numeric_limits<double>::infinity();
  for (int it = 1; it <= settings.max_iterations; ++it) {
    std::vector<double> accel = sum_of_sines(amp, omega, phase, env, dt, count);
    bring_to_rest(accel, dt, env);
    std::vector<double> sa = response_spectrum(accel, dt, periods, zeta);
    double dev = 0.0;
    for (std::size_t j = 0; j < periods.size(); ++j) {
      ratio[j] = std::clamp(goal[j] / sa[j], 0.5, 2.0);
      if (periods[j] >= settings.range_lo && periods[j] <= settings.range_hi)
        dev = std::max(dev, std::abs(sa[j] / goal[j] - 1.0));
    }
    if (dev < best_dev) {
      best_dev = dev;
      best.accel = std::move(accel);
      best.sa = std::move(sa);
      best.kept = it;
    }
    best.iterations = it;
    if (dev <= settings.tolerance) break;
    for (std::size_t k = 0; k < m; ++k)
      amp[k] *= interpolate_log(periods, ratio, 2.0 * kPi / omega[k]);
  }
  for (double a : best.accel) best.pga = std::max(best.pga, std::abs(a));
  return best;
}

SynthSet synthesize_set(const SynthSettings& settings, const std::function<double(double)>& target,
                        const std::vector<double>& periods, std::uint64_t seed, int count,
                        double pga_floor) {
  SynthSet set;
  set.records.resize(static_cast<std::size_t>(count));
  // Records are independent: one per thread at a time, each the same on any thread count.
#pragma omp parallel for schedule(dynamic, 1)
  for (int i = 0; i < count; ++i)
    set.records[static_cast<std::size_t>(i)] =
        synthesize_record(settings, target, periods, seed, i);
  double pga_sum = 0.0;
  for (const SynthRecord& r : set.records) pga_sum += r.pga;
  const double mean_pga = pga_sum / count;
  if (mean_pga < pga_floor) set.scale = pga_floor / mean_pga;
  set.mean.assign(periods.size(), 0.0);
  for (SynthRecord& r : set.records) {
    if (set.scale != 1.0) {
      for (double& a : r.accel) a *= set.scale;
      for (double& sa : r.sa) sa *= set.scale;
      r.pga *= set.scale;
    }
    for (std::size_t j = 0; j < periods.size(); ++j) set.mean[j] += r.sa[j] / count;
  }
  set.mean_pga = mean_pga * set.scale;
  return set;
}

}  // namespace voussoir

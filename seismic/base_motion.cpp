// Base-excitation signals: filter design, tabulation and integration (math and decisions in
// base_motion.hpp).

#include "seismic/base_motion.hpp"

#include <algorithm>

namespace voussoir {

namespace {

constexpr double kPi = std::numbers::pi;

// Largest number of uniform samples a file record is resampled to (memory and set-up time;
// 4e6 samples = 40 s at 1e-5 s). Beyond it the spacing grows to fit.
constexpr std::size_t kMaxSamples = 4'000'000;

// Padding after the record for the backward pass, in periods of the lowest cut-off: the
// slowest pole of a 4th-order Butterworth has damping ratio cos(3 pi / 8) = 0.383, so its
// envelope exp(-0.383 * 2 pi fc t) is 5e-7 after t = 6 / fc.
constexpr double kPadPeriods = 6.0;

// Runs the cascade over x in place, forward (step = +1) or backward (step = -1), from rest.
void run_cascade(const std::vector<Biquad>& sections, std::vector<double>& x, bool backward) {
  const std::ptrdiff_t n = static_cast<std::ptrdiff_t>(x.size());
  for (const Biquad& s : sections) {
    double x1 = 0.0, x2 = 0.0, y1 = 0.0, y2 = 0.0;
    for (std::ptrdiff_t k = 0; k < n; ++k) {
      double& v = x[backward ? n - 1 - k : k];
      const double y = s.b0 * v + s.b1 * x1 + s.b2 * x2 - s.a1 * y1 - s.a2 * y2;
      x2 = x1;
      x1 = v;
      y2 = y1;
      y1 = y;
      v = y;
    }
  }
}

}  // namespace

// Smallest time increment of the record, at most 1 / (10 hi) when filtering (ten samples per
// period of the upper cut-off keep the bilinear warping small), coarse enough for kMaxSamples.
double resample_spacing(const Accelerogram& rec, double band_hi) {
  double h = rec.time.back() - rec.time.front();
  for (std::size_t i = 1; i < rec.time.size(); ++i) h = std::min(h, rec.time[i] - rec.time[i - 1]);
  if (band_hi > 0.0) h = std::min(h, 0.1 / band_hi);
  return std::max(h, rec.time.back() / static_cast<double>(kMaxSamples));
}

// Analog Butterworth of order 4 = two second-order sections with quality factors
// Q_k = 1 / (2 cos((2k - 1) pi / 8)), k = 1, 2 (0.5412 and 1.3066):
//     low-pass  H(s) = 1 / (s^2/w^2 + s/(Q w) + 1),   high-pass  H(s) = (s/w)^2 / (same).
// Bilinear transform s = (2/dt)(1 - z^-1)/(1 + z^-1) with the analog cut-off pre-warped to
// w = (2/dt) tan(pi fc dt), so the digital cut-off is exactly fc. With K = tan(pi fc dt) and
// writing the denominator d = K^2 + K/Q + 1:
//     a1 = 2 (K^2 - 1) / d,  a2 = (K^2 - K/Q + 1) / d,
//     low-pass  b = K^2 (1, 2, 1) / d,   high-pass  b = (1, -2, 1) / d.
std::vector<Biquad> butterworth4(double fc, double dt, bool high_pass) {
  const double k = std::tan(kPi * fc * dt);
  std::vector<Biquad> out;
  for (int i = 1; i <= 2; ++i) {
    const double q = 1.0 / (2.0 * std::cos((2 * i - 1) * kPi / 8.0));
    const double d = k * k + k / q + 1.0;
    Biquad s;
    s.a1 = 2.0 * (k * k - 1.0) / d;
    s.a2 = (k * k - k / q + 1.0) / d;
    const double g = high_pass ? 1.0 / d : k * k / d;
    s.b0 = g;
    s.b1 = high_pass ? -2.0 * g : 2.0 * g;
    s.b2 = g;
    out.push_back(s);
  }
  return out;
}

double cascade_gain(const std::vector<Biquad>& sections, double f, double dt) {
  // |H(e^{iw})| with w = 2 pi f dt, z^-1 = e^{-iw}.
  const double w = 2.0 * kPi * f * dt;
  const double c1 = std::cos(w), s1 = std::sin(w), c2 = std::cos(2 * w), s2 = std::sin(2 * w);
  double gain = 1.0;
  for (const Biquad& b : sections) {
    const double nr = b.b0 + b.b1 * c1 + b.b2 * c2, ni = -(b.b1 * s1 + b.b2 * s2);
    const double dr = 1.0 + b.a1 * c1 + b.a2 * c2, di = -(b.a1 * s1 + b.a2 * s2);
    gain *= std::sqrt((nr * nr + ni * ni) / (dr * dr + di * di));
  }
  return gain;
}

std::vector<double> bandpass_zero_phase(const std::vector<double>& samples, double dt, double lo,
                                        double hi, std::size_t* tail_samples) {
  std::vector<Biquad> sections = butterworth4(hi, dt, false);
  if (lo > 0.0) {
    const std::vector<Biquad> hp = butterworth4(lo, dt, true);
    sections.insert(sections.end(), hp.begin(), hp.end());
  }
  const double slowest = lo > 0.0 ? lo : hi;
  const std::size_t tail = static_cast<std::size_t>(std::ceil(kPadPeriods / (slowest * dt)));
  std::vector<double> x(samples);
  x.resize(samples.size() + tail, 0.0);
  run_cascade(sections, x, false);
  run_cascade(sections, x, true);
  if (tail_samples) *tail_samples = tail;
  return x;
}

BaseSignal BaseSignal::none() {
  return BaseSignal();
}

BaseSignal BaseSignal::windowed(double amplitude, double frequency, int cycles) {
  BaseSignal s;
  s.kind_ = Kind::WindowedSine;
  s.amplitude_ = amplitude;
  s.frequency_ = frequency;
  s.cycles_ = cycles;
  s.duration_ = cycles / frequency;
  const std::size_t n = static_cast<std::size_t>(cycles) * kSamplesPerCycle;
  s.h_ = s.duration_ / static_cast<double>(n);
  s.acc_.resize(n + 1);
  for (std::size_t k = 0; k <= n; ++k)
    s.acc_[k] = windowed_sine(static_cast<double>(k) * s.h_, amplitude, frequency, cycles);
  s.integrate_motion();
  return s;
}

BaseSignal BaseSignal::one_sine(double amplitude, double frequency) {
  BaseSignal s;
  s.kind_ = Kind::SinePulse;
  s.amplitude_ = amplitude;
  s.frequency_ = frequency;
  s.cycles_ = 1;
  s.duration_ = 1.0 / frequency;
  const std::size_t n = kSamplesPerCycle;
  s.h_ = s.duration_ / static_cast<double>(n);
  s.acc_.resize(n + 1);
  for (std::size_t k = 0; k <= n; ++k)
    s.acc_[k] = sine_pulse(static_cast<double>(k) * s.h_, amplitude, frequency);
  s.acc_[n] = 0.0;  // sin(2 pi) up to round-off
  s.integrate_motion();
  return s;
}

BaseSignal BaseSignal::table(const Accelerogram& rec, double band_lo, double band_hi) {
  BaseSignal s;
  s.kind_ = Kind::Table;
  const double h = resample_spacing(rec, band_hi);
  const std::size_t n = static_cast<std::size_t>(std::ceil(rec.time.back() / h - 1e-9));
  s.h_ = h;
  s.acc_.assign(n + 1, 0.0);
  std::size_t j = 0;  // record interval [time[j], time[j+1]] containing t
  for (std::size_t k = 0; k <= n; ++k) {
    const double t = static_cast<double>(k) * h;
    if (t < rec.time.front() || t > rec.time.back()) continue;
    while (j + 2 < rec.time.size() && rec.time[j + 1] < t) ++j;
    const double u = (t - rec.time[j]) / (rec.time[j + 1] - rec.time[j]);
    s.acc_[k] = (1.0 - u) * rec.accel[j] + u * rec.accel[j + 1];
  }
  if (band_hi > 0.0) s.acc_ = bandpass_zero_phase(s.acc_, h, band_lo, band_hi);
  s.duration_ = static_cast<double>(s.acc_.size() - 1) * h;
  s.integrate_motion();
  return s;
}

void BaseSignal::scale(double factor) {
  amplitude_ *= factor;
  for (double& a : acc_) a *= factor;
  integrate_motion();
}

// Exact integration of the piecewise-linear acceleration through the samples (header).
void BaseSignal::integrate_motion() {
  const std::size_t n = acc_.size();
  vel_.assign(n, 0.0);
  disp_.assign(n, 0.0);
  peak_ = 0.0;
  for (std::size_t k = 0; k < n; ++k) peak_ = std::max(peak_, std::abs(acc_[k]));
  for (std::size_t k = 0; k + 1 < n; ++k) {
    vel_[k + 1] = vel_[k] + 0.5 * h_ * (acc_[k] + acc_[k + 1]);
    disp_[k + 1] = disp_[k] + h_ * vel_[k] + h_ * h_ * (2.0 * acc_[k] + acc_[k + 1]) / 6.0;
  }
}

double BaseSignal::velocity(double t) const {
  if (acc_.empty() || !(t > 0.0)) return 0.0;
  const std::size_t last = acc_.size() - 1;
  const double s = t / h_;
  if (s >= double(last)) return vel_[last];  // a_g = 0 after the end
  const std::size_t i = static_cast<std::size_t>(s);
  const double tau = t - double(i) * h_;
  const double slope = (acc_[i + 1] - acc_[i]) / h_;
  return vel_[i] + tau * acc_[i] + 0.5 * tau * tau * slope;
}

double BaseSignal::displacement(double t) const {
  if (acc_.empty() || !(t > 0.0)) return 0.0;
  const std::size_t last = acc_.size() - 1;
  const double s = t / h_;
  if (s >= double(last)) return disp_[last] + vel_[last] * (t - double(last) * h_);
  const std::size_t i = static_cast<std::size_t>(s);
  const double tau = t - double(i) * h_;
  const double slope = (acc_[i + 1] - acc_[i]) / h_;
  return disp_[i] + tau * vel_[i] + 0.5 * tau * tau * acc_[i] + tau * tau * tau * slope / 6.0;
}

}  // namespace voussoir

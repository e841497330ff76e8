#pragma once
// Test reference, not product code: Housner's (1963) rocking block under a ground acceleration
// record, integrated beside the tests, and the synthetic records they feed to it and to
// voussoir (tests/unit/test_rocking_records.cpp).
//
// The equation. A rectangular rigid block of half-width b and half-height h on a rigid base
// that does not let it slide, rotating by theta about one base corner (theta > 0: tilted
// towards +x, on its +x corner), with
//     R = sqrt(b^2 + h^2),  alpha = atan(b / h),  p^2 = m g R / I_o = 3 g / (4 R)
// (I_o = 4/3 m R^2 about the corner), under a horizontal ground acceleration a_g(t):
//     theta'' = -p^2 [ sin(alpha sgn(theta) - theta) + (a_g / g) cos(alpha sgn(theta) - theta) ]
// (Housner 1963; Makris & Zhang 2001, eq. 1, with the same signs: a_g > 0 tips the block to
// theta < 0, the inertial force -m a_g pointing to -x). At rest the block starts
// to rock when |a_g| > g tan(alpha), to the side s = -sgn(a_g), from theta = 0, theta' = 0.
// Each impact (theta crossing 0) changes the pivot; angular momentum about the new corner is
// kept, which multiplies theta' by Housner's
//     r = 1 - 3/2 sin^2(alpha)                                         (rectangle)
// or by the ratio a test measures on its own joints (HousnerOptions::restitution).
//
// Integration. Classical RK4 at a fixed step that divides the record's sample interval, so
// the piecewise-linear record is smooth inside every step. Events: an impact is located by
// bisection of the step length (60 halvings of one RK4 step from the step's start on the old
// side's equation); the uplift from rest is located exactly (a_g is linear inside a step).
// After an impact whose angular velocity is below `rest_speed` the block is put at rest (the
// infinite sequence of ever smaller impacts of a settling block ends there; it rocks again as
// soon as |a_g| > g tan(alpha)).
//
// Outcome. The block falls when |theta| reaches `fall_rotation` (1 rad: the rotation at which
// voussoir's `pulse` calls a fall, PulseCriteria::fall_rotation, so both classify one motion
// alike; past alpha a block only comes back if the ground pushes it back). After the record
// the ground is still, the rocking energy E = 1/2 I_o theta'^2 + m g R cos(alpha - |theta|)
// never grows, and the block survives for certain once |theta| < alpha and E < m g R (it can
// no longer reach alpha); it falls once |theta| > alpha (gravity tips it on). The free motion
// is followed until one of the two holds (at most `max_free_time`; then |theta| > alpha
// decides).
//
// Records. synthetic_record(): a stationary Gaussian-like process, a sum of cosines at
// f_k = f_min + k df with phases uniform in [0, 2 pi) from std::mt19937_64 (its output is fixed
// by the C++ standard; the uniforms are made by hand from its top 53 bits, so the records are
// the same on every platform), amplitudes sqrt(S(f_k) df) of the Kanai-Tajimi spectrum with
// the Clough-Penzien high-pass,
//     S(f) = [1 + 4 zg^2 (f/fg)^2] / [(1 - (f/fg)^2)^2 + 4 zg^2 (f/fg)^2]
//            x (f/ff)^4 / [(1 - (f/ff)^2)^2 + 4 zf^2 (f/ff)^2],
// (fg: dominant frequency of the site, zg its damping; ff, zf the high-pass that removes the
// slow content a real record's processing removes), times a rise / strong / decay envelope
// (t / t1)^2, 1, exp(-c (t - t2)), with a cosine taper over the last 0.5 s so the record ends
// at 0; scaled to a PGA of 1 g. Written as PEER AT2 files (values in g, %15.7E, five a line),
// and the samples the reference uses are those values read back, the ones voussoir reads.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace voussoir::testing {

// A rectangular block of half-width b and half-height h [m] (header comment).
struct HousnerBlock {
  double b = 0.125, h = 0.5;  // [m]
  double g = 9.81;            // [m/s2]
  double alpha() const { return std::atan(b / h); }
  double radius() const { return std::hypot(b, h); }
  double p2() const { return 3.0 * g / (4.0 * radius()); }  // [1/s2]
  double housner_restitution() const {
    const double s = std::sin(alpha());
    return 1.0 - 1.5 * s * s;
  }
};

// Ground acceleration a_g [g] at t_k = k dt, linear between samples, 0 after the last.
struct GroundRecord {
  double dt = 0.005;  // [s]
  std::vector<double> a;
  double duration() const { return dt * double(a.size() - 1); }
  double peak() const {
    double p = 0.0;
    for (double v : a) p = std::max(p, std::abs(v));
    return p;
  }
  double at(double t) const {
    if (!(t >= 0.0)) return 0.0;
    const double s = t / dt;
    const std::size_t i = static_cast<std::size_t>(s);
    if (i + 1 >= a.size()) return i + 1 == a.size() && s == double(i) ? a[i] : 0.0;
    const double u = s - double(i);
    return (1.0 - u) * a[i] + u * a[i + 1];
  }
};

struct HousnerOptions {
  double restitution = 1.0;     // angular velocity kept at an impact
  double fall_rotation = 1.0;   // [rad]
  int substeps = 10;            // RK4 steps per record sample interval
  double rest_speed = 1e-4;     // [rad/s] an impact slower than this ends at rest
  double max_free_time = 30.0;  // [s] after the record
  // Called at the end of every step with (t [s], theta [rad], theta' [rad/s]) when set.
  std::function<void(double, double, double)> observer;
};

struct HousnerResult {
  bool fell = false;
  double fell_at = -1.0;      // [s]
  double max_rotation = 0.0;  // largest |theta| [rad]
  int impacts = 0;
  double decided_at = 0.0;  // [s] when the outcome became certain
};

// The block under `scale` x record / record.peak() (a PGA of `scale` g, sign kept).
inline HousnerResult housner_response(const HousnerBlock& block, const GroundRecord& record,
                                      double scale, const HousnerOptions& opt) {
  const double alpha = block.alpha(), p2 = block.p2(), tan_alpha = std::tan(alpha);
  const double factor = scale / record.peak();
  const double t_rec = record.duration();
  auto ground = [&](double t) { return factor * record.at(t); };  // [g]
  auto accel = [&](double t, double th, int s) {
    const double u = s * alpha - th;
    return -p2 * (std::sin(u) + ground(t) * std::cos(u));
  };
  // One RK4 step of length tau from (t, th, om) on side s.
  auto rk4 = [&](double t, double th, double om, int s, double tau, double& th1, double& om1) {
    const double k1t = om, k1o = accel(t, th, s);
    const double k2t = om + 0.5 * tau * k1o, k2o = accel(t + 0.5 * tau, th + 0.5 * tau * k1t, s);
    const double k3t = om + 0.5 * tau * k2o, k3o = accel(t + 0.5 * tau, th + 0.5 * tau * k2t, s);
    const double k4t = om + tau * k3o, k4o = accel(t + tau, th + tau * k3t, s);
    th1 = th + tau / 6.0 * (k1t + 2.0 * k2t + 2.0 * k3t + k4t);
    om1 = om + tau / 6.0 * (k1o + 2.0 * k2o + 2.0 * k3o + k4o);
  };

  HousnerResult out;
  const double step = record.dt / opt.substeps;
  double th = 0.0, om = 0.0;
  int side = 0;  // 0: at rest on its base; +-1: rocking on theta >= 0 / theta <= 0
  const long long n_rec = std::llround(t_rec / step);
  const long long n_max = n_rec + std::llround(opt.max_free_time / step);
  for (long long k = 0; k < n_max; ++k) {
    const double tb = double(k + 1) * step;
    double t = double(k) * step;
    while (t < tb) {
      if (side == 0) {
        // Uplift where |a_g| first exceeds tan(alpha) inside [t, tb] (a_g linear there).
        const double a0 = ground(t), a1 = k < n_rec ? ground(tb) : 0.0;
        double start = -1.0;
        if (std::abs(a0) > tan_alpha)
          start = t;
        else if (std::abs(a1) > tan_alpha)
          start = t + (tb - t) * ((a1 > 0.0 ? tan_alpha : -tan_alpha) - a0) / (a1 - a0);
        if (start < 0.0) {
          t = tb;
          break;
        }
        const double a = std::abs(a0) > tan_alpha ? a0 : a1;
        side = a > 0.0 ? -1 : 1;
        th = 0.0, om = 0.0, t = start;
        if (t >= tb) break;
      }
      double th1, om1;
      rk4(t, th, om, side, tb - t, th1, om1);
      if (side * th1 >= 0.0) {
        th = th1, om = om1, t = tb;
        break;
      }
      // Impact inside the step: the largest tau with side * theta(tau) >= 0.
      double lo = 0.0, hi = tb - t;
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        rk4(t, th, om, side, mid, th1, om1);
        (side * th1 >= 0.0 ? lo : hi) = mid;
      }
      rk4(t, th, om, side, hi, th1, om1);
      t += hi;
      om = opt.restitution * om1;
      th = 0.0;
      ++out.impacts;
      if (std::abs(om) < opt.rest_speed) {
        side = 0, om = 0.0;
      } else {
        side = om > 0.0 ? 1 : -1;
      }
    }
    out.max_rotation = std::max(out.max_rotation, std::abs(th));
    if (opt.observer) opt.observer(tb, th, om);
    if (std::abs(th) >= opt.fall_rotation) {
      out.fell = true, out.fell_at = tb, out.decided_at = tb;
      return out;
    }
    if (k + 1 >= n_rec) {  // the ground is still: decided once certain
      const double energy = 0.5 * om * om / p2 + std::cos(alpha - std::abs(th));  // / (m g R)
      if (side == 0 || (std::abs(th) < alpha && energy < 1.0)) {
        out.decided_at = tb;
        return out;
      }
    }
  }
  out.fell = std::abs(th) > alpha;
  out.decided_at = double(n_max) * step;
  if (out.fell) out.fell_at = out.decided_at;
  return out;
}

// A synthetic record (header comment).
struct RecordSpec {
  std::string name;
  std::uint64_t seed = 1;
  double fg = 2.0, zg = 0.6;                    // Kanai-Tajimi: dominant frequency [Hz], damping
  double ff = 0.3, zf = 0.6;                    // Clough-Penzien high-pass [Hz], damping
  double t1 = 1.5, t2 = 5.0;                    // [s] end of the rise, end of the strong motion
  double decay = 0.6;                           // [1/s] c of the decay exp(-c (t - t2))
  double duration = 10.0;                       // [s]
  double dt = 0.005;                            // [s]
  double f_min = 0.1, f_max = 20.0, df = 0.02;  // [Hz] the cosines
};

// Uniform in [0, 1) from the top 53 bits of one draw (portable: mt19937_64's sequence is fixed
// by the standard, std::uniform_real_distribution's is not).
inline double uniform01(std::mt19937_64& gen) {
  return double(gen() >> 11) * 0x1.0p-53;
}

inline double record_envelope(const RecordSpec& s, double t) {
  double e = t < s.t1 ? (t / s.t1) * (t / s.t1) : t < s.t2 ? 1.0 : std::exp(-s.decay * (t - s.t2));
  const double taper = 0.5;  // [s]
  if (t > s.duration - taper)
    e *= 0.5 * (1.0 + std::cos(std::numbers::pi * (t - (s.duration - taper)) / taper));
  return e;
}

// The record's samples, PGA 1 g.
inline GroundRecord synthetic_record(const RecordSpec& s) {
  std::mt19937_64 gen(s.seed);
  std::vector<double> f, amp, phase;
  for (double fk = s.f_min; fk <= s.f_max + 1e-9; fk += s.df) {
    const double x = fk / s.fg, y = fk / s.ff;
    const double kt = (1.0 + 4.0 * s.zg * s.zg * x * x) /
                      ((1.0 - x * x) * (1.0 - x * x) + 4.0 * s.zg * s.zg * x * x);
    const double cp = y * y * y * y / ((1.0 - y * y) * (1.0 - y * y) + 4.0 * s.zf * s.zf * y * y);
    f.push_back(fk);
    amp.push_back(std::sqrt(kt * cp * s.df));
    phase.push_back(2.0 * std::numbers::pi * uniform01(gen));
  }
  GroundRecord r;
  r.dt = s.dt;
  const long long n = std::llround(s.duration / s.dt) + 1;
  r.a.resize(std::size_t(n));
  for (long long i = 0; i < n; ++i) {
    const double t = double(i) * s.dt;
    double sum = 0.0;
    for (std::size_t k = 0; k < f.size(); ++k)
      sum += amp[k] * std::cos(2.0 * std::numbers::pi * f[k] * t + phase[k]);
    r.a[std::size_t(i)] = record_envelope(s, t) * sum;
  }
  const double peak = r.peak();
  for (double& v : r.a) v /= peak;
  return r;
}

// Writes `record` as a PEER AT2 file (values in g) and returns the samples as written (each
// value read back from its text), which is what voussoir reads from the file.
inline GroundRecord write_at2(const GroundRecord& record, const std::string& title,
                              const std::string& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << "PEER NGA STRONG MOTION DATABASE RECORD\n"
      << title << "\nACCELERATION TIME SERIES IN UNITS OF G\n";
  char line[64];
  std::snprintf(line, sizeof line, "NPTS= %5zu, DT= %.4f SEC\n", record.a.size(), record.dt);
  out << line;
  GroundRecord written = record;
  for (std::size_t i = 0; i < record.a.size(); ++i) {
    char value[32];
    std::snprintf(value, sizeof value, "%15.7E", record.a[i]);
    written.a[i] = std::strtod(value, nullptr);
    out << value << ((i % 5 == 4 || i + 1 == record.a.size()) ? "\n" : "");
  }
  return written;
}

}  // namespace voussoir::testing

#pragma once
// Motion measures shared by the drivers that classify runs (capacity trials, pulses, the
// stability map): free-node speed, the reference block size, the at-rest rule, and the
// fractions and sampling period they use.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <vector>

#include "core/model.hpp"

namespace voussoir {

// Criteria are read every kSampleTime of simulated time: none needs a finer reading, and a
// sample costs a pass over the nodes.
constexpr double kSampleTime = 1e-3;  // [s]

// Hinge thresholds for reports: a joint is open when its gap exceeds 1% of L_ref, sliding
// when its slip exceeds 1% of L_ref.
constexpr double kHingeFraction = 0.01;

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Progress of a long run on stderr: due() is true once every kProgressPeriod of wall time
// (never when quiet), so a settle or trial of a large scene says where it is.
constexpr double kProgressPeriod = 30.0;  // [s] wall

class ProgressTicker {
 public:
  explicit ProgressTicker(bool quiet) : quiet_(quiet) {}
  bool due() {
    if (quiet_ || seconds_since(t0_) < next_) return false;
    next_ += kProgressPeriod;
    return true;
  }
  double wall() const { return seconds_since(t0_); }

 private:
  bool quiet_;
  std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
  double next_ = kProgressPeriod;
};

// Largest speed of any free node [m/s].
inline double max_free_speed(const Nodes& n) {
  double v2 = 0.0;
  for (Index i = 0; i < n.size(); ++i)
    if (n.inv_mass[i] != 0.0) v2 = std::max(v2, n.vx[i] * n.vx[i] + n.vy[i] * n.vy[i]);
  return std::sqrt(v2);
}

// L_ref: square root of the smallest free block area [m] (1 when no block is free).
inline double reference_length(const Model& model) {
  double a = std::numeric_limits<double>::infinity();
  for (const Block& b : model.blocks)
    if (!b.fixed) a = std::min(a, b.area);
  return std::isfinite(a) ? std::sqrt(a) : 1.0;
}

// Width and height of the free blocks' bounding box (reference outlines) [m]; 1 for an extent
// that is empty or flat.
struct FreeExtent {
  double width = 1.0, height = 1.0;
};
inline FreeExtent free_extent(const Model& model) {
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const Block& b : model.blocks)
    if (!b.fixed)
      for (const Vec2& p : b.polygon)
        x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y),
        y1 = std::max(y1, p.y);
  return {x1 > x0 ? x1 - x0 : 1.0, y1 > y0 ? y1 - y0 : 1.0};
}

// At rest: the largest free-node speed has stayed below v_rest for the hold window, and the
// kinetic energy is not growing over it (its peak over the second half of the window is no
// larger than over the first half). The second condition tells a decaying oscillation from a
// mechanism that has just started to move and is still slow. With require_decay false the
// speed alone decides (the pulses: a structure rocking to rest after the signal).
class RestDetector {
 public:
  RestDetector(double v_rest, double hold, bool require_decay = true)
      : v_rest_(v_rest), hold_(hold), require_decay_(require_decay) {}
  bool update(double t, double v_max, double kinetic) {
    if (v_max >= v_rest_) {
      window_.clear();
      slow_ = false;
      return false;
    }
    if (!slow_) slow_since_ = t, slow_ = true;
    window_.push_back({t, kinetic});
    const double t0 = window_.front().t;
    if (t - t0 < hold_) return false;
    if (!require_decay_) return true;
    const double mid = t0 + 0.5 * (t - t0);
    double first = 0.0, second = 0.0;
    for (const Sample& s : window_) {
      double& peak = s.t <= mid ? first : second;
      peak = std::max(peak, s.kinetic);
    }
    if (second <= first) return true;
    // Growing: keep watching the second half.
    while (!window_.empty() && window_.front().t <= mid) window_.erase(window_.begin());
    return false;
  }
  // The speed has stayed below v_rest for the hold window up to the last update at t, whatever
  // the kinetic energy did.
  bool slow_for_hold(double t) const { return slow_ && t - slow_since_ >= hold_; }
  // The last update's speed was below v_rest.
  bool slow() const { return slow_; }

 private:
  struct Sample {
    double t, kinetic;
  };
  double v_rest_, hold_;
  bool require_decay_;
  std::vector<Sample> window_;
  bool slow_ = false;
  double slow_since_ = 0.0;  // run time of the first slow sample of the current slow stretch
};

// Creep: a motion that is slow but does not stop. The motion measure m (max(d / d_scale,
// rot / rot_scale) of the free blocks since the start of the run: 1 at the collapse
// criterion) has grown by more than `tolerance` over the last `hold` of run time. A decaying
// motion passes below any tolerance once it has settled; a steady creep (a sliding mechanism
// that a damping force holds back, docs/capacity.md) never does. Samples come in time order;
// with less than `hold` of them the motion counts as creeping (not yet known to have stopped).
class CreepDetector {
 public:
  CreepDetector(double hold, double tolerance) : hold_(hold), tolerance_(tolerance) {}
  void add(double t, double m) {
    history_.push_back({t, m});
    // Keep one sample at or before t - hold (the start of the window).
    while (history_.size() > 2 && history_[1].t <= t - hold_) history_.pop_front();
  }
  // Growth of m over the last hold window (the last sample against the one at or just before
  // its start); infinity while the history is shorter than the window.
  double growth() const {
    if (history_.empty() || history_.back().t - history_.front().t < hold_ * (1.0 - 1e-9))
      return std::numeric_limits<double>::infinity();
    return history_.back().m - history_.front().m;
  }
  bool creeping() const { return !(growth() <= tolerance_); }

 private:
  struct Sample {
    double t, m;
  };
  double hold_, tolerance_;
  std::deque<Sample> history_;
};

}  // namespace voussoir

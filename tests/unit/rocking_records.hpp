#pragma once
// A rigid slender block under earthquake records, voussoir's `pulse` against Housner's rocking
// equation (tests/unit/housner.hpp): the set-up shared by tests/unit/test_rocking_records.cpp
// (the robust scales nearest each threshold) and tests/slow/test_rocking_records_slow.cpp
// (every scale of the scan). docs/rocking.md, "Rocking under records", gives the figures.
//
// Block: 0.25 x 1 m (the scene "block"; b/h = 0.25, alpha = 0.245 rad, p = 3.78 rad/s),
// rho = 2000, rigid, restitution 0 (the joints' full impact damping, docs/rigid.md "Impact
// damping"), joints of kn = 1e12 N/m3 and friction 2. Housner's block stands on a rigid base
// and never slides:
//   - stiff joints: on a Winkler joint a block starts to rock below g b/h, 2.7% below at
//     kn = 1e11 and 1.3% at 1e12 (the closed form of RigidContact.WinklerBlockReachesThe
//     ClosedFormCapacityOfItsContactStrip);
//   - friction above the largest PGA of the scan (1.6 g), so no ground acceleration can slide
//     the block even standing flat; run_rocking measures how far the pivot still moves (at
//     most 0.14 mm in the runs that survive, up to 1.4 mm in falls at 1.5 g).
//
// Impact ratio. Housner's r = 1 - 1.5 sin^2(alpha) = 0.912 is not what these joints give: the
// block released from alpha / 2 keeps 0.946 of its angular velocity at an impact (0.942 from
// alpha / 8; Rigid.RockingBlockImpactConvergesAsTheJointStiffens measures 0.94 at friction
// 0.8). The reference takes the ratio measured on the same block and joints
// (measured_restitution), not Housner's.
//
// Records: three synthetic accelerograms (housner.hpp synthetic_record: Kanai-Tajimi spectra
// of dominant frequency 2, 3.5 and 5 Hz, 10 s at DT = 0.005 s, PGA 0.3 g as written), PEER
// AT2 files read by voussoir through its deck, [load.base] signal = "file", amplitude = the
// PGA in g: the way a user gives a record.
//
// Robustness. Rocking under a long record is chaotic: near a threshold the outcome can flip
// with 1% of the scale or of r. The reference is run at scales S from 0.26 g (just above the
// uplift PGA g tan(alpha) = 0.25 g) to 1.6 g in steps of 3%; S is robust when the equation
// gives one outcome at all nine of S x {0.95, 1, 1.05} and r + {-0.01, 0, +0.01}, and
// dense-robust when it gives it over the whole neighbourhood sampled at 21 x 9 points
// (dense_robust). Also recorded per scale: whether 1% of the scale (S x 0.99, S x 1.01) or
// r +- 0.01 alone flips the outcome, and the outcome at Housner's own r.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "commands/pulse.hpp"
#include "core/rigid.hpp"
#include "engine/setup.hpp"
#include "engine/step.hpp"
#include "housner.hpp"
#include "io/deck.hpp"
#include "seismic/accelerogram.hpp"

namespace voussoir::testing {

inline constexpr double kRockWidth = 0.25, kRockHeight = 1.0;  // [m]
inline constexpr double kRockFriction = 2.0;  // above the largest PGA of the scan [g]
inline constexpr double kFirstScale = 0.26, kLastScale = 1.6, kScaleStep = 1.03;  // [g]

inline HousnerBlock rocking_block() {
  return {0.5 * kRockWidth, 0.5 * kRockHeight, 9.81};
}

// The deck of the block under `record_path` scaled to a PGA of `amplitude` g (0: as written),
// joints of normal stiffness `kn` [N/m3], stepped by `scheme` (solver.scheme; "nscd": rigid
// contacts, kn does not apply).
inline std::string rocking_deck(const std::string& record_path, double amplitude,
                                const std::string& kn = "1e12",
                                const std::string& scheme = "explicit") {
  if (scheme != "explicit")
    return rocking_deck(record_path, amplitude, kn) + "[solver]\nscheme = \"" + scheme + "\"\n";
  char deck[1024];
  std::snprintf(deck, sizeof deck,
                "[model]\nkind = \"block\"\nwidth = %g\nheight = %g\n"
                "[material]\nmodel = \"rigid\"\ndensity = 2000.0\n"
                "[contact]\nfriction = %g\nnormal_stiffness = %s\nrestitution = 0\n"
                "[load.base]\nsignal = \"file\"\nfile = \"%s\"\namplitude = %.17g\n",
                kRockWidth, kRockHeight, kRockFriction, kn.c_str(), record_path.c_str(), amplitude);
  return deck;
}

// The angular velocity the block of `deck` (the rectangle `block`) keeps at an impact:
// released at rest from `tilt_fraction` of its slenderness angle on its left corner, the ratio
// of the angular velocities just after and just before the first impact, each read a tenth of
// the tilt from upright and brought to upright by the free-rocking energy (as Rigid.Rocking
// BlockImpactConvergesAsTheJointStiffens reads them). -1 if no impact within 3 s.
inline double measured_restitution(const std::string& deck, double tilt_fraction,
                                   const HousnerBlock& block = rocking_block()) {
  Simulation sim = make_simulation(parse_deck(deck, "rocking"));
  Model& m = sim.model;
  Index b = 0;
  while (m.blocks[std::size_t(b)].fixed) ++b;
  const double alpha = block.alpha(), p2 = block.p2();
  const double th0 = tilt_fraction * alpha, probe = 0.1 * th0;
  const double px = m.rigid.cx0[b] - block.b, py = m.rigid.cy0[b] - block.h;  // left corner
  const double rx = m.rigid.cx0[b] - px, ry = m.rigid.cy0[b] - py;
  const double c = std::cos(th0), s = std::sin(th0);
  set_rigid_state(m, b, px + c * rx - s * ry, py + s * rx + c * ry, th0, 0.0, 0.0, 0.0);
  auto upright = [&](double th, double om) {  // |omega| at theta = 0 on the same energy
    return std::sqrt(om * om + 2.0 * p2 * (std::cos(alpha - std::abs(th)) - std::cos(alpha)));
  };
  double before = -1.0;
  while (sim.ctx.time < 3.0) {
    advance(sim);
    const double th = m.rigid.theta[b], om = m.rigid.omega[b];
    if (before < 0.0 && th < probe) before = upright(th, om);
    if (before > 0.0 && th < -probe) return upright(th, om) / before;
  }
  return -1.0;
}

struct ScaleResult {
  double scale = 0.0;         // PGA [g]
  HousnerResult nominal;      // at the measured r
  bool robust = false;        // one outcome over S x {0.95, 1, 1.05}, r + {-0.01, 0, 0.01}
  int dense = -1;             // dense_robust: 1 yes, 0 no, -1 not checked
  bool flips_at_1pc = false;  // S x 0.99, S x 1.01, r - 0.01 or r + 0.01 flips it
  bool fell_at_housner_r = false;
  bool ran = false;  // in voussoir
  PulseResult run;
  double max_slip = -1.0;  // [m] run_rocking (-1: not measured)
};

// A ground motion scanned in scale: a record (its AT2 file) or a windowed sine
// (tests/unit/rocking_sines.hpp, which sets the block and the fall rotation of its own).
struct RecordStudy {
  RecordSpec spec;
  std::string path;     // the AT2 file
  GroundRecord record;  // as written
  std::vector<ScaleResult> scales;
  HousnerBlock block = rocking_block();
  double fall_rotation = 1.0;  // [rad] the reference's fall (HousnerOptions::fall_rotation)
};

// The three records, written to `dir` as AT2 files.
inline std::vector<RecordStudy> rocking_records(const std::string& dir) {
  std::vector<RecordStudy> studies(3);
  const double fg[3] = {2.0, 3.5, 5.0};  // [Hz]
  for (std::size_t i = 0; i < 3; ++i) {
    RecordStudy& st = studies[i];
    st.spec.name = std::string(1, 'R') + std::to_string(i + 1);
    st.spec.seed = 20240601 + i;
    st.spec.fg = fg[i];
    st.path = dir + "rocking_" + st.spec.name + ".AT2";
    GroundRecord rec = synthetic_record(st.spec);
    for (double& v : rec.a) v *= 0.3;  // as recorded: a PGA of 0.3 g
    char title[128];
    std::snprintf(title, sizeof title,
                  "voussoir synthetic record %s, Kanai-Tajimi fg %.1f Hz, seed %llu",
                  st.spec.name.c_str(), st.spec.fg, (unsigned long long)st.spec.seed);
    st.record = write_at2(rec, title, st.path);
  }
  return studies;
}

// The reference's options for a study at impact ratio r.
inline HousnerOptions study_options(const RecordStudy& st, double r) {
  HousnerOptions opt;
  opt.restitution = r;
  opt.fall_rotation = st.fall_rotation;
  return opt;
}

inline bool housner_falls(const RecordStudy& st, double scale, double r) {
  return housner_response(st.block, st.record, scale, study_options(st, r)).fell;
}

// The reference over the scan (header comment) from `first` to `last` [g] in steps of
// kScaleStep, at impact ratio r.
inline void scan_reference(RecordStudy& st, double r, double first = kFirstScale,
                           double last = kLastScale) {
  const double r_housner = st.block.housner_restitution();
  for (double s = first; s <= last * 1.0001; s *= kScaleStep) {
    ScaleResult x;
    x.scale = s;
    x.nominal = housner_response(st.block, st.record, s, study_options(st, r));
    const bool fell = x.nominal.fell;
    x.robust = true;
    for (double f : {0.95, 1.0, 1.05})
      for (double dr : {-0.01, 0.0, 0.01})
        if ((f != 1.0 || dr != 0.0) && housner_falls(st, s * f, r + dr) != fell) x.robust = false;
    x.flips_at_1pc =
        housner_falls(st, 0.99 * s, r) != fell || housner_falls(st, 1.01 * s, r) != fell ||
        housner_falls(st, s, r - 0.01) != fell || housner_falls(st, s, r + 0.01) != fell;
    x.fell_at_housner_r = housner_falls(st, s, r_housner);
    st.scales.push_back(x);
  }
}

// One outcome over the whole neighbourhood, sampled densely: S x (0.95, 0.955, ..., 1.05) and
// r + (-0.01, -0.0075, ..., 0.01), 21 x 9 points. The nine points of `robust` miss what lies
// between them: in the fall-dominated range the reference's survivals are scattered islands a
// step of 0.5% or of 0.0025 in r wide (docs/rocking.md), and a scale robust at nine points can
// hold one in its neighbourhood.
inline bool dense_robust(const RecordStudy& st, double scale, double r, bool fell) {
  for (int j = -4; j <= 4; ++j)
    for (int i = -10; i <= 10; ++i)
      if (housner_falls(st, scale * (1.0 + 0.005 * i), r + 0.0025 * j) != fell) return false;
  return true;
}

// The same block in voussoir (`pulse` from one settled state) at `scale` g of the record.
// `max_slip` (optional): the largest horizontal displacement [m] of the lower base corner from
// its settled place while the block is within alpha of upright, sampled every millisecond (a
// block that rocks about corners that do not slide keeps it at the joint's compliance).
inline PulseResult run_rocking(const SettledState& settled, const RecordStudy& st, double scale,
                               const std::string& kn = "1e12", double* max_slip = nullptr,
                               const std::string& scheme = "explicit") {
  const Config config = parse_deck(rocking_deck(st.path, scale, kn, scheme), "rocking");
  const BaseSignal signal = make_base_signal(config.load.base, config.load.gravity);
  EXPECT_NEAR(signal.peak_acceleration(), scale * config.load.gravity, 1e-9 * config.load.gravity);
  const PulseCriteria crit;
  const RigidBodies& r0 = settled.sim.model.rigid;
  Index b = 0;
  while (settled.sim.model.blocks[std::size_t(b)].fixed) ++b;
  const HousnerBlock block = rocking_block();
  // Base corner k (-1 left, +1 right) of a body at (cx, cy, theta).
  auto corner = [&](double cx, double cy, double th, double k, double& x, double& y) {
    x = cx + std::cos(th) * k * block.b + std::sin(th) * block.h;
    y = cy + std::sin(th) * k * block.b - std::cos(th) * block.h;
  };
  double x0[2], y0[2];
  for (int k = 0; k < 2; ++k) corner(r0.cx[b], r0.cy[b], r0.theta[b], 2 * k - 1, x0[k], y0[k]);
  double slip = 0.0;
  const PulseRecorder recorder = [&](const Simulation& s, const PulseSample&) {
    const RigidBodies& r = s.model.rigid;
    if (std::abs(r.theta[b] - r0.theta[b]) >= block.alpha()) return;
    double x[2], y[2];
    for (int k = 0; k < 2; ++k) corner(r.cx[b], r.cy[b], r.theta[b], 2 * k - 1, x[k], y[k]);
    const int low = y[0] < y[1] ? 0 : 1;
    slip = std::max(slip, std::abs(x[low] - x0[low]));
  };
  PulseResult out =
      run_pulse(settled, signal, 0.0, find_control_points(settled.sim.model), crit, recorder);
  if (max_slip) *max_slip = slip;
  return out;
}

// The scan as one character a scale: S / F robust survival / fall, s / f not robust.
inline std::string outcome_map(const RecordStudy& st) {
  std::string line;
  for (const ScaleResult& x : st.scales)
    line += x.robust ? (x.nominal.fell ? 'F' : 'S') : (x.nominal.fell ? 'f' : 's');
  return line;
}

// The chaos figures of a record: the share of scales not robust, over the scan and over its
// transition band (from the lowest scale that falls or is not robust to the highest that
// survives or is not robust), the share flipped by 1% of the scale or by r +- 0.01 alone, the
// number of changes of outcome along the band in steps of 0.5% (at the nominal r), how many
// robust outcomes Housner's own r would change, and how many robust scales dense_robust
// checked and passed.
inline void print_chaos(const RecordStudy& st, double r) {
  int robust = 0, flips = 0, band = 0, band_robust = 0, band_flips = 0, housner_r = 0;
  int checked = 0, dense = 0;
  double lo = 1e9, hi = 0.0;
  for (const ScaleResult& x : st.scales) {
    robust += x.robust, flips += x.flips_at_1pc;
    housner_r += x.robust && x.fell_at_housner_r != x.nominal.fell;
    checked += x.dense >= 0, dense += x.dense == 1;
    if (x.nominal.fell || !x.robust) lo = std::min(lo, x.scale);
    if (!x.nominal.fell || !x.robust) hi = std::max(hi, x.scale);
  }
  for (const ScaleResult& x : st.scales)
    if (x.scale >= lo && x.scale <= hi)
      ++band, band_robust += x.robust, band_flips += x.flips_at_1pc;
  int changes = 0, fine = 0, fine_falls = 0;
  bool last = false;
  for (double s = lo; s <= hi * 1.0001; s *= 1.005, ++fine) {
    const bool f = housner_falls(st, s, r);
    if (fine > 0 && f != last) ++changes;
    fine_falls += f, last = f;
  }
  const int n = int(st.scales.size());
  std::printf("[rocking] %s (fg %.1f Hz) %s\n", st.spec.name.c_str(), st.spec.fg,
              outcome_map(st).c_str());
  std::printf(
      "[rocking] %s: not robust %d of %d scales (%.0f%%), flipped by 1%% or r +- 0.01: "
      "%d (%.0f%%); band %.3f to %.3f g: not robust %d of %d (%.0f%%), flipped %d; at "
      "0.5%% steps the outcome changes %d times in %d scales (%d falls); Housner's r "
      "changes %d robust outcomes; dense-robust %d of %d checked\n",
      st.spec.name.c_str(), n - robust, n, 100.0 * (n - robust) / n, flips, 100.0 * flips / n, lo,
      hi, band - band_robust, band, band > 0 ? 100.0 * (band - band_robust) / band : 0.0,
      band_flips, changes, fine, fine_falls, housner_r, dense, checked);
}

// The voussoir runs as a Markdown table.
inline void print_runs(const std::vector<RecordStudy>& studies) {
  std::printf(
      "| record | PGA [g] | Housner | robust | max rotation / alpha | voussoir | "
      "max rotation / alpha | decided at [s] | pivot slip [mm] | wall [s] |\n"
      "|---|---|---|---|---|---|---|---|---|---|\n");
  for (const RecordStudy& st : studies)
    for (const ScaleResult& x : st.scales) {
      if (!x.ran) continue;
      const double alpha = st.block.alpha();
      char slip[32] = "-";
      if (x.max_slip >= 0.0) std::snprintf(slip, sizeof slip, "%.3f", 1e3 * x.max_slip);
      std::printf("| %s | %.3f | %s | %s | %.3f | %s (%s) | %.3f | %.2f | %s | %.2f |\n",
                  st.spec.name.c_str(), x.scale, x.nominal.fell ? "falls" : "survives",
                  !x.robust      ? "no"
                  : x.dense == 1 ? "dense"
                  : x.dense == 0 ? "9 points"
                                 : "yes",
                  x.nominal.max_rotation / alpha, x.run.collapsed ? "falls" : "survives",
                  x.run.reason.c_str(), x.run.max_rotation / alpha, x.run.decided_at, slip,
                  x.run.wall_s);
    }
}

// The scans from `first` to `last` [g] (a line each, print_chaos) and the runs (print_runs).
inline void print_scans(const std::vector<RecordStudy>& studies, double r, double first,
                        double last) {
  std::printf(
      "[rocking] scan %.2f to %.2f g in steps of %.0f%%; S / F robust survival / fall, "
      "s / f not robust\n",
      first, last, 100.0 * (kScaleStep - 1.0));
  for (const RecordStudy& st : studies) print_chaos(st, r);
  print_runs(studies);
}

}  // namespace voussoir::testing

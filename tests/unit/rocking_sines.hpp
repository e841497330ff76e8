#pragma once
// A rigid slender block under windowed sines, voussoir's `pulse` against Housner's rocking
// equation (tests/unit/housner.hpp): the set-up shared by tests/unit/test_rocking_sines.cpp
// (the robust amplitudes nearest each change of outcome) and tests/slow/
// test_rocking_sines_slow.cpp (every amplitude of the scan, both schemes). docs/validation.md
// section 5 gives the figures.
//
// Block: 0.2 x 1 m (the scene "block"; b/h = 0.2, alpha = 0.197 rad, p = 3.79 rad/s), rho =
// 2000, rigid, restitution 0, joints of kn = 1e12 N/m3 (the explicit scheme; non-smooth
// contact dynamics has no joint stiffness) and friction 3, above the largest peak of the scan
// (2.7 g), so the block rocks and never slides, as Housner's block on its rigid base.
//
// Signal: `[load.base] signal = "windowed_sine"`, three cycles (the deck default) at 1, 1.5, 2
// and 3 Hz, a_g = A w(2t/T - 1) sin(2 pi f t) (seismic/base_motion.hpp), whose peak is 0.891 A.
// The reference reads the same function sampled 200 times a cycle, linear between samples (at
// 400 a cycle and four times the steps no robust outcome changes: the test checks it). An
// amplitude is named by its peak (PGA) S, as a record's scale is, and voussoir is given
// A = S / (the sampled signal's peak).
//
// Fall. voussoir's `pulse` calls a fall when a centroid moves by L_ref = sqrt(w h) = 0.447 m
// or a block turns by 1 rad (PulseCriteria); a block rocking about a base corner (distance R
// from its centroid) moves its centroid by 2 R sin(theta / 2), which reaches L_ref at theta =
// 0.908 rad: the reference's fall rotation.
//
// Impact ratio, scan and robustness as for the records (rocking_records.hpp): the reference
// takes the ratio measured on the same block and scheme; PGAs from 0.21 g (just above the
// uplift at g tan(alpha) = 0.2 g) to 2.7 g in steps of 3%, 86 a frequency; robust and
// dense-robust as there. Under a pulse the outcome changes several times along the scan (falls
// after an impact, a band of survival above them, falls again: Zhang & Makris 2001), so the
// points are taken at every change of outcome, not at one threshold.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "rocking_records.hpp"
#include "seismic/base_motion.hpp"

namespace voussoir::testing {

inline constexpr double kSineWidth = 0.2, kSineHeight = 1.0;  // [m]
inline constexpr double kSineFriction = 3.0;  // above the largest PGA of the scan [g]
inline constexpr int kSineCycles = 3;
inline constexpr int kSineSamples = 200;                     // a cycle, in the reference
inline constexpr double kSineFirst = 0.21, kSineLast = 2.7;  // PGA [g]
inline const std::vector<double> kSineFrequencies = {1.0, 1.5, 2.0, 3.0};  // [Hz]

inline HousnerBlock sine_block() {
  return {0.5 * kSineWidth, 0.5 * kSineHeight, 9.81};
}

// The rotation at which voussoir's displacement rule calls a fall of the rocking block (header).
inline double sine_fall_rotation() {
  const double l_ref = std::sqrt(kSineWidth * kSineHeight);
  return std::min(1.0, 2.0 * std::asin(l_ref / (2.0 * sine_block().radius())));
}

// The deck of the block stepped by `scheme` ("explicit" or "nscd"). The runs give it the
// windowed sine (run_sine) as `[load.base] signal = "windowed_sine"` with `frequency` and
// `amplitude` A would.
inline std::string sine_deck(const std::string& scheme) {
  char deck[512];
  std::snprintf(deck, sizeof deck,
                "[model]\nkind = \"block\"\nwidth = %g\nheight = %g\n"
                "[material]\nmodel = \"rigid\"\ndensity = 2000.0\n"
                "[contact]\nfriction = %g\nnormal_stiffness = 1e12\nrestitution = 0\n"
                "[solver]\nscheme = \"%s\"\n",
                kSineWidth, kSineHeight, kSineFriction, scheme.c_str());
  return deck;
}

// The windowed sine of unit amplitude at `frequency`, sampled `per_cycle` times a cycle.
inline GroundRecord sampled_sine(double frequency, int per_cycle = kSineSamples) {
  GroundRecord r;
  r.dt = 1.0 / (frequency * per_cycle);
  r.a.resize(std::size_t(kSineCycles * per_cycle + 1));
  for (std::size_t i = 0; i < r.a.size(); ++i)
    r.a[i] = windowed_sine(double(i) * r.dt, 1.0, frequency, kSineCycles);
  return r;
}

// One study a frequency, its reference scanned at impact ratio r.
inline std::vector<RecordStudy> sine_studies(double r) {
  std::vector<RecordStudy> out;
  for (double f : kSineFrequencies) {
    RecordStudy st;
    char name[32];
    std::snprintf(name, sizeof name, "%g Hz", f);
    st.spec.name = name;
    st.spec.fg = f;
    st.record = sampled_sine(f);
    st.block = sine_block();
    st.fall_rotation = sine_fall_rotation();
    scan_reference(st, r, kSineFirst, kSineLast);
    out.push_back(st);
  }
  return out;
}

// The robust outcomes of the reference that 400 samples a cycle and 40 steps a sample change
// (the reference converged: none).
inline int sine_reference_unconverged(const std::vector<RecordStudy>& studies, double r) {
  int changed = 0;
  for (const RecordStudy& st : studies) {
    const GroundRecord fine_record = sampled_sine(st.spec.fg, 2 * kSineSamples);
    HousnerOptions fine = study_options(st, r);
    fine.substeps = 40;
    for (const ScaleResult& x : st.scales)
      changed +=
          x.robust && housner_response(st.block, fine_record, x.scale, fine).fell != x.nominal.fell;
  }
  return changed;
}

// The block of `scheme` settled, from which every run of the scheme starts.
inline SettledState settled_sine_block(const std::string& scheme) {
  return settle(parse_deck(sine_deck(scheme), "rocking sine"), PulseCriteria{}.settle, true);
}

// The block in voussoir under the windowed sine of study `st` at PGA `scale` [g].
inline PulseResult run_sine(const SettledState& settled, const RecordStudy& st, double scale) {
  const double amplitude = scale / st.record.peak() * settled.gravity;  // A [m/s2]
  const BaseSignal signal = BaseSignal::windowed(amplitude, st.spec.fg, kSineCycles);
  return run_pulse(settled, signal, 0.0, find_control_points(settled.sim.model), PulseCriteria{});
}

// The scales nearest every change of outcome along the scan (at the nominal r): on each side
// of a change, the first scale of that side's outcome, walking away from the change without
// crossing another, that is dense-robust (rocking_records.hpp). Marks each scale checked in
// ScaleResult::dense; returns the indices, ascending, each once.
inline std::vector<std::size_t> scales_nearest_changes(RecordStudy& st, double r) {
  std::vector<char> pick(st.scales.size(), 0);
  auto dense = [&](std::size_t i) {
    ScaleResult& x = st.scales[i];
    if (x.dense < 0) x.dense = x.robust && dense_robust(st, x.scale, r, x.nominal.fell);
    return x.dense == 1;
  };
  const long n = long(st.scales.size());
  for (long i = 0; i + 1 < n; ++i) {
    const bool below = st.scales[std::size_t(i)].nominal.fell;
    if (st.scales[std::size_t(i + 1)].nominal.fell == below) continue;
    for (long k = i; k >= 0 && st.scales[std::size_t(k)].nominal.fell == below; --k)
      if (dense(std::size_t(k))) {
        pick[std::size_t(k)] = 1;
        break;
      }
    for (long k = i + 1; k < n && st.scales[std::size_t(k)].nominal.fell != below; ++k)
      if (dense(std::size_t(k))) {
        pick[std::size_t(k)] = 1;
        break;
      }
  }
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < pick.size(); ++i)
    if (pick[i]) out.push_back(i);
  return out;
}

// The block of `scheme` against the reference at the scales nearest every change of outcome
// (scales_nearest_changes), at the impact ratio measured on the block of that scheme: each
// must give the reference's outcome, with the energy ledger within 1%. Prints the impact
// ratio, the scans, the runs and their count; returns the studies, their runs marked.
inline std::vector<RecordStudy> check_sines_near_changes(const std::string& scheme) {
  const auto wall0 = std::chrono::steady_clock::now();
  const std::string deck = sine_deck(scheme);
  const double r = measured_restitution(deck, 0.5, sine_block());
  std::printf(
      "[sines] %s: impact ratio %.4f (from alpha / 2), %.4f (from alpha / 8); "
      "Housner's %.4f; fall at %.3f rad\n",
      scheme.c_str(), r, measured_restitution(deck, 0.125, sine_block()),
      sine_block().housner_restitution(), sine_fall_rotation());
  EXPECT_GT(r, 0.9);
  EXPECT_LT(r, 0.99);
  std::vector<RecordStudy> studies = sine_studies(r);
  EXPECT_EQ(sine_reference_unconverged(studies, r), 0);

  const SettledState settled = settled_sine_block(scheme);
  EXPECT_TRUE(settled.settled);
  int runs = 0, agree = 0;
  for (RecordStudy& st : studies) {
    int falls = 0, survivals = 0;
    for (std::size_t i : scales_nearest_changes(st, r)) {
      ScaleResult& x = st.scales[i];
      x.run = run_sine(settled, st, x.scale);
      x.ran = true;
      const bool fell = x.nominal.fell;
      ++runs, agree += x.run.collapsed == fell;
      (fell ? falls : survivals) += 1;
      EXPECT_EQ(x.run.collapsed, fell)
          << scheme << ", " << st.spec.name << " at a PGA of " << x.scale << " g: Housner "
          << (fell ? "falls" : "survives") << " (largest rotation " << x.nominal.max_rotation
          << " rad), voussoir " << x.run.reason << " (largest rotation " << x.run.max_rotation
          << " rad)";
      EXPECT_LT(x.run.max_energy_balance_error, 0.01) << st.spec.name << " at " << x.scale;
    }
    // Every frequency has its falls and its survivals near a change.
    EXPECT_GT(falls, 0) << st.spec.name;
    EXPECT_GT(survivals, 0) << st.spec.name;
  }
  print_scans(studies, r, kSineFirst, kSineLast);
  std::printf(
      "[sines] %s: voussoir agrees at %d of %d dense-robust scales nearest the changes "
      "of outcome; %.1f s of wall\n",
      scheme.c_str(), agree, runs,
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count());
  return studies;
}

}  // namespace voussoir::testing

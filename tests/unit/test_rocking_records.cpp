// A rigid slender block under earthquake records: voussoir's `pulse` against Housner's rocking
// equation integrated beside the test, at the scales where that equation's outcome is robust
// (set-up, records and robustness: tests/unit/rocking_records.hpp; the equation:
// tests/unit/housner.hpp; figures: docs/rigid.md, "Rocking under records").
//
// For each of three records, voussoir runs at the three highest robust survivals and the three
// lowest robust falls of the scan (the robust scales nearest a threshold) and must give the
// reference's outcome: 18 runs, 6 a record, falls and survivals on each. The reference takes
// the impact ratio measured on voussoir's joints (0.9445 at kn = 1e12), not Housner's 0.912.
// The chaos figures (the share of scales whose outcome 5% of the scale or 0.01 of r flips,
// and the changes of outcome along the transition band) are printed, not asserted.
// tests/slow/test_rocking_records_slow.cpp runs every scale of the scan.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "rocking_records.hpp"

namespace voussoir {
namespace {

using namespace voussoir::testing;

constexpr int kPerOutcome = 3;  // robust survivals and falls run in voussoir, per record

// The kPerOutcome highest robust survivals and the kPerOutcome lowest robust falls.
std::vector<std::size_t> chosen_scales(const RecordStudy& st) {
  std::vector<std::size_t> survivals, falls;
  for (std::size_t i = 0; i < st.scales.size(); ++i)
    if (st.scales[i].robust) (st.scales[i].nominal.fell ? falls : survivals).push_back(i);
  std::vector<std::size_t> out;
  for (std::size_t k = 0; k < survivals.size() && k < std::size_t(kPerOutcome); ++k)
    out.push_back(survivals[survivals.size() - 1 - k]);
  for (std::size_t k = 0; k < falls.size() && k < std::size_t(kPerOutcome); ++k)
    out.push_back(falls[k]);
  std::sort(out.begin(), out.end());
  return out;
}

TEST(RockingRecords, SlenderBlockMatchesHousnerWhereHisOutcomeIsRobust) {
  const auto wall0 = std::chrono::steady_clock::now();
  std::vector<RecordStudy> studies = rocking_records(::testing::TempDir());
  const std::string deck0 = rocking_deck(studies[0].path, 0.0);

  // The impact ratio of these joints, used by the reference.
  const double r = measured_restitution(deck0, 0.5);
  std::printf(
      "[rocking] impact ratio of voussoir's joints (kn 1e12, restitution 0) %.4f "
      "(from alpha / 2), %.4f (from alpha / 8); Housner's %.4f\n",
      r, measured_restitution(deck0, 0.125), rocking_block().housner_restitution());
  ASSERT_GT(r, 0.9);
  ASSERT_LT(r, 0.99);

  const auto ref0 = std::chrono::steady_clock::now();
  for (RecordStudy& st : studies) scan_reference(st, r);
  const double ref_wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - ref0).count();

  // The reference converged in its step: at 4 times the steps every robust outcome stays.
  int step_changed = 0, step_changed_robust = 0;
  for (const RecordStudy& st : studies)
    for (const ScaleResult& x : st.scales) {
      HousnerOptions fine;
      fine.restitution = r;
      fine.substeps = 40;
      const bool changed =
          housner_response(rocking_block(), st.record, x.scale, fine).fell != x.nominal.fell;
      step_changed += changed, step_changed_robust += changed && x.robust;
    }
  EXPECT_EQ(step_changed_robust, 0);
  std::printf(
      "[rocking] reference at 40 instead of 10 steps a sample: %d outcomes of %zu "
      "change, %d robust\n",
      step_changed, 3 * studies[0].scales.size(), step_changed_robust);

  const PulseCriteria crit;
  const SettledState settled = settle(parse_deck(deck0, "rocking"), crit.settle, true);
  ASSERT_TRUE(settled.settled);
  double run_wall = 0.0;
  int runs = 0, agree = 0;
  for (RecordStudy& st : studies) {
    int survivals = 0, falls = 0;
    for (std::size_t i : chosen_scales(st)) {
      ScaleResult& x = st.scales[i];
      x.run = run_rocking(settled, st, x.scale);
      x.ran = true;
      run_wall += x.run.wall_s;
      ++runs, agree += x.run.collapsed == x.nominal.fell;
      (x.nominal.fell ? falls : survivals) += 1;
      EXPECT_EQ(x.run.collapsed, x.nominal.fell)
          << st.spec.name << " at " << x.scale << " g: Housner "
          << (x.nominal.fell ? "falls" : "survives") << " (largest rotation "
          << x.nominal.max_rotation << " rad), voussoir " << x.run.reason << " (largest rotation "
          << x.run.max_rotation << " rad)";
      EXPECT_LT(x.run.max_energy_balance_error, 0.01) << st.spec.name << " at " << x.scale;
    }
    EXPECT_EQ(survivals, kPerOutcome) << st.spec.name << ": robust survivals";
    EXPECT_EQ(falls, kPerOutcome) << st.spec.name << ": robust falls";
  }

  std::printf(
      "[rocking] scan %.2f to %.2f g in steps of %.0f%%; S / F robust survival / fall, "
      "s / f not robust\n",
      kFirstScale, kLastScale, 100.0 * (kScaleStep - 1.0));
  for (const RecordStudy& st : studies) print_chaos(st, r);
  print_runs(studies);
  std::printf(
      "[rocking] voussoir agrees at %d of %d robust scales; reference scans %.1f s, "
      "voussoir runs %.1f s, in all %.1f s of wall\n",
      agree, runs, ref_wall, run_wall,
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count());
}

}  // namespace
}  // namespace voussoir

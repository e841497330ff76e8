// The rigid slender block under three records (tests/unit/rocking_records.hpp) at every scale
// of the scan, 0.26 to 1.6 g in steps of 3% (62 a record): voussoir's `pulse` must give
// Housner's outcome at every dense-robust scale (dense_robust: one outcome over the whole
// neighbourhood, 5% of the scale and 0.01 of r); at the others the agreement is printed: at
// the scales robust at the nine points only, whose neighbourhood holds islands of the other
// outcome, and at the rest, where the reference itself flips within that neighbourhood.
// Then the same at joints ten times softer (kn = 1e11 N/m3, with the impact ratio measured
// on them), printed only. docs/rocking.md, "Rocking under records", gives the figures.
// Label "slow": about 90 s on one core.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "../unit/rocking_records.hpp"

namespace voussoir {
namespace {

using namespace voussoir::testing;

struct Agreement {
  int dense = 0, dense_agree = 0, nine = 0, nine_agree = 0, other = 0, other_agree = 0;
  double wall = 0.0;
};

Agreement run_every_scale(std::vector<RecordStudy>& studies, const std::string& kn,
                          bool assert_dense) {
  const std::string deck0 = rocking_deck(studies[0].path, 0.0, kn);
  const double r = measured_restitution(deck0, 0.5);
  std::printf("[rocking] kn %s: impact ratio %.4f (Housner's %.4f)\n", kn.c_str(), r,
              rocking_block().housner_restitution());
  for (RecordStudy& st : studies) {
    st.scales.clear();
    scan_reference(st, r);
  }
  const PulseCriteria crit;
  const SettledState settled = settle(parse_deck(deck0, "rocking"), crit.settle, true);
  EXPECT_TRUE(settled.settled);
  Agreement a;
  for (RecordStudy& st : studies)
    for (ScaleResult& x : st.scales) {
      if (x.robust) x.dense = dense_robust(st, x.scale, r, x.nominal.fell);
      x.run = run_rocking(settled, st, x.scale, kn, &x.max_slip);
      x.ran = true;
      a.wall += x.run.wall_s;
      const bool same = x.run.collapsed == x.nominal.fell;
      if (x.dense == 1) {
        ++a.dense, a.dense_agree += same;
        if (assert_dense) {
          EXPECT_TRUE(same) << st.spec.name << " at " << x.scale << " g: Housner "
                            << (x.nominal.fell ? "falls" : "survives") << ", voussoir "
                            << x.run.reason;
        }
      } else if (x.robust) {
        ++a.nine, a.nine_agree += same;
      } else {
        ++a.other, a.other_agree += same;
      }
      EXPECT_LT(x.run.max_energy_balance_error, 0.01) << st.spec.name << " at " << x.scale;
    }
  for (const RecordStudy& st : studies) {
    print_chaos(st, r);
    std::string line;  // voussoir's outcome a scale: F falls, S survives
    for (const ScaleResult& x : st.scales) line += x.run.collapsed ? 'F' : 'S';
    std::printf("[rocking] %s voussoir    %s\n", st.spec.name.c_str(), line.c_str());
  }
  print_runs(studies);
  std::printf(
      "[rocking] kn %s: voussoir agrees at %d of %d dense-robust scales, at %d of %d robust "
      "at nine points only, at %d of %d others; %.1f s of runs\n",
      kn.c_str(), a.dense_agree, a.dense, a.nine_agree, a.nine, a.other_agree, a.other, a.wall);
  return a;
}

TEST(RockingRecordsSlow, EveryScaleOfTheScan) {
  std::vector<RecordStudy> studies = rocking_records(::testing::TempDir());
  const Agreement stiff = run_every_scale(studies, "1e12", true);
  EXPECT_EQ(stiff.dense_agree, stiff.dense);
  EXPECT_GE(stiff.dense, 30);
  run_every_scale(studies, "1e11", false);
}

}  // namespace
}  // namespace voussoir

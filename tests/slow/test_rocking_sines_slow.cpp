// The rigid slender block (0.2 x 1 m) under windowed sines against Housner's equation, by both
// schemes (set-up: tests/unit/rocking_sines.hpp; the default suite runs non-smooth contact
// dynamics at the scales nearest each change of outcome, tests/unit/test_rocking_sines.cpp):
//   - the explicit scheme (rigid blocks on joints of kn = 1e12 N/m3) at those scales;
//   - both schemes at every scale of the scan, each against the reference at the impact ratio
//     measured on its own block: each agrees at every dense-robust scale, and non-smooth contact
//     dynamics wherever the explicit scheme agrees and its own reference is dense-robust. The
//     tallies (dense-robust, robust at the nine points only, not robust) and the scales where
//     the explicit scheme agrees and nscd does not are printed (docs/validation.md section 5).
// Label `slow` (scripts/test --all): about 2 minutes of CPU (4 of wall on the shared 2 cores).

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "../unit/rocking_sines.hpp"

namespace voussoir {
namespace {

using namespace voussoir::testing;

TEST(RockingSinesSlow, ExplicitSchemeMatchesHousnerNearEveryChangeOfOutcome) {
  check_sines_near_changes("explicit");
}

// One scheme's runs at every scale of every frequency, against its reference.
struct SchemeScan {
  std::string scheme;
  double r = 0.0;
  std::vector<RecordStudy> studies;
};

SchemeScan scan_scheme(const std::string& scheme) {
  SchemeScan s;
  s.scheme = scheme;
  s.r = measured_restitution(sine_deck(scheme), 0.5, sine_block());
  s.studies = sine_studies(s.r);
  const SettledState settled = settled_sine_block(scheme);
  EXPECT_TRUE(settled.settled) << scheme;
  for (RecordStudy& st : s.studies)
    for (ScaleResult& x : st.scales) {
      if (x.robust) x.dense = dense_robust(st, x.scale, s.r, x.nominal.fell);
      x.run = run_sine(settled, st, x.scale);
      x.ran = true;
      EXPECT_LT(x.run.max_energy_balance_error, 0.01) << scheme << " " << st.spec.name;
      if (x.dense == 1) {
        EXPECT_EQ(x.run.collapsed, x.nominal.fell)
            << scheme << ", " << st.spec.name << " at a PGA of " << x.scale << " g: Housner "
            << (x.nominal.fell ? "falls" : "survives") << ", voussoir " << x.run.reason;
      }
    }
  return s;
}

bool agrees(const ScaleResult& x) {
  return x.run.collapsed == x.nominal.fell;
}

// A scale's reference as a character: S / F dense-robust survival / fall, s / f otherwise.
char reference_char(const ScaleResult& x) {
  return x.dense == 1 ? (x.nominal.fell ? 'F' : 'S') : (x.nominal.fell ? 'f' : 's');
}

// Agreements with the reference: dense-robust, robust at the nine points only, not robust.
void print_tally(const SchemeScan& s) {
  int agree[3] = {0, 0, 0}, total[3] = {0, 0, 0};
  for (const RecordStudy& st : s.studies)
    for (const ScaleResult& x : st.scales) {
      const int k = !x.robust ? 2 : x.dense == 1 ? 0 : 1;
      ++total[k], agree[k] += agrees(x);
    }
  std::printf(
      "[sines] %s (r = %.4f): agrees at %d of %d dense-robust scales, %d of %d robust at "
      "nine points only, %d of %d not robust\n",
      s.scheme.c_str(), s.r, agree[0], total[0], agree[1], total[1], agree[2], total[2]);
}

// Each scheme agrees with its reference at every dense-robust scale (scan_scheme); wherever the
// explicit scheme agrees with its reference and nscd's is dense-robust, nscd agrees. Printed:
// the scans, the tallies, and every scale where the explicit scheme agrees and nscd does not.
TEST(RockingSinesSlow, NonSmoothContactDynamicsAgreesWhereverTheExplicitSchemeDoes) {
  const auto wall0 = std::chrono::steady_clock::now();
  const SchemeScan ex = scan_scheme("explicit");
  const SchemeScan ns = scan_scheme("nscd");
  int scales = 0, explicit_agrees = 0, both_agree = 0;
  for (std::size_t f = 0; f < ex.studies.size(); ++f) {
    const RecordStudy &a = ex.studies[f], &b = ns.studies[f];
    ASSERT_EQ(a.scales.size(), b.scales.size());
    std::string ref_a, run_a, ref_b, run_b;
    for (std::size_t i = 0; i < a.scales.size(); ++i) {
      const ScaleResult &x = a.scales[i], &y = b.scales[i];
      ref_a += reference_char(x), ref_b += reference_char(y);
      run_a += x.run.collapsed ? 'F' : 'S', run_b += y.run.collapsed ? 'F' : 'S';
      ++scales;
      if (!agrees(x)) continue;
      ++explicit_agrees, both_agree += agrees(y);
      if (y.dense == 1) {
        EXPECT_TRUE(agrees(y)) << a.spec.name << " at a PGA of " << x.scale
                               << " g: the explicit scheme agrees with Housner, nscd does not";
      } else if (!agrees(y)) {
        std::printf(
            "[sines] %s at %.3f g: the explicit scheme agrees with Housner (%s, %s), "
            "nscd %s against Housner at its r (%s, %s)\n",
            a.spec.name.c_str(), x.scale, x.nominal.fell ? "falls" : "survives",
            x.robust ? "robust" : "not robust", y.run.collapsed ? "falls" : "survives",
            y.nominal.fell ? "falls" : "survives", y.robust ? "robust" : "not robust");
      }
    }
    const std::pair<const char*, const std::string*> lines[4] = {
        {"Housner at explicit's r", &ref_a},
        {"explicit", &run_a},
        {"Housner at nscd's r", &ref_b},
        {"nscd", &run_b}};
    for (const auto& [label, line] : lines)
      std::printf("[sines] %-6s %-23s %s\n", a.spec.name.c_str(), label, line->c_str());
  }
  print_tally(ex);
  print_tally(ns);
  std::printf(
      "[sines] the explicit scheme agrees with Housner at %d of %d scales, nscd at %d of "
      "those; %.0f s of wall\n",
      explicit_agrees, scales, both_agree,
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count());
  EXPECT_GT(explicit_agrees, 0);
}

}  // namespace
}  // namespace voussoir

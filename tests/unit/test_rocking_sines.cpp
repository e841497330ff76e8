// A rigid slender block (0.2 x 1 m) under three-cycle windowed sines at 1, 1.5, 2 and 3 Hz,
// stepped by non-smooth contact dynamics (solver.scheme = "nscd"), against Housner's rocking
// equation integrated beside the test (set-up: tests/unit/rocking_sines.hpp). At every change
// of outcome along the reference's scan of the peak acceleration, the nearest dense-robust
// scale on each side must give the reference's outcome. tests/slow/test_rocking_sines_slow.cpp
// runs the explicit scheme at the same scales, and both schemes at every scale of the scan.

#include <gtest/gtest.h>

#include "rocking_sines.hpp"

namespace voussoir {
namespace {

TEST(RockingSines, NonSmoothContactDynamicsMatchesHousnerNearEveryChangeOfOutcome) {
  testing::check_sines_near_changes("nscd");
}

}  // namespace
}  // namespace voussoir

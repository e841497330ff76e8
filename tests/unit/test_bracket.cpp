// The bracketing search of capacity and the pulse curve (drivers/bracket.hpp).

#include <gtest/gtest.h>

#include <vector>

#include "drivers/bracket.hpp"

namespace voussoir {
namespace {

TEST(Bracket, KSectionAndBisectionCloseOnAThreshold) {
  // A monotone response with threshold 0.3: both placements keep 0.3 inside the bracket and
  // stop once hi - lo <= tolerance x hi; k-section runs `points` probes per round.
  for (const ProbePlacement placement : {ProbePlacement::KSection, ProbePlacement::Midpoint}) {
    Bracket b{0.0, 1.0};
    int rounds = 0;
    const int probes = shrink_bracket(
        b, 0.01, 3, placement,
        [](const std::vector<double>& xs) {
          std::vector<bool> crossed;
          for (double x : xs) crossed.push_back(x > 0.3);
          return crossed;
        },
        [&](const Bracket&) { ++rounds; });
    EXPECT_LE(b.lo, 0.3);
    EXPECT_GT(b.hi, 0.3);
    EXPECT_LE(b.hi - b.lo, 0.01 * b.hi);
    EXPECT_EQ(probes, rounds * (placement == ProbePlacement::KSection ? 3 : 1));
  }
}

TEST(Bracket, ProbesAndNonMonotoneRounds) {
  const Bracket b{1.0, 2.0};
  EXPECT_EQ(bracket_probes(b, 3, ProbePlacement::KSection), (std::vector<double>{1.25, 1.5, 1.75}));
  EXPECT_EQ(bracket_probes(b, 3, ProbePlacement::Midpoint), (std::vector<double>{1.5}));
  // Crossed at 1.5, not at 1.75 (non-monotone): hi = 1.5, and 1.75 does not raise lo.
  Bracket n = b;
  EXPECT_TRUE(narrow_bracket(n, {1.25, 1.5, 1.75}, {false, true, false}));
  EXPECT_EQ(n.lo, 1.25);
  EXPECT_EQ(n.hi, 1.5);
}

}  // namespace
}  // namespace voussoir

// The bracketing search of capacity and the pulse curve (engine/bracket.hpp).

#include <gtest/gtest.h>

#include <limits>
#include <map>
#include <vector>

#include "engine/bracket.hpp"

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

// Ahead of a round's outcomes: once they are known, the first probes ahead are exactly the next
// round's (as a set, highest first); while one is pending it is guessed by the middle of the
// bracket, or by a known outcome it cannot contradict in a monotone response.
TEST(Bracket, ProbesAheadFollowTheSearch) {
  const double threshold = 0.37, tol = 0.005;
  Bracket b{0.0, 1.0};
  std::vector<double> probes = bracket_probes(b, 2, ProbePlacement::KSection);
  int rounds = 0;
  while (b.hi - b.lo > tol * b.hi) {
    std::vector<bool> crossed;
    std::vector<Outcome3> known;
    for (double p : probes) {
      crossed.push_back(p > threshold);
      known.push_back(p > threshold ? Outcome3::Crossed : Outcome3::NotCrossed);
    }
    const std::vector<double> ahead =
        probes_ahead(b, probes, known, tol, 2, ProbePlacement::KSection, 2);
    Bracket next = b;
    narrow_bracket(next, probes, crossed);
    if (!(next.hi - next.lo > tol * next.hi)) {
      EXPECT_TRUE(ahead.empty());  // the search stops: nothing to run ahead
    } else {
      const std::vector<double> want = bracket_probes(next, 2, ProbePlacement::KSection);
      ASSERT_GE(ahead.size(), 2u);
      EXPECT_EQ(ahead[0], want[1]);
      EXPECT_EQ(ahead[1], want[0]);
    }
    b = next;
    probes = bracket_probes(b, 2, ProbePlacement::KSection);
    ++rounds;
  }
  EXPECT_GT(rounds, 3);

  // Pending outcomes on [0, 3] with probes 1 and 2.
  const Bracket c{0.0, 3.0};
  const std::vector<double> p12{1.0, 2.0};
  using O = Outcome3;
  auto first_round = [&](std::vector<O> known) {
    return probes_ahead(c, p12, known, 1e-3, 2, ProbePlacement::KSection, 1);
  };
  auto highest_first = [](const Bracket& x) {
    std::vector<double> p = bracket_probes(x, 2, ProbePlacement::KSection);
    return std::vector<double>{p[1], p[0]};
  };
  // Nothing known: 1 below the middle stands, 2 above it collapses -> [1, 2].
  EXPECT_EQ(first_round({O::Unknown, O::Unknown}), highest_first({1.0, 2.0}));
  // 1 collapsed: 2 is ignored -> [0, 1].
  EXPECT_EQ(first_round({O::Crossed, O::Unknown}), highest_first({0.0, 1.0}));
  // 2 stood: 1 stands too -> [2, 3].
  EXPECT_EQ(first_round({O::Unknown, O::NotCrossed}), highest_first({2.0, 3.0}));
  // A guess of the threshold below both probes: both collapse -> [0, 1].
  EXPECT_EQ(probes_ahead(c, p12, {O::Unknown, O::Unknown}, 1e-3, 2, ProbePlacement::KSection, 1,
                         0.5),
            highest_first({0.0, 1.0}));
  // Two rounds ahead: the second guessed the same way inside [1, 2].
  const std::vector<double> two =
      probes_ahead(c, p12, {O::Unknown, O::Unknown}, 1e-3, 2, ProbePlacement::KSection, 2);
  ASSERT_EQ(two.size(), 4u);
  const std::vector<double> in12 = bracket_probes({1.0, 2.0}, 2, ProbePlacement::KSection);
  const std::vector<double> second = highest_first({in12[0], in12[1]});
  EXPECT_EQ(two[2], second[0]);
  EXPECT_EQ(two[3], second[1]);

  // Trials that have ended elsewhere (run ahead) are taken as they ended: a collapse at 0.5
  // makes both pending probes collapse -> [0, 1], against [1, 2] guessed from the middle.
  EXPECT_EQ(probes_ahead(c, p12, {O::Unknown, O::Unknown}, 1e-3, 2, ProbePlacement::KSection, 1,
                         std::numeric_limits<double>::quiet_NaN(), {{0.5, true}}),
            highest_first({0.0, 1.0}));
  // ... and so are the next round's probes: with 1 and 2 known, [1, 2] is next; both its
  // probes collapsed, so the round after it is inside [1, in12[0]] (guessed from the middle,
  // it would be inside [in12[0], in12[1]]).
  const std::map<double, bool> ran{{in12[0], true}, {in12[1], true}};
  const std::vector<double> three =
      probes_ahead(c, p12, {O::NotCrossed, O::Crossed}, 1e-3, 2, ProbePlacement::KSection, 2,
                   std::numeric_limits<double>::quiet_NaN(), ran);
  ASSERT_EQ(three.size(), 4u);
  const std::vector<double> inner = bracket_probes({1.0, in12[0]}, 2, ProbePlacement::KSection);
  EXPECT_EQ(three[2], inner[1]);
  EXPECT_EQ(three[3], inner[0]);
}

}  // namespace
}  // namespace voussoir

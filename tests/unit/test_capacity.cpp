// Capacity by bisection against the analytic rigid-block values (SPEC.md section 3, `block`):
// a block of width/height 0.5 overturns at lambda* = 0.5 when mu > 0.5 and slides at
// lambda* = mu otherwise.

#include <gtest/gtest.h>

#include <string>

#include "drivers/capacity.hpp"
#include "io/deck.hpp"

namespace voussoir {
namespace {

Config block_deck(double mu) {
  const std::string text = R"(
[model]
kind = "block"
width = 0.5
height = 1.0
[contact]
friction = )" + std::to_string(mu) + "\n";
  return parse_deck(text, "block.toml");
}

TEST(Capacity, BlockOverturnsAtWidthOverHeight) {
  const CapacityResult r = find_capacity(block_deck(0.8), TrialCriteria{}, 2, true);
  ASSERT_TRUE(r.bracketed);
  EXPECT_NEAR(r.lambda_star, 0.5, 0.005);
  EXPECT_LE(r.hi - r.lo, 0.005 * r.hi + 1e-12);
  // The mechanism is rotation about the toe: one hinge, no sliding.
  ASSERT_FALSE(r.hinges.empty());
  EXPECT_EQ(r.hinges.front().kind, "hinge");
}

TEST(Capacity, BlockSlidesAtFriction) {
  const CapacityResult r = find_capacity(block_deck(0.3), TrialCriteria{}, 2, true);
  ASSERT_TRUE(r.bracketed);
  EXPECT_NEAR(r.lambda_star, 0.3, 0.003);
  ASSERT_FALSE(r.hinges.empty());
  EXPECT_EQ(r.hinges.front().kind, "sliding");
  // Every trial lies on its side of the final bracket.
  for (const TrialResult& t : r.trials) {
    if (t.lambda <= r.lo) EXPECT_FALSE(t.collapsed) << t.lambda;
    if (t.lambda >= r.hi) EXPECT_TRUE(t.collapsed) << t.lambda;
  }
}

}  // namespace
}  // namespace voussoir

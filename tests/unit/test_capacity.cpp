// Capacity by bisection against the analytic rigid-block values (cases/README.md, `block`):
// a block of width/height 0.5 overturns at lambda* = 0.5 when mu > 0.5 and slides at
// lambda* = mu otherwise.

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "commands/capacity.hpp"
#include "engine/setup.hpp"
#include "io/deck.hpp"
#include "same_search.hpp"

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

// Every trial lies on its side of the final bracket.
void expect_trials_on_their_sides(const CapacityResult& r) {
  for (const TrialResult& t : r.trials) {
    if (t.lambda <= r.lo) {
      EXPECT_FALSE(t.collapsed) << t.lambda;
    }
    if (t.lambda >= r.hi) {
      EXPECT_TRUE(t.collapsed) << t.lambda;
    }
  }
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
  expect_trials_on_their_sides(r);
}

// A block on a ground inclined at 20 degrees with mu = 0.2 < tan 20 = 0.36 slides off under
// gravity alone: the settle stops at the collapse criterion, long before its time limit, and
// the search refuses with the reason (lambda* = 0). With mu = 0.6 the same block comes to rest.
TEST(Capacity, CollapseUnderGravityEndsTheSettleEarly) {
  auto deck = [](double mu) {
    Config c = block_deck(mu);
    c.model.incline = 20.0;
    return c;
  };
  const TrialCriteria crit;
  const SettledState sliding = settle(deck(0.2), crit, true);
  EXPECT_FALSE(sliding.settled);
  EXPECT_TRUE(sliding.collapsed);
  EXPECT_LT(sliding.settle_time, 0.5 * crit.settle_max_time);
  EXPECT_GT(sliding.max_displacement, crit.collapse_displacement * sliding.l_ref);
  try {
    find_capacity(deck(0.2), crit, 2, true);
    FAIL() << "a block sliding under gravity got a capacity";
  } catch (const RunError& e) {
    EXPECT_NE(std::string(e.what()).find("collapses under gravity alone"), std::string::npos)
        << e.what();
  }
  const SettledState resting = settle(deck(0.6), crit, true);
  EXPECT_TRUE(resting.settled);
  EXPECT_FALSE(resting.collapsed);
}

// A capacity run killed after some trials resumes from its journal: the finished trials are
// not run again and the result is the same bit for bit. The kill is imitated by cutting the
// journal after three trials and half of the fourth line.
TEST(Capacity, ResumesFromItsJournal) {
  const CapacitySearch search = journalled_search("capacity_resume.journal");
  const std::string& journal = search.journal;
  const Config config = block_deck(0.3);
  const CapacityResult full = find_capacity(config, TrialCriteria{}, search);
  ASSERT_GE(full.trials.size(), 5u);
  EXPECT_EQ(full.resumed_trials, 0);

  std::vector<std::string> lines;
  {
    std::ifstream in(journal);
    for (std::string l; std::getline(in, l);) lines.push_back(l);
  }
  ASSERT_EQ(lines.size(), full.trials.size() + 1);  // header + one line per trial
  {
    std::ofstream out(journal, std::ios::trunc);
    for (int i = 0; i < 4; ++i) out << lines[i] << '\n';
    out << lines[4].substr(0, lines[4].size() / 2);  // the kill cut this line
  }
  const CapacityResult resumed = find_capacity(config, TrialCriteria{}, search);
  EXPECT_EQ(resumed.resumed_trials, 3);
  EXPECT_EQ(resumed.lambda_star, full.lambda_star);
  EXPECT_EQ(resumed.lo, full.lo);
  EXPECT_EQ(resumed.hi, full.hi);
  ASSERT_EQ(resumed.trials.size(), full.trials.size());
  for (size_t i = 0; i < full.trials.size(); ++i) {
    EXPECT_EQ(resumed.trials[i].lambda, full.trials[i].lambda);
    EXPECT_EQ(resumed.trials[i].collapsed, full.trials[i].collapsed);
    EXPECT_EQ(resumed.trials[i].steps, full.trials[i].steps);
  }
  // A journal of other settings is refused rather than mixed in.
  EXPECT_THROW(find_capacity(block_deck(0.8), TrialCriteria{}, search), RunError);
}

// The limit-analysis seed's ends are presumed, not run, while lambda* lies between them: every
// trial of the default search lies strictly inside [0.92, 1.02] lambda_la. A tolerance that the
// seeded bracket already meets ends the search on both ends: they are then the only trials,
// and they confirm the seed.
TEST(Capacity, SeedEndsAreRunOnlyWhenTheSearchEndsOnThem) {
  const CapacityResult r = find_capacity(block_deck(0.8), TrialCriteria{}, 2, true);
  ASSERT_TRUE(r.seed.used);
  const double s_lo = kSeedLow * r.seed.lambda_la, s_hi = kSeedHigh * r.seed.lambda_la;
  EXPECT_EQ(r.seed.ends_run, 0);
  EXPECT_TRUE(r.seed.held);
  // The settle every trial starts from is reported: its steps at the search's step.
  EXPECT_GT(r.settle_steps, 0);
  EXPECT_NEAR(r.settle_time, static_cast<double>(r.settle_steps) * r.dt, r.dt);
  for (const TrialResult& t : r.trials) {
    EXPECT_GT(t.lambda, s_lo);
    EXPECT_LT(t.lambda, s_hi);
  }

  Config wide = block_deck(0.8);
  wide.capacity.tolerance = 0.5;
  const CapacityResult w = find_capacity(wide, TrialCriteria{}, 2, true);
  EXPECT_EQ(w.seed.ends_run, 2);
  EXPECT_TRUE(w.seed.held);
  ASSERT_EQ(w.trials.size(), 2u);
  EXPECT_EQ(w.lo, s_lo);
  EXPECT_EQ(w.hi, s_hi);
  EXPECT_FALSE(w.trials[0].collapsed);
  EXPECT_TRUE(w.trials[1].collapsed);
}

// Soft joints (kn = 1e6 N/m3) let the block's toe sink under the load, and it overturns at
// lambda* of about 0.044, far below its rigid-block limit analysis (0.5): every probe inside the
// presumed seed collapses, the search ends on the seed's low end, runs it, finds it collapsed,
// and widens down until a trial stands. The final bracket is then made of trials that ran, as
// always. (Springs this soft set a step of 0.07 s: the 22 trials take milliseconds.)
TEST(Capacity, AContradictedSeedWidensFromItsPresumedEnd) {
  const Config soft = parse_deck(R"(
[model]
kind = "block"
width = 0.5
height = 1.0
[material]
model = "rigid"
density = 2000.0
young = 40e9
poisson = 0.2
[contact]
friction = 0.8
normal_stiffness = 1e6
)",
                                 "soft_block.toml");
  TrialCriteria crit;
  crit.quasi_static = true;  // as `capacity` runs it (its physical settle rocks off the toe)
  const CapacityResult r = find_capacity(soft, crit, 2, true);
  ASSERT_TRUE(r.bracketed);
  ASSERT_TRUE(r.seed.used);
  EXPECT_FALSE(r.seed.held);
  EXPECT_EQ(r.seed.ends_run, 1);
  EXPECT_GT(r.seed.widenings, 0);
  EXPECT_LT(r.hi, kSeedLow * r.seed.lambda_la);
  EXPECT_LE(r.hi - r.lo, r.tolerance * r.hi);
  bool lo_ran = false, hi_ran = false;
  for (const TrialResult& t : r.trials) {
    if (t.lambda <= r.lo) {
      EXPECT_FALSE(t.collapsed) << t.lambda;
    }
    if (t.lambda >= r.hi) {
      EXPECT_TRUE(t.collapsed) << t.lambda;
    }
    lo_ran = lo_ran || t.lambda == r.lo;
    hi_ran = hi_ran || t.lambda == r.hi;
  }
  EXPECT_TRUE(lo_ran);
  EXPECT_TRUE(hi_ran);
}

// The block's search (mu 0.8: lambda* 0.5) from the deck's bracket [lo, hi].
CapacityResult from_deck_bracket(double lo, double hi) {
  Config deck = block_deck(0.8);
  deck.capacity.lambda_min = lo;
  deck.capacity.lambda_max = hi;
  return find_capacity(deck, TrialCriteria{}, 2, true);
}

// The deck's bracket (capacity.lambda_min, lambda_max) is run at both ends, side by side: a
// bracket that holds is searched in, one whose lower end collapses widens down from it and one
// whose upper end stands widens up, as a contradicted seed does.
TEST(Capacity, TheDecksBracketIsRunAtBothEnds) {
  const CapacityResult r = from_deck_bracket(0.45, 0.55);
  ASSERT_TRUE(r.bracketed);
  ASSERT_GE(r.trials.size(), 2u);
  EXPECT_EQ(r.trials[0].lambda, 0.45);
  EXPECT_FALSE(r.trials[0].collapsed);
  EXPECT_EQ(r.trials[1].lambda, 0.55);
  EXPECT_TRUE(r.trials[1].collapsed);
  EXPECT_EQ(r.seed.widenings, 0);
  EXPECT_NEAR(r.lambda_star, 0.5, 0.005);

  const CapacityResult w = from_deck_bracket(0.6, 0.7);
  ASSERT_TRUE(w.bracketed);
  EXPECT_EQ(w.trials[0].lambda, 0.6);
  EXPECT_TRUE(w.trials[0].collapsed);
  EXPECT_GT(w.seed.widenings, 0);
  EXPECT_LT(w.hi, 0.6);
  EXPECT_NEAR(w.lambda_star, 0.5, 0.005);
  expect_trials_on_their_sides(w);

  const CapacityResult u = from_deck_bracket(0.3, 0.4);
  ASSERT_TRUE(u.bracketed);
  EXPECT_EQ(u.trials[1].lambda, 0.4);
  EXPECT_FALSE(u.trials[1].collapsed);
  EXPECT_GT(u.seed.widenings, 0);
  EXPECT_GE(u.lo, 0.4);
  EXPECT_NEAR(u.lambda_star, 0.5, 0.005);
  expect_trials_on_their_sides(u);
}

// The settle under gravity does not read the load direction, so `--direction both` settles
// once and both searches start from it: towards -x, the search from a settle shared with +x is
// the search that settles alone, trial for trial and bit for bit.
TEST(Capacity, ASharedSettleGivesTheSameSearch) {
  const Config deck = block_deck(0.8);
  TrialCriteria crit;
  crit.quasi_static = true;
  CapacitySearch shared;
  shared.quiet = true;
  SettledState once = settle(deck, crit, true);
  once.wall_s = -1.0;  // a mark: a search that starts from this settle reports it
  shared.settled = std::make_shared<const SettledState>(std::move(once));
  crit.direction = -1.0;
  CapacitySearch alone;
  alone.quiet = true;
  const CapacityResult a = find_capacity(deck, crit, alone);
  const CapacityResult b = find_capacity(deck, crit, shared);
  ASSERT_TRUE(a.bracketed && b.bracketed);
  EXPECT_EQ(b.settle_wall_s, -1.0);
  EXPECT_GE(a.settle_wall_s, 0.0);
  EXPECT_EQ(a.settle_steps, b.settle_steps);
  expect_same_search(a, b);
}

// The unseeded search replayed with an oracle: geometric growth 0.125, 0.25 | 0.5, 1 brackets
// 0.3 in [0.25, 0.5] after 4 trials, then each round of 2 shrinks the bracket by 3.
TEST(Capacity, UnseededTrialCountReplaysTheSearch) {
  // Width 0.25 -> 0.0833 -> 0.0278 -> 0.00926 -> 0.00309 -> 0.00103 <= 0.005 x hi.
  EXPECT_EQ(unseeded_trial_count(0.3, 0.0, 0.005, 2), 4 + 2 * 5);
  // One point per round is plain bisection: 0.125 | 0.25 | 0.5 then halvings of 0.25.
  EXPECT_EQ(unseeded_trial_count(0.3, 0.0, 0.005, 1), 3 + 8);
}

}  // namespace
}  // namespace voussoir

// The pool of capacity trials (engine/trial_pool.hpp): the search's results whatever ran
// ahead, a wrong guess cancelled, and a search whose trials and bracket do not depend on the
// number of workers.

#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <cstdio>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "commands/capacity.hpp"
#include "engine/trial_pool.hpp"
#include "io/deck.hpp"
#include "same_search.hpp"

namespace voussoir {
namespace {

TrialResult fake(double lambda, double threshold) {
  TrialResult r;
  r.lambda = lambda;
  r.collapsed = lambda > threshold;
  r.steps = static_cast<long long>(1000 * lambda);
  return r;
}

// Three workers, a round of two: the idle third runs the planned lambda 5 ahead; the round's
// trial at 1 does not end before 5 has started, so the plan is certainly taken up. Once the
// round is known the planner drops 5, which is cancelled (its runner waits for that), and
// the journal sees only the round's trials.
TEST(TrialPool, RunsAheadAndCancelsAWrongGuess) {
  std::atomic<bool> ahead_started{false};
  std::vector<double> journal;
  {
    TrialPool pool(
        3,
        [&](double lambda, const TrialPool::Sample& sample) {
          if (lambda == 5.0) {
            ahead_started = true;
            while (sample(0.0)) std::this_thread::yield();
          }
          if (lambda == 1.0)
            while (!ahead_started.load()) std::this_thread::yield();
          return fake(lambda, 1.5);
        },
        [&](const TrialResult& r) { journal.push_back(r.lambda); });
    const std::vector<TrialResult> out = pool.run_round(
        {1.0, 2.0}, [](const std::vector<Outcome3>& known, const std::map<double, bool>&) {
          const bool pending = known[0] == Outcome3::Unknown || known[1] == Outcome3::Unknown;
          return pending ? std::vector<double>{5.0} : std::vector<double>{};
        });
    ASSERT_EQ(out.size(), 2u);
    EXPECT_EQ(out[0].lambda, 1.0);
    EXPECT_FALSE(out[0].collapsed);
    EXPECT_EQ(out[1].lambda, 2.0);
    EXPECT_TRUE(out[1].collapsed);
    pool.cancel_ahead();
    const PoolStats st = pool.stats();
    EXPECT_EQ(st.workers, 3);
    EXPECT_EQ(st.ahead, 1);
    EXPECT_EQ(st.ahead_used, 0);
    EXPECT_EQ(st.cancelled, 1);
  }
  ASSERT_EQ(journal.size(), 2u);
  EXPECT_EQ(journal[0] + journal[1], 3.0);
}

// Trials planned ahead give the search their results when it asks; a failing trial is
// rethrown when the search asks for it, not while it only ran ahead.
TEST(TrialPool, TakesTrialsRunAheadAndRethrowsOnlyAskedFailures) {
  TrialPool pool(
      2,
      [&](double lambda, const TrialPool::Sample&) {
        if (lambda == 9.0) throw std::runtime_error("trial 9 failed");
        return fake(lambda, 3.5);
      },
      [](const TrialResult&) {});
  // The planner keeps 3 and 9 ahead for as long as this round is the pool's.
  auto plan = [](const std::vector<Outcome3>&, const std::map<double, bool>&) {
    return std::vector<double>{3.0, 9.0};
  };
  EXPECT_EQ(pool.run_round({1.0}, plan).front().lambda, 1.0);
  const std::vector<TrialResult> next = pool.run_round({3.0}, TrialPool::nothing_ahead);
  EXPECT_FALSE(next.front().collapsed);
  EXPECT_THROW(pool.run_round({9.0}, TrialPool::nothing_ahead), std::runtime_error);
  pool.cancel_ahead();
}

// A pending trial that runs past the simulated time at which the round's stable trial came to
// rest is guessed collapsed, and the plan is made again at once: two workers, a round {1, 2};
// 1 rests at 0.3 s, 2 runs on (sampling every 0.01 s) until the planner has seen it guessed
// collapsed, then collapses. The planner asks for 5 while 2 is unknown (a wrong guess, taken by
// the idle worker) and for 1.5 once 2 is guessed collapsed: 5 is cancelled, 1.5 runs ahead and
// is taken by the next round.
TEST(TrialPool, ATrialRunningPastTheStableOnesIsGuessedCollapsed) {
  std::atomic<bool> guessed{false};
  std::atomic<int> runs_of_5{0};
  TrialPool pool(
      2,
      [&](double lambda, const TrialPool::Sample& sample) {
        TrialResult r = fake(lambda, 1.75);
        if (lambda == 1.0) r.sim_time = 0.3;
        if (lambda == 2.0)
          for (double t = 0.0; !guessed.load() && t < 1e4; t += 0.01) sample(t);
        if (lambda == 5.0) {
          ++runs_of_5;
          for (double t = 0.0; sample(t) && t < 1e4; t += 1e-6) std::this_thread::yield();
        }
        return r;
      },
      [](const TrialResult&) {});
  const std::vector<TrialResult> out = pool.run_round(
      {1.0, 2.0}, [&](const std::vector<Outcome3>& known, const std::map<double, bool>& done) {
        EXPECT_TRUE(done.count(2.0) == 0 || known[1] != Outcome3::Unknown);
        if (known[0] == Outcome3::NotCrossed && known[1] == Outcome3::Crossed) {
          guessed = true;
          return std::vector<double>{1.5};
        }
        return std::vector<double>{5.0};
      });
  EXPECT_TRUE(guessed.load());
  EXPECT_TRUE(out[1].collapsed);
  const std::vector<TrialResult> next = pool.run_round({1.5}, TrialPool::nothing_ahead);
  EXPECT_FALSE(next.front().collapsed);
  pool.cancel_ahead();
  const PoolStats st = pool.stats();
  EXPECT_EQ(st.ahead_used, 1);
  EXPECT_EQ(st.cancelled, runs_of_5.load());
}

Config block_deck() {
  return parse_deck(R"(
[model]
kind = "block"
width = 0.5
height = 1.0
[contact]
friction = 0.3
)",
                    "block.toml");
}

// The same trials, verdicts, steps and bracket with one worker (no running ahead) and with
// three (two rounds ahead), whatever ran ahead.
TEST(TrialPool, CapacityDoesNotDependOnTheWorkers) {
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const CapacityResult one = find_capacity(block_deck(), TrialCriteria{}, 2, true);
  omp_set_num_threads(3);
  const CapacityResult three = find_capacity(block_deck(), TrialCriteria{}, 2, true);
  omp_set_num_threads(threads);
  EXPECT_EQ(one.workers, 1);
  EXPECT_EQ(one.ahead, 0);
  EXPECT_EQ(three.workers, 3);
  expect_same_search(one, three);
}

// A search resumed from its whole journal takes every trial from it: none is run ahead and
// asked for again.
TEST(TrialPool, AWholeJournalRunsNoTrialAgain) {
  const CapacitySearch search = journalled_search("trial_pool_resume.journal");
  const CapacityResult full = find_capacity(block_deck(), TrialCriteria{}, search);
  const CapacityResult resumed = find_capacity(block_deck(), TrialCriteria{}, search);
  EXPECT_EQ(resumed.resumed_trials, static_cast<int>(full.trials.size()));
  EXPECT_EQ(resumed.ahead_used, 0);
  EXPECT_EQ(resumed.lambda_star, full.lambda_star);
  ASSERT_EQ(resumed.trials.size(), full.trials.size());
  for (std::size_t i = 0; i < full.trials.size(); ++i)
    EXPECT_EQ(resumed.trials[i].steps, full.trials[i].steps);
}

}  // namespace
}  // namespace voussoir

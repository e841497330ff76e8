// The board of runs ahead (engine/runs_ahead.hpp): a run started ahead is what its search then
// takes, a run dropped from its search's plan is cancelled, a search waiting for a run ahead
// runs the next planned one, a run ahead that failed fails when asked for, runs are kept apart
// by search, and an ended search frees the helper. The runners wait for one another, so what
// runs ahead is certain, not a matter of timing.

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "core/schema.hpp"
#include "engine/runs_ahead.hpp"

namespace voussoir {
namespace {

struct FakeRun {
  std::size_t search = 0;
  double amplitude = 0.0;
  bool ahead = false;  // run on the helper's thread
};

void expect_stats(const AheadStats& st, int started, int used, int cancelled) {
  EXPECT_EQ(st.started, started);
  EXPECT_EQ(st.used, used);
  EXPECT_EQ(st.cancelled, cancelled);
}

// The search's run of 1 does not end before the helper has started the planned 2.
TEST(RunsAhead, ASearchTakesTheRunStartedAhead) {
  std::atomic<bool> started{false};
  const std::thread::id main_thread = std::this_thread::get_id();
  RunsAhead<FakeRun> board(1, [&](std::size_t s, double a, const std::atomic<bool>&) {
    if (a == 2.0) started = true;
    if (a == 1.0)
      while (!started.load()) std::this_thread::yield();
    return FakeRun{s, a, std::this_thread::get_id() != main_thread};
  });
  std::thread helper([&] { board.help(); });
  const FakeRun first = board.take(0, 1.0, {2.0});
  const FakeRun second = board.take(0, 2.0, {});
  board.done(0);
  helper.join();
  EXPECT_EQ(first.amplitude, 1.0);
  EXPECT_FALSE(first.ahead);
  EXPECT_EQ(second.amplitude, 2.0);
  EXPECT_TRUE(second.ahead);
  expect_stats(board.stats(), 1, 1, 0);
}

// The helper's run of 2 goes on until cancelled; the search then asks for 3 instead, which
// drops 2 from its plan: 2 is cancelled and 3 runs on the search's thread.
TEST(RunsAhead, ARunDroppedFromThePlanIsCancelled) {
  std::atomic<bool> started{false};
  const std::thread::id main_thread = std::this_thread::get_id();
  RunsAhead<FakeRun> board(1, [&](std::size_t s, double a, const std::atomic<bool>& cancel) {
    if (a == 2.0) {
      started = true;
      while (!cancel.load()) std::this_thread::yield();
      throw RunError("run cancelled");
    }
    if (a == 1.0)
      while (!started.load()) std::this_thread::yield();
    return FakeRun{s, a, std::this_thread::get_id() != main_thread};
  });
  std::thread helper([&] { board.help(); });
  board.take(0, 1.0, {2.0});
  const FakeRun third = board.take(0, 3.0, {});
  board.done(0);
  helper.join();
  EXPECT_EQ(third.amplitude, 3.0);
  EXPECT_FALSE(third.ahead);
  expect_stats(board.stats(), 1, 0, 1);
}

// While the run ahead it asks for goes on, the search's thread runs the next planned amplitude:
// the helper's run of 2 cannot end before 3 has started, and only the search's thread is free
// to start it.
TEST(RunsAhead, ASearchWaitingForARunAheadRunsTheNextPlannedOne) {
  std::atomic<bool> two{false}, three{false};
  const std::thread::id main_thread = std::this_thread::get_id();
  RunsAhead<FakeRun> board(1, [&](std::size_t s, double a, const std::atomic<bool>&) {
    if (a == 2.0) {
      two = true;
      while (!three.load()) std::this_thread::yield();
    }
    if (a == 3.0) three = true;
    if (a == 1.0)
      while (!two.load()) std::this_thread::yield();
    return FakeRun{s, a, std::this_thread::get_id() != main_thread};
  });
  std::thread helper([&] { board.help(); });
  board.take(0, 1.0, {2.0});
  const FakeRun second = board.take(0, 2.0, {3.0});
  const FakeRun third = board.take(0, 3.0, {});
  board.done(0);
  helper.join();
  EXPECT_TRUE(second.ahead);
  EXPECT_EQ(third.amplitude, 3.0);
  EXPECT_FALSE(third.ahead);
  expect_stats(board.stats(), 2, 2, 0);
}

// A run ahead that throws throws again in the search that asks for it.
TEST(RunsAhead, ARunAheadThatFailedFailsWhenAskedFor) {
  std::atomic<bool> started{false};
  RunsAhead<FakeRun> board(1, [&](std::size_t s, double a, const std::atomic<bool>&) {
    if (a == 2.0) {
      started = true;
      throw RunError("the run at 2 failed");
    }
    while (!started.load()) std::this_thread::yield();
    return FakeRun{s, a, false};
  });
  std::thread helper([&] { board.help(); });
  board.take(0, 1.0, {2.0});
  EXPECT_THROW(board.take(0, 2.0, {}), RunError);
  board.done(0);
  helper.join();
  EXPECT_EQ(board.stats().used, 1);
}

// Two searches: the helper serves the plan of the first search to plan, and each search gets
// its own amplitude's run (the key is the search and the amplitude).
TEST(RunsAhead, RunsAreKeptApartBySearch) {
  std::atomic<int> started{0};
  RunsAhead<FakeRun> board(2, [&](std::size_t s, double a, const std::atomic<bool>&) {
    if (a == 2.0) ++started;
    if (a == 1.0)
      while (started.load() < 1 + int(s)) std::this_thread::yield();
    return FakeRun{s, a, false};
  });
  std::thread helper([&] { board.help(); });
  board.take(0, 1.0, {2.0});
  board.take(1, 1.0, {2.0});
  const FakeRun a = board.take(0, 2.0, {});
  const FakeRun b = board.take(1, 2.0, {});
  board.done(0);
  board.done(1);
  helper.join();
  EXPECT_EQ(a.search, 0u);
  EXPECT_EQ(b.search, 1u);
  EXPECT_EQ(board.stats().used, 2);
}

}  // namespace
}  // namespace voussoir

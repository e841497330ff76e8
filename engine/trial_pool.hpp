#pragma once
// Capacity trials on a pool of workers, with the idle ones running ahead (commands/capacity.cpp).
//
// The k-section of `capacity` runs its rounds one after the other, the `points` trials of a
// round side by side. A round lasts as long as its longest trial, and near lambda* that is a
// collapsing trial that starts slowly (critical slowing down: church B's last round holds a
// stable trial of 9 s of wall and a collapse of 14 s), so a core waits idle for part of the
// round. The pool gives such a core the trial the search is most likely to ask for next: the
// search hands each round a planner (engine/bracket.hpp probes_ahead: the next rounds' probes
// with the round's pending outcomes guessed, and every trial that has ended, run ahead or not,
// taken as it ended), and a worker with nothing of the round left to start takes the first
// planned lambda that is neither run nor running. When the search asks for a lambda that was
// run ahead, it takes the result (or waits for the running trial); a trial run ahead that has
// dropped out of every plan (a wrong guess) is cancelled at its next sample.
//
// The pending trials of the round are guessed from how long they have run: one that has run
// longer in simulated time than every stable trial so far took to end (at rest), above all of
// them in lambda, is guessed collapsed (a stable trial comes to rest, a collapse near lambda*
// goes on until the collapse criterion: church B's stable trials end after 0.26 to 0.45 s, its
// collapsed ones after 0.68 to 0.76 s); the others are guessed by the planner's own rule. Each
// trial reports the simulated time it has reached at its samples, and the plan is made again
// when one runs past that horizon, so a core that took a wrong guess is freed at once. (The
// planner's rule alone, an estimate of lambda* from limit analysis, guessed church B's first
// collapse stable and ran the wrong round ahead. A horizon of 1.5 or 2 times the stable
// trials' longest time guesses a collapse later, and the idle core gains less of its round:
// scripts/ahead_guess --timeline, docs/capacity.md.)
//
// What the search sees does not change: each trial's result is a function of its lambda alone
// (every trial starts from a copy of the same settled state), and the search reads only the
// results of the lambdas it asks for, in its own order, so lambda*, the bracket, the trials
// reported and their order are those of the search without the pool, bit for bit, whatever
// the number of workers and whatever ran ahead. Only wall times, and the count of trials run
// ahead (PoolStats), depend on timing.
//
// Workers are threads of their own, each running its trials with one OpenMP thread (results do
// not depend on the thread count); with one worker (one thread, or inside the parallel cells
// of a sweep) there is no thread and no running ahead: the trials run in the caller, in order,
// as before the pool.

#include <atomic>
#include <condition_variable>
#include <exception>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "engine/bracket.hpp"
#include "engine/load_trial.hpp"

namespace voussoir {

struct PoolStats {
  int workers = 1;
  int ahead = 0;          // trials started before the search asked for them
  int ahead_used = 0;     // of which the search then asked for
  int cancelled = 0;      // trials run ahead and cancelled (dropped out of every plan)
  double unused_s = 0.0;  // [s] of worker wall time on trials the search never asked for
};

class TrialPool {
 public:
  // At each sample a running trial calls `sample` with the simulated time it has reached [s];
  // false: stop early (any result, discarded).
  using Sample = std::function<bool(double sim_time)>;
  using Runner = std::function<TrialResult(double lambda, const Sample& sample)>;
  // The lambdas to run ahead, best first, from the round's outcomes (known or guessed, above)
  // and every trial that has ended (lambda -> collapsed).
  using Planner = std::function<std::vector<double>(const std::vector<Outcome3>& round,
                                                    const std::map<double, bool>& finished)>;
  // Called (serialised) once for every trial the search asks for and that ran here, as soon
  // as it has both finished and been asked for: the journal, which so holds only the search's
  // trials, as without the pool.
  using Finished = std::function<void(const TrialResult&)>;

  TrialPool(int workers, Runner run, Finished finished);
  ~TrialPool();
  TrialPool(const TrialPool&) = delete;
  TrialPool& operator=(const TrialPool&) = delete;

  // A result known beforehand (from the journal): the search's lookups and the planner see it.
  void preload(const TrialResult& result);
  // The results of `lambdas`, in their order (run here, taken from a trial run ahead, or from
  // preload); while they run, idle workers run `planner`'s lambdas ahead. The first failed
  // trial, in input order, is rethrown once all have ended.
  std::vector<TrialResult> run_round(const std::vector<double>& lambdas, Planner planner);
  // A planner with nothing ahead.
  static std::vector<double> nothing_ahead(const std::vector<Outcome3>&,
                                           const std::map<double, bool>&) {
    return {};
  }

  // Cancels every trial running ahead and waits for them to stop (the search is over).
  void cancel_ahead();

  PoolStats stats() const;

 private:
  enum class State { Running, Done, Failed };
  // What a running trial and the pool share without the lock.
  struct Live {
    std::atomic<bool> cancel{false};
    std::atomic<double> reached{0.0};  // [s] simulated, at its last sample
    // [s] past which the trial's guess changes (the horizon above; infinite: it cannot).
    std::atomic<double> recheck{std::numeric_limits<double>::infinity()};
  };
  struct Entry {
    State state = State::Running;
    TrialResult result;
    std::exception_ptr error;
    bool asked = false;     // the search asked for it
    bool ahead = false;     // started before it was asked for
    bool recorded = false;  // passed to Finished (or preloaded)
    std::shared_ptr<Live> live = std::make_shared<Live>();
  };

  void work();
  // Under the lock: the next lambda to start, or false.
  bool pick(double& lambda);
  // Under the lock: the plan from the round's outcomes, known or guessed; cancels what dropped
  // out of it and sets each running trial's recheck.
  void replan();
  // Under the lock: passes a finished trial the search asked for to Finished, once; a failure
  // of Finished fails the trial.
  void record(Entry& e);

  Runner run_;
  Finished finished_;
  int workers_ = 1;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::map<double, Entry> entries_;
  std::vector<double> round_;
  Planner planner_ = nothing_ahead;
  std::vector<double> plan_;
  int running_ = 0;
  bool stop_ = false;
  PoolStats stats_;
  std::vector<std::thread> threads_;
};

}  // namespace voussoir

#pragma once
// Runs of a study's searches run ahead on threads that have no search left (`pulse --curve` and
// `ida`: commands/pulse.cpp deal_searches).
//
// A study deals its searches (a curve's frequencies, an IDA's records) to threads, one search a
// thread, and a search makes its runs one after the other. Once fewer searches are left than
// threads, the threads without one would idle while the last searches go on (church B's IDA by
// nscd, docs/ida.md: its last record's search alone for minutes). So each search, as it asks for a
// run, tells the board the amplitudes it will most likely ask for next, best first (its plan); a
// thread with no search left takes the first planned amplitude, of the searches in the order they
// made their first plan, that is neither run nor running, and runs it. A search that asks for an
// amplitude run ahead takes the result; while that run still goes on, the search's own thread runs
// the next planned amplitude meanwhile (so both keep working down the plan, not one waiting for the
// other's run). A run ahead that has dropped out of its search's plan (the search went the other
// way) is cancelled: its runner sees `cancel` set and stops early (with an exception or any result,
// discarded).
//
// What the searches see does not change: a run's result is a function of its search and
// amplitude alone (each run starts from a copy of the same settled state; results do not
// depend on the thread that runs them), and a search reads only the runs it asks for, in its
// own order. The outcomes, the runs reported and their order are those without the board, bit
// for bit; only wall times depend on what ran ahead. (engine/trial_pool.hpp does the same for
// the rounds of one capacity search.)

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <utility>
#include <vector>

#include "engine/stop.hpp"

namespace voussoir {

struct AheadStats {
  int started = 0;        // runs started before their search asked for them
  int used = 0;           // of which their search then asked for
  int cancelled = 0;      // dropped out of their search's plan while running
  double unused_s = 0.0;  // [s] of wall time on runs ahead that no search asked for
};

template <class Result>
class RunsAhead {
 public:
  // Runs amplitude `a` of search `search`; stops early when `cancel` becomes true.
  using Runner =
      std::function<Result(std::size_t search, double a, const std::atomic<bool>& cancel)>;

  // `searches`: the searches that will run (each ends with done()).
  RunsAhead(std::size_t searches, Runner run) : run_(std::move(run)), left_(searches) {}

  // The run of `a` for search `search`, which plans `next` after it (best first): the run ahead
  // of `a` if one was started (running planned amplitudes here until it has ended), else run
  // here.
  Result take(std::size_t search, double a, std::vector<double> next) {
    std::unique_lock<std::mutex> lock(mutex_);
    const Key key{search, a};
    asked_.insert(key);
    const auto it = entries_.find(key);
    const bool ahead = it != entries_.end() && !it->second.cancel->load();
    if (ahead) it->second.asked = true;
    set_plan(search, std::move(next));
    changed_.notify_all();
    if (ahead) {
      // While that run goes on, this thread runs the next planned amplitude rather than wait
      // (else the search would always wait for the run it planned last, one core working).
      while (!entries_.at(key).done) {
        Key other;
        if (pick(other))
          run_ahead(lock, other);
        else
          changed_.wait(lock);
      }
      Entry e = std::move(entries_.at(key));
      entries_.erase(key);
      ++stats_.used;
      if (e.error) std::rethrow_exception(e.error);
      return std::move(e.result);
    }
    lock.unlock();
    const std::atomic<bool> never{false};
    return run_(search, a, never);
  }

  // Search `search` has ended: its plan is dropped, its runs ahead cancelled.
  void done(std::size_t search) {
    std::lock_guard<std::mutex> lock(mutex_);
    --left_;
    plans_.erase(search);
    for (auto it = entries_.begin(); it != entries_.end();) {
      if (it->first.first != search || !it->second.done) {
        if (it->first.first == search) it->second.cancel->store(true);
        ++it;
        continue;
      }
      stats_.unused_s += it->second.wall_s;
      it = entries_.erase(it);
    }
    changed_.notify_all();
  }

  // A thread with no search left: runs planned amplitudes until every search has ended (or a
  // stop is requested, engine/stop.hpp). Never throws: a run's failure is its result.
  void help() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (left_ > 0 && !stop_requested()) {
      Key key;
      if (!pick(key)) {
        // Woken by a new plan or an ended search; the timeout only looks at the stop request.
        changed_.wait_for(lock, std::chrono::milliseconds(200));
        continue;
      }
      run_ahead(lock, key);
    }
  }

  AheadStats stats() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return stats_;
  }

 private:
  using Key = std::pair<std::size_t, double>;  // (search, amplitude)
  struct Entry {
    bool done = false;
    bool asked = false;  // its search asked for it while it ran
    Result result{};
    std::exception_ptr error;
    double wall_s = 0.0;
    std::shared_ptr<std::atomic<bool>> cancel = std::make_shared<std::atomic<bool>>(false);
  };

  // Under the lock, released while it runs: runs `key` ahead and keeps its result (dropped
  // when it was cancelled meanwhile).
  void run_ahead(std::unique_lock<std::mutex>& lock, const Key& key) {
    Entry& e = entries_[key];
    ++stats_.started;
    const std::shared_ptr<std::atomic<bool>> cancel = e.cancel;
    lock.unlock();
    const auto t0 = std::chrono::steady_clock::now();
    Result result{};
    std::exception_ptr error;
    try {
      result = run_(key.first, key.second, *cancel);
    } catch (...) {
      error = std::current_exception();
    }
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    lock.lock();
    if (cancel->load()) {
      ++stats_.cancelled;
      stats_.unused_s += wall;
      entries_.erase(key);
    } else {
      Entry& ended = entries_.at(key);
      ended.done = true;
      ended.result = std::move(result);
      ended.error = error;
      ended.wall_s = wall;
    }
    changed_.notify_all();
  }

  // Under the lock: the search's new plan; its runs ahead not asked for and out of it cancelled.
  void set_plan(std::size_t search, std::vector<double> next) {
    if (plans_.find(search) == plans_.end()) order_.push_back(search);
    for (auto& [key, e] : entries_) {
      if (key.first != search || e.done || e.asked) continue;
      if (std::find(next.begin(), next.end(), key.second) == next.end()) e.cancel->store(true);
    }
    plans_[search] = std::move(next);
  }

  // Under the lock: the first planned amplitude neither asked for nor run nor running.
  bool pick(Key& key) const {
    for (std::size_t search : order_) {
      const auto plan = plans_.find(search);
      if (plan == plans_.end()) continue;
      for (double a : plan->second) {
        const Key k{search, a};
        if (asked_.count(k) == 0 && entries_.count(k) == 0) {
          key = k;
          return true;
        }
      }
    }
    return false;
  }

  Runner run_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::size_t left_;                                  // searches not yet done
  std::map<std::size_t, std::vector<double>> plans_;  // search -> its plan, best first
  std::vector<std::size_t> order_;                    // searches in the order of their plans
  std::map<Key, Entry> entries_;                      // runs ahead (running or ended)
  std::set<Key> asked_;                               // every run a search has asked for
  AheadStats stats_;
};

}  // namespace voussoir

// The pool of capacity trials (contract and decisions in trial_pool.hpp).
#include "engine/trial_pool.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>

namespace voussoir {

namespace {

bool contains(const std::vector<double>& v, double x) {
  return std::find(v.begin(), v.end(), x) != v.end();
}

}  // namespace

TrialPool::TrialPool(int workers, Runner run, Finished finished)
    : run_(std::move(run)), finished_(std::move(finished)), workers_(std::max(1, workers)) {
  stats_.workers = workers_;
  if (workers_ > 1)
    for (int k = 0; k < workers_; ++k) threads_.emplace_back([this] { work(); });
}

TrialPool::~TrialPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    for (auto& [lambda, e] : entries_)
      if (e.state == State::Running) e.live->cancel.store(true);
  }
  changed_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void TrialPool::preload(const TrialResult& result) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (entries_.count(result.lambda) != 0) return;  // run here already, or running
  Entry& e = entries_[result.lambda];
  e.state = State::Done;
  e.result = result;
  e.recorded = true;
}

void TrialPool::record(Entry& e) {
  if (e.recorded || e.state != State::Done || !e.asked) return;
  e.recorded = true;
  try {
    finished_(e.result);
  } catch (...) {
    e.state = State::Failed;
    e.error = std::current_exception();
  }
}

bool TrialPool::pick(double& lambda) {
  if (running_ >= workers_) return false;
  auto start = [&](double l, bool asked) {
    Entry& e = entries_[l];
    e.asked = asked;
    e.ahead = !asked;
    if (!asked) ++stats_.ahead;
    ++running_;
    lambda = l;
    return true;
  };
  // The round's own trials first, its highest lambda first (the slow collapse near lambda*).
  for (auto it = round_.rbegin(); it != round_.rend(); ++it)
    if (entries_.find(*it) == entries_.end()) return start(*it, true);
  for (double l : plan_)
    if (entries_.find(l) == entries_.end()) return start(l, false);
  return false;
}

void TrialPool::replan() {
  auto ended = [](const Entry& e) { return e.state == State::Done && !e.live->cancel.load(); };
  // Every trial that has ended, and the horizon of the stable ones (trial_pool.hpp).
  std::map<double, bool> finished;
  double horizon = 0.0, highest_stable = -std::numeric_limits<double>::infinity();
  for (const auto& [l, e] : entries_) {
    if (!ended(e)) continue;
    finished[l] = e.result.collapsed;
    if (e.result.collapsed) continue;
    horizon = std::max(horizon, e.result.sim_time);
    highest_stable = std::max(highest_stable, l);
  }
  if (!(horizon > 0.0)) horizon = std::numeric_limits<double>::infinity();  // none yet
  std::vector<Outcome3> known;
  for (double l : round_) {
    const auto it = entries_.find(l);
    Outcome3 o = Outcome3::Unknown;
    if (it != entries_.end() && ended(it->second))
      o = it->second.result.collapsed ? Outcome3::Crossed : Outcome3::NotCrossed;
    else if (it != entries_.end() && it->second.state == State::Running && l > highest_stable &&
             it->second.live->reached.load() > horizon)
      o = Outcome3::Crossed;  // guessed: running past every stable trial's end
    known.push_back(o);
  }
  plan_ = planner_(known, finished);
  for (auto& [l, e] : entries_) {
    if (e.state != State::Running) continue;
    const bool past = e.live->reached.load() > horizon;
    const bool may_turn = !past && l > highest_stable && contains(round_, l);
    e.live->recheck.store(may_turn ? horizon : std::numeric_limits<double>::infinity());
    if (!e.asked && !contains(round_, l) && !contains(plan_, l)) e.live->cancel.store(true);
  }
}

void TrialPool::work() {
  omp_set_num_threads(1);  // one trial per core; results do not depend on the thread count
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    double lambda = 0.0;
    changed_.wait(lock, [&] { return stop_ || pick(lambda); });
    if (stop_) return;
    const std::shared_ptr<Live> live = entries_.at(lambda).live;
    lock.unlock();
    // A trial that runs past its recheck time makes the plan again (trial_pool.hpp).
    const Sample sample = [this, live](double t) {
      live->reached.store(t);
      if (t > live->recheck.load()) {
        std::lock_guard<std::mutex> relock(mutex_);
        live->recheck.store(std::numeric_limits<double>::infinity());
        replan();
        changed_.notify_all();
      }
      return !live->cancel.load(std::memory_order_relaxed);
    };
    const auto t0 = std::chrono::steady_clock::now();
    TrialResult r;
    std::exception_ptr error;
    try {
      r = run_(lambda, sample);
    } catch (...) {
      error = std::current_exception();
    }
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    lock.lock();
    --running_;
    if (live->cancel.load()) {
      ++stats_.cancelled;
      stats_.unused_s += wall;
      entries_.erase(lambda);
    } else {
      Entry& e = entries_.at(lambda);
      e.state = error ? State::Failed : State::Done;
      e.result = std::move(r);
      e.error = error;
      record(e);
      replan();
    }
    changed_.notify_all();
  }
}

std::vector<TrialResult> TrialPool::run_round(const std::vector<double>& lambdas, Planner planner) {
  std::vector<TrialResult> out(lambdas.size());
  std::vector<std::exception_ptr> failed(lambdas.size());
  if (workers_ == 1) {
    // In the caller, in order, as before the pool.
    for (std::size_t i = 0; i < lambdas.size(); ++i) {
      const auto it = entries_.find(lambdas[i]);
      if (it != entries_.end() && it->second.state == State::Done) {
        out[i] = it->second.result;
        continue;
      }
      try {
        out[i] = run_(lambdas[i], [](double) { return true; });
        Entry& e = entries_[lambdas[i]];
        e.state = State::Done;
        e.result = out[i];
        e.asked = e.recorded = true;
        finished_(out[i]);
      } catch (...) {
        failed[i] = std::current_exception();
      }
    }
  } else {
    std::unique_lock<std::mutex> lock(mutex_);
    round_ = lambdas;
    planner_ = std::move(planner);
    for (double l : lambdas) {
      const auto it = entries_.find(l);
      if (it == entries_.end()) continue;
      if (it->second.ahead && !it->second.asked && !it->second.live->cancel.load())
        ++stats_.ahead_used;
      it->second.asked = true;
      record(it->second);
    }
    replan();
    changed_.notify_all();
    auto ended = [&](double l) {
      const auto it = entries_.find(l);
      return it != entries_.end() && it->second.state != State::Running &&
             !it->second.live->cancel.load();
    };
    changed_.wait(lock, [&] { return std::all_of(lambdas.begin(), lambdas.end(), ended); });
    for (std::size_t i = 0; i < lambdas.size(); ++i) {
      const Entry& e = entries_.at(lambdas[i]);
      if (e.state == State::Failed)
        failed[i] = e.error;
      else
        out[i] = e.result;
    }
    // The round stays the planner's: with all its outcomes known, idle workers start the next
    // round before the search asks for it.
  }
  for (const std::exception_ptr& e : failed)
    if (e) std::rethrow_exception(e);
  return out;
}

void TrialPool::cancel_ahead() {
  std::unique_lock<std::mutex> lock(mutex_);
  round_.clear();
  planner_ = nothing_ahead;
  replan();
  changed_.wait(lock, [&] { return running_ == 0; });
}

PoolStats TrialPool::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  PoolStats s = stats_;
  for (const auto& [l, e] : entries_)
    if (e.ahead && !e.asked && e.state == State::Done) s.unused_s += e.result.wall_s;
  return s;
}

}  // namespace voussoir

// `voussoir capacity DECK`: lambda* by k-section bisection (commands/capacity.hpp), with every
// trial in the JSON.

#include "commands/capacity.hpp"

#include <omp.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "commands/common.hpp"
#include "core/fnv.hpp"
#include "core/rigid.hpp"
#include "engine/bracket.hpp"
#include "engine/journal.hpp"
#include "engine/motion.hpp"
#include "engine/run_loop.hpp"
#include "engine/setup.hpp"
#include "engine/solver_report.hpp"
#include "engine/trial.hpp"
#include "engine/trial_pool.hpp"
#include "io/hdf5_output.hpp"
#include "io/json.hpp"
#include "io/plot.hpp"
#include "limit/limit_analysis.hpp"

namespace voussoir {
namespace {

using Clock = std::chrono::steady_clock;

void report(const TrialResult& r, bool quiet, bool resumed) {
  if (quiet) return;
  std::fprintf(stderr, "  lambda = %.5f  %-9s (%s, %.3f s simulated, %lld steps, %.2f s wall)%s\n",
               r.lambda, r.collapsed ? "collapsed" : "stable", r.reason.c_str(), r.sim_time,
               r.steps, r.wall_s, resumed ? " [journal]" : "");
  // A trial whose velocities the kinetic damping reset at most of its steps stood still
  // whatever the forces on it (docs/capacity.md, "The step of the quasi-static phases").
  if (4 * r.kinetic_resets > r.steps)
    std::fprintf(stderr,
                 "  warning: the kinetic damping reset the velocities at %lld of this trial's %lld "
                 "steps and may have held it still; check it with --dynamic\n",
                 r.kinetic_resets, r.steps);
}

}  // namespace

int unseeded_trial_count(double lambda_star, double lambda_min, double tolerance, int points) {
  constexpr double kFirstGuess = 0.125, kCap = 8.0;
  int trials = 0;
  double lo = lambda_min, hi = 0.0;
  bool have_hi = false;
  double next = std::max(kFirstGuess, 2.0 * lo);
  while (!have_hi && next <= kCap) {
    for (int i = 0; i < points && next <= kCap; ++i, next *= 2.0) {
      ++trials;
      if (!have_hi && next > lambda_star) {
        hi = next;
        have_hi = true;
      } else if (!have_hi) {
        lo = next;
      }
    }
  }
  if (!have_hi) return trials;
  Bracket b{lo, hi};
  auto oracle = [lambda_star](const std::vector<double>& probes) {
    std::vector<bool> crossed;
    for (double l : probes) crossed.push_back(l > lambda_star);
    return crossed;
  };
  return trials + shrink_bracket(b, tolerance, points, ProbePlacement::KSection, oracle,
                                 [](const Bracket&) {});
}

CapacityResult find_capacity(const Config& config, const TrialCriteria& crit, int points,
                             bool quiet) {
  CapacitySearch search;
  search.points = points;
  search.quiet = quiet;
  return find_capacity(config, crit, search);
}

// The unseeded search starts at kFirstLambda and grows geometrically up to kLambdaCap: beyond
// that the structure is not a masonry mechanism.
constexpr double kFirstLambda = 0.125, kLambdaCap = 8.0;

// Runs the rounds of a search on the pool (trials of the journal taken from it); reports each
// result and keeps it in res.trials; returns all results in input order.
struct Rounds {
  TrialPool& pool;
  CapacityResult& res;
  const std::set<double>& from_journal;
  bool quiet;
  std::vector<TrialResult> operator()(const std::vector<double>& lambdas,
                                      TrialPool::Planner planner = TrialPool::nothing_ahead) {
    const std::vector<TrialResult> out = pool.run_round(lambdas, std::move(planner));
    for (const TrialResult& r : out) {
      const bool resumed = from_journal.count(r.lambda) != 0;
      if (resumed) ++res.resumed_trials;
      report(r, quiet, resumed);
      res.trials.push_back(r);
    }
    return out;
  }
};

// A contradicted bracket (the seed's, or the deck's) widens geometrically: down from a low end
// `from` that collapsed (it becomes hi), up from a high end `from` that stood (it becomes lo; no
// collapse up to kLambdaCap leaves the search unbracketed).
void widen_down(Rounds& evaluate, double from, double& lo, double& hi) {
  hi = from;
  double down = from;
  while (down > 1e-3) {
    ++evaluate.res.seed.widenings;
    down *= kWidenDown;
    if (!evaluate.quiet)
      std::fprintf(stderr, "bracket contradicted (collapse at %.5f): widening down\n", hi);
    if (!evaluate({down})[0].collapsed) {
      lo = down;
      return;
    }
    hi = down;
  }
  lo = 0.0;
}

void widen_up(Rounds& evaluate, double from, double& lo, double& hi, bool& have_hi) {
  if (!evaluate.quiet)
    std::fprintf(stderr, "bracket contradicted (stable at %.5f): widening up\n", from);
  lo = from;
  have_hi = false;
  double up = from;
  while (!have_hi && up < kLambdaCap) {
    ++evaluate.res.seed.widenings;
    up *= kWidenUp;
    if (evaluate({up})[0].collapsed) {
      hi = up;
      have_hi = true;
    } else {
      lo = up;
    }
  }
}

// The seed of the bracket from limit analysis of the settled blocks: when lambda_la lies above
// lo, [lo, hi] = [s_lo, s_hi] = [kSeedLow, kSeedHigh] x lambda_la (ends presumed, not run) and
// the pool's guess kAheadGuess x lambda_la; returns whether it seeded.
bool seed_bracket(CapacityResult& res, const SettledState& settled, const Config& config,
                  const TrialCriteria& crit, bool quiet, double& lo, double& hi, double& s_lo,
                  double& s_hi, double& guess) {
  // Towards -x: limit analysis of the mirror image towards +x.
  const LimitResult la = limit_of_settled(settled, config.contact.friction, crit.direction);
  res.seed.status = la.status;
  if (la.status == "optimal" && la.lambda_la > lo) {
    res.seed.used = true;
    res.seed.held = true;  // until a presumed end that is run contradicts it
    res.seed.lambda_la = la.lambda_la;
    s_lo = std::max(lo, kSeedLow * la.lambda_la);
    s_hi = kSeedHigh * la.lambda_la;
    if (!quiet)
      std::fprintf(stderr, "limit analysis: lambda_la = %.5f, seeded bracket [%.5f, %.5f]\n",
                   la.lambda_la, s_lo, s_hi);
    lo = s_lo;
    hi = s_hi;
    guess = kAheadGuess * la.lambda_la;
    return true;
  }
  return false;
}

// Unseeded bracket: lambdas grow geometrically from kFirstLambda, `points` a round, until one
// collapses (cap kLambdaCap).
void grow_bracket(Rounds& evaluate, int points, double& lo, double& hi, bool& have_hi) {
  double next = std::max(kFirstLambda, 2.0 * lo);
  while (!have_hi && next <= kLambdaCap) {
    std::vector<double> lambdas;
    for (int i = 0; i < points && next <= kLambdaCap; ++i, next *= 2.0) lambdas.push_back(next);
    const auto round = evaluate(lambdas);
    for (const TrialResult& r : round) {
      if (r.collapsed) {
        hi = r.lambda;
        have_hi = true;
        break;
      }
      lo = std::max(lo, r.lambda);
    }
  }
}

// The joint resultants of the trials at the bracket's ends (CapacityResult): the stable trial
// at `at_lo` (the settled state when it is 0) and, when bracketed, the collapsed one at `at_hi`.
void keep_bracket_joints(CapacityResult& res, double at_lo, double at_hi) {
  const bool bracketed = res.bracketed;
  if (at_lo == 0.0) res.joints_stable = res.joints_settled, res.has_stable = true;
  for (const TrialResult& r : res.trials) {
    if (r.joints.empty()) continue;
    if (!r.collapsed && r.lambda == at_lo) res.joints_stable = r.joints, res.has_stable = true;
    if (bracketed && r.collapsed && r.lambda == at_hi)
      res.joints_collapsed = r.joints, res.has_collapsed = true;
  }
}

// The end of a search on [lo, hi] (bracketed or not: res.bracketed): the failure mode and the
// joint resultants of the trials at its ends, the movie when asked, lambda*.
void finish_search(CapacityResult& res, const Config& config, const SettledState& settled,
                   const TrialCriteria& crit, const CapacitySearch& search, double lo, double hi,
                   int points) {
  const bool quiet = search.quiet;
  if (!res.bracketed) {
    keep_bracket_joints(res, lo, hi);
    res.lo = res.hi = res.lambda_star = lo;
    return;
  }
  for (const TrialResult& r : res.trials) {
    if (!r.collapsed || r.lambda != hi) continue;
    res.hinges = r.hinges;
    if (!r.final_x.empty()) {
      res.has_mode = true;
      res.mode = settled.sim.model;
      res.mode.nodes.x = r.final_x;
      res.mode.nodes.y = r.final_y;
    }
  }
  keep_bracket_joints(res, lo, hi);
  // The movie: the collapsed trial at hi run again with snapshots (record_trial), about
  // kMovieFramesToCollapse frames until its collapse criterion fired.
  if (!search.movie.empty())
    for (const TrialResult& r : res.trials) {
      if (!r.collapsed || r.lambda != hi || res.has_movie) continue;
      if (!quiet) std::fprintf(stderr, "recording the trial lambda = %.5f for the movie\n", hi);
      const double every = std::max(res.dt, r.sim_time / kMovieFramesToCollapse);
      res.movie = record_trial(settled, hi, crit, every, search.movie, quiet);
      res.has_movie = true;
    }
  res.lo = lo;
  res.hi = hi;
  res.lambda_star = 0.5 * (lo + hi);
  if (res.seed.used)
    res.seed.unseeded_trials =
        unseeded_trial_count(res.lambda_star, config.capacity.lambda_min, res.tolerance, points);
}

CapacityResult find_capacity(const Config& config, const TrialCriteria& crit,
                             const CapacitySearch& search) {
  const auto t0 = Clock::now();
  const bool quiet = search.quiet;
  const int points = std::max(1, search.points);
  CapacityResult res;
  res.tolerance = config.capacity.tolerance;
  std::optional<SettledState> own;
  if (!search.settled) own = settle(config, crit, quiet);
  const SettledState& settled = search.settled ? *search.settled : *own;
  res.triangles = settled.sim.model.tris.size();
  res.dt = settled.sim.ctx.dt;
  res.settle_time = settled.settle_time;
  res.settle_steps = settled.steps;
  res.settle_wall_s = settled.wall_s;
  if (!settled.settled) throw RunError(unsettled_message(settled, crit));
  res.joints_settled = joint_resultants(settled.sim.model, settled.sim.contact, settled.sim.ctx.dt);
  Journal journal(search.journal, settled_fingerprint(settled, crit));

  // Trials on a pool of workers (engine/trial_pool.hpp): a round's trials side by side, and
  // idle workers running ahead the trials the search will most likely ask for next. One
  // worker inside an active parallel region (the cells of a sweep).
  const int workers = omp_in_parallel() ? 1 : std::max(1, omp_get_max_threads());
  TrialPool pool(
      workers,
      [&](double lambda, const TrialPool::Sample& sample) {
        return run_trial(settled, lambda, crit, quiet, &sample);
      },
      [&](const TrialResult& r) { journal.append(trial_json(r)); });
  // Rounds ahead that the planners list (bracket.hpp probes_ahead), and their guess of
  // lambda* (the middle of each bracket until limit analysis gives kAheadGuess x lambda_la).
  const int depth = 1 + (workers + points - 1) / points;
  double guess = std::numeric_limits<double>::quiet_NaN();
  // The journal's trials, known to the pool before anything runs (none is run ahead again).
  // Lambdas are written with 17 significant digits, so a resumed search that recomputes the
  // same lambdas finds them bit for bit; the first record of a lambda counts (preload).
  std::set<double> from_journal;
  for (const nlohmann::json& j : journal.records()) {
    if (!j.contains("lambda")) continue;
    try {
      pool.preload(trial_from_json(j));
    } catch (const std::exception&) {
      continue;  // a record without a trial's fields: that trial runs again
    }
    from_journal.insert(j.at("lambda").get<double>());
  }
  Rounds evaluate{pool, res, from_journal, quiet};

  double lo = config.capacity.lambda_min, hi = config.capacity.lambda_max;
  bool have_hi = false;
  // The seed's ends are presumed, not run: [s_lo, s_hi] is where the k-section starts, and an
  // end is run only when the search ends on it (below).
  double s_lo = 0.0, s_hi = 0.0;
  bool lo_presumed = false, hi_presumed = false;

  if (hi > lo) {
    // The deck's bracket: both ends are run, side by side (a lower end of 0 is not). A lower
    // end that collapses widens the bracket down, an upper end that stands widens it up.
    std::vector<double> ends;
    if (lo > 0.0) ends.push_back(lo);
    ends.push_back(hi);
    const auto round = evaluate(ends);
    have_hi = round.back().collapsed;
    if (lo > 0.0 && round.front().collapsed) {
      widen_down(evaluate, lo, lo, hi);
      have_hi = true;
    } else if (!have_hi) {
      widen_up(evaluate, hi, lo, hi, have_hi);
    }
  } else if (search.seed_from_limit &&
             seed_bracket(res, settled, config, crit, quiet, lo, hi, s_lo, s_hi, guess)) {
    have_hi = lo_presumed = hi_presumed = true;
  }

  grow_bracket(evaluate, points, lo, hi, have_hi);

  // k-section (engine/bracket.hpp): `points` interior lambdas per round, run in parallel. A
  // presumed seed end that is still an end of the bracket is also listed for idle workers,
  // after the rounds ahead.
  Bracket bracket{lo, hi};
  while (have_hi) {
    shrink_bracket(
        bracket, res.tolerance, points, ProbePlacement::KSection,
        [&](const std::vector<double>& lambdas) {
          const Bracket now = bracket;
          const double tol = res.tolerance;
          const bool check_lo = lo_presumed && now.lo == s_lo;
          const bool check_hi = hi_presumed && now.hi == s_hi;
          std::vector<bool> collapsed;
          for (const TrialResult& r : evaluate(lambdas, [=](const std::vector<Outcome3>&known,
                                                            const std::map<double, bool>&finished) {
                 std::vector<double> ahead =
                     probes_ahead(now, lambdas, known, tol, points, ProbePlacement::KSection, depth,
                                  guess, finished);
                 if (check_hi) ahead.push_back(s_hi);
                 if (check_lo) ahead.push_back(s_lo);
                 return ahead;
               }))
            collapsed.push_back(r.collapsed);
          return collapsed;
        },
        [&](const Bracket& b) {
          if (!quiet) std::fprintf(stderr, "bracket [%.5f, %.5f]\n", b.lo, b.hi);
        });
    lo = bracket.lo;
    hi = bracket.hi;
    // The seed's ends that the search ended on are run now (both in one round when it ended on
    // both: no probe fell between them). The bracket holds when they do as presumed.
    std::vector<double> ends;
    if (lo_presumed && lo == s_lo) ends.push_back(s_lo);
    if (hi_presumed && hi == s_hi) ends.push_back(s_hi);
    lo_presumed = hi_presumed = false;
    if (ends.empty()) break;
    res.seed.ends_run += static_cast<int>(ends.size());
    if (!quiet)
      for (double l : ends)
        std::fprintf(stderr, "the bracket ends on the seed's presumed %s end: running %.5f\n",
                     l == s_lo ? "low" : "high", l);
    bool lo_collapsed = false, hi_stood = false;
    for (const TrialResult& r : evaluate(ends)) {
      if (r.lambda == s_lo && r.collapsed) lo_collapsed = true;
      if (r.lambda == s_hi && !r.collapsed) hi_stood = true;
    }
    if (!lo_collapsed && !hi_stood) break;
    res.seed.held = false;
    if (lo_collapsed)
      widen_down(evaluate, s_lo, lo, hi);
    else
      widen_up(evaluate, s_hi, lo, hi, have_hi);
    bracket = Bracket{lo, hi};
  }

  // The search is over: what still runs ahead is cancelled, and the pool's figures kept.
  pool.cancel_ahead();
  const PoolStats st = pool.stats();
  res.workers = st.workers;
  res.ahead = st.ahead;
  res.ahead_used = st.ahead_used;
  res.ahead_cancelled = st.cancelled;
  res.ahead_unused_s = st.unused_s;
  res.bracketed = have_hi;
  finish_search(res, config, settled, crit, search, lo, hi, points);
  res.wall_s = seconds_since(t0);
  return res;
}

nlohmann::json hinges_to_json(const std::vector<Hinge>& hinges) {
  nlohmann::json out = nlohmann::json::array();
  for (const Hinge& h : hinges)
    out.push_back({{"joint", h.joint},
                   {"blocks", {h.block_a, h.block_b}},
                   {"kind", h.kind},
                   {"side", h.side},
                   {"position_deg", std::isfinite(h.position_deg) ? nlohmann::json(h.position_deg)
                                                                  : nlohmann::json(nullptr)},
                   {"x", h.x},
                   {"y", h.y},
                   {"opening", h.opening},
                   {"slip", h.slip}});
  return out;
}

std::string joint_list(const std::vector<Hinge>& hinges, const std::string& kind) {
  std::string out;
  for (const Hinge& h : hinges) {
    if (h.kind != kind) continue;
    if (!out.empty()) out += ' ';
    out += std::to_string(h.joint);
  }
  return out;
}

std::string failure_mode_text(const CapacityResult& r) {
  if (!r.bracketed) return kNoCollapse;
  auto any = [&r](const char* kind) {
    return std::any_of(r.hinges.begin(), r.hinges.end(),
                       [kind](const Hinge& h) { return h.kind == kind; });
  };
  const bool hinging = any("hinge"), sliding = any("sliding");
  if (hinging && sliding) return "hinging and sliding";
  if (hinging) return "hinging";
  if (sliding) return "sliding";
  return "none found";
}

namespace {

// The text report of one search: lambda*, the seed, and the hinges of the failure mode.
void print_capacity(const CapacityResult& res, const CapacityOptions& opts) {
  // No collapse: no lambda*, only the highest lambda that stood.
  if (res.bracketed)
    std::printf("lambda* = %.4f  bracket [%.4f, %.4f]  %zu trials  %.1f s wall\n", res.lambda_star,
                res.lo, res.hi, res.trials.size(), res.wall_s);
  else
    std::printf("%s = %.4f (every trial stood)  %zu trials  %.1f s wall\n", kNoCollapse, res.lo,
                res.trials.size(), res.wall_s);
  if (res.seed.used)
    std::printf(
        "seeded from limit analysis lambda_la = %.4f: %s, %d trials against about %d "
        "unseeded\n",
        res.seed.lambda_la, res.seed.held ? "bracket held" : "bracket widened",
        static_cast<int>(res.trials.size()), res.seed.unseeded_trials);
  if (res.resumed_trials > 0)
    std::printf("%d trials taken from the journal %s\n", res.resumed_trials, opts.resume.c_str());
  if (res.ahead > 0)
    std::printf("%d trials run ahead on idle cores, %d of them used\n", res.ahead, res.ahead_used);
  if (res.bracketed) std::printf("failure mode: %s\n", failure_mode_text(res).c_str());
  for (const Hinge& h : res.hinges) {
    std::printf("  %-7s joint %d (blocks %d-%d)", h.kind.c_str(), h.joint, h.block_a, h.block_b);
    // Joints off the arch centreline (a buttress on its ground) have no angular position.
    if (std::isfinite(h.position_deg)) std::printf(" at %.1f deg", h.position_deg);
    if (!h.side.empty()) std::printf(", pivot at %s", h.side.c_str());
    std::printf(" (%.4f, %.4f)\n", h.x, h.y);
  }
}

// The JSON of one search (docs/reference/output.md, capacity).
nlohmann::json capacity_json(const CapacityResult& res, const CapacityOptions& opts) {
  nlohmann::json runs = nlohmann::json::array();
  for (const TrialResult& r : res.trials) {
    nlohmann::json run = trial_json(r);
    run.erase("hinges");
    runs.push_back(std::move(run));
  }
  const nlohmann::json none(nullptr);
  nlohmann::json j = {
      {"lambda_star", res.bracketed ? nlohmann::json(res.lambda_star) : none},
      {"bracket", {res.lo, res.bracketed ? nlohmann::json(res.hi) : none}},
      {"bracketed", res.bracketed},
      {"result", res.bracketed ? "collapse" : kNoCollapse},
      {"failure_mode", failure_mode_text(res)},
      {"tolerance", res.tolerance},
      {"runs", runs},
      {"triangles", res.triangles},
      {"dt", res.dt},
      {"wall_s", res.wall_s},
      {"settle",
       {{"sim_time", res.settle_time}, {"steps", res.settle_steps}, {"wall_s", res.settle_wall_s}}},
      {"points_per_round", opts.points},
      {"hinges", hinges_to_json(res.hinges)},
      {"resumed_trials", res.resumed_trials},
      // Trials run ahead on idle cores (engine/trial_pool.hpp): timing, like wall_s.
      {"ahead",
       {{"workers", res.workers},
        {"started", res.ahead},
        {"used", res.ahead_used},
        {"cancelled", res.ahead_cancelled},
        {"unused_wall_s", res.ahead_unused_s}}},
      {"seed",
       {{"used", res.seed.used},
        {"limit_status", res.seed.status},
        {"lambda_la", res.seed.used ? nlohmann::json(res.seed.lambda_la) : nlohmann::json(nullptr)},
        {"held", res.seed.held},
        {"ends_run", res.seed.ends_run},
        {"widenings", res.seed.widenings},
        {"unseeded_trials_estimate", res.seed.unseeded_trials},
        {"trials_saved",
         res.seed.used ? res.seed.unseeded_trials - static_cast<int>(res.trials.size()) : 0}}}};
  // The line of thrust (engine/thrust.hpp): settled, last stable trial, collapsed trial.
  j["joints"] = joints_json(res.joints_settled);
  if (res.has_stable) j["joints_stable"] = joints_json(res.joints_stable);
  if (res.has_collapsed) j["joints_collapsed"] = joints_json(res.joints_collapsed);
  // The highest lambda tried, which stood: the lambda_max of "no collapse up to lambda_max".
  if (!res.bracketed) j["lambda_max"] = res.lo;
  return j;
}

// The failure-mode JSON and picture of the governing search.
void write_mode(const CapacityResult& res, const CapacityOptions& opts, const std::string& deck) {
  if ((!opts.mode_out.empty() || !opts.picture.empty()) && !res.has_mode)
    std::fprintf(stderr, "voussoir: no failure-mode picture: %s\n",
                 res.bracketed ? "the collapsed trial came from the journal" : "no collapse found");
  if (!res.has_mode) return;
  nlohmann::json mode = failure_mode_json(res.mode, res.hinges);
  // The lines of thrust under gravity and at the last stable lambda (engine/thrust.hpp).
  char stable[64];
  std::snprintf(stable, sizeof stable, "last stable lambda = %.4f", res.lo);
  mode["lambda"] = res.hi;  // of the collapsed trial drawn
  mode["thrust"] = nlohmann::json::array();
  mode["thrust"].push_back({{"label", "gravity"}, {"joints", joints_json(res.joints_settled)}});
  if (res.has_stable && res.lo > 0.0)
    mode["thrust"].push_back({{"label", stable}, {"joints", joints_json(res.joints_stable)}});
  if (!opts.mode_out.empty()) write_json(mode, opts.mode_out);
  if (!opts.picture.empty()) {
    char title[160];
    std::snprintf(title, sizeof title, "%s: lambda* = %.4f, bracket [%.4f, %.4f]",
                  std::filesystem::path(deck).stem().c_str(), res.lambda_star, res.lo, res.hi);
    draw_geometry(mode, opts.picture, {"--no-mesh", "--title", title});
  }
}

// Where the movie trial of direction d goes (removed once drawn).
std::string movie_h5(const CapacityOptions& opts, const std::string& d) {
  return opts.movie + (d == "-x" ? ".-x" : ".+x") + ".h5";
}

// --movie: the recorded trial of the governing search drawn by scripts/animate.
void write_movie(const CapacityResult& res, const CapacityOptions& opts, const std::string& h5,
                 const std::string& deck) {
  if (!res.has_movie) {
    std::fprintf(stderr, "voussoir: no movie: no collapse found\n");
    return;
  }
  char label[160];
  std::snprintf(label, sizeof label, "%s: capacity trial at the upper bound of lambda* = %.4f",
                std::filesystem::path(deck).stem().c_str(), res.lambda_star);
  if (draw_with_script("animate", {h5, "-o", opts.movie, "--label", label}, opts.movie))
    std::printf("movie %s: %d frames, %.3f s of the trial (collapse criterion at %.3f s)\n",
                opts.movie.c_str(), res.movie.frames, res.movie.duration, res.movie.collapse_time);
}

}  // namespace

int command_capacity(const Config& config, const CommonOptions& common,
                     const CapacityOptions& opts) {
  if (!opts.movie.empty()) {
    const std::string ext = std::filesystem::path(opts.movie).extension().string();
    if (ext != ".gif" && ext != ".mp4")
      throw DeckError("--movie " + opts.movie + ": the movie must end in .gif or .mp4");
  }
  warn_loose_tolerance(config, "capacity", common.quiet);
  TrialCriteria criteria = opts.criteria;
  criteria.limits = common.limits;
  criteria.quasi_static = !opts.dynamic;
  CapacitySearch search;
  search.points = opts.points;
  search.quiet = common.quiet;
  search.seed_from_limit = !opts.no_seed;
  search.journal = opts.resume;

  // One search per direction asked (`--direction both`: +x then -x, each with its own seed
  // and journal, from one settle under gravity; the smaller lambda* governs).
  std::vector<std::string> directions;
  if (opts.direction == "both")
    directions = {"+x", "-x"};
  else
    directions = {opts.direction};
  if (directions.size() > 1)
    search.settled = std::make_shared<const SettledState>(settle(config, criteria, common.quiet));
  std::vector<CapacityResult> results;
  for (const std::string& d : directions) {
    TrialCriteria c = criteria;
    c.direction = d == "-x" ? -1.0 : 1.0;
    CapacitySearch s = search;
    if (directions.size() > 1 && !s.journal.empty()) s.journal += d == "-x" ? ".-x" : ".+x";
    if (!opts.movie.empty()) s.movie = movie_h5(opts, d);
    if (directions.size() > 1 && !common.quiet) std::fprintf(stderr, "direction %s\n", d.c_str());
    results.push_back(find_capacity(config, c, s));
  }
  std::size_t governing = 0;
  for (std::size_t i = 1; i < results.size(); ++i)
    if (results[i].lambda_star < results[governing].lambda_star) governing = i;

  for (std::size_t i = 0; i < results.size(); ++i) {
    if (results.size() > 1) std::printf("direction %s:\n", directions[i].c_str());
    print_capacity(results[i], opts);
  }
  if (results.size() > 1)
    std::printf("governing direction %s: lambda* = %.4f\n", directions[governing].c_str(),
                results[governing].lambda_star);
  write_mode(results[governing], opts, config.deck_path);
  if (!opts.movie.empty()) {
    write_movie(results[governing], opts, movie_h5(opts, directions[governing]), config.deck_path);
    for (const std::string& d : directions) {
      std::remove(movie_h5(opts, d).c_str());
      std::remove(xdmf_path_for(movie_h5(opts, d)).c_str());
    }
  }

  const NscdStats solver = solver_record();
  warn_unconverged(config, solver, common.quiet);
  if (!common.json_path.empty()) {
    nlohmann::json j = capacity_json(results[governing], opts);
    const bool quasi_static = criteria.quasi_static && config.solver.scheme != "nscd";
    j["direction"] = directions[governing];
    j["quasi_static"] = quasi_static;
    j["mass_scaling"] = quasi_static ? config.capacity.mass_scaling : "none";
    j["solver"] = solver_json(config, solver);
    if (results.size() > 1) {
      nlohmann::json each = nlohmann::json::object();
      for (std::size_t i = 0; i < results.size(); ++i)
        each[directions[i]] = capacity_json(results[i], opts);
      j["directions"] = each;
    }
    write_json(j, common.json_path);
  }
  return 0;
}

// The options of `capacity` (docs/reference/commands.md).
CommandAction add_capacity_command(CLI::App& cmd, CommandLine& line) {
  auto opts = std::make_shared<CapacityOptions>();
  CapacityOptions& o = *opts;
  add_common(cmd, line);
  add_limit_options(&cmd, line.common.limits);
  cmd.add_option("--points", o.points,
                 "trial lambdas per bisection round, run in parallel (default 2)")
      ->check(CLI::Range(1, 64));

  cmd.add_flag("--no-seed", o.no_seed, "start from the generic bracket, not from limit analysis");
  cmd.add_option("--resume", o.resume,
                 "journal of finished trials: created, or resumed after a kill");
  cmd.add_option("--mode-out", o.mode_out, "JSON of the deformed collapse state with its hinges");
  cmd.add_option("--picture", o.picture,
                 "picture (PNG/SVG) of the failure mode with hinges marked");
  cmd.add_option("--movie", o.movie,
                 "movie (GIF, or MP4 with ffmpeg) of the collapsed trial at the upper bound");
  // Trial criteria (defaults and their study: docs/capacity.md).
  cmd.add_option("--ramp-time", o.criteria.ramp_time, "load ramp [s]")->check(CLI::PositiveNumber);
  cmd.add_option("--collapse-displacement", o.criteria.collapse_displacement,
                 "collapse when a block moves this x L_ref")
      ->check(CLI::PositiveNumber);
  cmd.add_option("--collapse-rotation", o.criteria.collapse_rotation,
                 "collapse when a block rotates this [rad]")
      ->check(CLI::PositiveNumber);
  cmd.add_option("--rest-speed", o.criteria.rest_speed, "at rest below this x sqrt(g L_ref)")
      ->check(CLI::PositiveNumber);
  cmd.add_option("--hold-time", o.criteria.hold_time, "rest hold window [s]")
      ->check(CLI::PositiveNumber);
  cmd.add_option("--max-time", o.criteria.max_time, "trial time limit [s]")
      ->check(CLI::PositiveNumber);
  cmd.add_option("--direction", o.direction,
                 "direction of lambda g: +x, -x, or both (reports each and the smaller)")
      ->check(CLI::IsMember({"+x", "-x", "both"}));
  cmd.add_flag("--dynamic", o.dynamic, "physical settle and trials: no quasi-static local damping");
  cmd.add_option("--settle-time", o.criteria.settle_max_time,
                 "longest settle under gravity before the trials [s]")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  CommandAction action;
  action.run = [&line, opts] {
    const Config config = load_command_deck(line);
    require_gravity(config, "capacity");
    return command_capacity(config, line.common, *opts);
  };
  return action;
}

}  // namespace voussoir

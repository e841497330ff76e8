// `voussoir capacity DECK`: lambda* by k-section bisection, with every trial in the JSON.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "drivers/capacity.hpp"
#include "drivers/commands.hpp"
#include "drivers/plot.hpp"
#include "drivers/solver_report.hpp"
#include "io/hdf5_output.hpp"
#include "io/json.hpp"

namespace voussoir {

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

// The JSON of one search (SPEC.md section 2).
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
      // Trials run ahead on idle cores (drivers/trial_pool.hpp): timing, like wall_s.
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
  // The line of thrust (drivers/thrust.hpp): settled, last stable trial, collapsed trial.
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
  // The lines of thrust under gravity and at the last stable lambda (drivers/thrust.hpp).
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

}  // namespace voussoir

// `voussoir pushover DECK`: the capacity curve and its equivalent SDOF curve.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "drivers/commands.hpp"
#include "drivers/plot.hpp"
#include "drivers/pushover.hpp"
#include "io/json.hpp"

namespace voussoir {
namespace {

void print_pushover(const PushoverResult& r, const std::string& deck) {
  std::printf("pushover of %s towards %s: control block %d, centroid (%.4f, %.4f)\n", deck.c_str(),
              r.direction > 0.0 ? "+x" : "-x", r.control, r.control_point.x, r.control_point.y);
  std::printf("peak lambda = %.4f at d = %.4g m\n", r.peak.lambda, r.peak.displacement);
  if (r.reached_zero)
    std::printf("ultimate displacement d0 = %.4g m (lambda falls to 0)\n", r.ultimate_displacement);
  else
    std::printf("lambda did not fall to 0: ended at %s, d = %.4g m, lambda = %.4f\n",
                r.ended.c_str(), r.curve.back().displacement, r.curve.back().lambda);
  if (r.sdof.valid) {
    std::printf("equivalent SDOF: e* = %.4f, M* = %.4g kg, a*0 = %.4g m/s2",
                r.sdof.participating_mass_ratio, r.sdof.participating_mass,
                r.peak.lambda * r.gravity / r.sdof.participating_mass_ratio);
    if (r.reached_zero)
      std::printf(", d*0 = %.4g m, d*u = %.4g m", r.sdof.d_star_0, r.sdof.d_star_u);
    std::printf("\n");
  }
  for (const HingeEvent& e : r.hinges) {
    const Hinge& h = e.hinge;
    std::printf("  %-7s joint %d (blocks %d-%d)", h.kind.c_str(), h.joint, h.block_a, h.block_b);
    if (std::isfinite(h.position_deg)) std::printf(" at %.1f deg", h.position_deg);
    if (!h.side.empty()) std::printf(", pivot at %s", h.side.c_str());
    std::printf(": opened at d = %.4g m, lambda = %.4f\n", e.displacement, e.lambda);
  }
  std::printf("technique: %s\n", r.technique.c_str());
  std::printf(
      "%zu points, %.3f s simulated in %lld steps, servo K = %.4g /m, rate %.4g m/s, "
      "energy balance error %.2g, %.1f s wall\n",
      r.curve.size(), r.sim_time, r.steps, r.servo, r.rate, r.energy_balance_error, r.wall_s);
}

void write_csv(const PushoverResult& r, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw OutputError(path + ": cannot write the pushover CSV");
  out.precision(9);
  out << "displacement,lambda,time,d_star,a_star\n";
  for (std::size_t i = 0; i < r.curve.size(); ++i) {
    const PushoverPoint& p = r.curve[i];
    if (!p.quasi_static) continue;  // a snap's window: in the JSON's "dynamic_windows"
    out << p.displacement << "," << p.lambda << "," << p.time << ",";
    if (r.sdof.valid)
      out << r.sdof.d_star[i] << "," << r.sdof.a_star[i];
    else
      out << ",";
    out << "\n";
  }
  if (!out) throw OutputError(path + ": cannot write the pushover CSV");
}

}  // namespace

int command_pushover(const Config& config, const CommonOptions& common,
                     const PushoverOptions& opts) {
  if (opts.direction != "+x" && opts.direction != "-x")
    throw DeckError("--direction " + opts.direction + ": must be +x or -x");
  PushoverSettings set;
  set.control = opts.control;
  set.direction = opts.direction == "-x" ? -1.0 : 1.0;
  set.rate = opts.rate;
  set.max_displacement = opts.max_displacement;
  set.servo = opts.servo;
  if (!(opts.stop_at >= 0.0 && opts.stop_at < 1.0)) {
    char v[32];
    std::snprintf(v, sizeof v, "%g", opts.stop_at);
    throw DeckError(std::string("--stop-at ") + v +
                    ": must be at least 0 and below 1 (a fraction of the peak)");
  }
  set.stop_fraction = opts.stop_at;
  if (opts.dynamic && opts.quasi_static)
    throw DeckError(
        "--dynamic and --quasi-static: give one of them, or neither (the default "
        "chooses by the limit-analysis mechanism)");
  set.technique = opts.dynamic ? "dynamic" : opts.quasi_static ? "quasi-static" : "auto";
  set.criteria.settle_max_time = opts.settle_time;
  set.criteria.limits = common.limits;
  const PushoverResult r = run_pushover(config, set, common.quiet);
  print_pushover(r, config.deck_path);

  const nlohmann::json j = pushover_json(r);
  if (!common.json_path.empty()) write_json(j, common.json_path);
  if (!opts.csv.empty()) write_csv(r, opts.csv);
  if (!opts.plot.empty()) {
    const std::string tmp = opts.plot + ".pushover.json";
    write_json(j, tmp);
    char title[200];
    std::snprintf(title, sizeof title, "%s towards %s, control block %d",
                  std::filesystem::path(config.deck_path).stem().c_str(),
                  r.direction > 0.0 ? "+x" : "-x", r.control);
    draw_with_script("plot_pushover", {tmp, "-o", opts.plot, "--title", title}, opts.plot);
    std::remove(tmp.c_str());
  }
  if (!opts.picture.empty()) {
    char title[200];
    std::snprintf(title, sizeof title, "%s: pushover end, d = %.4g m, lambda = %.4f",
                  std::filesystem::path(config.deck_path).stem().c_str(),
                  r.curve.back().displacement,
                  // no "-0.0000" for the small negative lambda that ends a curve
                  std::abs(r.curve.back().lambda) < 5e-5 ? 0.0 : r.curve.back().lambda);
    draw_geometry(failure_mode_json(r.at_end, r.hinges_at_end), opts.picture,
                  {"--no-mesh", "--title", title});
  }
  return 0;
}

}  // namespace voussoir

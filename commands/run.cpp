// `voussoir run DECK`: one simulation to `output.file` (HDF5 + XDMF) and a JSON summary.
//
// Checkpoints (--checkpoint-every T, --restart FILE; engine/checkpoint.hpp). Every T seconds of
// simulated time (whole steps), and once at the end, the state goes to the checkpoint file
// together with this driver's bookkeeping: the series rows so far, the next snapshot time, the
// largest energy error, the loop statistics. A restart rebuilds the simulation from the deck,
// restores the state and continues; its output file holds the whole series (the rows before
// the restart come from the checkpoint) and the snapshots from the restart time on (earlier
// ones are in the interrupted run's `.tmp` file). The final state, the series and the summary
// are bit for bit those of the uninterrupted run (tests/unit/test_restart.cpp); only wall
// times differ. A restart may raise solver.end_time to extend a finished run.

#include "commands/run.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands/common.hpp"
#include "core/cst.hpp"
#include "engine/checkpoint.hpp"
#include "engine/motion.hpp"
#include "engine/run_loop.hpp"
#include "engine/setup.hpp"
#include "engine/solver_report.hpp"
#include "engine/thrust.hpp"
#include "io/deck.hpp"
#include "io/hdf5_output.hpp"
#include "io/json.hpp"
#include "io/plot.hpp"

namespace voussoir {
namespace {

// Driver values of a checkpoint (engine/checkpoint.hpp keeps them opaque): a format tag, the
// scalars below, then the series rows, kRowValues doubles each.
constexpr double kDriverFormat = 1.0;
constexpr std::size_t kRowValues = 10;

struct RunBookkeeping {
  double next_snapshot = 0.0;
  double max_energy_error = 0.0;
  LoopStats stats;
  std::vector<SeriesRecord> rows;  // series so far (kept only when checkpointing with output)
};

std::vector<double> encode(const RunBookkeeping& b) {
  std::vector<double> v = {kDriverFormat,      b.next_snapshot,
                           b.max_energy_error, static_cast<double>(b.stats.max_active_pairs),
                           b.stats.wall_s,     static_cast<double>(b.rows.size())};
  for (const SeriesRecord& r : b.rows)
    v.insert(v.end(), {r.time, r.kinetic, r.strain, r.contact, r.damping_dissipated,
                       r.friction_dissipated, r.external_work, r.max_displacement,
                       static_cast<double>(r.active_contacts), r.energy_balance_error});
  return v;
}

RunBookkeeping decode(const std::vector<double>& v, const std::string& path) {
  auto bad = [&] {
    return DeckError("restart file '" + path + "': not written by `voussoir run`");
  };
  // Counts travel as doubles (exact below 2^53); anything else is not ours.
  auto count = [&](double c) {
    if (!(c >= 0.0 && c <= 9007199254740992.0) || c != std::floor(c)) throw bad();
    return static_cast<std::int64_t>(c);
  };
  if (v.size() < 6 || v[0] != kDriverFormat) throw bad();
  RunBookkeeping b;
  b.next_snapshot = v[1];
  b.max_energy_error = v[2];
  b.stats.max_active_pairs = count(v[3]);
  b.stats.wall_s = v[4];
  if (static_cast<std::size_t>(count(v[5])) * kRowValues != v.size() - 6) throw bad();
  for (std::size_t k = 6; k < v.size(); k += kRowValues) {
    SeriesRecord r;
    r.time = v[k];
    r.kinetic = v[k + 1];
    r.strain = v[k + 2];
    r.contact = v[k + 3];
    r.damping_dissipated = v[k + 4];
    r.friction_dissipated = v[k + 5];
    r.external_work = v[k + 6];
    r.max_displacement = v[k + 7];
    r.active_contacts = count(v[k + 8]);
    r.energy_balance_error = v[k + 9];
    b.rows.push_back(r);
  }
  return b;
}

// --checkpoint, else OUTPUT.ckpt, else DECKNAME.ckpt in the current directory.
std::string checkpoint_path(const RunOptions& opts, const std::string& out_path,
                            const Config& config) {
  if (!opts.checkpoint.empty()) return opts.checkpoint;
  if (!out_path.empty()) return out_path + ".ckpt";
  std::string stem = std::filesystem::path(config.deck_path).stem().string();
  return (stem.empty() ? std::string("run") : stem) + ".ckpt";
}

}  // namespace

void draw_current_state(const Simulation& sim, const std::string& title,
                        const std::string& picture) {
  const std::vector<JointResultant> joints = joint_resultants(sim.model, sim.contact, sim.ctx.dt);
  const double tol = kHingeFraction * reference_length(sim.model);
  std::vector<Hinge> hinges;
  for (const Hinge& h : find_hinges(sim.model, tol, tol))
    if (joints[std::size_t(h.joint)].closed) hinges.push_back(h);
  nlohmann::json geo = failure_mode_json(sim.model, hinges);
  char label[64];
  std::snprintf(label, sizeof label, "t = %.4g s", sim.ctx.time);
  geo["thrust"] = {{{"label", label}, {"joints", joints_json(joints)}}};
  draw_geometry(geo, picture, {"--no-mesh", "--scale", "1", "--title", title});
}

int command_run(const Config& config, const CommonOptions& common, const RunOptions& opts) {
  SetupInfo info;
  Simulation sim = make_simulation(config, &info);
  if (config.load.base.signal != "none" && !common.quiet)
    std::fprintf(stderr,
                 "run: the deck's base signal (load.base.signal = \"%s\") is not applied by "
                 "`run`; `pulse` runs it\n",
                 config.load.base.signal.c_str());
  // One physical history: gravity from t = 0 (over [0, load.gravity_ramp] when the deck ramps
  // it) and the supports moving over [0, supports.ramp] (core/supports.hpp); the quasi-static
  // commands move them after their settle instead.
  if (!sim.supports.empty()) start_support_motion(sim.supports, 0.0, config.supports.ramp);
  return run_simulation(sim, info, config, common, opts);
}

int run_simulation(Simulation& sim, const SetupInfo& info, const Config& config,
                   const CommonOptions& common, const RunOptions& opts) {
  const std::string out_path = opts.output.empty() ? config.output.file : opts.output;
  const bool write = !out_path.empty();
  const bool want_stress = std::find(config.output.fields.begin(), config.output.fields.end(),
                                     "stress") != config.output.fields.end();
  const bool checkpoints = opts.checkpoint_every > 0.0;
  const std::string ckpt_path = checkpoint_path(opts, out_path, config);
  const double friction = config.contact.friction;
  const std::uint64_t fingerprint = simulation_fingerprint(sim, friction);

  RunBookkeeping book;
  if (!opts.restart.empty()) {
    book = decode(read_checkpoint(opts.restart, sim, fingerprint), opts.restart);
    if (sim.ctx.time > config.solver.end_time + 0.5 * info.dt)
      throw DeckError(opts.restart + ": the checkpoint is at t = " + std::to_string(sim.ctx.time) +
                      " s, beyond solver.end_time = " + std::to_string(config.solver.end_time) +
                      " s");
    if (!common.quiet)
      std::fprintf(stderr, "run: restarted from %s at t = %.6g s (step %lld)\n",
                   opts.restart.c_str(), sim.ctx.time, sim.step);
  }
  const bool keep_rows = write && checkpoints;

  RunWriter writer;
  if (write) {
    writer.open(out_path, sim.model, config.output.fields);
    for (const SeriesRecord& r : book.rows) writer.append_series(r);
  }
  if (!keep_rows) book.rows.clear();

  // Series every 1/10 of the snapshot interval (at least every step); snapshots every
  // output.every of simulated time.
  const double snap_every = config.output.every;
  const double series_every = std::max(info.dt, snap_every / 10.0);
  auto sample = [&](const Simulation& s) {
    book.max_energy_error = std::max(book.max_energy_error, s.ledger.balance_error());
    if (!write) return true;
    const SeriesRecord record = series_record(s);
    writer.append_series(record);
    if (keep_rows) book.rows.push_back(record);
    if (s.ctx.time >= book.next_snapshot - 0.5 * info.dt) {
      writer.write_snapshot(s.ctx.time, s.model,
                            want_stress ? triangle_stresses(s) : std::vector<double>{});
      // The line of thrust of this state (docs/thrust.md), from a copy of the contact system.
      write_snapshot_thrust(writer, s.model, s.contact, s.ctx.dt, config.load.lambda);
      book.next_snapshot += snap_every;
    }
    return true;
  };

  LoopOptions loop;
  loop.end_time = config.solver.end_time;
  loop.sample_every = series_every;
  loop.quiet = common.quiet;
  loop.label = "run";
  loop.limits = common.limits;
  LoadProgram loads;
  loads.gravity = config.load.gravity;
  loads.lambda = config.load.lambda;
  loads.gravity_ramp = loads.lambda_ramp = config.load.gravity_ramp;
  loop.loads = loads;
  if (checkpoints) {
    loop.checkpoint_every = opts.checkpoint_every;
    loop.checkpoint_at_end = true;  // so that a restart can extend a finished run
    loop.checkpoint = [&](const Simulation& s, const LoopStats& st) {
      book.stats = st;
      write_checkpoint(ckpt_path, s, fingerprint, friction, encode(book));
    };
  }

  LoopStats stats;
  try {
    stats = run_loop(sim, loop, sample, book.stats);
    if (write) writer.close_complete();
  } catch (const std::exception& e) {
    if (write) writer.close_incomplete(e.what());
    throw;
  }
  const double max_energy_error = book.max_energy_error;
  const double dmax = max_free_displacement(sim.model);
  std::printf(
      "%lld steps of %.4g s to t = %.4g s on %d triangles in %.2f s wall (%.3g "
      "triangle-steps/s)\n",
      stats.steps, info.dt, sim.ctx.time, sim.model.tris.size(), stats.wall_s,
      stats.steps * double(sim.model.tris.size()) / std::max(stats.wall_s, 1e-9));
  std::printf(
      "final kinetic energy %.4g J, max displacement %.4g m, energy balance error "
      "%.2e, contacts %lld (max %lld)\n",
      sim.ledger.kinetic, dmax, sim.ledger.balance_error(),
      static_cast<long long>(sim.contact.active_pairs()),
      static_cast<long long>(stats.max_active_pairs));
  if (write) std::printf("output %s (+ %s)\n", out_path.c_str(), writer.xdmf_path().c_str());
  warn_unconverged(config, sim.nscd_stats, common.quiet);
  if (!opts.picture.empty()) {
    char title[96];
    std::snprintf(title, sizeof title, "end of the run: t = %.4g s, lambda = %.4g", sim.ctx.time,
                  config.load.lambda);
    draw_current_state(sim, title, opts.picture);
  }

  if (!common.json_path.empty()) {
    nlohmann::json j = {{"steps", stats.steps},
                        {"triangles", sim.model.tris.size()},
                        {"dt", info.dt},
                        {"dt_stable", info.dt_stable},
                        {"end_time", sim.ctx.time},
                        {"wall_s", stats.wall_s},
                        {"final_kinetic_energy", sim.ledger.kinetic},
                        {"max_displacement", dmax},
                        {"energy_balance_error", sim.ledger.balance_error()},
                        {"max_energy_balance_error", max_energy_error},
                        {"energy",
                         {{"kinetic", sim.ledger.kinetic},
                          {"strain", sim.ledger.strain},
                          {"contact", sim.ledger.contact},
                          {"damping_dissipated", sim.ledger.damping_dissipated},
                          {"friction_dissipated", sim.ledger.friction_dissipated},
                          {"impact_dissipated", sim.ledger.impact_dissipated},
                          {"external_work", sim.ledger.external_work}}},
                        {"active_contacts", sim.contact.active_pairs()},
                        {"max_active_contacts", stats.max_active_pairs},
                        {"output", out_path}};
    // The line of thrust at the end of the run (engine/thrust.hpp; the run's state untouched).
    j["joints"] = joints_json(joint_resultants(sim.model, sim.contact, sim.ctx.dt));
    j["solver"] = solver_json(config, sim.nscd_stats);
    if (checkpoints) j["checkpoint"] = ckpt_path;
    if (!opts.restart.empty()) j["restarted_from"] = opts.restart;
    write_json(j, common.json_path);
  }
  return 0;
}

// The options of `run` (docs/reference/commands.md).
CommandAction add_run_command(CLI::App& cmd, CommandLine& line) {
  auto opts = std::make_shared<RunOptions>();
  RunOptions& o = *opts;
  add_common(cmd, line);
  add_limit_options(&cmd, line.common.limits);
  cmd.add_option("-o,--output", o.output, "HDF5 output file (overrides output.file)");
  cmd.add_option("--checkpoint-every", o.checkpoint_every,
                 "write a checkpoint every T seconds of simulated time (and at the end)")
      ->check(CLI::PositiveNumber);
  cmd.add_option("--checkpoint", o.checkpoint,
                 "checkpoint file (default OUTPUT.ckpt, or DECKNAME.ckpt without output)");
  cmd.add_option("--restart", o.restart, "continue the run saved in this checkpoint (same deck)");
  cmd.add_option("--picture", o.picture,
                 "picture (PNG/SVG) of the final state with its line of thrust");
  CommandAction action;
  action.run = [&line, opts] {
    const Config config = load_command_deck(line);
    return command_run(config, line.common, *opts);
  };
  return action;
}

}  // namespace voussoir

// voussoir: the command-line program. Parses arguments (CLI11), reads the deck, dispatches to
// a subcommand in drivers/. Exit status: 0 success, 2 bad deck or arguments, 1 failure
// during a run (SPEC.md section 2).

#include <omp.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "drivers/commands.hpp"
#include "drivers/dealer.hpp"
#include "drivers/ida.hpp"
#include "drivers/limit_command.hpp"
#include "drivers/pulse.hpp"
#include "drivers/pushover.hpp"
#include "drivers/setup.hpp"
#include "drivers/spread.hpp"
#include "drivers/stability.hpp"
#include "drivers/synth_command.hpp"
#include "io/deck.hpp"
#include "io/deck_reference.hpp"
#include "voussoir/config.hpp"

namespace {

// The folders of the output files named on the command line, created before the command
// runs: a missing folder then neither fails a search at its end, with its results lost, nor
// asks for a `mkdir` first. A folder that cannot be made is bad input (exit 2) naming the
// option and the path. Options whose value is a file written by the command; synth's
// --spectrum names a spectrum, pulse's a CSV.
void make_output_folders(const CLI::App& cmd) {
  static const std::set<std::string> kFiles = {
      "--json",     "--mesh-out", "--output",       "--checkpoint",    "--picture",
      "--mode-out", "--movie",    "--csv",          "--mechanism-out", "--series",
      "--plot",     "--resume",   "--spectrum-plot"};
  for (const CLI::Option* opt : cmd.get_options()) {
    const std::string name = opt->get_name();
    const bool file = kFiles.count(name) > 0 || (name == "--spectrum" && cmd.get_name() == "pulse");
    if (!file || opt->count() == 0) continue;
    for (const std::string& value : opt->results()) {
      if (value.empty() || value == "-") continue;
      const std::filesystem::path folder = std::filesystem::path(value).parent_path();
      if (folder.empty()) continue;
      std::error_code ec;
      std::filesystem::create_directories(folder, ec);
      if (!std::filesystem::is_directory(folder))  // another rank may have made it meanwhile
        throw voussoir::DeckError(name + " " + value + ": cannot create the folder " +
                                  folder.string() + (ec ? ": " + ec.message() : ""));
    }
  }
}

struct DeckArgs {
  std::string deck;
  std::vector<std::string> sets;
};

// Options every subcommand takes: the deck, --set, --threads, --json, --quiet.
void add_common(CLI::App* cmd, DeckArgs& deck, voussoir::CommonOptions& common) {
  cmd->add_option("deck", deck.deck, "input deck (TOML)")->required();
  cmd->add_option("--set", deck.sets, "override a deck key: --set model.embrace=150 (repeatable)")
      ->allow_extra_args(false);
  cmd->add_option("--threads", common.threads, "OpenMP threads (default: all cores)")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--json", common.json_path, "write a JSON summary to FILE ('-' for stdout)");
  cmd->add_flag("-q,--quiet", common.quiet, "no progress on stderr");
}

}  // namespace

int main(int argc, char** argv) {
  // MPI, when launched by mpirun or srun (drivers/dealer.hpp): for the life of main().
  std::optional<voussoir::Ranks> ranks;
  try {
    ranks.emplace(argc, argv);
  } catch (const std::exception& e) {
    if (voussoir::is_dealer_rank()) std::fprintf(stderr, "voussoir: error: %s\n", e.what());
    return 1;
  }
  // Under mpirun only rank 0 prints (messages and errors alike).
  const bool speaks = voussoir::is_dealer_rank();
  CLI::App app{"voussoir " VOUSSOIR_VERSION
               " - collapse capacity of dry-joint masonry arches by FDEM"};
  app.require_subcommand(1);
  app.set_version_flag("--version", VOUSSOIR_VERSION);

  DeckArgs deck;
  voussoir::CommonOptions common;

  voussoir::CheckOptions check_opts;
  CLI::App* check = app.add_subcommand("check", "validate the deck and print the model summary");
  add_common(check, deck, common);
  check->add_option("--mesh-out", check_opts.mesh_out, "write the meshed model as JSON");

  voussoir::RunOptions run_opts;
  CLI::App* run = app.add_subcommand("run", "one simulation: HDF5 output and JSON summary");
  add_common(run, deck, common);
  voussoir::add_limit_options(run, common.limits);
  run->add_option("-o,--output", run_opts.output, "HDF5 output file (overrides output.file)");
  run->add_option("--checkpoint-every", run_opts.checkpoint_every,
                  "write a checkpoint every T seconds of simulated time (and at the end)")
      ->check(CLI::PositiveNumber);
  run->add_option("--checkpoint", run_opts.checkpoint,
                  "checkpoint file (default OUTPUT.ckpt, or DECKNAME.ckpt without output)");
  run->add_option("--restart", run_opts.restart,
                  "continue the run saved in this checkpoint (same deck)");
  run->add_option("--picture", run_opts.picture,
                  "picture (PNG/SVG) of the final state with its line of thrust");

  voussoir::CapacityOptions cap_opts;
  CLI::App* capacity =
      app.add_subcommand("capacity", "collapse load factor lambda* by bisection on lambda");
  add_common(capacity, deck, common);
  voussoir::add_limit_options(capacity, common.limits);
  capacity
      ->add_option("--points", cap_opts.points,
                   "trial lambdas per bisection round, run in parallel (default 2)")
      ->check(CLI::Range(1, 64));

  capacity->add_flag("--no-seed", cap_opts.no_seed,
                     "start from the generic bracket, not from limit analysis");
  capacity->add_option("--resume", cap_opts.resume,
                       "journal of finished trials: created, or resumed after a kill");
  capacity->add_option("--mode-out", cap_opts.mode_out,
                       "JSON of the deformed collapse state with its hinges");
  capacity->add_option("--picture", cap_opts.picture,
                       "picture (PNG/SVG) of the failure mode with hinges marked");
  capacity->add_option("--movie", cap_opts.movie,
                       "movie (GIF, or MP4 with ffmpeg) of the collapsed trial at the upper bound");
  // Trial criteria (defaults and their study: docs/capacity.md).
  capacity->add_option("--ramp-time", cap_opts.criteria.ramp_time, "load ramp [s]")
      ->check(CLI::PositiveNumber);
  capacity
      ->add_option("--collapse-displacement", cap_opts.criteria.collapse_displacement,
                   "collapse when a block moves this x L_ref")
      ->check(CLI::PositiveNumber);
  capacity
      ->add_option("--collapse-rotation", cap_opts.criteria.collapse_rotation,
                   "collapse when a block rotates this [rad]")
      ->check(CLI::PositiveNumber);
  capacity
      ->add_option("--rest-speed", cap_opts.criteria.rest_speed,
                   "at rest below this x sqrt(g L_ref)")
      ->check(CLI::PositiveNumber);
  capacity->add_option("--hold-time", cap_opts.criteria.hold_time, "rest hold window [s]")
      ->check(CLI::PositiveNumber);
  capacity->add_option("--max-time", cap_opts.criteria.max_time, "trial time limit [s]")
      ->check(CLI::PositiveNumber);
  capacity
      ->add_option("--direction", cap_opts.direction,
                   "direction of lambda g: +x, -x, or both (reports each and the smaller)")
      ->check(CLI::IsMember({"+x", "-x", "both"}));
  capacity->add_flag("--dynamic", cap_opts.dynamic,
                     "physical settle and trials: no quasi-static local damping");
  capacity
      ->add_option("--settle-time", cap_opts.criteria.settle_max_time,
                   "longest settle under gravity before the trials [s]")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);

  voussoir::PushoverOptions push_opts;
  CLI::App* pushover = app.add_subcommand(
      "pushover",
      "capacity curve: lambda against a control point's displacement, through the "
      "peak and down the softening branch, with its equivalent SDOF curve");
  add_common(pushover, deck, common);
  voussoir::add_limit_options(pushover, common.limits);
  pushover->add_option("--control", push_opts.control,
                       "control block (its centroid); default: the crown block of an arch, the "
                       "top block otherwise");
  pushover->add_option("--direction", push_opts.direction, "direction of the load: +x or -x")
      ->capture_default_str();
  pushover->add_option("--rate", push_opts.rate,
                       "speed of the control target [m/s] (default " +
                           voussoir::option_number(voussoir::kRateFactor) + " sqrt(g L_ref))");
  pushover->add_option("--max-displacement", push_opts.max_displacement,
                       "largest control displacement [m] (default half the structure's height)");
  pushover->add_option("--servo", push_opts.servo,
                       "servo stiffness K [1/m]: lambda = K (target - d) (default 50 lambda_la "
                       "/ L_ref)");
  pushover->add_option("--stop-at", push_opts.stop_at,
                       "end when lambda has fallen past the peak to this fraction of it (for "
                       "lambda* alone; default 0: down to lambda <= 0)");
  pushover->add_flag("--dynamic", push_opts.dynamic,
                     "physical settle and run: no quasi-static local damping (default when the "
                     "limit-analysis mechanism slides)");
  pushover->add_flag("--quasi-static", push_opts.quasi_static,
                     "quasi-static settle and run even when the limit-analysis mechanism slides");
  pushover
      ->add_option("--settle-time", push_opts.settle_time,
                   "longest settle under gravity before the pushover [s]")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  pushover->add_option("--csv", push_opts.csv, "CSV of the curve and its SDOF curve");
  pushover->add_option(
      "--plot", push_opts.plot,
      "PNG of the curve, the SDOF curve and the mechanism (scripts/plot_pushover)");
  pushover->add_option("--picture", push_opts.picture,
                       "picture (PNG/SVG) of the state at the end with its hinges");

  voussoir::LimitCommandOptions limit_opts;
  CLI::App* limit =
      app.add_subcommand("limit", "rigid-block limit analysis: lambda_la and its mechanism (LP)");
  add_common(limit, deck, common);
  limit->add_flag("--gravity-only", limit_opts.gravity_only,
                  "only decide whether an admissible equilibrium exists under self-weight");
  limit->add_option("--mechanism-out", limit_opts.mechanism_out,
                    "write the block polygons and the mechanism as JSON (scripts/draw)");
  limit
      ->add_option("--thrust", limit_opts.thrust,
                   "least (min) or greatest (max) horizontal support thrust under gravity")
      ->check(CLI::IsMember({"min", "max"}));
  limit
      ->add_option("--open-joints", limit_opts.open_joints,
                   "with [supports] moves: the joints that opened closed over their face "
                   "(default) or point contacts at their pivots")
      ->check(CLI::IsMember({"closed", "points"}));

  voussoir::SpreadOptions spread_opts;
  CLI::App* spread = app.add_subcommand(
      "spread", "move a support step by step until the structure collapses: thrust, hinges");
  add_common(spread, deck, common);
  voussoir::add_limit_options(spread, common.limits);
  spread->add_option("--block", spread_opts.block,
                     "fixed block to move (default: the deck's first move, else the leftmost)");
  spread
      ->add_option("--direction", spread_opts.direction,
                   "DX,DY of the movement (default: horizontal, away from the structure)")
      ->delimiter(',')
      ->expected(2);
  spread->add_option("--rotation", spread_opts.rotation,
                     "turn of the support [deg] per metre of movement");
  spread->add_option("--step", spread_opts.step, "movement per step [m] (default 0.25% of width)")
      ->check(CLI::NonNegativeNumber);
  spread
      ->add_option("--max", spread_opts.max_movement,
                   "largest movement [m] (default 25% of the structure's width)")
      ->check(CLI::NonNegativeNumber);
  spread
      ->add_option("--tolerance", spread_opts.tolerance,
                   "relative width of the bracket on the movement at collapse")
      ->capture_default_str()
      ->check(CLI::Range(1e-4, 1.0));
  spread->add_option("--csv", spread_opts.csv, "thrust and hinges per step")->capture_default_str();

  voussoir::PulseOptions pulse_opts;
  CLI::App* pulse = app.add_subcommand(
      "pulse", "base-excitation run; --curve: collapse amplitude per frequency (failure curve)");
  add_common(pulse, deck, common);
  voussoir::add_limit_options(pulse, common.limits);
  pulse->add_option("-o,--output", pulse_opts.output, "HDF5 output file (overrides output.file)");
  pulse->add_option("--picture", pulse_opts.picture,
                    "picture (PNG/SVG) of the single run's final state with its line of thrust");
  pulse->add_option("--series", pulse_opts.series,
                    "CSV time series of the run (input, energy, control points)");
  pulse->add_flag("--curve", pulse_opts.curve,
                  "failure curve: the collapse amplitude per frequency (--search)");
  pulse->add_option("--freqs", pulse_opts.freqs, "curve frequencies F1,F2,... [Hz]")
      ->delimiter(',');
  pulse->add_option("--csv", pulse_opts.csv, "curve CSV (default curve.csv)");
  pulse->add_option("--plot", pulse_opts.plot, "curve PNG (scripts/plot_curve)");
  pulse->add_option("--lambda-star", pulse_opts.lambda_star,
                    "tilting capacity to draw (skips the capacity search)");
  pulse->add_option("--tolerance", pulse_opts.tolerance,
                    "relative bracket width of the amplitude (default 0.02)");
  pulse->add_option("--points", pulse_opts.points, "capacity trials per round (default 2)")
      ->check(CLI::Range(1, 64));
  pulse->add_option("--search", pulse_opts.search,
                    "curve amplitude search: step (raise A step by step, then bisect the first "
                    "collapsing step; default) or bisect (grow by 1.5, then bisect)");
  pulse->add_option("--start", pulse_opts.start,
                    "first amplitude of the curve search [g] (default lambda*/peak factor; "
                    "bisect: lambda*)");
  pulse->add_option("--step", pulse_opts.step,
                    "relative amplitude step of --search step (default 0.05: 5% a step)");
  pulse->add_option("--steps-above", pulse_opts.steps_above,
                    "steps run past the first collapse, to find survivals above it (default 2)");
  pulse->add_option("--resume", pulse_opts.resume,
                    "curve: journal of finished runs (and FILE.capacity of the tilting "
                    "capacity): created, or resumed after a kill");
  pulse->add_option("--free-time", pulse_opts.free_time,
                    "free motion after the signal before an undecided run is classified by its "
                    "trend [s] (default 1.5)");
  pulse->add_option("--tilt-reference", pulse_opts.tilt_reference,
                    "a measured tilting capacity to report lambda* against");
  pulse->add_option("--spectrum", pulse_opts.spectrum,
                    "CSV of the 5%-damped pseudo-acceleration spectrum of the base signal "
                    "(period,sa_g; docs/records.md), written before the run");
  pulse->add_option("--spectrum-plot", pulse_opts.spectrum_plot,
                    "PNG of that spectrum (scripts/plot_spectrum; needs --spectrum)");
  pulse->add_flag("--spectrum-only", pulse_opts.spectrum_only,
                  "write the spectrum and stop (no simulation)");

  voussoir::IdaOptions ida_opts;
  CLI::App* ida = app.add_subcommand(
      "ida", "incremental dynamic analysis: collapse intensity per record, lognormal fragility");
  add_common(ida, deck, common);
  voussoir::add_limit_options(ida, common.limits);
  ida->add_option("--records", ida_opts.records,
                  "ground-motion records F1,F2,... (PEER .AT2 or two-column; docs/records.md)")
      ->delimiter(',');
  ida->add_option("--im", ida_opts.im,
                  "intensity measure: pga (default) or sa (5%-damped Sa at --period)");
  ida->add_option("--period", ida_opts.period, "period T of Sa(T) [s] (with --im sa)");
  ida->add_option("--lambda-star", ida_opts.lambda_star,
                  "tilting capacity to start from (skips the capacity search)");
  ida->add_option("--points", ida_opts.points, "capacity trials per round (default 2)")
      ->check(CLI::Range(1, 64));
  ida->add_option("--start", ida_opts.start,
                  "first intensity [g of the IM] (default: lambda* in PGA)");
  ida->add_option("--step", ida_opts.step,
                  "relative intensity step (default 0.1: each run 10% above the last)");
  ida->add_option("--steps-above", ida_opts.steps_above,
                  "runs past the first collapse, looking for survivals (default 2)");
  ida->add_option("--tolerance", ida_opts.tolerance,
                  "relative bracket width of the bisection (default 0.05)");
  ida->add_option("--free-time", ida_opts.free_time,
                  "free motion after the record before a timeout decision [s] (default 1.5)");
  ida->add_option("--bootstrap", ida_opts.bootstrap,
                  "bootstrap resamples for the median's interval (default 1000)");
  ida->add_option("--confidence", ida_opts.confidence,
                  "confidence level of the median's interval (default 0.95)");
  ida->add_option("--seed", ida_opts.seed, "seed of the bootstrap (default 1)");
  ida->add_option("--csv", ida_opts.csv,
                  "a line per record (default ida.csv); the runs go to its stem + _runs.csv");
  ida->add_option("--plot", ida_opts.plot,
                  "PNG of the IDA points and the fragility (scripts/plot_ida)");
  ida->add_option("--resume", ida_opts.resume,
                  "journal of the runs: created, or resumed after a kill");

  voussoir::SweepOptions sweep_opts;
  CLI::App* sweep = app.add_subcommand("sweep", "capacity over a grid of deck values");
  add_common(sweep, deck, common);
  voussoir::add_limit_options(sweep, common.limits);
  sweep->add_option("--param", sweep_opts.params, "KEY=V1,V2,... (repeat for a grid)")->required();
  sweep->add_option("--csv", sweep_opts.csv, "CSV output (default sweep.csv)");
  sweep->add_option("--plot", sweep_opts.plot, "PNG plot of lambda* over the grid");
  sweep
      ->add_option("--settle-time", sweep_opts.criteria.settle_max_time,
                   "longest settle under gravity before each cell's trials [s]")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  sweep->add_flag("--dynamic", sweep_opts.dynamic,
                  "physical settle and trials: no quasi-static local damping");
  sweep->add_option("--resume", sweep_opts.resume,
                    "journal of finished cells: created, or resumed after a kill");
  sweep->add_option("--points", sweep_opts.points, "trial lambdas per round (default 2)")
      ->check(CLI::Range(1, 64));

  voussoir::StabilityOptions stab_opts;
  CLI::App* stability = app.add_subcommand(
      "stability", "gravity-only stability map over a grid (kinetic-energy criterion)");
  add_common(stability, deck, common);
  voussoir::add_limit_options(stability, common.limits);
  stability
      ->add_option("--param", stab_opts.params,
                   "KEY=V1,V2,... or KEY=start:stop:step (repeat for a grid); "
                   "model.thickness_ratio=R sets model.thickness = R x model.radius")
      ->required();
  stability->add_option("--csv", stab_opts.csv, "CSV output (default stability.csv)");
  stability->add_option("--plot", stab_opts.plot, "PNG map (scripts/plot_stability)");
  stability->add_option("--mode-out", stab_opts.mode_out,
                        "folder for the block outlines of every collapsed cell (JSON)");
  stability->add_option("--ke-time", stab_opts.ke_time,
                        "time at which the kinetic energy is read [s] (default 1)");
  stability->add_option("--resume", stab_opts.resume,
                        "journal of finished cells: created, or resumed after a kill");
  stability->add_option("--max-time", stab_opts.max_time,
                        "simulated time after which undecided cells are decided [s] (default 3)");

  voussoir::SynthOptions synth_opts;
  CLI::App* synth = app.add_subcommand(
      "synth",
      "artificial accelerograms compatible with the EN 1998-1 elastic spectrum (AT2 "
      "records, their spectra; docs/records.md)");
  synth->add_option("--spectrum", synth_opts.spectrum, "target spectrum: ec8 (EN 1998-1 Type 1)")
      ->capture_default_str();
  synth->add_option("--ag", synth_opts.ag, "design ground acceleration on type A ground [g]")
      ->required();
  synth->add_option("--soil", synth_opts.soil, "ground type A, B, C, D or E (EN 1998-1 Table 3.2)")
      ->capture_default_str();
  synth->add_option("--count", synth_opts.count, "number of records")->capture_default_str();
  synth->add_option("--duration", synth_opts.duration, "length of each record [s]")
      ->capture_default_str();
  synth->add_option("--dt", synth_opts.dt, "time step of the records [s]")->capture_default_str();
  synth->add_option("--seed", synth_opts.seed, "seed of the random phases (>= 0)")
      ->capture_default_str();
  synth
      ->add_option("--range", synth_opts.range,
                   "TMIN,TMAX: periods [s] where the mean spectrum is checked against 90% of the "
                   "target (default 0.05,3)")
      ->delimiter(',')
      ->expected(2);
  synth->add_option("-o,--output", synth_opts.output, "output folder")->capture_default_str();
  synth->add_option("--plot", synth_opts.plot,
                    "PNG of the spectra and the first record (default DIR/spectra.png; "
                    "scripts/plot_synth)");
  synth->add_flag("--no-plot", synth_opts.no_plot, "no plot");
  synth->add_option("--json", synth_opts.json, "write a JSON summary to FILE ('-' for stdout)");
  synth->add_option("--threads", synth_opts.threads, "OpenMP threads (records in parallel)")
      ->check(CLI::Range(1, 1024));

  CLI::App* keys =
      app.add_subcommand("keys",
                         "print the deck reference: every key, type, unit, default, allowed values "
                         "(docs/reference/deck.md)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (!speaks) return e.get_exit_code() == 0 ? 0 : 2;
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }

  try {
    // Under mpirun these deal their cells to the ranks; any other command runs on rank 0 alone.
    const bool dealt = sweep->parsed() || stability->parsed() || ida->parsed() ||
                       (pulse->parsed() && pulse_opts.curve);
    if (!dealt && !speaks) return 0;
    for (const CLI::App* cmd : app.get_subcommands()) make_output_folders(*cmd);
    if (keys->parsed()) {
      std::fputs(voussoir::deck_reference_markdown().c_str(), stdout);
      return 0;
    }
    if (synth->parsed()) return voussoir::command_synth(synth_opts);
    if (common.threads > 0) omp_set_num_threads(common.threads);
    if (sweep->parsed()) return voussoir::command_sweep(deck.deck, deck.sets, common, sweep_opts);
    if (stability->parsed())
      return voussoir::command_stability(deck.deck, deck.sets, common, stab_opts);
    const voussoir::Config config = voussoir::load_deck(deck.deck, deck.sets);
    if (check->parsed()) return voussoir::command_check(config, common, check_opts);
    if (run->parsed()) return voussoir::command_run(config, common, run_opts);
    for (const CLI::App* cmd : {capacity, pushover, spread, ida, pulse})
      if (cmd->parsed()) voussoir::require_gravity(config, cmd->get_name());
    if (capacity->parsed()) return voussoir::command_capacity(config, common, cap_opts);
    if (limit->parsed()) return voussoir::command_limit(config, common, limit_opts);
    if (pushover->parsed()) return voussoir::command_pushover(config, common, push_opts);
    if (spread->parsed()) return voussoir::command_spread(config, common, spread_opts);
    if (ida->parsed()) {
      ida_opts.period_given = ida->count("--period") > 0;
      ida_opts.start_given = ida->count("--start") > 0;
      ida_opts.lambda_star_given = ida->count("--lambda-star") > 0;
      return voussoir::command_ida(config, common, ida_opts);
    }
    if (pulse->parsed()) {
      pulse_opts.start_given = pulse->count("--start") > 0;
      pulse_opts.lambda_star_given = pulse->count("--lambda-star") > 0;
      pulse_opts.tilt_reference_given = pulse->count("--tilt-reference") > 0;
      return voussoir::command_pulse(config, common, pulse_opts);
    }
  } catch (const voussoir::DeckError& e) {
    if (speaks) std::fprintf(stderr, "voussoir: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {  // RunError and the rest: a failure during a run
    if (speaks) std::fprintf(stderr, "voussoir: run failed: %s\n", e.what());
    return 1;
  }
  return 2;
}

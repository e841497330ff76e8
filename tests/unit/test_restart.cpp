// Checkpoint and restart of `voussoir run` (docs/robustness.md; engine/checkpoint.hpp): a run
// restarted from a checkpoint ends bit for bit where the uninterrupted run ends -- every node
// position and velocity, every ledger term, the step and the time -- and writes the same series
// and summary. Scene: the shipped circular arch on a coarse mesh under lambda = 0.5 (above its
// lambda* of 0.29), so blocks move and contacts open and close, with a 0.1 mm contact buffer so
// that the broad phase re-detects several times after the restart point.
//
// Contact state (engine/checkpoint.hpp "Contact state"): ContactSystem::save_state/restore_state
// carry the candidate pairs, the friction slip history and the last detection's positions, so
// runs with and without friction restart bit for bit.

#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "commands/common.hpp"
#include "commands/run.hpp"
#include "engine/checkpoint.hpp"
#include "engine/run_loop.hpp"
#include "engine/setup.hpp"
#include "io/deck.hpp"
#include "subprocess.hpp"

namespace voussoir {
namespace {

namespace fs = std::filesystem;

constexpr double kEndTime = 0.012;  // [s], about 17000 steps

Config arch(double friction, double end_time) {
  return load_deck(std::string(VOUSSOIR_SOURCE_DIR) + "/cases/circular_arch.toml",
                   {"material.model=elastic", "mesh.through_thickness=1", "load.lambda=0.5",
                    "contact.buffer=0.0001",
                    "contact.friction=" + std::to_string(friction),
                    "solver.end_time=" + std::to_string(end_time), "output.every=0.002"});
}

// Bitwise equality of two doubles (also NaN payloads and signed zeros).
bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

void expect_same_state(const Simulation& a, const Simulation& b) {
  EXPECT_EQ(a.step, b.step);
  EXPECT_TRUE(same_bits(a.ctx.time, b.ctx.time));
  const Nodes& na = a.model.nodes;
  const Nodes& nb = b.model.nodes;
  ASSERT_EQ(na.size(), nb.size());
  int differ = 0;
  for (Index i = 0; i < na.size(); ++i) {
    const bool same = same_bits(na.x[i], nb.x[i]) && same_bits(na.y[i], nb.y[i]) &&
                      same_bits(na.vx[i], nb.vx[i]) && same_bits(na.vy[i], nb.vy[i]);
    if (!same && differ++ < 5)
      ADD_FAILURE() << "node " << i << ": (" << na.x[i] << ", " << na.y[i] << ", " << na.vx[i]
                    << ", " << na.vy[i] << ") vs (" << nb.x[i] << ", " << nb.y[i] << ", "
                    << nb.vx[i] << ", " << nb.vy[i] << ")";
  }
  EXPECT_EQ(differ, 0) << "nodes differing in position or velocity";
  const EnergyLedger& la = a.ledger;
  const EnergyLedger& lb = b.ledger;
  EXPECT_TRUE(same_bits(la.kinetic, lb.kinetic));
  EXPECT_TRUE(same_bits(la.strain, lb.strain));
  EXPECT_TRUE(same_bits(la.contact, lb.contact));
  EXPECT_TRUE(same_bits(la.external_work, lb.external_work));
  EXPECT_TRUE(same_bits(la.damping_dissipated, lb.damping_dissipated));
  EXPECT_TRUE(same_bits(la.friction_dissipated, lb.friction_dissipated));
  EXPECT_TRUE(same_bits(la.max_energy, lb.max_energy));
  // The broad phase detected at the same steps (its reference positions were restored).
  EXPECT_EQ(a.contact.detections(), b.contact.detections());
  EXPECT_EQ(a.contact.candidate_pairs(), b.contact.candidate_pairs());
  EXPECT_EQ(a.contact.active_pairs(), b.contact.active_pairs());
}

std::vector<double> read_series(const std::string& file, const std::string& name) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return {};
  const hid_t d = H5Dopen2(f, ("/series/" + name).c_str(), H5P_DEFAULT);
  std::vector<double> v;
  if (d >= 0) {
    const hid_t space = H5Dget_space(d);
    const hssize_t n = H5Sget_simple_extent_npoints(space);
    v.resize(static_cast<std::size_t>(n));
    H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    H5Sclose(space);
    H5Dclose(d);
  }
  H5Fclose(f);
  return v;
}

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

struct Scratch {
  fs::path dir;
  explicit Scratch(const std::string& name) : dir(fs::temp_directory_path() / name) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  ~Scratch() { fs::remove_all(dir); }
  std::string operator/(const std::string& f) const { return (dir / f).string(); }
};

// Runs `voussoir run` in process (run_simulation) and returns the final simulation.
Simulation run(const Config& config, const RunOptions& opts, const std::string& json) {
  SetupInfo info;
  Simulation sim = make_simulation(config, &info);
  CommonOptions common;
  common.quiet = true;
  common.json_path = json;
  run_simulation(sim, info, config, common, opts);
  return sim;
}

// Uninterrupted run to kEndTime versus: run to `stop` with checkpoints, then restart to
// kEndTime. Final state, series and summary must agree bit for bit.
void check_restart_identity(double friction, double stop, const std::string& tag) {
  Scratch s("voussoir_restart_" + tag);
  RunOptions full;
  full.output = s / "full.h5";
  const Simulation a = run(arch(friction, kEndTime), full, s / "full.json");
  // The restart must cover re-detections after the restart point, and friction must work.
  ASSERT_GE(a.contact.detections(), 4);
  if (friction > 0.0) {
    EXPECT_GT(a.ledger.friction_dissipated, 0.0);
  }

  RunOptions first;
  first.output = s / "first.h5";
  first.checkpoint_every = stop / 3.0;
  first.checkpoint = s / "run.ckpt";
  const Simulation half = run(arch(friction, stop), first, "");
  ASSERT_TRUE(fs::exists(first.checkpoint));
  EXPECT_FALSE(fs::exists(first.checkpoint + ".tmp"));
  EXPECT_LT(half.step, a.step);

  RunOptions second;
  second.output = s / "second.h5";
  second.restart = first.checkpoint;
  const Simulation b = run(arch(friction, kEndTime), second, s / "second.json");
  expect_same_state(a, b);

  // The series of the restarted file (rows before the restart come from the checkpoint) is
  // the uninterrupted one.
  for (const char* name :
       {"time", "kinetic", "strain", "contact", "external_work", "damping_dissipated",
        "friction_dissipated", "max_displacement", "energy_balance_error"}) {
    const std::vector<double> ra = read_series(full.output, name);
    const std::vector<double> rb = read_series(second.output, name);
    ASSERT_FALSE(ra.empty()) << name;
    ASSERT_EQ(ra.size(), rb.size()) << name;
    EXPECT_EQ(std::memcmp(ra.data(), rb.data(), ra.size() * sizeof(double)), 0) << name;
  }
  // And so is the summary, but for wall times and file names.
  nlohmann::json ja = read_json(s / "full.json"), jb = read_json(s / "second.json");
  for (nlohmann::json* j : {&ja, &jb})
    for (const char* k : {"wall_s", "output", "restarted_from", "checkpoint"}) j->erase(k);
  EXPECT_EQ(ja, jb);
}

TEST(Restart, FrictionlessRunRestartsBitForBit) {
  // Stopped at 5/12 of the way: checkpoints at 1/3 and 2/3 of that and at its end.
  check_restart_identity(0.0, 0.005, "mu0");
}

TEST(Restart, RunWithFrictionRestartsBitForBit) {
  check_restart_identity(0.6, 0.005, "mu06");
}

TEST(Restart, LoopCheckpointMidRunAndResume) {
  // The checkpoints written by run_loop itself between two samples (not at the end of a run):
  // "killed" right after the second one, resumed from it, compared with the uninterrupted loop.
  const Config config = arch(0.0, kEndTime);
  Simulation a = make_simulation(config);
  LoopOptions opts;
  opts.end_time = kEndTime;
  opts.sample_every = 0.0007;  // not a divisor of the checkpoint interval
  opts.quiet = true;
  std::vector<double> times_a;
  run_loop(a, opts, [&](const Simulation& s) {
    times_a.push_back(s.ctx.time);
    return true;
  });

  Scratch s("voussoir_restart_loop");
  const std::string ckpt = s / "loop.ckpt";
  Simulation b = make_simulation(config);
  const std::uint64_t key = simulation_fingerprint(b, 0.0);
  struct Killed {};
  int written = 0;
  LoopOptions with = opts;
  with.checkpoint_every = 0.0031;
  with.checkpoint = [&](const Simulation& sim, const LoopStats& st) {
    write_checkpoint(ckpt, sim, key, 0.0, {static_cast<double>(st.max_active_pairs)});
    if (++written == 2) throw Killed{};
  };
  std::vector<double> times_b;
  EXPECT_THROW(run_loop(b, with,
                        [&](const Simulation& sim) {
                          times_b.push_back(sim.ctx.time);
                          return true;
                        }),
               Killed);
  const long long killed_at = b.step;
  EXPECT_GT(killed_at, 0);

  Simulation c = make_simulation(config);
  const std::vector<double> driver = read_checkpoint(ckpt, c, key);
  ASSERT_EQ(driver.size(), 1u);
  EXPECT_EQ(c.step, killed_at);
  LoopStats resume;
  resume.max_active_pairs = static_cast<std::int64_t>(driver[0]);
  run_loop(
      c, opts,
      [&](const Simulation& sim) {
        times_b.push_back(sim.ctx.time);
        return true;
      },
      resume);
  expect_same_state(a, c);
  // Samples at the same steps: the killed part and the resumed part add up to the whole.
  ASSERT_EQ(times_a.size(), times_b.size());
  for (std::size_t k = 0; k < times_a.size(); ++k) EXPECT_TRUE(same_bits(times_a[k], times_b[k]));
}

TEST(Restart, RefusesAnotherModelOrABrokenFile) {
  Scratch s("voussoir_restart_refuse");
  RunOptions first;
  first.checkpoint_every = 0.001;
  first.checkpoint = s / "run.ckpt";
  run(arch(0.0, 0.002), first, "");
  ASSERT_TRUE(fs::exists(first.checkpoint));

  auto restart_message = [&](const Config& config, const std::string& file) {
    RunOptions opts;
    opts.restart = file;
    try {
      run(config, opts, "");
    } catch (const DeckError& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  // Another model: other thickness, other friction, other time step.
  Config thick = arch(0.0, 0.004);
  thick.model.thickness = 0.25;
  EXPECT_NE(restart_message(thick, first.checkpoint).find("another model"), std::string::npos);
  EXPECT_NE(restart_message(arch(0.1, 0.004), first.checkpoint).find("another"), std::string::npos);
  Config safer = arch(0.0, 0.004);
  safer.solver.dt_safety = 0.4;
  EXPECT_NE(restart_message(safer, first.checkpoint).find("another"), std::string::npos);
  // Same model, longer end time: accepted (extends the run).
  EXPECT_EQ(restart_message(arch(0.0, 0.004), first.checkpoint), "(accepted)");
  // Missing, truncated, corrupt, not a checkpoint.
  EXPECT_NE(restart_message(arch(0.0, 0.004), s / "none.ckpt").find("no such file"),
            std::string::npos);
  std::string bytes;
  {
    std::ifstream in(first.checkpoint, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  auto write = [&](const std::string& name, const std::string& content) {
    std::ofstream(s / name, std::ios::binary) << content;
    return s / name;
  };
  for (std::size_t cut : {std::size_t(0), std::size_t(10), bytes.size() / 2, bytes.size() - 1}) {
    const std::string msg =
        restart_message(arch(0.0, 0.004), write("cut.ckpt", bytes.substr(0, cut)));
    EXPECT_NE(msg.find("restart file"), std::string::npos) << cut << ": " << msg;
  }
  std::string flipped = bytes;
  flipped[flipped.size() / 2] ^= 0x10;
  EXPECT_NE(restart_message(arch(0.0, 0.004), write("flip.ckpt", flipped)).find("checksum"),
            std::string::npos);
  EXPECT_NE(restart_message(arch(0.0, 0.004),
                            std::string(VOUSSOIR_SOURCE_DIR) + "/cases/circular_arch.toml")
                .find("not a voussoir checkpoint"),
            std::string::npos);
}

TEST(Restart, ProgramOptions) {
  // Through the program: checkpoint next to the output, restart, exit statuses.
  Scratch s("voussoir_restart_cli");
  const std::string deck = std::string(VOUSSOIR_SOURCE_DIR) + "/cases/circular_arch.toml";
  const std::vector<std::string> base = {
      VOUSSOIR_BINARY,     "run", deck, "-q", "--set", "material.model=elastic", "--set",
      "mesh.through_thickness=1", "--set", "contact.friction=0"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = base;
    args.insert(args.end(), extra.begin(), extra.end());
    return testing::run_process(args, {}, s / "child");
  };
  const auto first =
      with({"--set", "solver.end_time=0.002", "-o", s / "a.h5", "--checkpoint-every", "0.001"});
  ASSERT_TRUE(first.exited && first.status == 0) << first.describe() << first.err;
  EXPECT_TRUE(fs::exists(s / "a.h5.ckpt"));  // default: next to the output
  const auto second = with({"--set", "solver.end_time=0.003", "-o", s / "b.h5", "--restart",
                            s / "a.h5.ckpt", "--json", s / "b.json"});
  ASSERT_TRUE(second.exited && second.status == 0) << second.describe() << second.err;
  EXPECT_EQ(read_json(s / "b.json")["restarted_from"], s / "a.h5.ckpt");
  const auto missing = with({"--restart", s / "nothing.ckpt"});
  EXPECT_TRUE(missing.exited && missing.status == 2) << missing.describe();
  EXPECT_NE(missing.err.find("no such file"), std::string::npos) << missing.err;
  const auto negative = with({"--checkpoint-every", "-1"});
  EXPECT_TRUE(negative.exited && negative.status == 2) << negative.describe();
  // With friction (the deck's mu = 0.6): checkpoints are written and a restart continues.
  auto with_friction = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = {VOUSSOIR_BINARY,           "run", deck, "-q", "--set",
                                     "mesh.through_thickness=1"};
    args.insert(args.end(), extra.begin(), extra.end());
    return testing::run_process(args, {}, s / "child");
  };
  const auto written = with_friction(
      {"--set", "solver.end_time=0.002", "-o", s / "f.h5", "--checkpoint-every", "0.001"});
  ASSERT_TRUE(written.exited && written.status == 0) << written.describe() << written.err;
  const auto resumed = with_friction(
      {"--set", "solver.end_time=0.003", "-o", s / "g.h5", "--restart", s / "f.h5.ckpt"});
  EXPECT_TRUE(resumed.exited && resumed.status == 0) << resumed.describe() << resumed.err;
}

}  // namespace
}  // namespace voussoir

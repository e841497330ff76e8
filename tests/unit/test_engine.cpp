// The engine (engine/trial.hpp): its guards in every classified run, its load program, and
// its limits on the command line. The guard tests run the program end to end: a deck value
// the reader accepts whose run overflows, in a capacity trial, a pulse run and a stability
// cell; each must exit with status 1 and a message naming the run, the time and the quantity.

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "engine/setup.hpp"
#include "engine/trial.hpp"
#include "io/deck.hpp"
#include "io/plot.hpp"
#include "subprocess.hpp"

namespace voussoir {
namespace {

namespace fs = std::filesystem;

std::string case_path(const std::string& name) {
  return std::string(VOUSSOIR_SOURCE_DIR) + "/cases/" + name + ".toml";
}

testing::ProcessResult run_voussoir(const std::string& scratch, std::vector<std::string> args) {
  const fs::path dir = fs::temp_directory_path() / ("voussoir_engine_" + scratch);
  fs::remove_all(dir);
  fs::create_directories(dir);
  args.insert(args.begin(), VOUSSOIR_BINARY);
  return testing::run_process(args, {}, (dir / "child").string());
}

// Exit status 1, "run failed: non-finite QUANTITY in RUN at step S (t = T s)".
void expect_guard_stop(const testing::ProcessResult& r, const std::string& run) {
  ASSERT_TRUE(r.exited) << r.describe();
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("run failed: non-finite "), std::string::npos) << r.err;
  const bool quantity = r.err.find("non-finite velocity") != std::string::npos ||
                        r.err.find("non-finite force") != std::string::npos ||
                        r.err.find("non-finite position") != std::string::npos ||
                        r.err.find("energy") != std::string::npos;
  EXPECT_TRUE(quantity) << r.err;
  EXPECT_NE(r.err.find("in " + run), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(t = "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("of block"), std::string::npos) << r.err;
  std::printf("[engine] %s", r.err.c_str());
}

TEST(EngineGuards, NonFiniteForceStopsACapacityTrial) {
  // The settle is sound; the deck's bracket end lambda = 1e300 overflows the horizontal load.
  expect_guard_stop(run_voussoir("capacity", {"capacity", case_path("block"), "--set",
                                              "capacity.lambda_max=1e300", "-q"}),
                    "the capacity trial lambda = 1e+300");
}

TEST(EngineGuards, NonFiniteForceStopsAPulseRun) {
  expect_guard_stop(run_voussoir("pulse", {"pulse", case_path("block"), "--set",
                                           "load.base.signal=windowed_sine", "--set",
                                           "load.base.frequency=4", "--set",
                                           "load.base.amplitude=1e300", "-q"}),
                    "the pulse run");
}

TEST(EngineGuards, NonFiniteForceStopsAStabilityCell) {
  const std::string csv = (fs::temp_directory_path() / "voussoir_engine_map.csv").string();
  expect_guard_stop(run_voussoir("stability", {"stability", case_path("block"), "--param",
                                               "load.gravity=1e300", "--csv", csv, "-q"}),
                    "the stability cell load.gravity=1e300");
}

TEST(EngineLimits, MaxStepsStopsEveryClassifiedCommand) {
  // --max-steps 500: the settle of the block (about 64000 steps) is the first run to pass it.
  const std::string csv = (fs::temp_directory_path() / "voussoir_engine_steps.csv").string();
  const std::vector<std::vector<std::string>> commands = {
      {"run", case_path("block"), "--set", "solver.end_time=0.01"},
      {"capacity", case_path("block")},
      {"pulse", case_path("block"), "--set", "load.base.signal=windowed_sine", "--set",
       "load.base.frequency=4"},
      {"stability", case_path("block"), "--param", "contact.friction=0.6", "--csv", csv},
      {"sweep", case_path("block"), "--param", "contact.friction=0.6", "--csv", csv}};
  for (std::vector<std::string> args : commands) {
    const std::string name = args[0];
    args.insert(args.end(), {"--max-steps", "500", "-q"});
    const testing::ProcessResult r = run_voussoir("steps_" + name, args);
    ASSERT_TRUE(r.exited) << name << ": " << r.describe();
    EXPECT_EQ(r.status, 1) << name << ": " << r.err;
    EXPECT_NE(r.err.find("--max-steps 500 reached in "), std::string::npos)
        << name << ": " << r.err;
    EXPECT_NE(r.err.find("(t = "), std::string::npos) << name << ": " << r.err;
  }
  // Far above what the run needs: no effect.
  const testing::ProcessResult ok =
      run_voussoir("steps_ok", {"run", case_path("block"), "--set", "solver.end_time=0.01",
                                "--max-steps", "100000", "-q"});
  EXPECT_EQ(ok.status, 0) << ok.err;
}

TEST(LoadProgram, RampsAndSignalFromTheSimulationTime) {
  Simulation sim = make_simulation(load_deck(case_path("block"), {}));
  const BaseSignal signal = BaseSignal::one_sine(2.0, 1.0);  // 2 m/s2 at 1 Hz
  LoadProgram p;
  p.gravity = 10.0;
  p.gravity_ramp = 0.5;
  p.lambda = 0.2;
  p.lambda_ramp = 1.0;
  p.start = 1.0;
  p.signal = &signal;
  p.signal_start = 1.0;
  sim.ctx.time = 1.25;  // gravity half on, lambda a quarter on, the sine at its peak
  p.apply(sim);
  EXPECT_DOUBLE_EQ(sim.ctx.body_ay, -5.0);
  EXPECT_DOUBLE_EQ(sim.ctx.body_ax, 0.2 * 0.25 * 10.0 - 2.0);
  sim.ctx.time = 3.0;  // ramps done; the one-cycle sine is over
  p.apply(sim);
  EXPECT_DOUBLE_EQ(sim.ctx.body_ay, -10.0);
  EXPECT_DOUBLE_EQ(sim.ctx.body_ax, 2.0);
}

TEST(Plot, AFailedScriptIsAWarningNotAnError) {
  // io/plot.hpp: a script that fails (here: one that does not exist) returns false and
  // says so on stderr; nothing is thrown, so the command's exit status stays that of its result.
  EXPECT_FALSE(draw_with_script("no_such_script", {"a.csv", "-o", "a.png"}, "a.png"));
}

}  // namespace
}  // namespace voussoir

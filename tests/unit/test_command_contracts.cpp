// What the program promises at its edges (docs/reference/commands.md, exit statuses): the help's
// defaults are the ones the code uses, and the docs say the same; a deck without gravity is
// refused by name by every analysis whose loads are multiples of the weight, and run by `run`;
// options that cannot mean anything (--lambda-star negative or NaN, --thrust with
// --gravity-only) are refused with exit 2 naming them; a deck's supports.moves error names the
// deck's line; `synth` exits 1 when its set fails the EN 1998-1 rule, its JSON written with
// `wall_s` as every command writes it.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands/pushover.hpp"
#include "subprocess.hpp"

namespace voussoir {
namespace {

const std::string kBlock = std::string(VOUSSOIR_SOURCE_DIR) + "/cases/block.toml";

std::filesystem::path scratch_dir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / name;
  std::filesystem::create_directories(dir);
  return dir;
}

testing::ProcessResult voussoir(const std::vector<std::string>& args,
                                const std::filesystem::path& dir) {
  std::vector<std::string> all = {VOUSSOIR_BINARY};
  all.insert(all.end(), args.begin(), args.end());
  return testing::run_process(all, {}, (dir / "child").string());
}

std::string read_file(const std::filesystem::path& p) {
  return testing::read_text_file(p);
}

TEST(CommandContracts, PushoverHelpStatesTheRateTheRunUses) {
  const auto dir = scratch_dir("voussoir_contract_help");
  const testing::ProcessResult r = voussoir({"pushover", "--help"}, dir);
  ASSERT_TRUE(r.exited && r.status == 0) << r.describe() << r.err;
  const std::string want = "(default " + option_number(kRateFactor) + " sqrt(g L_ref))";
  EXPECT_NE(r.out.find(want), std::string::npos) << r.out;
  // The command reference is the help as printed (scripts/reference_commands; pushover's page
  // is docs/reference/commands/statics.md).
  const std::string doc =
      read_file(std::filesystem::path(VOUSSOIR_SOURCE_DIR) / "docs/reference/commands/statics.md");
  const std::size_t at = doc.find("--rate FLOAT");
  ASSERT_NE(at, std::string::npos);
  const std::string line = doc.substr(at, doc.find('\n', at) - at);
  EXPECT_NE(line.find(want), std::string::npos) << line;
  std::filesystem::remove_all(dir);
}

TEST(CommandContracts, WeightlessDeckRefusedByNameWhereTheLoadsAreMultiplesOfTheWeight) {
  const auto dir = scratch_dir("voussoir_contract_gravity");
  const std::vector<std::vector<std::string>> commands = {
      {"capacity"},
      {"limit"},
      {"pushover"},
      {"spread"},
      {"pulse"},
      {"ida", "--records", (dir / "none.AT2").string(), "--csv", (dir / "ida.csv").string()},
      {"sweep", "--param", "contact.friction=0.7,0.8", "--csv", (dir / "s.csv").string()},
      {"stability", "--param", "contact.friction=0.7,0.8", "--csv", (dir / "st.csv").string()}};
  for (const std::vector<std::string>& c : commands) {
    std::vector<std::string> args = {c[0], kBlock, "-q", "--set", "load.gravity=0"};
    args.insert(args.end(), c.begin() + 1, c.end());
    const testing::ProcessResult r = voussoir(args, dir);
    ASSERT_TRUE(r.exited) << c[0] << ": " << r.describe();
    EXPECT_EQ(r.status, 2) << c[0] << ": " << r.err;
    EXPECT_NE(r.err.find("load.gravity = 0"), std::string::npos) << c[0] << ": " << r.err;
    EXPECT_NE(r.err.find("`" + c[0] + "` needs gravity > 0"), std::string::npos)
        << c[0] << ": " << r.err;
  }
  // `run` takes it: a weightless run of 2 ms.
  const testing::ProcessResult run =
      voussoir({"run", kBlock, "-q", "--set", "load.gravity=0", "--set", "solver.end_time=0.002",
                "--set", "mesh.size=0.5", "-o", (dir / "w.h5").string()},
               dir);
  EXPECT_TRUE(run.exited && run.status == 0) << run.describe() << run.err;
  std::filesystem::remove_all(dir);
}

TEST(CommandContracts, MeaninglessOptionsRefusedWithStatusTwo) {
  const auto dir = scratch_dir("voussoir_contract_options");
  const std::string record = (dir / "r.txt").string();
  {
    std::ofstream f(record);
    f << "0 0\n0.01 0.1\n0.02 0\n";
  }
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"ida", kBlock, "--records", record, "--lambda-star", "-1"}, "--lambda-star -1"},
      {{"ida", kBlock, "--records", record, "--lambda-star", "nan"}, "--lambda-star nan"},
      {{"ida", kBlock, "--records", record, "--lambda-star", "0"}, "--lambda-star 0"},
      {{"pulse", kBlock, "--curve", "--freqs", "2", "--lambda-star", "-0.5"}, "--lambda-star -0.5"},
      {{"limit", kBlock, "--thrust", "min", "--gravity-only"}, "--gravity-only"}};
  for (const auto& [args, named] : cases) {
    std::vector<std::string> all = args;
    all.push_back("-q");
    const testing::ProcessResult r = voussoir(all, dir);
    ASSERT_TRUE(r.exited) << named << ": " << r.describe();
    EXPECT_EQ(r.status, 2) << named << ": " << r.err;
    EXPECT_NE(r.err.find(named), std::string::npos) << r.err;
  }
  std::filesystem::remove_all(dir);
}

// A move of a block that is not fixed: the message names the deck's line of `block`.
TEST(CommandContracts, SupportsMoveErrorNamesTheDeckLine) {
  const auto dir = scratch_dir("voussoir_contract_supports");
  const std::filesystem::path deck = dir / "moved.toml";
  {
    std::ofstream f(deck);
    // Block 1 is the fixed ground, block 0 the free block.
    f << read_file(kBlock) << "\n[supports]\nramp = 0.1\nmoves = [\n  {block = 1, dx = 0.001},\n"
      << "  {block = 0, dx = 0.002},\n]\n";
  }
  int lines = 0;
  for (char c : read_file(kBlock)) lines += c == '\n';
  const testing::ProcessResult r = voussoir({"check", deck.string(), "-q"}, dir);
  ASSERT_TRUE(r.exited) << r.describe();
  EXPECT_EQ(r.status, 2) << r.err;
  // The free block's entry, the second: line lines + 6 of moved.toml, its value at column 12.
  const std::string where = deck.string() + ":" + std::to_string(lines + 6) + ":";
  EXPECT_NE(r.err.find(where + "12: supports.moves[1].block = 0"), std::string::npos)
      << r.err << "\nexpected " << where;
  std::filesystem::remove_all(dir);
}

// A run whose plan is absurd (solver.dt_safety = 1e-9: about 1e10 steps for 1e-4 s) is refused
// before it starts, naming the steps and the wall they imply, with exit 2; --max-steps lets it
// start, and it then fails at that step (exit 1), as any run that reaches the limit.
TEST(CommandContracts, AbsurdStepCountRefusedBeforeTheRunUnlessMaxStepsGiven) {
  const auto dir = scratch_dir("voussoir_contract_steps");
  const std::vector<std::string> args = {"run",
                                         kBlock,
                                         "-q",
                                         "--set",
                                         "solver.dt_safety=1e-9",
                                         "--set",
                                         "solver.end_time=1e-4",
                                         "-o",
                                         (dir / "r.h5").string()};
  const testing::ProcessResult r = voussoir(args, dir);
  ASSERT_TRUE(r.exited) << r.describe();
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("steps, about"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("s of wall"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--max-steps"), std::string::npos) << r.err;
  std::vector<std::string> limited = args;
  limited.insert(limited.end(), {"--max-steps", "50"});
  const testing::ProcessResult l = voussoir(limited, dir);
  ASSERT_TRUE(l.exited) << l.describe();
  EXPECT_EQ(l.status, 1) << l.err;
  EXPECT_NE(l.err.find("--max-steps 50"), std::string::npos) << l.err;
  std::filesystem::remove_all(dir);
}

// A set that fails EN 1998-1 3.2.3.1.2 (4) -- periods to 4 s in records of 5 s, one record --
// exits 1 naming the rule, with its records and JSON written; one that meets it exits 0.
TEST(CommandContracts, SynthExitsOneWhenTheSetFailsTheRule) {
  const auto dir = scratch_dir("voussoir_contract_synth");
  auto synth = [&](const std::string& name, const std::vector<std::string>& extra) {
    std::vector<std::string> args = {"synth",
                                     "--ag",
                                     "0.25",
                                     "-o",
                                     (dir / name).string(),
                                     "--no-plot",
                                     "--json",
                                     (dir / (name + ".json")).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return voussoir(args, dir);
  };
  const testing::ProcessResult bad =
      synth("bad", {"--count", "1", "--duration", "5", "--range", "0.05,4"});
  ASSERT_TRUE(bad.exited) << bad.describe();
  const nlohmann::json jb = nlohmann::json::parse(read_file(dir / "bad.json"));
  ASSERT_FALSE(jb.at("ec8_mean_spectrum_ok").get<bool>() && jb.at("ec8_mean_pga_ok").get<bool>())
      << "this set was meant to fail the rule: " << bad.out;
  EXPECT_EQ(bad.status, 1) << bad.err;
  EXPECT_NE(bad.err.find("EN 1998-1 3.2.3.1.2 (4)"), std::string::npos) << bad.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "bad" / "synth_01.AT2"));
  EXPECT_TRUE(jb.contains("wall_s"));
  EXPECT_FALSE(jb.contains("wall_seconds"));
  const testing::ProcessResult good = synth("good", {});
  ASSERT_TRUE(good.exited) << good.describe();
  const nlohmann::json jg = nlohmann::json::parse(read_file(dir / "good.json"));
  ASSERT_TRUE(jg.at("ec8_mean_spectrum_ok").get<bool>() && jg.at("ec8_mean_pga_ok").get<bool>());
  EXPECT_EQ(good.status, 0) << good.err;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace voussoir

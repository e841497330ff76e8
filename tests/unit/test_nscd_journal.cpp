// Journals and --resume under non-smooth contact dynamics (solver.scheme = "nscd";
// docs/nscd.md "Journals, resume and MPI"), as the explicit scheme's tests check them
// (Capacity.ResumesFromItsJournal, PulseCurve.ResumedCurveEqualsTheUninterruptedOne): a run
// whose journal a kill cut, resumed, gives the uninterrupted run's results bit for bit and
// runs only what the journal lacked; a journal of other solver settings is refused, never
// mixed in. Under mpirun: tests/python/mpi_ranks.py --part nscd (ctest mpi_nscd).

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands/capacity.hpp"
#include "io/deck.hpp"
#include "same_search.hpp"
#include "subprocess.hpp"

namespace voussoir {
namespace {

// A rigid 0.5 x 1 block by non-smooth contact dynamics: it slides at lambda* = mu = 0.3.
Config sliding_block(const std::vector<std::string>& sets = {}) {
  return parse_deck(
      "[model]\nkind = \"block\"\nwidth = 0.5\nheight = 1.0\n[material]\nmodel = \"rigid\"\n"
      "[contact]\nfriction = 0.3\n[solver]\nscheme = \"nscd\"\n",
      "nscd_block", sets);
}

std::vector<std::string> lines_of(const std::string& path) {
  std::vector<std::string> lines;
  std::ifstream in(path);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

// Keeps the journal's header and its first `kept` records, and half of the next line: what a
// kill leaves.
void cut_journal(const std::string& path, std::size_t kept) {
  const std::vector<std::string> lines = lines_of(path);
  ASSERT_GT(lines.size(), kept + 1);
  std::ofstream out(path, std::ios::trunc);
  for (std::size_t i = 0; i <= kept; ++i) out << lines[i] << '\n';
  out << lines[kept + 1].substr(0, lines[kept + 1].size() / 2);
}

TEST(NscdJournal, CapacityResumesFromItsJournalBitForBit) {
  CapacitySearch search = journalled_search("nscd_capacity_resume.journal");
  search.seed_from_limit = false;  // a bracket from lambda_max: more trials to cut between
  const Config config = sliding_block({"capacity.lambda_max=1"});
  const CapacityResult full = find_capacity(config, TrialCriteria{}, search);
  ASSERT_TRUE(full.bracketed);
  EXPECT_NEAR(full.lambda_star, 0.3, 0.005 * 0.3);
  ASSERT_GE(full.trials.size(), 5u);
  EXPECT_EQ(full.resumed_trials, 0);
  ASSERT_EQ(lines_of(search.journal).size(), full.trials.size() + 1);

  cut_journal(search.journal, 3);
  const CapacityResult resumed = find_capacity(config, TrialCriteria{}, search);
  EXPECT_EQ(resumed.resumed_trials, 3);
  expect_same_search(resumed, full);
  // The journal again holds each trial once.
  EXPECT_EQ(lines_of(search.journal).size(), full.trials.size() + 1);
}

// The settled state under nscd need not show a change of the solver's settings (a block set on
// its ground is still after the first step at any theta or tolerance), but the trials do: the
// journal's fingerprint carries them, as the checkpoint's does.
TEST(NscdJournal, AJournalOfOtherSolverSettingsIsRefused) {
  CapacitySearch search = journalled_search("nscd_capacity_settings.journal");
  search.seed_from_limit = false;
  const std::vector<std::string> bracket = {"capacity.lambda_max=1"};
  find_capacity(sliding_block(bracket), TrialCriteria{}, search);
  for (const char* other : {"solver.theta=1", "solver.tolerance=1e-4", "solver.max_iterations=50",
                            "solver.scheme=\"explicit\""}) {
    std::vector<std::string> sets = bracket;
    sets.push_back(other);
    EXPECT_THROW(find_capacity(sliding_block(sets), TrialCriteria{}, search), RunError) << other;
  }
  // The same settings resume it (every trial from the journal).
  const CapacityResult again = find_capacity(sliding_block(bracket), TrialCriteria{}, search);
  EXPECT_EQ(again.resumed_trials, static_cast<int>(again.trials.size()));
}

// `pulse --curve --resume` of the rigid block under windowed sines by nscd.
nlohmann::json run_curve(const std::string& name, const std::string& journal) {
  const std::string dir = ::testing::TempDir();
  const std::string json = dir + name + ".json";
  const testing::ProcessResult p =
      testing::run_process({VOUSSOIR_BINARY,
                            "pulse",
                            std::string(VOUSSOIR_SOURCE_DIR) + "/cases/block.toml",
                            "-q",
                            "--set",
                            "material.model=\"rigid\"",
                            "--set",
                            "solver.scheme=\"nscd\"",
                            "--set",
                            "load.base.signal=\"windowed_sine\"",
                            "--curve",
                            "--freqs",
                            "4,2",
                            "--lambda-star",
                            "0.5",
                            "--search",
                            "bisect",
                            "--threads",
                            "2",
                            "--json",
                            json,
                            "--resume",
                            journal},
                           {.wall_s = 120, .cpu_s = 240}, dir + name);
  EXPECT_TRUE(p.exited && p.status == 0) << p.describe() << p.err;
  if (!p.exited || p.status != 0) return nlohmann::json::object();
  return nlohmann::json::parse(testing::read_text_file(json));
}

// A run's record without its wall time.
nlohmann::json without_wall(nlohmann::json run) {
  run.erase("wall_s");
  return run;
}

TEST(NscdJournal, ResumedPulseCurveEqualsTheUninterruptedOne) {
  const std::string journal = ::testing::TempDir() + "nscd_curve_resume.journal";
  std::remove(journal.c_str());
  const nlohmann::json straight = run_curve("nscd_curve_straight", journal);
  ASSERT_TRUE(straight.contains("curve"));
  const std::size_t records = lines_of(journal).size() - 1;
  ASSERT_GE(records, 6u);
  cut_journal(journal, 3);
  const nlohmann::json resumed = run_curve("nscd_curve_resumed", journal);
  ASSERT_TRUE(resumed.contains("curve"));
  ASSERT_EQ(resumed.at("curve").size(), straight.at("curve").size());
  for (std::size_t i = 0; i < straight.at("curve").size(); ++i) {
    const nlohmann::json &a = straight["curve"][i], &b = resumed["curve"][i];
    EXPECT_EQ(a.at("amplitude"), b.at("amplitude"));
    EXPECT_EQ(a.at("bracket"), b.at("bracket"));
    EXPECT_EQ(a.at("trials"), b.at("trials"));
    ASSERT_EQ(a.at("runs").size(), b.at("runs").size());
    for (std::size_t k = 0; k < a.at("runs").size(); ++k)
      EXPECT_EQ(without_wall(a["runs"][k]), without_wall(b["runs"][k])) << i << " run " << k;
  }
  // Each run journalled once: the three kept and the ones run again.
  EXPECT_EQ(lines_of(journal).size(), records + 1);
}

}  // namespace
}  // namespace voussoir

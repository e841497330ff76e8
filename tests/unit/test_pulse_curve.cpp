// `voussoir pulse --curve` on the rigid block of cases/block.toml (width/height = 0.5,
// mu = 0.8): the collapse amplitude of a 3-cycle Bohman-windowed sine at 2 and 4 Hz, two
// frequencies run in parallel. Checks: the JSON and CSV of docs/reference/output.md; the bisection
// bracket (survived at lo, collapsed at hi, hi - lo within the tolerance); and physics: the
// block cannot start rocking unless the pulse peak (0.891 A for 3 cycles) exceeds
// g width/height, so A_c >= 0.5 / 0.891 = 0.561 g, and a faster pulse needs more amplitude
// (Housner: the overturning amplitude grows with frequency above the static threshold).
// Measured: A_c = 2.19 g at 2 Hz, 4.69 g at 4 Hz (bisection brackets within 2%).
// About 4 s of CPU (E lowered to 1 GPa, mesh of one element across).

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands/pulse.hpp"
#include "io/deck.hpp"

namespace {

// A structure that collapses at every amplitude (here: a fall criterion that any motion meets,
// 1e-12 L_ref) stops the search at the smallest amplitude it steps down to (kMinAmplitude):
// no bisection from [0, hi], which a relative tolerance never closes (about 1000 runs, until
// hi underflows). The point says so, with A_c the smallest amplitude run, lo 0, and every run
// collapsed; the search's runs are the steps down and nothing else. `pulse --curve` and `ida`
// share this search.
TEST(PulseCurve, CollapseAtEveryAmplitudeStopsAtTheSmallestTried) {
  using namespace voussoir;
  const Config config = parse_deck(
      "[model]\nkind = \"block\"\nwidth = 0.5\nheight = 1.0\n[material]\nmodel = \"rigid\"\n"
      "[contact]\nfriction = 0.8\nnormal_stiffness = 1e10\n[load.base]\n"
      "signal = \"windowed_sine\"\n",
      "test");
  PulseCriteria crit;
  crit.fall_displacement = 1e-12;
  crit.fall_rotation = 1e-15;
  const SettledState settled = settle(config, crit.settle, true);
  ASSERT_TRUE(settled.settled);
  for (const AmplitudeSearch kind : {AmplitudeSearch::Step, AmplitudeSearch::Bisect}) {
    AmplitudeSearchOptions search;
    search.search = kind;
    search.start = 0.05;
    search.step = 0.5;
    const double growth = kind == AmplitudeSearch::Step ? 1.0 + search.step : kBracketGrowth;
    const CurvePoint p =
        find_collapse_amplitude(settled, config.load.base, 5.0, search, crit, true);
    EXPECT_TRUE(p.collapses_everywhere);
    EXPECT_TRUE(p.bracketed);
    double smallest = search.start;
    for (const PulseResult& r : p.runs) {
      EXPECT_TRUE(r.collapsed) << "A = " << r.amplitude_g;
      smallest = std::min(smallest, r.amplitude_g);
    }
    EXPECT_EQ(p.amplitude, smallest);
    EXPECT_EQ(p.hi, smallest);
    EXPECT_EQ(p.lo, 0.0);
    // start / growth^k for k = 0 .. K, K the first step at or below kMinAmplitude.
    const int steps = static_cast<int>(
        std::ceil(std::log(search.start / kMinAmplitude) / std::log(growth) - 1e-12));
    EXPECT_EQ(p.trials, steps + 1);
    EXPECT_LE(smallest, kMinAmplitude);
    EXPECT_GT(smallest * growth, kMinAmplitude);
    EXPECT_NE(point_note(p).find(kCollapsesEverywhere), std::string::npos) << point_note(p);
  }
}

TEST(PulseCurve, RigidBlockCollapseAmplitudes) {
  const std::string dir = ::testing::TempDir();
  const std::string json = dir + "curve_block.json", csv = dir + "curve_block.csv";
  const std::string cmd = std::string(VOUSSOIR_BINARY) + " pulse " + VOUSSOIR_SOURCE_DIR +
                          "/cases/block.toml -q --set mesh.size=0.5 --set material.young=1e9"
                          " --set load.base.signal=\\\"windowed_sine\\\" --curve --freqs 4,2"
                          " --lambda-star 0.5 --search bisect --threads 2 --csv " +
                          csv + " --json " + json + " > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_DOUBLE_EQ(j.at("lambda_star").get<double>(), 0.5);
  const double peak = j.at("peak_factor").get<double>();
  EXPECT_NEAR(peak, 0.8909, 1e-3);
  const auto& curve = j.at("curve");
  ASSERT_EQ(curve.size(), 2u);
  EXPECT_DOUBLE_EQ(curve[0].at("frequency").get<double>(), 4.0);  // input order kept
  EXPECT_DOUBLE_EQ(curve[1].at("frequency").get<double>(), 2.0);
  double amp[2];
  for (int i = 0; i < 2; ++i) {
    const auto& p = curve[i];
    ASSERT_TRUE(p.at("bracketed").get<bool>());
    const double lo = p.at("bracket")[0].get<double>(), hi = p.at("bracket")[1].get<double>();
    amp[i] = p.at("amplitude").get<double>();
    EXPECT_DOUBLE_EQ(amp[i], hi);
    EXPECT_LE(hi - lo, 0.02 * hi);
    EXPECT_GT(p.at("trials").get<int>(), 2);
    EXPECT_GT(p.at("wall_s").get<double>(), 0.0);
    EXPECT_LT(p.at("max_energy_balance_error").get<double>(), 0.01);
    // The runs at lo and hi are in the list with the matching outcome.
    bool saw_lo = false, saw_hi = false;
    for (const auto& r : p.at("runs")) {
      if (r.at("amplitude").get<double>() == lo && !r.at("collapsed").get<bool>()) saw_lo = true;
      if (r.at("amplitude").get<double>() == hi && r.at("collapsed").get<bool>()) saw_hi = true;
    }
    EXPECT_TRUE(saw_lo) << "frequency " << p.at("frequency");
    EXPECT_TRUE(saw_hi) << "frequency " << p.at("frequency");
    EXPECT_GE(amp[i], 0.5 / peak) << "collapse below the static rocking threshold";
  }
  EXPECT_GT(amp[0], amp[1]);  // 4 Hz needs more than 2 Hz

  std::ifstream c(csv);
  std::string header;
  std::getline(c, header);
  EXPECT_EQ(header.rfind("frequency,amplitude,lo,hi,bracketed,trials,wall_s", 0), 0u);
  int rows = 0;
  for (std::string line; std::getline(c, line);) rows += !line.empty();
  EXPECT_EQ(rows, 2);
}

// `pulse --curve --resume`: a curve killed midway (its journal cut after its first few runs)
// and run again with the same journal gives the same curve as an uninterrupted run, running
// only the missing runs; a journal of another deck is refused with exit status 1.
nlohmann::json run_curve(const std::string& dir, const std::string& name,
                         const std::string& extra) {
  const std::string json = dir + name + ".json";
  const std::string cmd = std::string(VOUSSOIR_BINARY) + " pulse " + VOUSSOIR_SOURCE_DIR +
                          "/cases/block.toml -q --set mesh.size=0.5 --set material.young=1e9"
                          " --set load.base.signal=\\\"windowed_sine\\\" --curve --freqs 4,2"
                          " --lambda-star 0.5 --search bisect --threads 2 --csv " +
                          dir + name + ".csv --json " + json + " " + extra + " > /dev/null";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream in(json);
  return nlohmann::json::parse(in);
}

TEST(PulseCurve, ResumedCurveEqualsTheUninterruptedOne) {
  const std::string dir = ::testing::TempDir();
  const std::string journal = dir + "curve_resume.journal";
  std::remove(journal.c_str());
  const nlohmann::json straight = run_curve(dir, "curve_straight", "--resume " + journal);
  // Cut the journal after its header and three runs, as a kill would leave it.
  std::vector<std::string> lines;
  {
    std::ifstream in(journal);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
  }
  ASSERT_GT(lines.size(), 5u);
  {
    std::ofstream out(journal, std::ios::trunc);
    for (size_t i = 0; i < 4; ++i) out << lines[i] << "\n";
  }
  const nlohmann::json resumed = run_curve(dir, "curve_resumed", "--resume " + journal);
  ASSERT_EQ(resumed.at("curve").size(), straight.at("curve").size());
  for (size_t i = 0; i < straight.at("curve").size(); ++i) {
    const auto &a = straight["curve"][i], &b = resumed["curve"][i];
    EXPECT_EQ(a.at("amplitude"), b.at("amplitude"));
    EXPECT_EQ(a.at("bracket"), b.at("bracket"));
    EXPECT_EQ(a.at("trials"), b.at("trials"));
    for (size_t k = 0; k < a.at("runs").size(); ++k) {
      EXPECT_EQ(a["runs"][k].at("amplitude"), b["runs"][k].at("amplitude"));
      EXPECT_EQ(a["runs"][k].at("collapsed"), b["runs"][k].at("collapsed"));
      EXPECT_EQ(a["runs"][k].at("max_rotation"), b["runs"][k].at("max_rotation"));
      EXPECT_EQ(a["runs"][k].at("steps"), b["runs"][k].at("steps"));
    }
  }
  // The journal holds every run once: the three kept and the ones run again.
  size_t records = 0;
  {
    std::ifstream in(journal);
    for (std::string line; std::getline(in, line);) records += !line.empty();
  }
  EXPECT_EQ(records, lines.size());

  // Another deck (another friction): refused, the journal kept.
  const std::string cmd = std::string(VOUSSOIR_BINARY) + " pulse " + VOUSSOIR_SOURCE_DIR +
                          "/cases/block.toml -q --set mesh.size=0.5 --set material.young=1e9"
                          " --set contact.friction=0.7"
                          " --set load.base.signal=\\\"windowed_sine\\\" --curve --freqs 4"
                          " --lambda-star 0.5 --search bisect --resume " +
                          journal + " > /dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << status;
  std::remove(journal.c_str());
}

}  // namespace

// `voussoir sweep` through the program: a killed sweep resumed from its journal writes the
// same CSV as an uninterrupted one, and finished cells are not run again.

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace {

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Rows of a CSV whose fields hold no commas except inside double quotes.
std::vector<std::vector<std::string>> table(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> row(1);
    bool quoted = false;
    for (char ch : line) {
      if (ch == '"') quoted = !quoted;
      if (ch == ',' && !quoted)
        row.emplace_back();
      else
        row.back() += ch;
    }
    rows.push_back(row);
  }
  return rows;
}

std::size_t column(const std::vector<std::string>& header, const std::string& name) {
  for (std::size_t k = 0; k < header.size(); ++k)
    if (header[k] == name) return k;
  ADD_FAILURE() << "no column " << name;
  return 0;
}

int run(const std::string& args) {
  const std::string cmd = std::string(VOUSSOIR_BINARY) + " " + args + " -q > /dev/null 2>&1";
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

TEST(Sweep, ResumedSweepWritesTheSameCsv) {
  const std::string dir = ::testing::TempDir();
  const std::string deck = std::string(VOUSSOIR_SOURCE_DIR) + "/cases/block.toml";
  // A coarse tolerance keeps each cell to a few trials.
  const std::string grid =
      deck + " --set capacity.tolerance=0.05 --param contact.friction=0.2,0.3,0.9";
  const std::string full_csv = dir + "sweep_full.csv", resumed_csv = dir + "sweep_resumed.csv";
  const std::string journal = dir + "sweep.journal";
  std::remove(journal.c_str());
  const std::string json = dir + "sweep_full.json";
  ASSERT_EQ(run("sweep " + grid + " --csv " + full_csv + " --resume " + journal + " --json " + json),
            0);
  // JSON numbers are numbers: the swept values too.
  const std::string j = read_file(json);
  EXPECT_NE(j.find("\"contact.friction\": 0.2"), std::string::npos) << j;
  EXPECT_EQ(j.find("\"0.2\""), std::string::npos) << j;
  EXPECT_NE(j.find("\"failure_mode\": \"sliding\""), std::string::npos) << j;

  // Keep the header (engine/journal.hpp), the first finished cell and half a line of the
  // second: what a kill leaves.
  std::vector<std::string> lines;
  {
    std::ifstream in(journal);
    for (std::string l; std::getline(in, l);) lines.push_back(l);
  }
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_NE(lines[0].find("fingerprint"), std::string::npos) << lines[0];
  {
    std::ofstream out(journal, std::ios::trunc);
    out << lines[0] << '\n' << lines[1] << '\n' << lines[2].substr(0, lines[2].size() / 2);
  }
  ASSERT_EQ(run("sweep " + grid + " --csv " + resumed_csv + " --resume " + journal), 0);
  // Same results; only the wall times of the re-run cells may differ.
  const std::string a = read_file(full_csv), b = read_file(resumed_csv);
  EXPECT_FALSE(a.empty());
  const std::vector<std::vector<std::string>> ta = table(a), tb = table(b);
  ASSERT_EQ(ta.size(), 4u);
  ASSERT_EQ(tb.size(), ta.size());
  const std::vector<std::string>& header = ta[0];
  const std::size_t wall = column(header, "wall_s");
  for (std::size_t r = 0; r < ta.size(); ++r) {
    ASSERT_EQ(ta[r].size(), header.size()) << a;
    ASSERT_EQ(tb[r].size(), header.size()) << b;
    for (std::size_t k = 0; k < header.size(); ++k)
      if (k != wall || r == 0) {
        EXPECT_EQ(ta[r][k], tb[r][k]) << header[k] << " row " << r;
      }
  }
  // The journalled cell (cells finish in any order) keeps its wall time.
  const std::size_t kept = nlohmann::json::parse(lines[1]).at("cell").get<std::size_t>();
  ASSERT_LT(kept + 1, ta.size());
  EXPECT_EQ(ta[kept + 1][wall], tb[kept + 1][wall]);
  // The resumed run journals only the two cells it ran (plus the one it kept).
  int count = 0;
  {
    std::ifstream in(journal);
    for (std::string l; std::getline(in, l);)
      if (l.find("\"cell\"") != std::string::npos && l.back() == '}') ++count;
  }
  EXPECT_EQ(count, 3);
  // The sliding cells find lambda* = mu on the block's one joint (0) sliding, the overturning
  // one width/height = 0.5 with that joint opened (within the 5% bracket of this coarse
  // sweep); every cell carries its trials and a positive wall time.
  const double expected[3] = {0.2, 0.3, 0.5};
  const char* mode[3] = {"sliding", "sliding", "hinging"};
  for (int c = 0; c < 3; ++c) {
    const std::vector<std::string>& row = ta[c + 1];
    const double lambda_star = std::stod(row[column(header, "lambda_star")]);
    EXPECT_NEAR(lambda_star, expected[c], 0.05 * expected[c]) << a;
    EXPECT_EQ(row[column(header, "failure_mode")], mode[c]) << a;
    EXPECT_EQ(row[column(header, c < 2 ? "sliding_joints" : "hinge_joints")], "0") << a;
    EXPECT_EQ(row[column(header, c < 2 ? "hinge_joints" : "sliding_joints")], "") << a;
    EXPECT_GT(std::stoi(row[column(header, "trials")]), 1) << a;
    EXPECT_GT(std::stod(row[column(header, "wall_s")]), 0.0) << a;
  }
}

TEST(Sweep, BadParamIsRefusedWithExitTwo) {
  const std::string deck = std::string(VOUSSOIR_SOURCE_DIR) + "/cases/block.toml";
  EXPECT_EQ(run("sweep " + deck + " --param contact.friction"), 2);
  EXPECT_EQ(run("sweep " + deck + " --param contact.frictoin=0.2,0.3"), 2);
  EXPECT_EQ(run("sweep " + deck + " --param contact.friction=0.2,,0.3"), 2);
}

}  // namespace

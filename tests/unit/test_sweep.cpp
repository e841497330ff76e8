// `voussoir sweep` through the program: a killed sweep resumed from its journal writes the
// same CSV as an uninterrupted one, and finished cells are not run again.

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
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
  ASSERT_EQ(run("sweep " + grid + " --csv " + full_csv + " --resume " + journal), 0);

  // Keep the header (drivers/journal.hpp), the first finished cell and half a line of the
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
  const std::string a = read_file(full_csv), b = read_file(resumed_csv);
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, b);
  // The resumed run journals only the two cells it ran (plus the one it kept).
  int count = 0;
  {
    std::ifstream in(journal);
    for (std::string l; std::getline(in, l);)
      if (l.find("\"cell\"") != std::string::npos && l.back() == '}') ++count;
  }
  EXPECT_EQ(count, 3);
  // The sliding cells find lambda* = mu, the overturning one width/height = 0.5 (within the
  // 5% bracket of this coarse sweep).
  std::istringstream rows(a);
  std::string row;
  std::getline(rows, row);  // header
  const double expected[3] = {0.2, 0.3, 0.5};
  for (double e : expected) {
    ASSERT_TRUE(std::getline(rows, row));
    const double lambda_star = std::stod(row.substr(row.find(',') + 1));
    EXPECT_NEAR(lambda_star, e, 0.05 * e) << row;
  }
}

TEST(Sweep, BadParamIsRefusedWithExitTwo) {
  const std::string deck = std::string(VOUSSOIR_SOURCE_DIR) + "/cases/block.toml";
  EXPECT_EQ(run("sweep " + deck + " --param contact.friction"), 2);
  EXPECT_EQ(run("sweep " + deck + " --param contact.frictoin=0.2,0.3"), 2);
  EXPECT_EQ(run("sweep " + deck + " --param contact.friction=0.2,,0.3"), 2);
}

}  // namespace

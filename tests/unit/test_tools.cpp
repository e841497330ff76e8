// Files and answers that users' tools take as they are (docs/reference/output.md). Through the
// program:
//   - a wall drawn in gmsh (cases/wall.geo, meshed by Debian's gmsh here): one joint per
//     physical interface (10), the physical names in `check`, its sliding capacity = mu;
//   - `check` refuses a model with no free block or a `fixed` index outside the blocks,
//     naming model.fixed (exit 2);
//   - `capacity` with no collapse says "no collapse up to lambda_max" and gives no lambda*;
//   - docs/reference/deck.md is `voussoir keys`, and every key the reader accepts has its line.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "io/deck.hpp"
#include "io/deck_reference.hpp"
#include "mesh/geometry.hpp"
#include "mesh/scene.hpp"
#include "subprocess.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using voussoir::testing::ProcessResult;

const std::string kSource = VOUSSOIR_SOURCE_DIR;

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path scratch(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / ("voussoir_tools_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

ProcessResult voussoir_run(std::vector<std::string> args, const fs::path& dir,
                           unsigned wall_s = 120) {
  args.insert(args.begin(), VOUSSOIR_BINARY);
  voussoir::testing::Limits limits;
  limits.wall_s = wall_s;
  limits.cpu_s = 4 * wall_s;
  return voussoir::testing::run_process(args, limits, (dir / "child").string());
}

// cases/wall.geo meshed by gmsh into `dir`; fails the test when gmsh is missing
// (scripts/install-deps installs Debian's).
fs::path mesh_wall(const fs::path& dir) {
  const fs::path msh = dir / "wall.msh";
  const std::string cmd = "gmsh -2 -format msh41 '" + kSource + "/cases/wall.geo' -o '" +
                          msh.string() + "' > '" + (dir / "gmsh.log").string() + "' 2>&1";
  const int rc = std::system(cmd.c_str());
  EXPECT_EQ(rc, 0) << "gmsh failed or is not installed (scripts/install-deps installs it): "
                   << read_text(dir / "gmsh.log");
  return msh;
}

TEST(GmshWall, OneJointPerInterfaceAndThePhysicalNames) {
  const fs::path dir = scratch("wall_check");
  const fs::path msh = mesh_wall(dir);
  ASSERT_TRUE(fs::exists(msh));
  const ProcessResult r = voussoir_run(
      {"check", kSource + "/cases/wall.toml", "--set", "model.file=" + msh.string(), "--json",
       (dir / "check.json").string(), "--mesh-out", (dir / "mesh.json").string()},
      dir);
  ASSERT_TRUE(r.exited && r.status == 0) << r.describe() << r.err;
  const json c = json::parse(read_text(dir / "check.json"));
  EXPECT_EQ(c.at("blocks"), 7);
  EXPECT_EQ(c.at("free_blocks"), 6);
  // 3 blocks on the ground, 3 between the courses, 2 in each course (it was 46: one per pair
  // of facing mesh edges).
  EXPECT_EQ(c.at("joints"), 10);
  const std::vector<std::string> names = {"ground",      "block_r0_c0", "block_r0_c1",
                                          "block_r0_c2", "block_r1_c0", "block_r1_c1",
                                          "block_r1_c2"};
  EXPECT_EQ(c.at("block_names").get<std::vector<std::string>>(), names);
  for (const std::string& n : names)
    EXPECT_NE(r.out.find("\"" + n + "\""), std::string::npos) << r.out;
  // The very interfaces, each once: blocks by physical tag order (ground 0, bottom row 1-3,
  // top row 4-6), and each joint spans its whole interface (0.4 m across, 0.3 m up).
  const json m = json::parse(read_text(dir / "mesh.json"));
  std::multiset<std::pair<int, int>> pairs;
  for (const json& j : m.at("joints")) {
    const int a = j.at("blocks")[0], b = j.at("blocks")[1];
    pairs.insert({std::min(a, b), std::max(a, b)});
    const double dx = j.at("b")[0].get<double>() - j.at("a")[0].get<double>();
    const double dy = j.at("b")[1].get<double>() - j.at("a")[1].get<double>();
    const double length = std::hypot(dx, dy);
    const bool vertical = std::abs(dx) < 1e-9;
    EXPECT_NEAR(length, vertical ? 0.3 : 0.4, 1e-9) << j.dump();
  }
  const std::multiset<std::pair<int, int>> expected = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {2, 3},
                                                       {1, 4}, {2, 5}, {3, 6}, {4, 5}, {5, 6}};
  EXPECT_EQ(pairs, expected);
}

TEST(GmshWall, SlidesAtMu) {
  const fs::path dir = scratch("wall_capacity");
  const fs::path msh = mesh_wall(dir);
  ASSERT_TRUE(fs::exists(msh));
  const double mu = 0.4, tolerance = 0.02;
  const ProcessResult r =
      voussoir_run({"capacity", kSource + "/cases/wall.toml", "--set", "model.file=" + msh.string(),
                    "--set", "capacity.tolerance=" + std::to_string(tolerance), "--json",
                    (dir / "cap.json").string(), "-q"},
                   dir, 600);
  ASSERT_TRUE(r.exited && r.status == 0) << r.describe() << r.err;
  const json c = json::parse(read_text(dir / "cap.json"));
  const double lo = c.at("bracket")[0], hi = c.at("bracket")[1];
  // mu within the final bracket's tolerance: |lambda* - mu| <= tolerance x lambda*.
  EXPECT_NEAR(c.at("lambda_star").get<double>(), mu, tolerance * hi) << c.dump();
  EXPECT_EQ(c.at("failure_mode"), "sliding") << c.at("hinges").dump();
  EXPECT_LT(lo, hi);
}

TEST(Joints, PointsAlongASideAreMergedBeforeTheJointSearch) {
  // A ground and two blocks side by side, every side drawn with points along it (as a mesh
  // boundary has): one joint per interface, spanning it, as with the corners alone.
  const fs::path dir = scratch("merge");
  auto write_and_build = [&](const std::string& name, const std::string& blocks) {
    std::ofstream(dir / name) << blocks;
    voussoir::Config c =
        voussoir::parse_deck("[model]\nkind = \"polygons\"\nfile = \"" + name + "\"\nfixed = [0]\n",
                             "deck.toml", {}, dir.string());
    return voussoir::build_model(voussoir::scene_params(c));
  };
  const voussoir::Model corners = write_and_build(
      "corners.txt",
      "-1 -0.2\n1 -0.2\n1 0\n-1 0\n\n-0.5 0\n0 0\n0 1\n-0.5 1\n\n0 0\n0.5 0\n0.5 1\n0 1\n");
  const voussoir::Model dense =
      write_and_build("dense.txt",
                      "-1 -0.2\n1 -0.2\n1 0\n0.75 0\n0.25 0\n-0.25 0\n-0.75 0\n-1 0\n\n"
                      "-0.5 0\n-0.25 0\n0 0\n0 0.3\n0 0.6\n0 1\n-0.5 1\n\n"
                      "0 0\n0.5 0\n0.5 0.5\n0.5 1\n0 1\n0 0.5\n");
  ASSERT_EQ(corners.joints.size(), 3u);
  ASSERT_EQ(dense.joints.size(), corners.joints.size());
  for (std::size_t k = 0; k < dense.joints.size(); ++k) {
    EXPECT_EQ(dense.joints[k].block_a, corners.joints[k].block_a) << k;
    EXPECT_EQ(dense.joints[k].block_b, corners.joints[k].block_b) << k;
    EXPECT_NEAR(voussoir::distance(dense.joints[k].a, corners.joints[k].a), 0.0, 1e-12) << k;
    EXPECT_NEAR(voussoir::distance(dense.joints[k].b, corners.joints[k].b), 0.0, 1e-12) << k;
  }
  // A side that bends (a polygon's real corner, however shallow) is kept.
  const std::vector<voussoir::Vec2> bent = {{0, 0}, {1, 0}, {2, 1e-6}, {2, 1}, {0, 1}};
  EXPECT_EQ(voussoir::merge_collinear(bent).size(), 5u);
  const std::vector<voussoir::Vec2> straight = {{0, 0}, {1, 0}, {2, 0}, {2, 1}, {1, 1}, {0, 1}};
  EXPECT_EQ(voussoir::merge_collinear(straight).size(), 4u);
}

TEST(Check, RefusesModelsThatCannotRun) {
  const fs::path dir = scratch("check_refusals");
  const std::string deck = (dir / "two.toml").string();
  std::ofstream(deck) << "[model]\nkind = \"polygons\"\nfile = \"" << kSource
                      << "/tests/data/two_blocks.txt\"\nfixed = [1]\n";
  ASSERT_EQ(voussoir_run({"check", deck}, dir).status, 0);
  for (const char* fixed : {"[0, 1]", "[2]", "[1, 5]"}) {
    const ProcessResult r =
        voussoir_run({"check", deck, "--set", std::string("model.fixed=") + fixed}, dir);
    EXPECT_TRUE(r.exited && r.status == 2) << fixed << ": " << r.describe() << r.err;
    EXPECT_NE(r.err.find("model.fixed"), std::string::npos) << r.err;
  }
  // Every block fixed: capacity and limit refuse it the same way (they failed with exit 1).
  for (const char* cmd : {"capacity", "limit"}) {
    const ProcessResult r = voussoir_run({cmd, deck, "--set", "model.fixed=[0, 1]", "-q"}, dir);
    EXPECT_TRUE(r.exited && r.status == 2) << cmd << ": " << r.describe() << r.err;
    EXPECT_NE(r.err.find("model.fixed"), std::string::npos) << r.err;
  }
}

TEST(Capacity, NoCollapseIsSaidInWordsWithoutLambdaStar) {
  // A block 20 wide and 1 high with mu = 20 stands up to lambda = 20; the unseeded search
  // stops at its cap (8) with every trial stable.
  const fs::path dir = scratch("no_collapse");
  const ProcessResult r = voussoir_run(
      {"capacity", kSource + "/cases/block.toml", "--set", "model.width=20", "--set",
       "contact.friction=20", "--no-seed", "--json", (dir / "cap.json").string(), "-q"},
      dir, 600);
  ASSERT_TRUE(r.exited && r.status == 0) << r.describe() << r.err;
  EXPECT_NE(r.out.find("no collapse up to lambda_max"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("lambda*"), std::string::npos) << r.out;
  const json c = json::parse(read_text(dir / "cap.json"));
  EXPECT_TRUE(c.at("lambda_star").is_null()) << c.dump();
  EXPECT_EQ(c.at("result"), "no collapse up to lambda_max");
  EXPECT_FALSE(c.at("bracketed").get<bool>());
  double highest = 0.0;
  for (const json& t : c.at("runs")) {
    EXPECT_FALSE(t.at("collapsed").get<bool>());
    highest = std::max(highest, t.at("lambda").get<double>());
  }
  EXPECT_EQ(c.at("lambda_max").get<double>(), highest);
}

TEST(DeckReference, EveryKeyHasAMeaning) {
  const std::vector<voussoir::KeyReference> ref = voussoir::deck_reference();
  EXPECT_EQ(ref.size(), voussoir::known_keys().size());
  for (const voussoir::KeyReference& k : ref) {
    EXPECT_FALSE(k.meaning.empty())
        << "deck key " << k.key
        << " has no meaning in its row of the key table (io/deck.cpp); add it and "
           "regenerate docs/reference/deck.md with build/voussoir keys > docs/reference/deck.md";
    EXPECT_FALSE(k.default_value.empty())
        << "deck key " << k.key << ": its rule shows no default (io/deck.cpp)";
    EXPECT_FALSE(k.type.empty()) << "deck key " << k.key << ": its reader names no type";
    EXPECT_FALSE(k.allowed.empty()) << "deck key " << k.key << ": its reader names no rule";
  }
}

TEST(DeckReference, DocsMatchTheCode) {
  const fs::path dir = scratch("keys");
  const ProcessResult r = voussoir_run({"keys"}, dir);
  ASSERT_TRUE(r.exited && r.status == 0) << r.describe() << r.err;
  EXPECT_EQ(r.out, voussoir::deck_reference_markdown());
  const std::string docs = read_text(kSource + "/docs/reference/deck.md");
  // Name the keys whose row is missing or differs, then compare the whole file.
  std::istringstream lines(r.out);
  std::string section;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("## [", 0) == 0) section = line.substr(4, line.size() - 5);
    if (line.rfind("| `", 0) != 0) continue;
    const std::string key = section + "." + line.substr(3, line.find('`', 3) - 3);
    EXPECT_NE(docs.find(line + "\n"), std::string::npos)
        << "docs/reference/deck.md: the row of deck key " << key
        << " is missing or stale; regenerate with build/voussoir keys > docs/reference/deck.md";
  }
  EXPECT_EQ(docs, r.out)
      << "docs/reference/deck.md is stale: build/voussoir keys > docs/reference/deck.md";
}

}  // namespace

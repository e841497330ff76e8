// Gravity-only stability maps (commands/stability.hpp, `voussoir stability`).
//
// Scene: the shipped semicircular arch (cases/circular_arch.toml: Rc = 1 m, 11 voussoirs) on a
// coarse mesh (one element through the thickness) with soft blocks (E = 40 MPa, so a 1 m arch
// under gravity still strains only ~5e-4) to keep the time step large and the test fast. The
// rigid-block minimum thickness of a semicircular arch is t/R ~ 0.107 (Heyman 0.1075), so
// t/R = 0.25 must stand and t/R = 0.05 must fall, whatever the details of the criteria.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "commands/stability.hpp"
#include "io/deck.hpp"

namespace voussoir {
namespace {

const std::string kDeck = std::string(VOUSSOIR_SOURCE_DIR) + "/cases/circular_arch.toml";
const std::vector<std::string> kCoarse = {"material.model=elastic", "mesh.through_thickness=1",
                                          "material.young=4e7"};

StabilityCriteria fast_criteria() {
  StabilityCriteria c;
  c.ke_time = 0.3;         // [s] the thin arch crosses the threshold at ~0.1 s; the thick one has
                           // stopped ringing after the ramp (KE/MgRc ~1e-7; 8e-7 at 0.2 s)
  c.trial.max_time = 1.5;  // [s] the thick arch is at rest by ~0.7 s
  return c;
}

Config arch(double ratio, double mu) {
  std::vector<std::string> sets = kCoarse;
  sets.push_back("model.thickness=" + std::to_string(ratio));  // Rc = 1
  sets.push_back("contact.friction=" + std::to_string(mu));
  return load_deck(kDeck, sets);
}

TEST(StabilityRange, ExpandsWithoutFloatingDrift) {
  const std::vector<std::string> v = expand_range("0.2:0.8:0.05");
  ASSERT_EQ(v.size(), 13u);
  EXPECT_EQ(v.front(), "0.20");
  EXPECT_EQ(v[5], "0.45");
  EXPECT_EQ(v.back(), "0.80");
  EXPECT_EQ(std::strtod(v.back().c_str(), nullptr), 0.8);  // the deck reads exactly 0.8
  for (size_t i = 0; i < v.size(); ++i)
    EXPECT_NEAR(std::strtod(v[i].c_str(), nullptr), 0.2 + 0.05 * i, 1e-15) << i;

  const GridAxis t = parse_grid_param("model.thickness_ratio=0.05:0.25:0.01");
  EXPECT_EQ(t.key, kThicknessRatioKey);
  ASSERT_EQ(t.values.size(), 21u);
  EXPECT_EQ(t.values.back(), "0.25");
  // Lists and ranges mix; a stop off the grid is not passed.
  const GridAxis m = parse_grid_param("contact.friction=0.1,0.3:0.5:0.1,0.9");
  EXPECT_EQ(m.values, (std::vector<std::string>{"0.1", "0.3", "0.4", "0.5", "0.9"}));
  EXPECT_EQ(expand_range("0:1:0.3"), (std::vector<std::string>{"0.0", "0.3", "0.6", "0.9"}));

  EXPECT_THROW(expand_range("0.2:0.8:0"), DeckError);
  EXPECT_THROW(expand_range("0.8:0.2:0.05"), DeckError);
  EXPECT_THROW(expand_range("0.2:0.8"), DeckError);
  EXPECT_THROW(parse_grid_param("contact.friction"), DeckError);
  EXPECT_THROW(parse_grid_param("model.thickness_ratio=-0.1"), DeckError);
}

TEST(Grid, ThicknessRatioScalesWithRadius) {
  std::vector<std::string> sets = kCoarse;
  sets.push_back("model.radius=10");
  const Grid g = make_grid(kDeck, sets,
                           {parse_grid_param("contact.friction=0.3,0.7"),
                            parse_grid_param("model.thickness_ratio=0.05,0.13")});
  ASSERT_EQ(g.configs.size(), 4u);
  // Row-major, last axis fastest.
  EXPECT_EQ(g.values[1], (std::vector<std::string>{"0.3", "0.13"}));
  EXPECT_DOUBLE_EQ(g.configs[0].model.thickness, 0.5);
  EXPECT_DOUBLE_EQ(g.configs[1].model.thickness, 1.3);
  EXPECT_DOUBLE_EQ(g.configs[2].contact.friction, 0.7);
  EXPECT_DOUBLE_EQ(g.configs[3].model.thickness, 1.3);
}

TEST(StabilityCell, ThickArchStandsThinArchFalls) {
  const StabilityCriteria crit = fast_criteria();
  StabilityCell thick = run_stability_cell(arch(0.25, 0.8), crit, false);
  EXPECT_TRUE(thick.stable) << thick.reason;
  EXPECT_EQ(thick.reason, "rest");
  EXPECT_LT(thick.max_displacement, crit.trial.collapse_displacement * thick.l_ref);
  EXPECT_LT(thick.normalised_kinetic_energy, 1e-6);
  EXPECT_DOUBLE_EQ(thick.ke_length, 1.0);  // Rc

  StabilityCell thin = run_stability_cell(arch(0.05, 0.8), crit, true);
  EXPECT_FALSE(thin.stable);
  EXPECT_EQ(thin.reason, "displacement");
  EXPECT_LT(thin.decision_time, crit.ke_time);
  // Run on to ke_time, where the falling arch has turned a visible share of M g Rc into motion.
  EXPECT_GE(thin.ke_time, crit.ke_time);
  EXPECT_GT(thin.normalised_kinetic_energy, 1e-3);
  EXPECT_GT(thin.normalised_kinetic_energy, 1e4 * thick.normalised_kinetic_energy);
  EXPECT_FALSE(thin.hinges.empty());
  // Mode outlines: one per block, fixed abutments unmoved, some voussoir moved.
  ASSERT_EQ(thin.outlines.size(), thin.outlines0.size());
  ASSERT_EQ(thin.fixed.size(), thin.outlines.size());
  double moved = 0.0;
  for (size_t b = 0; b < thin.outlines.size(); ++b)
    for (size_t k = 0; k < thin.outlines[b].size(); ++k) {
      const double d = std::hypot(thin.outlines[b][k].x - thin.outlines0[b][k].x,
                                  thin.outlines[b][k].y - thin.outlines0[b][k].y);
      if (thin.fixed[b]) {
        EXPECT_EQ(d, 0.0);
      }
      moved = std::max(moved, d);
    }
  EXPECT_GT(moved, crit.trial.collapse_displacement * thin.l_ref);

  // Limit analysis agrees on both.
  check_limit_admissibility(arch(0.25, 0.8), thick);
  check_limit_admissibility(arch(0.05, 0.8), thin);
  EXPECT_TRUE(thick.la_admissible);
  EXPECT_FALSE(thin.la_admissible);
  EXPECT_FALSE(thick.disagrees());
  EXPECT_FALSE(thin.disagrees());
}

TEST(StabilityMap, SameResultsOnOneAndTwoThreads) {
  const Grid g = make_grid(kDeck, kCoarse,
                           {parse_grid_param("model.thickness_ratio=0.05,0.25"),
                            parse_grid_param("contact.friction=0.6,0.8")});
  const StabilityCriteria crit = fast_criteria();
  const std::vector<StabilityCell> one = run_stability_map(g, crit, 1, false, true);
  const std::vector<StabilityCell> two = run_stability_map(g, crit, 2, false, true);
  ASSERT_EQ(one.size(), 4u);
  ASSERT_EQ(two.size(), 4u);
  for (size_t c = 0; c < 4; ++c) {
    EXPECT_TRUE(one[c].error.empty()) << one[c].error;
    // Thin row collapses, thick row stands, at both frictions; LA agrees.
    EXPECT_EQ(one[c].stable, c >= 2) << c;
    EXPECT_EQ(one[c].la_admissible, c >= 2) << c;
    EXPECT_EQ(two[c].stable, one[c].stable) << c;
    EXPECT_EQ(two[c].reason, one[c].reason) << c;
    EXPECT_EQ(two[c].steps, one[c].steps) << c;
    // Each cell is a serial simulation: bit-identical whatever the thread count.
    EXPECT_EQ(two[c].kinetic_energy, one[c].kinetic_energy) << c;
    EXPECT_EQ(two[c].max_displacement, one[c].max_displacement) << c;
    EXPECT_EQ(two[c].values, g.values[c]);
  }
}

// `stability --resume`: a map killed after its first cell, run again with the same journal,
// takes that cell from the journal and runs only the others; every cell, the collapse-mode
// outlines included, equals the uninterrupted map's bit for bit (but the wall time of the cell
// run again). A journal of another grid is
// refused.
TEST(StabilityMap, ResumedMapEqualsTheUninterruptedOne) {
  const Grid g = make_grid(kDeck, kCoarse, {parse_grid_param("model.thickness_ratio=0.05,0.25")});
  const StabilityCriteria crit = fast_criteria();
  const std::vector<StabilityCell> straight = run_stability_map(g, crit, 1, true, true);
  const std::string path =
      (std::filesystem::temp_directory_path() / "voussoir_stability_resume.journal").string();
  std::filesystem::remove(path);
  {
    Journal first(path, "test-print");
    nlohmann::json record = stability_cell_record(straight[0]);
    record["cell"] = 0;
    first.append(record);  // the kill came after cell 0
  }
  Journal journal(path, "test-print");
  ASSERT_EQ(journal.records().size(), 1u);
  const std::vector<StabilityCell> resumed = run_stability_map(g, crit, 1, true, true, &journal);
  ASSERT_EQ(resumed.size(), 2u);
  for (size_t c = 0; c < 2; ++c) {
    nlohmann::json a = stability_cell_record(resumed[c]), b = stability_cell_record(straight[c]);
    if (c == 1) a.erase("wall_s"), b.erase("wall_s");  // run again: its own wall time
    EXPECT_EQ(a, b) << c;
    EXPECT_EQ(resumed[c].la_admissible, straight[c].la_admissible) << c;
  }
  EXPECT_FALSE(resumed[0].outlines.empty());  // the collapsed thin arch keeps its mode
  EXPECT_EQ(Journal(path, "test-print").records().size(), 2u);  // cell 1 was appended

  const Grid other =
      make_grid(kDeck, kCoarse, {parse_grid_param("model.thickness_ratio=0.06,0.25")});
  EXPECT_THROW(run_stability_map(other, crit, 1, true, true, &journal), RunError);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace voussoir

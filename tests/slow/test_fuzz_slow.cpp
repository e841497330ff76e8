// Bad input (docs/reference/commands.md: exit status 2, never a crash), full set: 300 mutated
// versions of each shipped deck and 200 of each geometry file (3100 inputs to `voussoir check`),
// every third one also to `voussoir run` (1034 runs); about ten minutes on two cores. Seeds differ
// from the default share (tests/unit/test_fuzz.cpp), so these are other inputs; contract and
// mutations in tests/unit/fuzz_inputs.hpp.

#include "../unit/fuzz_inputs.hpp"

namespace voussoir::testing {
namespace {

constexpr int kDeckInputs = 300;
constexpr int kGeometryInputs = 200;
constexpr int kRunEvery = 3;

class FuzzFull : public ::testing::TestWithParam<const char*> {};

TEST_P(FuzzFull, Deck) {
  const std::string name = GetParam();
  std::uint64_t seed = 1000;
  for (const char c : name) seed = seed * 131 + static_cast<unsigned char>(c);
  const FuzzTally t = fuzz_deck(name, kDeckInputs, kRunEvery, seed);
  std::printf("[fuzz] %s: %s\n", name.c_str(), t.summary().c_str());
  EXPECT_EQ(t.failures, 0) << t.summary();
}

INSTANTIATE_TEST_SUITE_P(Cases, FuzzFull,
                         ::testing::Values("circular_arch", "basket_arch", "buttressed_circular",
                                           "buttressed_basket", "church_a", "church_b",
                                           "gilbert_arch", "scaled_arch", "block"));

TEST(FuzzFullGeometry, PolygonTextFile) {
  const FuzzTally t = fuzz_geometry("two_blocks.txt", kGeometryInputs, kRunEvery, 2001);
  std::printf("[fuzz] two_blocks.txt: %s\n", t.summary().c_str());
  EXPECT_EQ(t.failures, 0) << t.summary();
}

TEST(FuzzFullGeometry, GmshFile) {
  const FuzzTally t = fuzz_geometry("two_blocks.msh", kGeometryInputs, kRunEvery, 2002);
  std::printf("[fuzz] two_blocks.msh: %s\n", t.summary().c_str());
  EXPECT_EQ(t.failures, 0) << t.summary();
}

}  // namespace
}  // namespace voussoir::testing

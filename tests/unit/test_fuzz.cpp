// Bad input (issue 8, item 3), default share: 100 mutated versions of each of the nine shipped
// decks and 60 of each geometry file (polygon text, gmsh) -- 1020 inputs to `voussoir check`,
// every tenth also to `voussoir run` with a 1e-4 s end time (102 runs). The contract and the
// mutations are in tests/unit/fuzz_inputs.hpp; the full set (5x more, every third input run)
// is tests/slow/test_fuzz_slow.cpp. Seeds are fixed: the same inputs on every run.

#include "fuzz_inputs.hpp"

namespace voussoir::testing {
namespace {

constexpr int kDeckInputs = 100;
constexpr int kGeometryInputs = 60;
constexpr int kRunEvery = 10;

void fuzz_case(const std::string& name, std::uint64_t seed) {
  const FuzzTally t = fuzz_deck(name, kDeckInputs, kRunEvery, seed);
  std::printf("[fuzz] %s: %s\n", name.c_str(), t.summary().c_str());
  EXPECT_EQ(t.failures, 0) << t.summary();
  EXPECT_EQ(t.inputs, kDeckInputs + (kDeckInputs + kRunEvery - 1) / kRunEvery);
}

TEST(Fuzz, CircularArchDeck) {
  fuzz_case("circular_arch", 101);
}
TEST(Fuzz, BasketArchDeck) {
  fuzz_case("basket_arch", 102);
}
TEST(Fuzz, ButtressedCircularDeck) {
  fuzz_case("buttressed_circular", 103);
}
TEST(Fuzz, ButtressedBasketDeck) {
  fuzz_case("buttressed_basket", 104);
}
TEST(Fuzz, ChurchADeck) {
  fuzz_case("church_a", 105);
}
TEST(Fuzz, ChurchBDeck) {
  fuzz_case("church_b", 106);
}
TEST(Fuzz, GilbertArchDeck) {
  fuzz_case("gilbert_arch", 107);
}
TEST(Fuzz, ScaledArchDeck) {
  fuzz_case("scaled_arch", 108);
}
TEST(Fuzz, BlockDeck) {
  fuzz_case("block", 109);
}

TEST(Fuzz, PolygonTextFile) {
  const FuzzTally t = fuzz_geometry("two_blocks.txt", kGeometryInputs, kRunEvery, 201);
  std::printf("[fuzz] two_blocks.txt: %s\n", t.summary().c_str());
  EXPECT_EQ(t.failures, 0) << t.summary();
}

TEST(Fuzz, GmshFile) {
  const FuzzTally t = fuzz_geometry("two_blocks.msh", kGeometryInputs, kRunEvery, 202);
  std::printf("[fuzz] two_blocks.msh: %s\n", t.summary().c_str());
  EXPECT_EQ(t.failures, 0) << t.summary();
}

}  // namespace
}  // namespace voussoir::testing

// Bad input (docs/reference/commands.md: exit status 2, never a crash), default share: 100 mutated
// versions of each of the nine shipped decks and 60 of each geometry file (polygon text, gmsh) --
// 1020 inputs to `voussoir check`, every tenth also to `voussoir run` with a 1e-4 s end time (102
// runs). The contract and the mutations are in tests/unit/fuzz_inputs.hpp; the full set (5x more,
// every third input run) is tests/slow/test_fuzz_slow.cpp. Seeds are fixed: the same inputs on
// every run.

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

// Inputs the fuzzer found that broke the exit-status contract (docs/reference/commands.md),
// each reduced to --set overrides of a shipped deck (or a two-line polygon change), kept here so
// that a fix is seen at once and never undone. Each must exit 0 or 2 from `check`; the last
// one must finish a 1e-4 s `run` within the fuzz time limit (or be refused).
namespace voussoir::testing {
namespace {

ProcessResult check_with(const std::string& deck, const std::vector<std::string>& sets,
                         const std::string& command = "check") {
  std::vector<std::string> args = {VOUSSOIR_BINARY, command, source_path("cases/" + deck), "-q"};
  for (const std::string& s : sets) args.insert(args.end(), {"--set", s});
  Limits limits;
  limits.wall_s = command == "run" ? 40 : 20;
  limits.cpu_s = 2 * limits.wall_s;
  // One scratch folder per process: ctest runs these tests side by side.
  const std::string scratch =
      (fuzz_fs::temp_directory_path() /
       ("voussoir_finding_" + std::to_string(static_cast<long long>(::getpid()))))
          .string();
  return run_process(args, limits, scratch);
}

// `check` of a polygons deck whose file `blocks.txt` holds `blocks` (block 1 fixed).
ProcessResult check_polygons(const std::string& blocks) {
  const fuzz_fs::path dir =
      fuzz_fs::temp_directory_path() /
      ("voussoir_finding_polygons_" + std::to_string(static_cast<long long>(::getpid())));
  fuzz_fs::create_directories(dir);
  write_text((dir / "deck.toml").string(),
             "[model]\nkind = \"polygons\"\nfile = \"blocks.txt\"\nfixed = [1]\n");
  write_text((dir / "blocks.txt").string(), blocks);
  Limits limits;
  limits.wall_s = 20;
  limits.cpu_s = 40;
  const ProcessResult r =
      run_process({VOUSSOIR_BINARY, "check", (dir / "deck.toml").string(), "-q"}, limits,
                  (dir / "child").string());
  std::error_code ec;
  fuzz_fs::remove_all(dir, ec);
  return r;
}

void expect_refused_or_accepted(const ProcessResult& r) {
  EXPECT_TRUE(r.exited && (r.status == 0 || r.status == 2))
      << r.describe() << "\nstderr: " << r.err;
  if (r.exited && r.status == 2) {
    EXPECT_NE(r.err.find("voussoir: error:"), std::string::npos);
  }
}

// A finding now refused up front: exit 2, with every one of `parts` in the message.
void expect_refused_naming(const ProcessResult& r, const std::vector<std::string>& parts,
                           const std::string& label = "") {
  expect_refused_or_accepted(r);
  EXPECT_TRUE(r.exited && r.status == 2) << label << r.describe();
  for (const std::string& part : parts) EXPECT_NE(r.err.find(part), std::string::npos) << r.err;
}

// mesh/scenes_arch.cpp: an embrace of 1 degree, 11 voussoirs -> "triangulate_polygon: the
// outline is not a simple polygon" as a run failure (exit 1).
TEST(FuzzFindings, ArchEmbraceOneDegree) {
  expect_refused_or_accepted(check_with("circular_arch.toml", {"model.embrace=1"}));
}

// mesh/scenes_arch.cpp: radius 4e10 m -> "cannot create std::vector larger than max_size()"
// (exit 1): the triangle-count limit does not see the radius.
TEST(FuzzFindings, ArchHugeRadius) {
  expect_refused_or_accepted(check_with("gilbert_arch.toml", {"model.radius=40e9"}));
}

// mesh/scenes_arch.cpp: embrace 5e-324 degrees -> vector larger than max_size() (exit 1).
TEST(FuzzFindings, ArchDenormalEmbrace) {
  expect_refused_or_accepted(check_with("scaled_arch.toml", {"model.embrace=5e-324"}));
}

// mesh/scenes_block.cpp: a 4e10 m tall block -> vector larger than max_size() (exit 1).
TEST(FuzzFindings, BlockHugeHeight) {
  expect_refused_or_accepted(check_with("block.toml", {"model.height=40e9"}));
}

// mesh/scenes_church.cpp: outer_width 4294967296 m -> std::bad_alloc (exit 1): the supports
// were outlined at the element size before any triangle budget. Now refused up front (exit 2)
// naming the key, the value and the limit (100 x the largest span, 600 m for church_a); so are
// a pier just over the limit and an absurd height; a wide but sane buttress (3 m) is accepted.
TEST(FuzzFindings, ChurchHugeOuterWidth) {
  expect_refused_naming(check_with("church_a.toml", {"model.outer_width=4294967296"}),
                        {"model.outer_width = 4294967296", "at most 100 x the largest span (6 m)"});
  for (const std::string& set :
       {std::string("model.pier_width=601"), std::string("model.height=1e12")}) {
    const ProcessResult q = check_with("church_a.toml", {set});
    EXPECT_TRUE(q.exited && q.status == 2) << set << ": " << q.describe();
    EXPECT_NE(q.err.find(set.substr(0, set.find('=')) + " = "), std::string::npos) << q.err;
  }
  const ProcessResult ok = check_with("church_a.toml", {"model.outer_width=3"});
  EXPECT_TRUE(ok.exited && ok.status == 0) << ok.describe() << "\n" << ok.err;
}

// mesh/scenes_church.cpp: supports of 5e-324 m (or 1e-6 m) were outlined into ever more course
// slivers and `check` never finished (slow fuzz tier).
TEST(FuzzFindings, ChurchTinyHeight) {
  for (const std::string& set :
       {std::string("model.height=5e-324"), std::string("model.height=1e-6")}) {
    expect_refused_naming(check_with("church_a.toml", {set}),
                          {"at least 0.01 x the largest span (6 m)"}, set + ": ");
  }
  const ProcessResult ok = check_with("church_a.toml", {"model.height=0.5"});
  EXPECT_TRUE(ok.exited && ok.status == 0) << ok.describe() << "\n" << ok.err;
}

// engine/setup.cpp: a damping factor of 9e18 made a stable step of 1.9e-25 s, refused only by
// the run loop (exit 1) after set-up (slow fuzz tier). Now refused up front.
TEST(FuzzFindings, AbsurdDampingTimeStep) {
  expect_refused_naming(
      check_with("church_a.toml",  // elastic: the element damping sets no step for rigid blocks
                 {"material.model=elastic", "solver.damping_factor=9223372036854775807"}),
      {"solver.damping_factor = ", "at least 1e-15 s needed"});
}

// mesh/scenes_polygons.cpp: block 0 = (-0.25, 0), (0.25, 0), (0.25, 2147483648), (-1.75, -0.25),
// a 2e9 m tall sliver reaching into the ground -> std::bad_alloc (exit 1). Now its
// 5e-8 degree corner is refused where the file is read; a 2e9 m tall column with square corners
// still meets the triangle estimate.
TEST(FuzzFindings, PolygonHugeCoordinate) {
  const std::string ground = "\nblock\n-1.75 -0.25\n1.75 -0.25\n1.75 0\n-1.75 0\n";
  expect_refused_naming(
      check_polygons("block\n-0.25 0\n0.25 0\n0.25 2147483648\n-1.75 -0.25\n" + ground),
      {"blocks.txt:4: block 0: the corner at vertex (0.25, 2.14748e+09) is a needle of"});
  // Refused by the triangle estimate before the edges are cut (mesh/scenes_polygons.cpp); it
  // used to allocate until the memory limit (without one, until the machine ran out).
  expect_refused_naming(
      check_polygons("block\n-0.25 0\n0.25 0\n0.25 2147483648\n-0.25 2147483648\n" + ground),
      {"triangles (limit"});
}

// mesh/scenes_polygons.cpp: tests/data/two_blocks.txt with block 0's first vertex moved to
// (65536, 0) and one vertex gone: a needle 65 km long with a 4e-6 rad tip, still a simple
// polygon. `check` first spent minutes in the O(n^2) simplicity test of the refined outline,
// then (with a sweep there) in the constrained triangulation of the needle (slow fuzz
// tier). With the tip at x = 1024 to 16384 the inexact simplicity test called the
// refined outline "not simple". Now the corner is refused where it is read, naming its line.
TEST(FuzzFindings, PolygonNeedleCorner) {
  for (const std::string tip : {"1024", "65536"}) {
    expect_refused_naming(
        check_polygons("block\n" + tip +
                       " 0\n0.25 0\n0.25 1\n-0.25 1\n-1.75, -0.25\nblock\n\n"
                       "1.75, 0\n-1.75, 0\n-1.75, -0.25\n"),
        {"blocks.txt:2: block 0: the corner at vertex (" + tip + ", 0) is a needle of"}, tip);
  }
  // A notch: block 0 of the file with a slit 1e-3 m wide and 1 m deep cut into its top.
  expect_refused_naming(
      check_polygons("block\n-0.25 0\n0.25 0\n0.25 1\n0.0005 1\n0 0.001\n-0.0005 1\n-0.25 1\n"
                     "block\n-1.75 -0.25\n1.75 -0.25\n1.75 0\n-1.75 0\n"),
      {"blocks.txt:6: block 0: the corner at vertex (0, 0.001) is a notch of"});
}

// mesh/scenes_block.cpp: a block 1e5 m tall on its 0.5 m base (or 1 m tall on a 0.1 mm base)
// lays a ground strip 1e5 m long and 0.25 m deep (or 1 m and 50 micrometres) under it, whose
// quality mesh runs past the runaway cap only after hours (seconds): `check` hit the time limit
// (slow fuzz tier). Now refused up front, naming the height and the ratio; the tallest stack
// the key range allows on the shipped blocks (1000 blocks, 2000 widths) is still accepted.
TEST(FuzzFindings, BlockTallStackOnANarrowBase) {
  expect_refused_naming(check_with("block.toml", {"model.height=100000"}),
                        {"model.height = 100000", "200000 times taller than wide (at most 2000)"});
  expect_refused_naming(check_with("block.toml", {"model.width=0.0001"}),
                        {"0.0001 m wide (model.width)", "10000 times taller than wide"});
  const ProcessResult ok = check_with("block.toml", {"model.stack=1000"});
  EXPECT_TRUE(ok.exited && ok.status == 0) << ok.describe() << "\n" << ok.err;
}

// mesh/scene.cpp: the block deck with width and density swapped (width 2000 m, slow fuzz tier)
// is a valid deck of 1.7 million triangles, whose `check` took 15 to 30 s against the fuzz's
// 20 s limit on a loaded machine. Under the fuzz's mesh.max_triangles (fuzz_inputs.hpp) it is
// refused before it is meshed, naming the limit.
TEST(FuzzFindings, BlockWideBaseUnderTheFuzzTriangleLimit) {
  expect_refused_naming(
      check_with("block.toml", {"model.width=2000", "material.density=0.5",
                                "mesh.max_triangles=" + std::to_string(kFuzzMaxTriangles)}),
      {"would make about 1675226 triangles (limit mesh.max_triangles = 20000)"});
}

// mesh/scenes_arch.cpp (or io/deck.cpp ranges): embrace 0.092 degrees with 13 voussoirs of a
// 36 mm thick arch makes 46 micrometre wide voussoirs, 39734 triangles and dt = 7.5e-11 s:
// `check` accepts it, and `run` to 1e-4 s (1.3 million steps) does not end in 40 s.
TEST(FuzzFindings, ArchSliverVoussoirsRun) {
  expect_refused_or_accepted(
      check_with("scaled_arch.toml", {"model.embrace=0.092", "solver.end_time=1e-4"}, "run"));
}

}  // namespace
}  // namespace voussoir::testing

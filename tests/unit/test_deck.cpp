// Deck reading and validation (io/deck.cpp): a full deck round-trips into Config; every kind
// of bad deck throws DeckError with one line naming the key and the value (or the line); the
// real program turns a bad deck into exit status 2 with that line.

#include <gtest/gtest.h>
#include <toml++/toml.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include "io/deck.hpp"
#include "subprocess.hpp"

namespace voussoir {
namespace {

namespace fs = std::filesystem;

// Every deck key (docs/reference/deck.md), each with a value different from its default.
const char* kFullDeck = R"(
[model]
kind = "buttressed_arch"
radius = 2.5
thickness = 0.4
embrace = 150
voussoirs = 13
offset = 0.75
small_radius = 0.6
shape = "basket"
buttress_width = 1.6
base_depth = 6.0
courses = 0.3
spans = [3.0, 5, 3.5]
height = 4.5
pier_width = 0.9
outer_width = 1.1
eccentricity = 0.3
voussoir_angle = 3.0
width = 0.7
incline = 12.5
stack = 3
file = "blocks.txt"
fixed = [0, 4]
out_of_plane = 0.092

[mesh]
size = 0.05
through_thickness = 3
chord_tolerance = 0.02
max_triangles = 250000

[material]
density = 450
young = 3.5e9
poisson = 0.25
plane = "stress"
model = "elastic"

[contact]
friction = 0.68
penalty_factor = 50
penalty = 1e12
buffer = 0.002
restitution = 1.0

[solver]
dt = 2e-7
dt_safety = 0.4
damping_factor = 0.5
end_time = 2.5
scheme = "explicit"
theta = 0.75
tolerance = 1e-5
max_iterations = 300

[load]
gravity = 9.8
lambda = 0.3
gravity_ramp = 0.2

[load.base]
signal = "windowed_sine"
amplitude = 0.4
frequency = 5.0
cycles = 4
file = "quake.csv"
units = "m/s2"
band = [0.5, 25]
baseline = "linear"

[capacity]
lambda_min = 0.1
lambda_max = 1.5
tolerance = 0.01
local_damping = 0.6
local_damping_mode = "full"
kinetic_damping = 0.01
mass_scaling = "none"

[supports]
moves = [{block = 11, dx = -0.002, dy = 0.001, rotation = 0.5}, {block = 12, dy = -0.003}]
ramp = 0.3

[output]
file = "run.h5"
every = 0.02
fields = ["velocity", "stress"]
)";

const char* kMinimal = "[model]\nkind = \"circular_arch\"\n";

// Expects parse_deck to throw DeckError whose one-line message contains every `part`.
std::string expect_deck_error(const std::string& text, const std::vector<std::string>& parts,
                              const std::vector<std::string>& sets = {}) {
  try {
    parse_deck(text, "deck.toml", sets);
  } catch (const DeckError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "not one line: " << msg;
    for (const std::string& p : parts)
      EXPECT_NE(msg.find(p), std::string::npos) << "message lacks '" << p << "': " << msg;
    return msg;
  }
  ADD_FAILURE() << "no DeckError for deck:\n" << text;
  return {};
}

// A fresh scratch folder per test (tests may run in parallel under ctest).
fs::path scratch_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir = fs::temp_directory_path() /
                       ("voussoir_deck_" + std::to_string(::getpid()) + "_" + info->name());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void write_file(const fs::path& p, const std::string& text) {
  std::ofstream out(p);
  out << text;
}

TEST(Deck, FullDeckRoundTripsIntoConfig) {
  const Config c = parse_deck(kFullDeck, "full.toml", {}, "/data/decks");
  EXPECT_EQ(c.deck_path, "full.toml");
  EXPECT_EQ(c.deck_dir, "/data/decks");
  const ModelConfig& m = c.model;
  EXPECT_EQ(m.kind, "buttressed_arch");
  EXPECT_DOUBLE_EQ(m.radius, 2.5);
  EXPECT_DOUBLE_EQ(m.thickness, 0.4);
  EXPECT_DOUBLE_EQ(m.embrace, 150.0);  // integer accepted for a number
  EXPECT_EQ(m.voussoirs, 13);
  EXPECT_DOUBLE_EQ(m.offset, 0.75);
  EXPECT_DOUBLE_EQ(m.small_radius, 0.6);
  EXPECT_EQ(m.shape, "basket");
  EXPECT_DOUBLE_EQ(m.buttress_width, 1.6);
  EXPECT_DOUBLE_EQ(m.base_depth, 6.0);
  EXPECT_DOUBLE_EQ(m.courses, 0.3);
  EXPECT_EQ(m.spans, (std::vector<double>{3.0, 5.0, 3.5}));
  EXPECT_DOUBLE_EQ(m.height, 4.5);
  EXPECT_DOUBLE_EQ(m.pier_width, 0.9);
  EXPECT_DOUBLE_EQ(m.outer_width, 1.1);
  EXPECT_DOUBLE_EQ(m.eccentricity, 0.3);
  EXPECT_DOUBLE_EQ(m.voussoir_angle, 3.0);
  EXPECT_DOUBLE_EQ(m.width, 0.7);
  EXPECT_DOUBLE_EQ(m.incline, 12.5);
  EXPECT_EQ(m.stack, 3);
  EXPECT_EQ(m.file, "/data/decks/blocks.txt");  // relative to the deck folder
  EXPECT_EQ(m.fixed, (std::vector<int>{0, 4}));
  EXPECT_DOUBLE_EQ(m.out_of_plane, 0.092);
  EXPECT_EQ(m.given.size(), 23u);
  EXPECT_TRUE(m.has("embrace"));
  EXPECT_TRUE(m.has("model.embrace"));
  EXPECT_DOUBLE_EQ(c.mesh.size, 0.05);
  EXPECT_EQ(c.mesh.through_thickness, 3);
  EXPECT_DOUBLE_EQ(c.mesh.chord_tolerance, 0.02);
  EXPECT_EQ(c.mesh.max_triangles, 250000);
  EXPECT_DOUBLE_EQ(c.material.density, 450.0);
  EXPECT_DOUBLE_EQ(c.material.young, 3.5e9);
  EXPECT_DOUBLE_EQ(c.material.poisson, 0.25);
  EXPECT_EQ(c.material.plane, "stress");
  EXPECT_EQ(c.material.model, "elastic");
  EXPECT_DOUBLE_EQ(c.contact.restitution, 1.0);
  EXPECT_DOUBLE_EQ(c.contact.friction, 0.68);
  EXPECT_DOUBLE_EQ(c.contact.penalty_factor, 50.0);
  EXPECT_DOUBLE_EQ(c.contact.penalty, 1e12);
  EXPECT_DOUBLE_EQ(c.contact.buffer, 0.002);
  EXPECT_DOUBLE_EQ(c.solver.dt, 2e-7);
  EXPECT_DOUBLE_EQ(c.solver.dt_safety, 0.4);
  EXPECT_DOUBLE_EQ(c.solver.damping_factor, 0.5);
  EXPECT_DOUBLE_EQ(c.solver.end_time, 2.5);
  EXPECT_EQ(c.solver.scheme, "explicit");
  EXPECT_DOUBLE_EQ(c.solver.theta, 0.75);
  EXPECT_DOUBLE_EQ(c.solver.tolerance, 1e-5);
  EXPECT_EQ(c.solver.max_iterations, 300);
  EXPECT_DOUBLE_EQ(c.load.gravity, 9.8);
  EXPECT_DOUBLE_EQ(c.load.lambda, 0.3);
  EXPECT_DOUBLE_EQ(c.load.gravity_ramp, 0.2);
  EXPECT_EQ(c.load.base.signal, "windowed_sine");
  EXPECT_DOUBLE_EQ(c.load.base.amplitude, 0.4);
  EXPECT_DOUBLE_EQ(c.load.base.frequency, 5.0);
  EXPECT_EQ(c.load.base.cycles, 4);
  EXPECT_EQ(c.load.base.file, "/data/decks/quake.csv");
  EXPECT_EQ(c.load.base.units, "m/s2");
  EXPECT_DOUBLE_EQ(c.load.base.band[0], 0.5);
  EXPECT_DOUBLE_EQ(c.load.base.band[1], 25.0);
  EXPECT_EQ(c.load.base.baseline, "linear");
  EXPECT_DOUBLE_EQ(c.capacity.lambda_min, 0.1);
  EXPECT_DOUBLE_EQ(c.capacity.lambda_max, 1.5);
  EXPECT_DOUBLE_EQ(c.capacity.tolerance, 0.01);
  EXPECT_DOUBLE_EQ(c.capacity.local_damping, 0.6);
  EXPECT_EQ(c.capacity.local_damping_mode, "full");
  ASSERT_EQ(c.supports.moves.size(), 2u);
  EXPECT_EQ(c.supports.moves[0].block, 11);
  EXPECT_DOUBLE_EQ(c.supports.moves[0].dx, -0.002);
  EXPECT_DOUBLE_EQ(c.supports.moves[0].dy, 0.001);
  EXPECT_DOUBLE_EQ(c.supports.moves[0].rotation, 0.5);
  EXPECT_EQ(c.supports.moves[1].block, 12);
  EXPECT_DOUBLE_EQ(c.supports.moves[1].dx, 0.0);
  EXPECT_DOUBLE_EQ(c.supports.moves[1].dy, -0.003);
  EXPECT_DOUBLE_EQ(c.supports.ramp, 0.3);
  EXPECT_DOUBLE_EQ(c.capacity.kinetic_damping, 0.01);
  EXPECT_EQ(c.capacity.mass_scaling, "none");
  EXPECT_EQ(c.output.file, "run.h5");  // output paths stay relative to the working directory
  EXPECT_DOUBLE_EQ(c.output.every, 0.02);
  EXPECT_EQ(c.output.fields, (std::vector<std::string>{"velocity", "stress"}));
}

// The full deck above exercises every key the reader knows, and nothing else.
// The joint-stiffness keys, which the full deck cannot hold beside its penalty (one or the
// other, test_rigid.cpp).
const char* kJointKeys = R"(
[model]
kind = "block"
[contact]
normal_stiffness = 1e10
shear_stiffness = 4e9
)";

TEST(Deck, JointStiffnessKeysRoundTrip) {
  const Config c = parse_deck(kJointKeys, "joints.toml");
  EXPECT_DOUBLE_EQ(c.contact.normal_stiffness, 1e10);
  EXPECT_DOUBLE_EQ(c.contact.shear_stiffness, 4e9);
  EXPECT_DOUBLE_EQ(c.contact.restitution, 1.0);
  EXPECT_EQ(c.material.model, "elastic");
  EXPECT_TRUE(c.contact.has("normal_stiffness"));
  EXPECT_FALSE(c.contact.has("penalty"));
}

TEST(Deck, FullDeckCoversEveryKnownKey) {
  std::set<std::string> in_deck;
  const toml::table t = toml::parse(kFullDeck);
  std::function<void(const toml::table&, const std::string&)> collect =
      [&](const toml::table& tab, const std::string& prefix) {
        for (auto&& [k, v] : tab) {
          const std::string key = prefix + std::string(k.str());
          if (v.is_table())
            collect(*v.as_table(), key + ".");
          else
            in_deck.insert(key);
        }
      };
  collect(t, "");
  collect(toml::parse(kJointKeys), "");
  in_deck.erase("model.kind");  // in both
  in_deck.insert("model.kind");
  const std::set<std::string> known(known_keys().begin(), known_keys().end());
  EXPECT_EQ(known.size(), known_keys().size()) << "duplicate key in known_keys()";
  EXPECT_EQ(in_deck, known);
  EXPECT_TRUE(known.count("load.base.signal"));
  EXPECT_TRUE(known.count("contact.penalty_factor"));
}

TEST(Deck, MinimalDeckKeepsDefaults) {
  const Config c = parse_deck(kMinimal, "min.toml");
  const Config d;
  EXPECT_EQ(c.model.kind, "circular_arch");
  EXPECT_EQ(c.model.given, std::vector<std::string>{"kind"});
  EXPECT_FALSE(c.model.has("embrace"));
  EXPECT_EQ(c.model.voussoirs, d.model.voussoirs);
  EXPECT_EQ(c.material.young, d.material.young);
  EXPECT_EQ(c.solver.dt, 0.0);
  EXPECT_EQ(c.output.fields, d.output.fields);
}

// ---- the key table: one place per key ------------------------------------------------------

// Collapses every run of white space to one blank, so a row reads the same however it is
// formatted.
std::string squeeze(const std::string& text) {
  std::string out;
  for (char ch : text) {
    const bool space = ch == ' ' || ch == '\n' || ch == '\t' || ch == '\r';
    if (!space)
      out += ch;
    else if (!out.empty() && out.back() != ' ')
      out += ' ';
  }
  return out;
}

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

// A key's name is written in one place: its row of the key table (io/deck.cpp), which also
// names the Config field of the same path. core/schema.hpp holds the field and its default
// without the dotted name; io/deck_reference.cpp prints the rows; no other file of io/ writes
// the name, and the scene generators of mesh/ spell it from the field (VOUSSOIR_KEY,
// core/schema.hpp).
TEST(DeckKeys, EachKeyIsNamedByOneRowOfTheKeyTable) {
  const fs::path source = VOUSSOIR_SOURCE_DIR;
  std::vector<fs::path> files = {source / "core" / "schema.hpp"};
  for (const char* folder : {"io", "mesh"})
    for (const fs::directory_entry& e : fs::directory_iterator(source / folder))
      if (e.path().extension() == ".cpp" || e.path().extension() == ".hpp")
        files.push_back(e.path());
  const fs::path table = source / "io" / "deck.cpp";
  ASSERT_NE(std::find(files.begin(), files.end(), table), files.end());
  for (const fs::path& f : files) {
    std::ifstream in(f);
    ASSERT_TRUE(in) << f;
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string rel = fs::relative(f, source).string();
    for (const std::string& key : known_keys()) {
      const std::string quoted = "\"" + key + "\"";
      if (f == table) {
        const std::string row = "{" + quoted + ", [](auto& c) { return &c." + key + "; }";
        EXPECT_EQ(count_of(squeeze(text), row), 1u)
            << "io/deck.cpp: deck key " << key << " needs one row " << row << "...";
      } else {
        EXPECT_EQ(count_of(text, quoted), 0u)
            << rel << " writes the deck key " << quoted
            << "; its one place is its row of the key table in io/deck.cpp";
      }
    }
  }
}

// Every row has its meaning, default, type and rule, and the default the reference shows is a
// value the key's own reader accepts.
TEST(DeckKeys, EveryShownDefaultIsAcceptedByItsReader) {
  for (const std::string& key : known_keys()) {
    const KeyRule rule = describe_key(key);
    EXPECT_FALSE(rule.meaning.empty()) << key;
    EXPECT_FALSE(rule.default_value.empty()) << key;
    EXPECT_FALSE(rule.type.empty()) << key;
    EXPECT_FALSE(rule.allowed.empty()) << key;
    const std::string& d = rule.default_value;
    if (d == "none" || d.rfind("required", 0) == 0 || d == "[] (none)") continue;
    EXPECT_NO_THROW({
      const Config c = parse_deck(kMinimal, "defaults.toml", {key + "=" + d});
      (void)c;
    }) << key
       << " = " << d;
  }
}

TEST(Deck, DtAutoAndEmptyFields) {
  const Config c = parse_deck(
      std::string(kMinimal) + "[solver]\ndt = \"auto\"\n[output]\nfields = []\n", "d.toml");
  EXPECT_EQ(c.solver.dt, 0.0);
  EXPECT_TRUE(c.output.fields.empty());
}

// ---- overrides ------------------------------------------------------------------------------

TEST(Deck, SetOverridesParseAsTomlValues) {
  const Config c =
      parse_deck(std::string(kMinimal) + "embrace = 180\n", "s.toml",
                 {"model.embrace=135", "load.base.signal=windowed_sine", "model.spans=[4,6,4]",
                  "output.file = out/run 1.h5", "contact.friction=0.9", "solver.dt=auto",
                  "model.voussoirs=21", "output.fields=[\"stress\"]", "material.plane=\"stress\"",
                  "model.kind=church", "model.embrace=140"});
  EXPECT_DOUBLE_EQ(c.model.embrace, 140.0);        // the later --set wins
  EXPECT_EQ(c.load.base.signal, "windowed_sine");  // bare word taken as a string
  EXPECT_EQ(c.model.spans, (std::vector<double>{4.0, 6.0, 4.0}));
  EXPECT_EQ(c.output.file, "out/run 1.h5");
  EXPECT_DOUBLE_EQ(c.contact.friction, 0.9);
  EXPECT_EQ(c.solver.dt, 0.0);
  EXPECT_EQ(c.model.voussoirs, 21);
  EXPECT_EQ(c.output.fields, std::vector<std::string>{"stress"});
  EXPECT_EQ(c.material.plane, "stress");
  EXPECT_EQ(c.model.kind, "church");
  EXPECT_TRUE(c.model.has("spans"));
  // A string key given something that parses as a number keeps the text typed.
  const Config n = parse_deck(kMinimal, "s.toml", {"output.file=2024"});
  EXPECT_EQ(n.output.file, "2024");
  // --set can supply a required key the file lacks.
  const Config k = parse_deck("", "empty.toml", {"model.kind=block", "model.width=0.4"});
  EXPECT_EQ(k.model.kind, "block");
  EXPECT_DOUBLE_EQ(k.model.width, 0.4);
}

TEST(Deck, SetIsValidatedLikeTheFile) {
  expect_deck_error(kMinimal, {"--set", "model.embrace = 400", "(0, 360)"}, {"model.embrace=400"});
  expect_deck_error(kMinimal,
                    {"unknown key 'model.embrase'", "--set model.embrase=135", "'model.embrace'"},
                    {"model.embrase=135"});
  expect_deck_error(kMinimal, {"--set 'model.embrace'", "expected KEY=VALUE"}, {"model.embrace"});
  expect_deck_error(kMinimal, {"model.voussoirs = \"many\"", "integer"}, {"model.voussoirs=many"});
  expect_deck_error(kMinimal, {"'model' is a section"}, {"model=3"});
  expect_deck_error(kMinimal, {"'model.kind' is a value, not a section"}, {"model.kind.x=1"});
  expect_deck_error(kMinimal,
                    {"unknown section [modle]", "--set modle.kind=block", "did you mean 'model'"},
                    {"modle.kind=block"});
}

// ---- bad decks ------------------------------------------------------------------------------

TEST(DeckErrors, UnknownKeySuggestsNearest) {
  const std::string msg = expect_deck_error(
      std::string(kMinimal) + "[contact]\nfrictoin = 0.5\n",
      {"deck.toml:4:", "unknown key 'contact.frictoin'", "(did you mean 'contact.friction'?)"});
  // A known key in the wrong section points to the right one.
  expect_deck_error(std::string(kMinimal) + "friction = 0.5\n",
                    {"unknown key 'model.friction'", "did you mean 'contact.friction'"});
  expect_deck_error(std::string(kMinimal) + "frction = 0.5\n",
                    {"unknown key 'model.frction'", "did you mean 'contact.friction'"});
  // Far from anything: no suggestion.
  const std::string far = expect_deck_error(std::string(kMinimal) + "zzzzzzzzqqq = 1\n",
                                            {"unknown key 'model.zzzzzzzzqqq'"});
  EXPECT_EQ(far.find("did you mean"), std::string::npos) << far;
  expect_deck_error("title = \"x\"\n" + std::string(kMinimal), {"unknown key 'title'"});
}

TEST(DeckErrors, FirstProblemInFileOrderIsReported) {
  // toml++ keeps keys sorted by name; the error on the earlier line must still win.
  expect_deck_error(std::string(kMinimal) + "voussoirs = 0\nembrace = 400\n",
                    {"deck.toml:3:", "model.voussoirs = 0"});
  expect_deck_error(std::string(kMinimal) + "embrace = 400\nvoussoirs = 0\n",
                    {"deck.toml:3:", "model.embrace = 400"});
}

TEST(DeckErrors, UnknownSection) {
  expect_deck_error(std::string(kMinimal) + "[materail]\nyoung = 1e9\n",
                    {"unknown section [materail]", "did you mean 'material'"});
  expect_deck_error(std::string(kMinimal) + "[load.bsae]\nsignal = \"none\"\n",
                    {"unknown section [load.bsae]", "did you mean 'load.base'"});
}

TEST(DeckErrors, WrongType) {
  expect_deck_error(std::string(kMinimal) + "[material]\nyoung = \"hard\"\n",
                    {"deck.toml:4:", "material.young = \"hard\"", "expected a number > 0"});
  expect_deck_error(std::string(kMinimal) + "[output]\nfields = \"stress\"\n",
                    {"output.fields = \"stress\"", "array"});
  expect_deck_error(std::string(kMinimal) + "[model]\n", {"model"});  // duplicate table
  expect_deck_error("model = 3\n", {"'model' is a section"});
  expect_deck_error(std::string(kMinimal) + "spans = [4, \"six\", 4]\n",
                    {"model.spans = [4, \"six\", 4]", "spans > 0"});
  expect_deck_error(std::string(kMinimal) + "[load.base]\nband = [1.0]\n",
                    {"load.base.band = [1.0]", "0 <= low < high"});
}

TEST(DeckErrors, OutOfRange) {
  expect_deck_error(std::string(kMinimal) + "[material]\ndensity = -2000\n",
                    {"material.density = -2000", "> 0"});
  expect_deck_error(std::string(kMinimal) + "embrace = 360\n", {"model.embrace = 360", "(0, 360)"});
  expect_deck_error(std::string(kMinimal) + "voussoirs = 0\n",
                    {"model.voussoirs = 0", "an integer in [1,"});
  expect_deck_error(std::string(kMinimal) + "[contact]\nfriction = -0.1\n",
                    {"contact.friction = -0.1", ">= 0"});
  expect_deck_error(std::string(kMinimal) + "[solver]\ndt_safety = 1.5\n",
                    {"solver.dt_safety = 1.5", "(0, 1]"});
  expect_deck_error(std::string(kMinimal) + "[capacity]\ntolerance = 1\n",
                    {"capacity.tolerance = 1", "(0, 1)"});
  expect_deck_error(std::string(kMinimal) + "incline = 90\n", {"model.incline = 90", "[0, 90)"});
  expect_deck_error(std::string(kMinimal) + "[capacity]\nlambda_min = 2\nlambda_max = 1\n",
                    {"capacity.lambda_min = 2", "< capacity.lambda_max = 1"});
  expect_deck_error(std::string(kMinimal) + "[output]\nfields = [\"stress\", \"strain\"]\n",
                    {"output.fields", "\"strain\"", "position"});
  expect_deck_error(std::string(kMinimal) + "[load.base]\nsignal = \"earthquake\"\n",
                    {"load.base.signal = \"earthquake\"", "windowed_sine"});
  expect_deck_error(std::string(kMinimal) + "[load.base]\nunits = \"ft/s2\"\n",
                    {"load.base.units = \"ft/s2\"", "\"m/s2\""});
  expect_deck_error(std::string(kMinimal) + "[load.base]\nbaseline = \"cubic\"\n",
                    {"load.base.baseline = \"cubic\"", "\"quadratic\""});
  expect_deck_error(std::string(kMinimal) + "[material]\nplane = \"3d\"\n",
                    {"material.plane = \"3d\"", "\"strain\""});
  expect_deck_error("[model]\nkind = \"arch\"\n", {"model.kind = \"arch\"", "circular_arch"});
  expect_deck_error(std::string(kMinimal) + "shape = \"pointed\"\n",
                    {"model.shape = \"pointed\"", "basket"});
  expect_deck_error(std::string(kMinimal) + "fixed = [0, -1]\n", {"model.fixed = [0, -1]"});
}

TEST(DeckErrors, PoissonHalfIsRefused) {
  expect_deck_error(std::string(kMinimal) + "[material]\npoisson = 0.5\n",
                    {"deck.toml:4:", "material.poisson = 0.5", "[0, 0.5)"});
  EXPECT_NO_THROW(parse_deck(std::string(kMinimal) + "[material]\npoisson = 0.499\n", "p.toml"));
}

TEST(DeckErrors, NonFiniteNumbersAreRefused) {
  expect_deck_error(std::string(kMinimal) + "[contact]\nfriction = nan\n",
                    {"contact.friction = nan", "a finite number >= 0"});
  expect_deck_error(std::string(kMinimal) + "[material]\nyoung = inf\n",
                    {"material.young = inf", "finite"});
  expect_deck_error(std::string(kMinimal) + "[load]\nlambda = -inf\n",
                    {"load.lambda = -inf", "finite"});
  expect_deck_error(std::string(kMinimal) + "[load.base]\nband = [1, inf]\n",
                    {"load.base.band = [1, inf]"});
  expect_deck_error(kMinimal, {"--set", "model.radius = nan"}, {"model.radius=nan"});
}

TEST(DeckErrors, FloatWhereIntegerRequired) {
  expect_deck_error(std::string(kMinimal) + "voussoirs = 11.0\n",
                    {"deck.toml:3:", "model.voussoirs = 11.0", "an integer"});
  expect_deck_error(std::string(kMinimal) + "[mesh]\nthrough_thickness = 2.5\n",
                    {"mesh.through_thickness = 2.5", "an integer"});
  expect_deck_error(std::string(kMinimal) + "[mesh]\nmax_triangles = 100.5\n",
                    {"mesh.max_triangles = 100.5", "an integer in [1, 1000000000]"});
  expect_deck_error(std::string(kMinimal) + "[mesh]\nmax_triangles = 0\n",
                    {"mesh.max_triangles = 0", "an integer in [1, 1000000000]"});
  expect_deck_error(std::string(kMinimal) + "fixed = [0, 1.0]\n",
                    {"model.fixed = [0, 1.0]", "integers"});
}

TEST(DeckErrors, DtMustBeAutoOrPositive) {
  expect_deck_error(std::string(kMinimal) + "[solver]\ndt = \"fast\"\n",
                    {"solver.dt = \"fast\"", "\"auto\" or a time step > 0"});
  expect_deck_error(std::string(kMinimal) + "[solver]\ndt = -1\n",
                    {"solver.dt = -1", "\"auto\" or a time step > 0"});
  expect_deck_error(std::string(kMinimal) + "[solver]\ndt = 0\n", {"solver.dt = 0"});
  expect_deck_error(kMinimal, {"--set", "solver.dt = \"fast\""}, {"solver.dt=fast"});
}

TEST(DeckErrors, MissingRequiredKeys) {
  expect_deck_error("[model]\nradius = 2\n", {"missing required key 'model.kind'", "church"});
  expect_deck_error("", {"missing required key 'model.kind'"});
  expect_deck_error("[model]\nkind = \"polygons\"\n", {"missing required key 'model.file'"});
  expect_deck_error(std::string(kMinimal) + "[load.base]\nsignal = \"file\"\n",
                    {"missing required key 'load.base.file'"});
}

TEST(DeckErrors, InputFilesMustExist) {
  const fs::path dir = scratch_dir();
  write_file(dir / "deck.toml", "[model]\nkind = \"polygons\"\nfile = \"absent.txt\"\n");
  try {
    load_deck((dir / "deck.toml").string());
    ADD_FAILURE() << "no DeckError for a missing model.file";
  } catch (const DeckError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("deck.toml:3:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("model.file = \"absent.txt\""), std::string::npos) << msg;
    EXPECT_NE(msg.find((dir / "absent.txt").string()), std::string::npos) << msg;
  }
  // Present: resolved against the deck's folder, whatever the working directory.
  write_file(dir / "absent.txt", "0 0 1 0 1 1\n");
  const Config c = load_deck((dir / "deck.toml").string());
  EXPECT_EQ(c.model.file, (dir / "absent.txt").string());
  EXPECT_EQ(c.deck_dir, dir.string());
  EXPECT_EQ(c.deck_path, (dir / "deck.toml").string());
  fs::remove_all(dir);
}

TEST(DeckErrors, SyntaxErrorGivesLineAndColumn) {
  const std::string msg =
      expect_deck_error(std::string(kMinimal) + "radius = 1.0\nthickness = = 0.2\n",
                        {"deck.toml:4:", "TOML syntax error"});
  // Column is given too: "deck.toml:4:<col>: ...".
  EXPECT_TRUE(std::isdigit(static_cast<unsigned char>(msg.at(std::string("deck.toml:4:").size()))))
      << msg;
  expect_deck_error("[model\nkind = \"block\"\n", {"deck.toml:1:", "TOML syntax error"});
}

TEST(DeckErrors, MissingOrUnreadableFile) {
  const fs::path dir = scratch_dir();
  const std::string missing = (dir / "nope.toml").string();
  try {
    load_deck(missing);
    ADD_FAILURE() << "no DeckError for a missing deck";
  } catch (const DeckError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot read deck '" + missing + "'"), std::string::npos)
        << e.what();
  }
  try {
    load_deck(dir.string());
    ADD_FAILURE() << "no DeckError for a folder";
  } catch (const DeckError& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

// ---- the real program -----------------------------------------------------------------------

// The program run on `args` (after the program's path) with the test's default limits; its
// standard output and error joined, as a user's terminal shows them.
struct ProgramResult {
  int status = -1;  // exit status, -1 when the program did not exit
  std::string out;  // standard output then standard error
};

ProgramResult run_program(const fs::path& dir, std::vector<std::string> args) {
  args.insert(args.begin(), VOUSSOIR_BINARY);
  const testing::ProcessResult p = testing::run_process(args, {}, (dir / "child").string());
  return {p.exited ? p.status : -1, p.out + p.err};
}

TEST(DeckProgram, CheckRefusesBadDeckWithStatus2AndOneLine) {
  if (!fs::exists(VOUSSOIR_BINARY)) GTEST_SKIP() << "no program at " << VOUSSOIR_BINARY;
  const fs::path dir = scratch_dir();
  const fs::path deck = dir / "bad.toml";
  write_file(deck, "[model]\nkind = \"circular_arch\"\n[contact]\nfrictoin = 0.6\n");
  const ProgramResult r = run_program(dir, {"check", deck.string()});
  const std::string& out = r.out;
  EXPECT_EQ(r.status, 2) << out;
  EXPECT_NE(out.find("contact.frictoin"), std::string::npos) << out;
  EXPECT_NE(out.find("contact.friction"), std::string::npos) << out;
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.find('\n'), out.size() - 1) << "more than one line:\n" << out;
  fs::remove_all(dir);
}

// Output files named on the command line get their folders before the command runs.
TEST(DeckProgram, OutputFoldersAreMadeBeforeTheCommandRuns) {
  if (!fs::exists(VOUSSOIR_BINARY)) GTEST_SKIP() << "no program at " << VOUSSOIR_BINARY;
  const fs::path dir = scratch_dir();
  const fs::path mesh = dir / "a" / "b" / "mesh.json", json = dir / "c" / "check.json";
  const ProgramResult r =
      run_program(dir, {"check", std::string(VOUSSOIR_SOURCE_DIR) + "/cases/block.toml",
                        "--mesh-out", mesh.string(), "--json", json.string()});
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(fs::is_regular_file(mesh)) << r.out;
  EXPECT_TRUE(fs::is_regular_file(json)) << r.out;
  fs::remove_all(dir);
}

// A folder that cannot be made (a file stands in its place) is bad input, refused at once
// naming the option and the path.
TEST(DeckProgram, OutputFolderThatCannotBeMadeIsBadInput) {
  if (!fs::exists(VOUSSOIR_BINARY)) GTEST_SKIP() << "no program at " << VOUSSOIR_BINARY;
  const fs::path dir = scratch_dir();
  write_file(dir / "taken", "a file, not a folder\n");
  const fs::path picture = dir / "taken" / "arch.png";
  const ProgramResult r =
      run_program(dir, {"capacity", std::string(VOUSSOIR_SOURCE_DIR) + "/cases/circular_arch.toml",
                        "--quiet", "--picture", picture.string()});
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("--picture " + picture.string()), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("lambda*"), std::string::npos) << "the search ran:\n" << r.out;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace voussoir

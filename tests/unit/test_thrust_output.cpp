// The line of thrust in the outputs (docs/thrust.md): the joint resultants of every
// snapshot of `voussoir run`'s HDF5 file are those of `run --json` at the final snapshot,
// value for value; RunWriter refuses a non-finite resultant other than an open joint's;
// `voussoir capacity --movie` writes a GIF of the collapsed trial (scripts/animate, matplotlib
// and Pillow: installed by scripts/install-deps); run and capacity --picture write a PNG.

#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands/capacity.hpp"
#include "engine/setup.hpp"
#include "engine/thrust.hpp"
#include "io/deck.hpp"
#include "io/hdf5_output.hpp"
#include "subprocess.hpp"

namespace voussoir {
namespace {

namespace fs = std::filesystem;

fs::path scratch_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir = fs::temp_directory_path() /
                       ("voussoir_thrust_out_" + std::to_string(::getpid()) + "_" + info->name());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string source(const std::string& rel) {
  return std::string(VOUSSOIR_SOURCE_DIR) + "/" + rel;
}

// A whole dataset of the file read as doubles (or ints), with its dimensions.
template <typename T>
std::vector<T> read_dataset(hid_t file, const std::string& name, hid_t type,
                            std::vector<hsize_t>* dims = nullptr) {
  const hid_t d = H5Dopen2(file, name.c_str(), H5P_DEFAULT);
  EXPECT_GE(d, 0) << name;
  if (d < 0) return {};
  const hid_t space = H5Dget_space(d);
  std::vector<hsize_t> shape(H5Sget_simple_extent_ndims(space));
  H5Sget_simple_extent_dims(space, shape.data(), nullptr);
  H5Sclose(space);
  std::size_t n = 1;
  for (hsize_t s : shape) n *= s;
  std::vector<T> out(n);
  if (n > 0) {
    EXPECT_GE(H5Dread(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), 0) << name;
  }
  H5Dclose(d);
  if (dims) *dims = shape;
  return out;
}

double snapshot_attribute(hid_t file, const std::string& group, const char* name) {
  double v = std::numeric_limits<double>::quiet_NaN();
  const hid_t a = H5Aopen_by_name(file, group.c_str(), name, H5P_DEFAULT, H5P_DEFAULT);
  EXPECT_GE(a, 0) << group << " @" << name;
  if (a < 0) return v;
  H5Aread(a, H5T_NATIVE_DOUBLE, &v);
  H5Aclose(a);
  return v;
}

// The first n bytes of a file.
std::string magic_of(const std::string& path, std::size_t n) {
  std::ifstream in(path, std::ios::binary);
  std::string out(n, '\0');
  in.read(out.data(), std::streamsize(n));
  return out.substr(0, std::size_t(in.gcount()));
}

// The rigid semicircular arch released under gravity and lambda = 0.2 for 0.05 s, a snapshot
// every 0.01 s: the last snapshot is the end of the run, the state of run --json's "joints".
TEST(ThrustOutput, RunHdf5JointsAreTheJsonJointsAtTheFinalSnapshot) {
  const fs::path dir = scratch_dir();
  const std::string h5 = (dir / "run.h5").string(), json = (dir / "run.json").string();
  const auto r = testing::run_process(
      {VOUSSOIR_BINARY, "run", source("cases/circular_arch.toml"), "-q", "--set",
       "material.model=rigid", "--set", "solver.end_time=0.05", "--set", "output.every=0.01",
       "--set", "load.lambda=0.2", "-o", h5, "--json", json, "--picture",
       (dir / "end.png").string()},
      {}, (dir / "child").string());
  ASSERT_TRUE(r.exited && r.status == 0) << r.describe() << r.err;
  EXPECT_EQ(magic_of((dir / "end.png").string(), 8), "\x89PNG\r\n\x1a\n");  // run --picture
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  const nlohmann::json& joints = j.at("joints");
  ASSERT_EQ(joints.size(), 12u);

  const hid_t f = H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  std::vector<hsize_t> dims;
  const std::vector<int> blocks = read_dataset<int>(f, "/mesh/joint_blocks", H5T_NATIVE_INT, &dims);
  ASSERT_EQ(dims, (std::vector<hsize_t>{12, 2}));
  const hid_t snaps = H5Gopen2(f, "/snapshots", H5P_DEFAULT);
  hsize_t count = 0;
  H5Gget_num_objs(snaps, &count);
  H5Gclose(snaps);
  ASSERT_EQ(count, 6u);  // t = 0, 0.01, ..., 0.05
  char name[64];
  std::snprintf(name, sizeof name, "/snapshots/%06d", int(count) - 1);
  const std::string last = name;
  EXPECT_EQ(snapshot_attribute(f, last, "time"), j.at("end_time").get<double>());
  EXPECT_EQ(snapshot_attribute(f, last, "lambda"), 0.2);
  const auto normal = read_dataset<double>(f, last + "/joints/normal_force", H5T_NATIVE_DOUBLE);
  const auto shear = read_dataset<double>(f, last + "/joints/shear_force", H5T_NATIVE_DOUBLE);
  const auto ecc = read_dataset<double>(f, last + "/joints/eccentricity", H5T_NATIVE_DOUBLE);
  const auto point = read_dataset<double>(f, last + "/joints/point", H5T_NATIVE_DOUBLE, &dims);
  ASSERT_EQ(dims, (std::vector<hsize_t>{12, 2}));
  // Every earlier snapshot has its resultants too.
  for (hsize_t k = 0; k < count; ++k) {
    std::snprintf(name, sizeof name, "/snapshots/%06d/joints/normal_force", int(k));
    EXPECT_EQ(read_dataset<double>(f, name, H5T_NATIVE_DOUBLE).size(), 12u) << name;
  }
  H5Fclose(f);
  fs::remove_all(dir);

  ASSERT_EQ(normal.size(), 12u);
  int closed = 0;
  for (std::size_t k = 0; k < 12; ++k) {
    const nlohmann::json& jk = joints[k];
    EXPECT_EQ(blocks[2 * k], jk["blocks"][0].get<int>()) << k;
    EXPECT_EQ(blocks[2 * k + 1], jk["blocks"][1].get<int>()) << k;
    // The same doubles: the JSON prints them to round trip.
    EXPECT_EQ(normal[k], jk["normal_force"].get<double>()) << k;
    EXPECT_EQ(shear[k], jk["shear_force"].get<double>()) << k;
    if (jk["eccentricity"].is_null()) {
      EXPECT_TRUE(std::isnan(ecc[k]) && std::isnan(point[2 * k]) && std::isnan(point[2 * k + 1]))
          << k;
      continue;
    }
    ++closed;
    EXPECT_EQ(ecc[k], jk["eccentricity"].get<double>()) << k;
    EXPECT_EQ(point[2 * k], jk["point"][0].get<double>()) << k;
    EXPECT_EQ(point[2 * k + 1], jk["point"][1].get<double>()) << k;
  }
  EXPECT_GT(closed, 6);
}

// load.gravity_ramp: `run` brings gravity and lambda g on together, linearly. A rigid block on
// its joint (its joint's period is 1e-4 s, so a ramp of 0.2 s is quasi-static) carries at
// t = 0.1 s half its weight, W = rho b h g, and a shear of lambda times that; a negative ramp is
// refused naming the key.
TEST(ThrustOutput, RunRampsGravityAndLambdaTogether) {
  const fs::path dir = scratch_dir();
  const std::string json = (dir / "run.json").string();
  const auto r = testing::run_process(
      {VOUSSOIR_BINARY, "run", source("cases/block.toml"), "-q", "--set",
       "material.model=\"rigid\"", "--set", "load.gravity_ramp=0.2", "--set", "load.lambda=0.2",
       "--set", "solver.end_time=0.1", "-o", (dir / "run.h5").string(), "--json", json},
      {}, (dir / "child").string());
  ASSERT_TRUE(r.exited && r.status == 0) << r.describe() << r.err;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j.at("joints").size(), 1u);
  const double weight = 2000.0 * 0.5 * 1.0 * 9.81;  // cases/block.toml, out-of-plane 1 m
  const double t = j.at("end_time").get<double>();
  const double normal = j["joints"][0]["normal_force"].get<double>();
  const double shear = j["joints"][0]["shear_force"].get<double>();
  EXPECT_NEAR(normal, weight * t / 0.2, 1e-3 * weight);
  EXPECT_NEAR(std::abs(shear), 0.2 * normal, 1e-3 * normal);

  const auto bad = testing::run_process(
      {VOUSSOIR_BINARY, "run", source("cases/block.toml"), "-q", "--set", "load.gravity_ramp=-1"},
      {}, (dir / "bad").string());
  EXPECT_TRUE(bad.exited && bad.status == 2) << bad.describe();
  EXPECT_NE(bad.err.find("load.gravity_ramp"), std::string::npos) << bad.err;
  fs::remove_all(dir);
}

// pulse --picture: the shaking-table arch after a small 12 Hz pulse (survived) is drawn to a
// PNG; with --curve the option is refused (exit 2) before any run.
TEST(ThrustOutput, PulsePictureDrawsTheFinalStateAndIsRefusedWithTheCurve) {
  const fs::path dir = scratch_dir();
  const std::string png = (dir / "pulse.png").string();
  const auto r = testing::run_process(
      {VOUSSOIR_BINARY, "pulse", source("cases/scaled_arch.toml"), "-q", "--set",
       "load.base.amplitude=0.05", "--set", "load.base.frequency=12", "--free-time", "0.2",
       "--picture", png},
      {}, (dir / "child").string());
  ASSERT_TRUE(r.exited && r.status == 0) << r.describe() << r.err;
  EXPECT_NE(r.out.find("survived"), std::string::npos) << r.out;
  EXPECT_EQ(magic_of(png, 8), "\x89PNG\r\n\x1a\n");
  const auto refused = testing::run_process(
      {VOUSSOIR_BINARY, "pulse", source("cases/scaled_arch.toml"), "-q", "--curve", "--freqs",
       "4", "--picture", (dir / "curve.png").string()},
      {}, (dir / "child2").string());
  ASSERT_TRUE(refused.exited) << refused.describe();
  EXPECT_EQ(refused.status, 2) << refused.err;
  EXPECT_NE(refused.err.find("--picture"), std::string::npos) << refused.err;
  EXPECT_FALSE(fs::exists(dir / "curve.png"));
}

TEST(ThrustOutput, WriterRefusesNonFiniteResultantsAndWrongSizes) {
  const fs::path dir = scratch_dir();
  Simulation sim = make_simulation(parse_deck(
      "[model]\nkind = \"block\"\nwidth = 0.5\nheight = 1.0\n[material]\nmodel = \"rigid\"\n",
      "block.toml"));
  RunWriter w;
  w.open((dir / "w.h5").string(), sim.model, {"position"});
  std::vector<JointResultant> joints(1);
  joints[0].normal_force = 1.0;
  EXPECT_THROW(w.write_snapshot_joints(snapshot_joints(joints)), std::logic_error);  // no snapshot
  w.write_snapshot(0.0, sim.model, {});
  SnapshotJoints open = snapshot_joints(joints);  // an open joint: NaN eccentricity and point
  EXPECT_NO_THROW(w.write_snapshot_joints(open));
  w.write_snapshot(0.1, sim.model, {});
  joints[0].closed = true;
  joints[0].eccentricity = std::numeric_limits<double>::infinity();
  EXPECT_THROW(w.write_snapshot_joints(snapshot_joints(joints)), std::runtime_error);
  joints[0].eccentricity = 0.5;
  joints[0].point = {std::numeric_limits<double>::quiet_NaN(), 0.0};  // half a point
  EXPECT_THROW(w.write_snapshot_joints(snapshot_joints(joints)), std::runtime_error);
  EXPECT_THROW(w.write_snapshot_joints(snapshot_joints({})), std::logic_error);  // J = 1
  EXPECT_THROW(w.write_snapshot_attribute("lambda", std::nan("")), std::runtime_error);
  w.close_complete();
  fs::remove_all(dir);
}

// The block (0.5 x 1 m, rigid) overturns at lambda* = b/h = 0.5: its collapsed trial at the
// upper bound as a GIF (about 50 frames), the temporary HDF5 file removed; a movie that is
// neither GIF nor MP4 is refused before any work (exit status 2).
TEST(ThrustOutput, CapacityMovieWritesAGifOfTheCollapsedTrial) {
  const fs::path dir = scratch_dir();
  const std::string gif = (dir / "block.gif").string();
  const std::string png = (dir / "mode.png").string();
  const auto r = testing::run_process({VOUSSOIR_BINARY, "capacity", source("cases/block.toml"),
                                       "-q", "--set", "material.model=rigid", "--movie", gif,
                                       "--picture", png},
                                      {}, (dir / "child").string());
  ASSERT_TRUE(r.exited && r.status == 0) << r.describe() << r.err;
  ASSERT_TRUE(fs::exists(gif)) << r.out << r.err;
  EXPECT_GT(fs::file_size(gif), 10000u);
  EXPECT_EQ(magic_of(gif, 6), "GIF89a");
  EXPECT_NE(r.out.find("movie " + gif), std::string::npos) << r.out;
  EXPECT_EQ(magic_of(png, 8), "\x89PNG\r\n\x1a\n");
  EXPECT_FALSE(fs::exists(gif + ".+x.h5"));
  EXPECT_FALSE(fs::exists(gif + ".+x.xdmf"));

  const auto bad = testing::run_process({VOUSSOIR_BINARY, "capacity", source("cases/block.toml"),
                                         "-q", "--movie", (dir / "block.avi").string()},
                                        {}, (dir / "child2").string());
  EXPECT_TRUE(bad.exited && bad.status == 2) << bad.describe() << bad.err;
  EXPECT_NE(bad.err.find(".gif or .mp4"), std::string::npos) << bad.err;
  fs::remove_all(dir);
}

// The movie is the trial: re-run from the settled state, the collapsed trial at the upper
// bound fires its collapse criterion at the same time as in the search, then goes on to the
// movie's end (a block rotated kMovieRotation or moved kMovieDisplacement x L_ref); every
// frame has its resultants and the ramped lambda.
TEST(ThrustOutput, MovieTrialCollapsesWhenTheSearchedTrialDid) {
  const fs::path dir = scratch_dir();
  const Config config = parse_deck(
      "[model]\nkind = \"block\"\nwidth = 0.5\nheight = 1.0\n[material]\nmodel = \"rigid\"\n"
      "[contact]\nfriction = 0.8\n",
      "block.toml");
  TrialCriteria crit;
  crit.quasi_static = true;
  CapacitySearch search;
  search.quiet = true;
  search.movie = (dir / "movie.h5").string();
  const CapacityResult r = find_capacity(config, crit, search);
  ASSERT_TRUE(r.bracketed);
  ASSERT_TRUE(r.has_movie);
  double searched = -1.0;
  for (const TrialResult& t : r.trials)
    if (t.collapsed && t.lambda == r.hi) searched = t.sim_time;
  EXPECT_TRUE(r.movie.collapsed);
  EXPECT_EQ(r.movie.collapse_time, searched);
  EXPECT_GT(r.movie.duration, r.movie.collapse_time);
  EXPECT_GE(r.movie.frames, 40);
  EXPECT_LE(r.movie.frames, kMovieFrames);

  const hid_t f = H5Fopen(search.movie.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  char name[64];
  std::snprintf(name, sizeof name, "/snapshots/%06d", r.movie.frames - 1);
  EXPECT_EQ(snapshot_attribute(f, name, "lambda"), r.hi);  // the ramp is over
  EXPECT_EQ(snapshot_attribute(f, name, "time"), r.movie.duration);
  EXPECT_EQ(snapshot_attribute(f, "/snapshots/000000", "lambda"), 0.0);  // the ramp starts
  const auto ecc =
      read_dataset<double>(f, std::string(name) + "/joints/eccentricity", H5T_NATIVE_DOUBLE);
  H5Fclose(f);
  ASSERT_EQ(ecc.size(), 1u);
  EXPECT_GT(ecc[0], 0.99);  // overturning about its toe
  fs::remove_all(dir);
}

}  // namespace
}  // namespace voussoir

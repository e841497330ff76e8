// Run output (io/hdf5_output.cpp, io/json.cpp): what RunWriter writes is read back with the
// HDF5 C API and compared with what was given; the completeness contract (tmp file, rename,
// complete flag) holds on the success and on the error path; the XDMF names every snapshot.

#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "core/model.hpp"
#include "io/hdf5_output.hpp"
#include "io/json.hpp"

namespace voussoir {
namespace {

namespace fs = std::filesystem;

// Two blocks: a fixed 2 x 1 ground of two triangles and a free unit triangle on it.
Model tiny_model() {
  Model m;
  const std::vector<Vec2> ground = {{0, 0}, {2, 0}, {2, 1}, {0, 1}};
  add_block(m, ground, ground, {{0, 1, 2}, {0, 2, 3}}, true, "ground");
  const std::vector<Vec2> tri = {{0.5, 1}, {1.5, 1}, {1, 2}};
  add_block(m, tri, tri, {{0, 2, 1}}, false, "voussoir");  // clockwise: add_block flips it
  m.kind = "polygons";
  m.out_of_plane = 0.5;
  finalize_model(m);
  return m;
}

fs::path scratch_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir = fs::temp_directory_path() /
                       ("voussoir_out_" + std::to_string(::getpid()) + "_" + info->name());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

// ---- reading back with the C API ----------------------------------------------------------

struct File {
  hid_t id;
  explicit File(const fs::path& p) : id(H5Fopen(p.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT)) {}
  ~File() {
    if (id >= 0) H5Fclose(id);
  }
};

bool has_link(hid_t f, const std::string& name) {
  return H5Lexists(f, name.c_str(), H5P_DEFAULT) > 0;
}

std::vector<hsize_t> dims_of(hid_t f, const std::string& name) {
  const hid_t d = H5Dopen2(f, name.c_str(), H5P_DEFAULT);
  EXPECT_GE(d, 0) << name;
  if (d < 0) return {};
  const hid_t s = H5Dget_space(d);
  std::vector<hsize_t> dims(H5Sget_simple_extent_ndims(s));
  H5Sget_simple_extent_dims(s, dims.data(), nullptr);
  H5Sclose(s);
  H5Dclose(d);
  return dims;
}

template <typename T>
std::vector<T> read_all(hid_t f, const std::string& name, hid_t type) {
  std::size_t n = 1;
  for (hsize_t d : dims_of(f, name)) n *= d;
  std::vector<T> out(n);
  const hid_t d = H5Dopen2(f, name.c_str(), H5P_DEFAULT);
  if (d < 0) return {};
  if (n > 0) {
    EXPECT_GE(H5Dread(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), 0) << name;
  }
  H5Dclose(d);
  return out;
}
std::vector<double> read_doubles(hid_t f, const std::string& name) {
  return read_all<double>(f, name, H5T_NATIVE_DOUBLE);
}
std::vector<int> read_ints(hid_t f, const std::string& name) {
  return read_all<int>(f, name, H5T_NATIVE_INT);
}

template <typename T>
T read_attr(hid_t loc, const std::string& obj, const char* name, hid_t type) {
  T v{};
  const hid_t a = H5Aopen_by_name(loc, obj.c_str(), name, H5P_DEFAULT, H5P_DEFAULT);
  EXPECT_GE(a, 0) << obj << " @" << name;
  if (a < 0) return v;
  EXPECT_GE(H5Aread(a, type, &v), 0);
  H5Aclose(a);
  return v;
}
int attr_int(hid_t f, const std::string& obj, const char* name) {
  return read_attr<int>(f, obj, name, H5T_NATIVE_INT);
}
double attr_double(hid_t f, const std::string& obj, const char* name) {
  return read_attr<double>(f, obj, name, H5T_NATIVE_DOUBLE);
}
std::string attr_string(hid_t f, const std::string& obj, const char* name) {
  const hid_t a = H5Aopen_by_name(f, obj.c_str(), name, H5P_DEFAULT, H5P_DEFAULT);
  if (a < 0) return "<missing>";
  const hid_t t = H5Aget_type(a);
  std::string s(H5Tget_size(t), '\0');
  H5Aread(a, t, s.data());
  H5Tclose(t);
  H5Aclose(a);
  return s.c_str();
}

SeriesRecord record(int k) {
  SeriesRecord r;
  r.time = 0.01 * k;
  r.kinetic = 1.0 + k;
  r.strain = 2.0 + k;
  r.contact = 3.0 + k;
  r.damping_dissipated = 4.0 + k;
  r.friction_dissipated = 5.0 + k;
  r.external_work = 6.0 + k;
  r.max_displacement = 7.0 + k;
  r.active_contacts = 100 + k;
  r.energy_balance_error = 1e-3 * k;
  return r;
}

// Moves the free block and gives it a velocity, so snapshots differ from the reference.
void move(Model& m, double s) {
  for (Index i = 0; i < m.nodes.size(); ++i) {
    if (m.nodes.inv_mass[i] == 0.0) continue;
    m.nodes.x[i] = m.nodes.x0[i] + 0.1 * s;
    m.nodes.y[i] = m.nodes.y0[i] - 0.01 * s * i;
    m.nodes.vx[i] = s * (1.0 + i);
    m.nodes.vy[i] = -s * i;
  }
}

std::vector<double> stress_of(const Model& m, double s) {
  std::vector<double> st;
  for (Index e = 0; e < m.tris.size(); ++e) {
    st.push_back(s * (e + 1));   // sxx
    st.push_back(-s * (e + 2));  // syy
    st.push_back(0.5 * s * e);   // sxy
  }
  return st;
}

TEST(RunWriter, WritesMeshSeriesSnapshotsAndCompletes) {
  const fs::path dir = scratch_dir();
  const fs::path h5 = dir / "run.h5";
  Model m = tiny_model();
  ASSERT_EQ(m.nodes.size(), 7);
  ASSERT_EQ(m.tris.size(), 3);
  move(m, 1.0);
  const std::vector<double> s1 = stress_of(m, 1e5);
  std::vector<double> pos1x = m.nodes.x, pos1y = m.nodes.y, vel1x = m.nodes.vx;
  {
    RunWriter w;
    w.open(h5.string(), m, {"position", "velocity", "stress"});
    EXPECT_TRUE(w.is_open());
    EXPECT_TRUE(fs::exists(dir / "run.h5.tmp"));
    EXPECT_FALSE(fs::exists(h5));
    w.set_control_columns({"crown_ux", "crown_uy"});
    for (int k = 0; k < 3; ++k) {
      SeriesRecord r = record(k);
      r.control_displacements = {0.1 * k, -0.2 * k};
      w.append_series(r);
    }
    w.write_snapshot(0.1, m, s1);
    move(m, 2.0);
    w.append_series([] {
      SeriesRecord r = record(3);
      r.control_displacements = {0.3, -0.6};
      return r;
    }());
    w.write_snapshot(0.25, m, stress_of(m, 2e5));
    EXPECT_EQ(w.snapshot_count(), 2);
    EXPECT_EQ(w.series_rows(), 4);
    w.close_complete();
    EXPECT_FALSE(w.is_open());
  }
  ASSERT_TRUE(fs::exists(h5));
  EXPECT_FALSE(fs::exists(dir / "run.h5.tmp"));

  File f(h5);
  ASSERT_GE(f.id, 0);
  EXPECT_EQ(attr_int(f.id, "/", "complete"), 1);
  EXPECT_EQ(attr_int(f.id, "/", "snapshot_count"), 2);
  EXPECT_EQ(attr_string(f.id, "/", "kind"), "polygons");
  EXPECT_EQ(attr_string(f.id, "/", "fields"), "position,velocity,stress");
  EXPECT_DOUBLE_EQ(attr_double(f.id, "/", "out_of_plane"), 0.5);

  // Mesh: reference positions, triangles as the model holds them, ownership, fixed flags.
  EXPECT_EQ(dims_of(f.id, "/mesh/nodes"), (std::vector<hsize_t>{7, 2}));
  const auto nodes = read_doubles(f.id, "/mesh/nodes");
  for (Index i = 0; i < 7; ++i) {
    EXPECT_EQ(nodes[2 * i], m.nodes.x0[i]);
    EXPECT_EQ(nodes[2 * i + 1], m.nodes.y0[i]);
  }
  EXPECT_EQ(dims_of(f.id, "/mesh/triangles"), (std::vector<hsize_t>{3, 3}));
  const auto tris = read_ints(f.id, "/mesh/triangles");
  for (Index e = 0; e < 3; ++e) {
    EXPECT_EQ(tris[3 * e], m.tris.n0[e]);
    EXPECT_EQ(tris[3 * e + 1], m.tris.n1[e]);
    EXPECT_EQ(tris[3 * e + 2], m.tris.n2[e]);
  }
  EXPECT_EQ(read_ints(f.id, "/mesh/block"), (std::vector<int>{0, 0, 1}));
  EXPECT_EQ(read_ints(f.id, "/mesh/node_block"), (std::vector<int>{0, 0, 0, 0, 1, 1, 1}));
  EXPECT_EQ(read_ints(f.id, "/mesh/fixed"), (std::vector<int>{1, 0}));

  // Series: one row per record, in order.
  const char* names[] = {"time",
                         "kinetic",
                         "strain",
                         "contact",
                         "damping_dissipated",
                         "friction_dissipated",
                         "external_work",
                         "max_displacement",
                         "energy_balance_error"};
  for (const char* n : names)
    EXPECT_EQ(dims_of(f.id, std::string("/series/") + n), std::vector<hsize_t>{4}) << n;
  const auto time = read_doubles(f.id, "/series/time");
  const auto kinetic = read_doubles(f.id, "/series/kinetic");
  const auto external = read_doubles(f.id, "/series/external_work");
  const auto ebe = read_doubles(f.id, "/series/energy_balance_error");
  const auto contacts = read_all<std::int64_t>(f.id, "/series/active_contacts", H5T_NATIVE_INT64);
  for (int k = 0; k < 4; ++k) {
    EXPECT_DOUBLE_EQ(time[k], record(k).time);
    EXPECT_DOUBLE_EQ(kinetic[k], record(k).kinetic);
    EXPECT_DOUBLE_EQ(external[k], record(k).external_work);
    EXPECT_DOUBLE_EQ(ebe[k], record(k).energy_balance_error);
    EXPECT_EQ(contacts[k], record(k).active_contacts);
  }
  EXPECT_EQ(dims_of(f.id, "/series/control_displacement"), (std::vector<hsize_t>{4, 2}));
  EXPECT_EQ(read_doubles(f.id, "/series/control_displacement"),
            (std::vector<double>{0, 0, 0.1, -0.2, 0.2, -0.4, 0.3, -0.6}));
  EXPECT_EQ(attr_string(f.id, "/series/control_displacement", "columns"), "crown_ux,crown_uy");

  // Snapshots: time attribute and the state at that moment.
  EXPECT_DOUBLE_EQ(attr_double(f.id, "/snapshots/000000", "time"), 0.1);
  EXPECT_DOUBLE_EQ(attr_double(f.id, "/snapshots/000001", "time"), 0.25);
  EXPECT_EQ(dims_of(f.id, "/snapshots/000000/position"), (std::vector<hsize_t>{7, 2}));
  // Point vectors with 3 components (z = 0), as ParaView's filters want them.
  EXPECT_EQ(dims_of(f.id, "/snapshots/000000/displacement"), (std::vector<hsize_t>{7, 3}));
  EXPECT_EQ(dims_of(f.id, "/snapshots/000000/velocity"), (std::vector<hsize_t>{7, 3}));
  const auto p0 = read_doubles(f.id, "/snapshots/000000/position");
  const auto u0 = read_doubles(f.id, "/snapshots/000000/displacement");
  const auto v0 = read_doubles(f.id, "/snapshots/000000/velocity");
  const auto p1 = read_doubles(f.id, "/snapshots/000001/position");
  const auto v1 = read_doubles(f.id, "/snapshots/000001/velocity");
  for (Index i = 0; i < 7; ++i) {
    EXPECT_EQ(p0[2 * i], pos1x[i]);
    EXPECT_EQ(p0[2 * i + 1], pos1y[i]);
    EXPECT_EQ(u0[3 * i], pos1x[i] - m.nodes.x0[i]);
    EXPECT_EQ(u0[3 * i + 1], pos1y[i] - m.nodes.y0[i]);
    EXPECT_EQ(u0[3 * i + 2], 0.0);
    EXPECT_EQ(v0[3 * i], vel1x[i]);
    EXPECT_EQ(v0[3 * i + 2], 0.0);
    EXPECT_EQ(p1[2 * i], m.nodes.x[i]);
    EXPECT_EQ(p1[2 * i + 1], m.nodes.y[i]);
    EXPECT_EQ(v1[3 * i], m.nodes.vx[i]);
    EXPECT_EQ(v1[3 * i + 1], m.nodes.vy[i]);
  }
  EXPECT_NE(p0, p1);  // the block moved between the snapshots
  // Stress: named scalars, the components as given and the principal stresses.
  for (const auto& [snap, st] :
       {std::pair{std::string("000000"), s1}, std::pair{std::string("000001"), stress_of(m, 2e5)}}) {
    const std::string g = "/snapshots/" + snap + "/";
    EXPECT_EQ(dims_of(f.id, g + "stress_xx"), (std::vector<hsize_t>{3}));
    const auto xx = read_doubles(f.id, g + "stress_xx"), yy = read_doubles(f.id, g + "stress_yy"),
               xy = read_doubles(f.id, g + "stress_xy"), s_1 = read_doubles(f.id, g + "stress_1"),
               s_2 = read_doubles(f.id, g + "stress_2");
    // The T x 3 dataset of the earlier layout stays in the HDF5 file, equal to the scalars.
    EXPECT_EQ(dims_of(f.id, g + "stress"), (std::vector<hsize_t>{3, 3}));
    EXPECT_EQ(read_doubles(f.id, g + "stress"), st);
    for (std::size_t e = 0; e < 3; ++e) {
      EXPECT_EQ(xx[e], st[3 * e]);
      EXPECT_EQ(yy[e], st[3 * e + 1]);
      EXPECT_EQ(xy[e], st[3 * e + 2]);
      // Invariants: trace and determinant of the in-plane tensor.
      const double scale = std::abs(xx[e]) + std::abs(yy[e]) + std::abs(xy[e]);
      EXPECT_NEAR(s_1[e] + s_2[e], xx[e] + yy[e], 1e-12 * scale);
      EXPECT_NEAR(s_1[e] * s_2[e], xx[e] * yy[e] - xy[e] * xy[e], 1e-12 * scale * scale);
      EXPECT_GE(s_1[e], s_2[e]);
    }
  }

  // XDMF beside it: a temporal collection naming the final .h5 and each snapshot's datasets.
  const fs::path xdmf = dir / "run.xdmf";
  ASSERT_TRUE(fs::exists(xdmf));
  EXPECT_FALSE(fs::exists(dir / "run.xdmf.tmp"));
  const std::string x = read_text(xdmf);
  EXPECT_NE(x.find("CollectionType=\"Temporal\""), std::string::npos);
  EXPECT_EQ(count_of(x, "<Time Value="), 2u);
  EXPECT_NE(x.find("<Time Value=\"0.1\""), std::string::npos);
  EXPECT_NE(x.find("<Time Value=\"0.25\""), std::string::npos);
  EXPECT_NE(x.find("TopologyType=\"Triangle\" NumberOfElements=\"3\""), std::string::npos);
  EXPECT_NE(x.find("GeometryType=\"XY\""), std::string::npos);
  EXPECT_EQ(count_of(x, "run.h5:/mesh/triangles"), 2u);
  EXPECT_EQ(count_of(x, "run.h5:/mesh/block"), 2u);
  EXPECT_EQ(count_of(x, "run.h5:/mesh/nodes"), 2u);  // the reference geometry on every grid
  for (const char* s : {"000000", "000001"}) {
    for (const char* d : {"displacement", "velocity", "stress_xx", "stress_yy", "stress_xy",
                          "stress_1", "stress_2"})
      EXPECT_NE(x.find(std::string("run.h5:/snapshots/") + s + "/" + d), std::string::npos)
          << s << "/" << d;
  }
  // Vectors are declared with their 3 components; no stress "Vector".
  EXPECT_EQ(count_of(x, "AttributeType=\"Vector\""), 4u);
  EXPECT_EQ(count_of(x, "Dimensions=\"7 3\""), 4u);
  EXPECT_EQ(count_of(x, "Dimensions=\"7 2\""), 2u);  // the geometry only
  EXPECT_EQ(x.find(".tmp"), std::string::npos) << "XDMF must name the final file";
  EXPECT_EQ(count_of(x, "<Grid "), count_of(x, "</Grid>"));
  fs::remove_all(dir);
}

TEST(RunWriter, SeriesLongerThanTheBufferKeepsEveryRowInOrder) {
  const fs::path dir = scratch_dir();
  const fs::path h5 = dir / "long.h5";
  const Model m = tiny_model();
  const int rows = static_cast<int>(2 * RunWriter::kSeriesBlock + 37);
  {
    RunWriter w;
    w.open(h5.string(), m, {});
    for (int k = 0; k < rows; ++k) w.append_series(record(k));
    w.close_complete();
  }
  File f(h5);
  const auto time = read_doubles(f.id, "/series/time");
  const auto strain = read_doubles(f.id, "/series/strain");
  ASSERT_EQ(time.size(), static_cast<std::size_t>(rows));
  for (int k = 0; k < rows; ++k) {
    EXPECT_DOUBLE_EQ(time[k], record(k).time);
    EXPECT_DOUBLE_EQ(strain[k], record(k).strain);
  }
  EXPECT_FALSE(has_link(f.id, "/series/control_displacement"));
  // No snapshot: the XDMF still shows the reference mesh.
  const std::string x = read_text(dir / "long.xdmf");
  EXPECT_NE(x.find("long.h5:/mesh/nodes"), std::string::npos);
  EXPECT_EQ(x.find("<Time"), std::string::npos);
  fs::remove_all(dir);
}

TEST(RunWriter, OnlyRequestedFieldsAreWritten) {
  const fs::path dir = scratch_dir();
  const fs::path h5 = dir / "v.h5";
  Model m = tiny_model();
  move(m, 1.0);
  {
    RunWriter w;
    w.open(h5.string(), m, {"velocity"});
    w.write_snapshot(0.5, m, {});  // no stress needed
    w.close_complete();
  }
  File f(h5);
  EXPECT_TRUE(has_link(f.id, "/snapshots/000000/velocity"));
  EXPECT_FALSE(has_link(f.id, "/snapshots/000000/position"));
  EXPECT_FALSE(has_link(f.id, "/snapshots/000000/displacement"));
  EXPECT_FALSE(has_link(f.id, "/snapshots/000000/stress_xx"));
  const std::string x = read_text(dir / "v.xdmf");
  EXPECT_NE(x.find("v.h5:/snapshots/000000/velocity"), std::string::npos);
  EXPECT_NE(x.find("v.h5:/mesh/nodes"), std::string::npos);  // geometry: reference positions
  EXPECT_EQ(x.find("stress"), std::string::npos);
  EXPECT_EQ(x.find("/position"), std::string::npos);
  fs::remove_all(dir);
}

TEST(RunWriter, ErrorPathLeavesNothingLookingComplete) {
  const fs::path dir = scratch_dir();
  const fs::path h5 = dir / "out" / "fail.h5";  // parent folder created by open()
  fs::create_directories(h5.parent_path());
  // A finished run from before, at the same name.
  { std::ofstream(h5) << "old"; }
  { std::ofstream(dir / "out" / "fail.xdmf") << "old"; }
  Model m = tiny_model();
  {
    RunWriter w;
    w.open(h5.string(), m, {"position"});
    EXPECT_FALSE(fs::exists(h5)) << "a stale complete file survived open()";
    EXPECT_FALSE(fs::exists(dir / "out" / "fail.xdmf"));
    for (int k = 0; k < 5; ++k) w.append_series(record(k));
    w.write_snapshot(0.1, m, {});
    w.append_series(record(5));
    // ... the run throws here: the writer goes out of scope without close_complete().
  }
  EXPECT_FALSE(fs::exists(h5));
  EXPECT_FALSE(fs::exists(dir / "out" / "fail.xdmf"));
  const fs::path tmp = dir / "out" / "fail.h5.tmp";
  ASSERT_TRUE(fs::exists(tmp));
  {
    File f(tmp);
    ASSERT_GE(f.id, 0);
    EXPECT_EQ(attr_int(f.id, "/", "complete"), 0);
    EXPECT_EQ(read_doubles(f.id, "/series/time").size(), 6u);  // buffered rows kept
    EXPECT_TRUE(has_link(f.id, "/snapshots/000000/position"));
    EXPECT_EQ(H5Aexists(f.id, "error"), 0);
  }
  // Explicit failure with a reason.
  {
    RunWriter w;
    w.open(h5.string(), m, {"position"});
    w.append_series(record(0));
    w.close_incomplete("non-finite velocity at t = 0.3 s");
    EXPECT_FALSE(w.is_open());
  }
  EXPECT_FALSE(fs::exists(h5));
  File f(tmp);
  EXPECT_EQ(attr_int(f.id, "/", "complete"), 0);
  EXPECT_EQ(attr_string(f.id, "/", "error"), "non-finite velocity at t = 0.3 s");
  fs::remove_all(dir);
}

TEST(RunWriter, RefusesNonFiniteValuesAndWrongSizes) {
  const fs::path dir = scratch_dir();
  Model m = tiny_model();
  RunWriter w;
  w.open((dir / "nan.h5").string(), m, {"position", "velocity", "stress"});
  SeriesRecord r = record(1);
  r.kinetic = std::numeric_limits<double>::quiet_NaN();
  try {
    w.append_series(r);
    ADD_FAILURE() << "NaN kinetic energy accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("kinetic"), std::string::npos) << e.what();
  }
  EXPECT_EQ(w.series_rows(), 0);
  m.nodes.vy[5] = std::numeric_limits<double>::infinity();
  try {
    w.write_snapshot(0.2, m, stress_of(m, 1.0));
    ADD_FAILURE() << "infinite velocity accepted";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("velocity of node 5"), std::string::npos) << msg;
    EXPECT_NE(msg.find("t = 0.2"), std::string::npos) << msg;
  }
  EXPECT_EQ(w.snapshot_count(), 0);
  m.nodes.vy[5] = 0.0;
  EXPECT_THROW(w.write_snapshot(0.2, m, {1.0, 2.0}), std::logic_error);  // stress not 3 x T
  w.write_snapshot(0.2, m, stress_of(m, 1.0));
  EXPECT_EQ(w.snapshot_count(), 1);
  w.close_complete();
  File f(dir / "nan.h5");
  EXPECT_TRUE(has_link(f.id, "/snapshots/000000"));
  EXPECT_FALSE(has_link(f.id, "/snapshots/000001"));
  fs::remove_all(dir);
}

TEST(RunWriter, UnwritablePathIsReportedWithItsName) {
  const fs::path dir = scratch_dir();
  { std::ofstream(dir / "plainfile") << "x"; }
  const std::string bad = (dir / "plainfile" / "run.h5").string();  // parent is a file
  const Model m = tiny_model();
  RunWriter w;
  try {
    w.open(bad, m, {});
    ADD_FAILURE() << "open succeeded under a plain file";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
  EXPECT_FALSE(w.is_open());
  fs::remove_all(dir);
}

TEST(Json, WritesFileAndNamesUnwritablePath) {
  const fs::path dir = scratch_dir();
  const fs::path p = dir / "summary.json";
  write_json({{"lambda_star", 0.294}, {"runs", {1, 2}}}, p.string());
  const nlohmann::json back = nlohmann::json::parse(read_text(p));
  EXPECT_DOUBLE_EQ(back.at("lambda_star").get<double>(), 0.294);
  EXPECT_EQ(back.at("runs").size(), 2u);
  EXPECT_FALSE(fs::exists(dir / "summary.json.tmp"));
  const std::string bad = (dir / "no" / "such" / "dir" / "x.json").string();
  try {
    write_json({{"a", 1}}, bad);
    ADD_FAILURE() << "wrote into a missing folder";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace voussoir

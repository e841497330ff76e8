// HDF5 run output and its XDMF companion (layout and completeness contract in the header).
//
// Implementation notes:
//   - HDF5 C API only (the Debian build is thread-safe, so concurrent writers of different
//     files in a sweep are fine). The library's automatic error printing is switched off for
//     the calling thread in open(): every failure is reported once, by our exception.
//   - Every handle lives in an `H5Handle` that closes it, so an exception on any path leaks
//     nothing and leaves the .tmp file closed and readable.
//   - XDMF: checked with ParaView 5.11's three readers (XDMF Reader, Xdmf3ReaderS/T). Point
//     vectors are stored with 3 components (z = 0) in the HDF5 file itself: an N x 2 "Vector"
//     was kept at 2 components by the Xdmf3 readers and Warp By Vector then aborted
//     (vtkWarpVector: GetNumberOfComponents() == 3 failed). Stress is five named scalars, each
//     its own dataset: a 3-component "Vector" stress made ParaView offer X/Y/Z and a
//     meaningless magnitude. Tried and dropped: HyperSlab and JOIN function data items
//     (per-component stress scalars, zero-padded velocity) work in the Xdmf2 reader but the
//     Xdmf3 readers skip them, hence the separate datasets.

#include "io/hdf5_output.hpp"

#include <hdf5.h>

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "io/json.hpp"
#include "voussoir/config.hpp"

namespace voussoir {

namespace fs = std::filesystem;

std::string xdmf_path_for(const std::string& h5_path) {
  fs::path p(h5_path);
  if (p.has_extension()) return p.replace_extension(".xdmf").string();
  return h5_path + ".xdmf";
}

namespace {

// Owns one HDF5 identifier and closes it with the matching H5?close.
class H5Handle {
 public:
  H5Handle() = default;
  H5Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  H5Handle(H5Handle&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = -1; }
  H5Handle& operator=(H5Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = o.id_;
      close_ = o.close_;
      o.id_ = -1;
    }
    return *this;
  }
  H5Handle(const H5Handle&) = delete;
  H5Handle& operator=(const H5Handle&) = delete;
  ~H5Handle() { reset(); }
  void reset() {
    if (id_ >= 0 && close_ != nullptr) close_(id_);
    id_ = -1;
  }
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }

 private:
  hid_t id_ = -1;
  herr_t (*close_)(hid_t) = nullptr;
};

const char* const kSeriesNames[] = {"time",
                                    "kinetic",
                                    "strain",
                                    "contact",
                                    "damping_dissipated",
                                    "friction_dissipated",
                                    "external_work",
                                    "max_displacement",
                                    "energy_balance_error"};
constexpr std::size_t kSeriesDoubles = sizeof(kSeriesNames) / sizeof(kSeriesNames[0]);

std::array<double, kSeriesDoubles> series_values(const SeriesRecord& r) {
  return {r.time,
          r.kinetic,
          r.strain,
          r.contact,
          r.damping_dissipated,
          r.friction_dissipated,
          r.external_work,
          r.max_displacement,
          r.energy_balance_error};
}

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// Shortest text that reads back to the same double.
std::string format_time(double t) {
  char buf[40];
  const auto res = std::to_chars(buf, buf + sizeof buf, t);
  return std::string(buf, res.ptr);
}

// Snapshot datasets of the "stress" field, one scalar per triangle [Pa].
const char* const kStressNames[] = {"stress_xx", "stress_yy", "stress_xy", "stress_1",
                                    "stress_2"};

std::string snapshot_name(int k) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%06d", k);
  return buf;
}

}  // namespace

struct RunWriter::Impl {
  std::string path, tmp;
  std::vector<std::string> fields;
  bool want_position = false, want_velocity = false, want_stress = false;
  Index nodes = 0, tris = 0;
  std::size_t joints = 0;  // the model's joints (/mesh/joint_blocks)

  H5Handle file;
  std::array<H5Handle, kSeriesDoubles> series;
  H5Handle contacts;  // /series/active_contacts (int64)
  H5Handle control;   // /series/control_displacement (R x C), created with the first rows

  // Buffered rows not yet written.
  std::array<std::vector<double>, kSeriesDoubles> buf;
  std::vector<std::int64_t> buf_contacts;
  std::vector<double> buf_control;  // row-major, C per row
  long control_cols = -1;           // -1: not yet known
  std::vector<std::string> control_names;
  std::int64_t rows_written = 0, rows_total = 0;

  std::vector<double> snapshot_times;
  std::vector<double> scratch;  // N x 2 interleaving buffer

  [[noreturn]] void fail(const std::string& what) const {
    throw OutputError("HDF5 output '" + tmp + "': cannot " + what);
  }
  hid_t check(hid_t id, const std::string& what) const {
    if (id < 0) fail(what);
    return id;
  }

  // ---- small writers ---------------------------------------------------------------------

  void write_array(hid_t loc, const std::string& name, hid_t type, hsize_t rows, hsize_t cols,
                   const void* data) {
    const hsize_t dims[2] = {rows, cols};
    H5Handle space(check(H5Screate_simple(cols == 0 ? 1 : 2, dims, nullptr), "create dataspace"),
                   H5Sclose);
    H5Handle set(check(H5Dcreate2(loc, name.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT,
                                  H5P_DEFAULT),
                       "create dataset " + name),
                 H5Dclose);
    if (rows * (cols == 0 ? 1 : cols) > 0)
      check(H5Dwrite(set.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "write " + name);
  }

  template <typename T>
  void write_attr(hid_t loc, const char* name, hid_t type, const T& value) {
    if (H5Aexists(loc, name) > 0) check(H5Adelete(loc, name), std::string("replace ") + name);
    H5Handle space(check(H5Screate(H5S_SCALAR), "create dataspace"), H5Sclose);
    H5Handle attr(check(H5Acreate2(loc, name, type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                        std::string("create attribute ") + name),
                  H5Aclose);
    check(H5Awrite(attr.get(), type, &value), std::string("write attribute ") + name);
  }
  void write_attr_int(hid_t loc, const char* name, int value) {
    write_attr(loc, name, H5T_NATIVE_INT, value);
  }
  void write_attr_double(hid_t loc, const char* name, double value) {
    write_attr(loc, name, H5T_NATIVE_DOUBLE, value);
  }
  void write_attr_string(hid_t loc, const char* name, const std::string& value) {
    if (H5Aexists(loc, name) > 0) check(H5Adelete(loc, name), std::string("replace ") + name);
    H5Handle type(check(H5Tcopy(H5T_C_S1), "copy string type"), H5Tclose);
    check(H5Tset_size(type.get(), value.size() + 1), "size string type");
    check(H5Tset_strpad(type.get(), H5T_STR_NULLTERM), "pad string type");
    H5Handle space(check(H5Screate(H5S_SCALAR), "create dataspace"), H5Sclose);
    H5Handle attr(check(H5Acreate2(loc, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
                        std::string("create attribute ") + name),
                  H5Aclose);
    check(H5Awrite(attr.get(), type.get(), value.c_str()), std::string("write attribute ") + name);
  }

  // An empty dataset that grows along its first dimension.
  H5Handle create_growing(hid_t loc, const char* name, hid_t type, hsize_t cols) {
    const int rank = cols == 0 ? 1 : 2;
    const hsize_t dims[2] = {0, cols};
    const hsize_t maxdims[2] = {H5S_UNLIMITED, cols};
    const hsize_t chunk[2] = {1024, cols == 0 ? 1 : cols};
    H5Handle space(check(H5Screate_simple(rank, dims, maxdims), "create dataspace"), H5Sclose);
    H5Handle plist(check(H5Pcreate(H5P_DATASET_CREATE), "create property list"), H5Pclose);
    check(H5Pset_chunk(plist.get(), rank, chunk), "set chunking");
    return H5Handle(
        check(H5Dcreate2(loc, name, type, space.get(), H5P_DEFAULT, plist.get(), H5P_DEFAULT),
              std::string("create dataset /series/") + name),
        H5Dclose);
  }

  // Appends `rows` rows (of `cols` values, 0 = 1D) to a growing dataset holding `before` rows.
  void append_rows(hid_t set, hid_t type, hsize_t before, hsize_t rows, hsize_t cols,
                   const void* data) {
    const int rank = cols == 0 ? 1 : 2;
    const hsize_t size[2] = {before + rows, cols};
    check(H5Dset_extent(set, size), "extend a series");
    H5Handle fspace(check(H5Dget_space(set), "get dataspace"), H5Sclose);
    const hsize_t start[2] = {before, 0};
    const hsize_t count[2] = {rows, cols};
    check(H5Sselect_hyperslab(fspace.get(), H5S_SELECT_SET, start, nullptr, count, nullptr),
          "select rows");
    H5Handle mspace(check(H5Screate_simple(rank, count, nullptr), "create dataspace"), H5Sclose);
    check(H5Dwrite(set, type, mspace.get(), fspace.get(), H5P_DEFAULT, data), "append a series");
  }

  void flush_series() {
    const hsize_t rows = static_cast<hsize_t>(rows_total - rows_written);
    if (rows == 0) return;
    const hsize_t before = static_cast<hsize_t>(rows_written);
    for (std::size_t k = 0; k < kSeriesDoubles; ++k) {
      append_rows(series[k].get(), H5T_NATIVE_DOUBLE, before, rows, 0, buf[k].data());
      buf[k].clear();
    }
    append_rows(contacts.get(), H5T_NATIVE_INT64, before, rows, 0, buf_contacts.data());
    buf_contacts.clear();
    if (control_cols > 0) {
      if (!control.valid()) {
        H5Handle group(check(H5Gopen2(file.get(), "/series", H5P_DEFAULT), "open /series"),
                       H5Gclose);
        control = create_growing(group.get(), "control_displacement", H5T_NATIVE_DOUBLE,
                                 static_cast<hsize_t>(control_cols));
        std::string cols;
        for (std::size_t k = 0; k < control_names.size(); ++k)
          cols += (k ? "," : "") + control_names[k];
        if (!cols.empty()) write_attr_string(control.get(), "columns", cols);
      }
      append_rows(control.get(), H5T_NATIVE_DOUBLE, before, rows,
                  static_cast<hsize_t>(control_cols), buf_control.data());
      buf_control.clear();
    }
    rows_written = rows_total;
  }

  // Closes every handle; the file is left as it is on disk.
  void close_handles() {
    for (H5Handle& h : series) h.reset();
    contacts.reset();
    control.reset();
    if (file.valid()) {
      H5Fflush(file.get(), H5F_SCOPE_LOCAL);
      file.reset();
    }
  }

  void write_xdmf() const;
};

RunWriter::RunWriter() : impl_(std::make_unique<Impl>()) {}

RunWriter::~RunWriter() {
  if (is_open()) close_incomplete("");
}

bool RunWriter::is_open() const {
  return impl_->file.valid();
}
const std::string& RunWriter::path() const {
  return impl_->path;
}
std::string RunWriter::tmp_path() const {
  return impl_->tmp;
}
std::string RunWriter::xdmf_path() const {
  return xdmf_path_for(impl_->path);
}
int RunWriter::snapshot_count() const {
  return static_cast<int>(impl_->snapshot_times.size());
}
std::int64_t RunWriter::series_rows() const {
  return impl_->rows_total;
}

void RunWriter::open(const std::string& path, const Model& model,
                     const std::vector<std::string>& fields) {
  if (is_open()) throw std::logic_error("RunWriter::open: already open on " + impl_->path);
  impl_ = std::make_unique<Impl>();
  Impl& s = *impl_;
  s.path = path;
  s.tmp = path + ".tmp";
  s.fields = fields;
  for (const std::string& f : fields) {
    if (f == "position")
      s.want_position = true;
    else if (f == "velocity")
      s.want_velocity = true;
    else if (f == "stress")
      s.want_stress = true;
    else
      throw std::invalid_argument("RunWriter::open: unknown field '" + f + "'");
  }
  s.nodes = model.nodes.size();
  s.tris = model.tris.size();

  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  // An earlier run's results must not survive looking like this run's.
  std::error_code ec;
  fs::remove(path, ec);
  fs::remove(xdmf_path_for(path), ec);
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty()) fs::create_directories(parent, ec);

  s.file = H5Handle(
      s.check(H5Fcreate(s.tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), "create the file"),
      H5Fclose);
  const hid_t f = s.file.get();
  s.write_attr_int(f, "complete", 0);
  s.write_attr_string(f, "format", "voussoir-run");
  s.write_attr_string(f, "version", VOUSSOIR_VERSION);
  s.write_attr_string(f, "kind", model.kind);
  s.write_attr_double(f, "out_of_plane", model.out_of_plane);
  std::string list;
  for (std::size_t k = 0; k < fields.size(); ++k) list += (k ? "," : "") + fields[k];
  s.write_attr_string(f, "fields", list);

  // /mesh
  {
    H5Handle mesh(
        s.check(H5Gcreate2(f, "mesh", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "create /mesh"),
        H5Gclose);
    const Nodes& n = model.nodes;
    const Triangles& t = model.tris;
    std::vector<double> xy(2 * static_cast<std::size_t>(s.nodes));
    for (Index i = 0; i < s.nodes; ++i) xy[2 * i] = n.x0[i], xy[2 * i + 1] = n.y0[i];
    s.write_array(mesh.get(), "nodes", H5T_NATIVE_DOUBLE, s.nodes, 2, xy.data());
    std::vector<std::int32_t> tri(3 * static_cast<std::size_t>(s.tris));
    for (Index e = 0; e < s.tris; ++e)
      tri[3 * e] = t.n0[e], tri[3 * e + 1] = t.n1[e], tri[3 * e + 2] = t.n2[e];
    s.write_array(mesh.get(), "triangles", H5T_NATIVE_INT32, s.tris, 3, tri.data());
    static_assert(sizeof(Index) == sizeof(std::int32_t));
    s.write_array(mesh.get(), "block", H5T_NATIVE_INT32, s.tris, 0, t.block.data());
    s.write_array(mesh.get(), "node_block", H5T_NATIVE_INT32, s.nodes, 0, n.block.data());
    std::vector<std::int32_t> fixed;
    for (const Block& b : model.blocks) fixed.push_back(b.fixed ? 1 : 0);
    s.write_array(mesh.get(), "fixed", H5T_NATIVE_INT32, fixed.size(), 0, fixed.data());
    std::vector<std::int32_t> joint_blocks;
    std::vector<double> joint_ends;
    for (const Joint& j : model.joints) {
      joint_blocks.insert(joint_blocks.end(), {j.block_a, j.block_b});
      joint_ends.insert(joint_ends.end(), {j.a.x, j.a.y, j.b.x, j.b.y});
    }
    s.joints = model.joints.size();
    s.write_array(mesh.get(), "joint_blocks", H5T_NATIVE_INT32, s.joints, 2, joint_blocks.data());
    s.write_array(mesh.get(), "joint_ends", H5T_NATIVE_DOUBLE, s.joints, 4, joint_ends.data());
  }
  // /series
  {
    H5Handle series(
        s.check(H5Gcreate2(f, "series", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "create /series"),
        H5Gclose);
    for (std::size_t k = 0; k < kSeriesDoubles; ++k)
      s.series[k] = s.create_growing(series.get(), kSeriesNames[k], H5T_NATIVE_DOUBLE, 0);
    s.contacts = s.create_growing(series.get(), "active_contacts", H5T_NATIVE_INT64, 0);
  }
  H5Handle snaps(s.check(H5Gcreate2(f, "snapshots", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                         "create /snapshots"),
                 H5Gclose);
  s.check(H5Fflush(f, H5F_SCOPE_LOCAL), "flush");
}

void RunWriter::set_control_columns(const std::vector<std::string>& names) {
  Impl& s = *impl_;
  if (s.rows_total > 0)
    throw std::logic_error("RunWriter::set_control_columns: call it before the first record");
  s.control_names = names;
}

void RunWriter::append_series(const SeriesRecord& r) {
  Impl& s = *impl_;
  if (!is_open()) throw std::logic_error("RunWriter::append_series: not open");
  const auto v = series_values(r);
  for (std::size_t k = 0; k < kSeriesDoubles; ++k)
    if (!std::isfinite(v[k]))
      throw std::runtime_error("refusing to write a non-finite " + std::string(kSeriesNames[k]) +
                               " (" + format_time(v[k]) + ") at t = " + format_time(r.time) +
                               " s to " + s.path);
  const long cols = static_cast<long>(r.control_displacements.size());
  if (s.control_cols < 0) {
    s.control_cols = cols;
    if (!s.control_names.empty() && static_cast<long>(s.control_names.size()) != cols)
      throw std::logic_error("RunWriter::append_series: " + std::to_string(cols) +
                             " control displacements for " +
                             std::to_string(s.control_names.size()) + " column names");
  } else if (cols != s.control_cols) {
    throw std::logic_error("RunWriter::append_series: record has " + std::to_string(cols) +
                           " control displacements, earlier ones had " +
                           std::to_string(s.control_cols));
  }
  for (double d : r.control_displacements)
    if (!std::isfinite(d))
      throw std::runtime_error("refusing to write a non-finite control displacement at t = " +
                               format_time(r.time) + " s to " + s.path);

  for (std::size_t k = 0; k < kSeriesDoubles; ++k) s.buf[k].push_back(v[k]);
  s.buf_contacts.push_back(r.active_contacts);
  s.buf_control.insert(s.buf_control.end(), r.control_displacements.begin(),
                       r.control_displacements.end());
  ++s.rows_total;
  if (static_cast<std::size_t>(s.rows_total - s.rows_written) >= kSeriesBlock) s.flush_series();
}

void RunWriter::write_snapshot(double time, const Model& model,
                               const std::vector<double>& stress_xx_yy_xy) {
  Impl& s = *impl_;
  if (!is_open()) throw std::logic_error("RunWriter::write_snapshot: not open");
  if (model.nodes.size() != s.nodes || model.tris.size() != s.tris)
    throw std::logic_error("RunWriter::write_snapshot: model size differs from the one opened");
  if (!std::isfinite(time))
    throw std::runtime_error("refusing to write a snapshot at non-finite time to " + s.path);
  const Nodes& n = model.nodes;
  const std::size_t N = static_cast<std::size_t>(s.nodes);

  // Refuse NaN before anything is written, so a snapshot is either whole or absent.
  auto check_finite = [&](const std::vector<double>& a, const std::vector<double>& b,
                          const char* what) {
    for (std::size_t i = 0; i < N; ++i)
      if (!std::isfinite(a[i]) || !std::isfinite(b[i]))
        throw std::runtime_error("refusing to write a non-finite " + std::string(what) +
                                 " of node " + std::to_string(i) + " (block " +
                                 std::to_string(n.block[i]) + ") at t = " + format_time(time) +
                                 " s to " + s.path);
  };
  if (s.want_position) check_finite(n.x, n.y, "position");
  if (s.want_velocity) check_finite(n.vx, n.vy, "velocity");
  if (s.want_stress) {
    if (stress_xx_yy_xy.size() != 3 * static_cast<std::size_t>(s.tris))
      throw std::logic_error("RunWriter::write_snapshot: stress has " +
                             std::to_string(stress_xx_yy_xy.size()) + " values, expected 3 x " +
                             std::to_string(s.tris));
    for (std::size_t k = 0; k < stress_xx_yy_xy.size(); ++k)
      if (!std::isfinite(stress_xx_yy_xy[k]))
        throw std::runtime_error("refusing to write a non-finite stress of triangle " +
                                 std::to_string(k / 3) + " at t = " + format_time(time) + " s to " +
                                 s.path);
  }

  s.flush_series();
  const std::string name = "/snapshots/" + snapshot_name(snapshot_count());
  const std::size_t T = static_cast<std::size_t>(s.tris);
  H5Handle group(
      s.check(H5Gcreate2(s.file.get(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
              "create " + name),
      H5Gclose);
  s.write_attr_double(group.get(), "time", time);
  auto interleave = [&](const std::vector<double>& a, const std::vector<double>& b) {
    s.scratch.resize(2 * N);
    for (std::size_t i = 0; i < N; ++i) s.scratch[2 * i] = a[i], s.scratch[2 * i + 1] = b[i];
    return s.scratch.data();
  };
  // (a - a0, b - b0, 0) per node: a 3-component point vector for ParaView.
  auto vector3 = [&](const std::vector<double>& a, const std::vector<double>& b,
                     const std::vector<double>* a0, const std::vector<double>* b0) {
    s.scratch.assign(3 * N, 0.0);
    for (std::size_t i = 0; i < N; ++i) {
      s.scratch[3 * i] = a0 ? a[i] - (*a0)[i] : a[i];
      s.scratch[3 * i + 1] = b0 ? b[i] - (*b0)[i] : b[i];
    }
    return s.scratch.data();
  };
  if (s.want_position) {
    s.write_array(group.get(), "position", H5T_NATIVE_DOUBLE, N, 2, interleave(n.x, n.y));
    s.write_array(group.get(), "displacement", H5T_NATIVE_DOUBLE, N, 3,
                  vector3(n.x, n.y, &n.x0, &n.y0));
  }
  if (s.want_velocity)
    s.write_array(group.get(), "velocity", H5T_NATIVE_DOUBLE, N, 3,
                  vector3(n.vx, n.vy, nullptr, nullptr));
  if (s.want_stress) {
    // Components and in-plane principal stresses s1,2 = c +- r, c = (sxx + syy) / 2,
    // r = hypot((sxx - syy) / 2, sxy).
    std::array<std::vector<double>, 5> parts;
    for (auto& p : parts) p.resize(T);
    for (std::size_t e = 0; e < T; ++e) {
      const double xx = stress_xx_yy_xy[3 * e], yy = stress_xx_yy_xy[3 * e + 1],
                   xy = stress_xx_yy_xy[3 * e + 2];
      const double c = 0.5 * (xx + yy), r = std::hypot(0.5 * (xx - yy), xy);
      parts[0][e] = xx, parts[1][e] = yy, parts[2][e] = xy, parts[3][e] = c + r,
      parts[4][e] = c - r;
    }
    for (std::size_t k = 0; k < parts.size(); ++k)
      s.write_array(group.get(), kStressNames[k], H5T_NATIVE_DOUBLE, T, 0, parts[k].data());
    // The T x 3 (sxx, syy, sxy) dataset of the earlier layout, kept for readers of the HDF5
    // file (h5py scripts); the XDMF does not declare it (ParaView would take it for a vector).
    s.write_array(group.get(), "stress", H5T_NATIVE_DOUBLE, T, 3, stress_xx_yy_xy.data());
  }
  s.snapshot_times.push_back(time);
  s.check(H5Fflush(s.file.get(), H5F_SCOPE_LOCAL), "flush");
}

void RunWriter::write_snapshot_joints(const SnapshotJoints& j) {
  Impl& s = *impl_;
  if (!is_open()) throw std::logic_error("RunWriter::write_snapshot_joints: not open");
  if (snapshot_count() == 0)
    throw std::logic_error("RunWriter::write_snapshot_joints: no snapshot written yet");
  const std::size_t J = s.joints;
  if (j.normal_force.size() != J || j.shear_force.size() != J || j.eccentricity.size() != J ||
      j.point.size() != 2 * J)
    throw std::logic_error("RunWriter::write_snapshot_joints: expected " + std::to_string(J) +
                           " joints (points 2 x J)");
  const double time = s.snapshot_times.back();
  // Forces finite; eccentricity and point finite, or all three NaN (an open joint).
  for (std::size_t k = 0; k < J; ++k) {
    const bool open = std::isnan(j.eccentricity[k]);
    const bool ok = std::isfinite(j.normal_force[k]) && std::isfinite(j.shear_force[k]) &&
                    (open ? std::isnan(j.point[2 * k]) && std::isnan(j.point[2 * k + 1])
                          : std::isfinite(j.eccentricity[k]) && std::isfinite(j.point[2 * k]) &&
                                std::isfinite(j.point[2 * k + 1]));
    if (!ok)
      throw std::runtime_error("refusing to write a non-finite resultant of joint " +
                               std::to_string(k) + " at t = " + format_time(time) + " s to " +
                               s.path);
  }
  const std::string name = "/snapshots/" + snapshot_name(snapshot_count() - 1) + "/joints";
  H5Handle group(
      s.check(H5Gcreate2(s.file.get(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
              "create " + name),
      H5Gclose);
  s.write_array(group.get(), "normal_force", H5T_NATIVE_DOUBLE, J, 0, j.normal_force.data());
  s.write_array(group.get(), "shear_force", H5T_NATIVE_DOUBLE, J, 0, j.shear_force.data());
  s.write_array(group.get(), "eccentricity", H5T_NATIVE_DOUBLE, J, 0, j.eccentricity.data());
  s.write_array(group.get(), "point", H5T_NATIVE_DOUBLE, J, 2, j.point.data());
  s.check(H5Fflush(s.file.get(), H5F_SCOPE_LOCAL), "flush");
}

void RunWriter::write_snapshot_attribute(const char* name, double value) {
  Impl& s = *impl_;
  if (!is_open()) throw std::logic_error("RunWriter::write_snapshot_attribute: not open");
  if (snapshot_count() == 0)
    throw std::logic_error("RunWriter::write_snapshot_attribute: no snapshot written yet");
  if (!std::isfinite(value))
    throw std::runtime_error("refusing to write a non-finite " + std::string(name) + " at t = " +
                             format_time(s.snapshot_times.back()) + " s to " + s.path);
  const std::string group_name = "/snapshots/" + snapshot_name(snapshot_count() - 1);
  H5Handle group(s.check(H5Gopen2(s.file.get(), group_name.c_str(), H5P_DEFAULT),
                         "open " + group_name),
                 H5Gclose);
  s.write_attr_double(group.get(), name, value);
}

void RunWriter::close_complete() {
  Impl& s = *impl_;
  if (!is_open()) throw std::logic_error("RunWriter::close_complete: not open");
  s.flush_series();
  s.write_attr_int(s.file.get(), "snapshot_count", snapshot_count());
  s.close_handles();  // complete is still 0 here

  // Rename first, mark complete second: at no moment does a file claim to be complete while it
  // is not at its final name with all its data.
  std::error_code ec;
  fs::rename(s.tmp, s.path, ec);
  if (ec) throw OutputError("cannot rename '" + s.tmp + "' to '" + s.path + "': " + ec.message());
  {
    H5Handle f(H5Fopen(s.path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
    if (!f.valid()) throw OutputError("HDF5 output '" + s.path + "': cannot reopen to finish it");
    s.write_attr_int(f.get(), "complete", 1);
    if (H5Fflush(f.get(), H5F_SCOPE_LOCAL) < 0)
      throw OutputError("HDF5 output '" + s.path + "': cannot flush");
  }
  s.write_xdmf();
}

void RunWriter::close_incomplete(const std::string& reason) noexcept {
  if (!is_open()) return;
  Impl& s = *impl_;
  try {
    s.flush_series();
    if (!reason.empty()) s.write_attr_string(s.file.get(), "error", reason);
    s.write_attr_int(s.file.get(), "snapshot_count", snapshot_count());
  } catch (...) {
    // Best effort: the file stays marked incomplete whatever happens here.
  }
  s.close_handles();
}

// ---------------------------------------------------------------------------------------------
// XDMF: one Uniform grid per snapshot in a Temporal collection; every data item references the
// .h5 file by its name alone, so the pair can be moved together.

void RunWriter::Impl::write_xdmf() const {
  const std::string h5 = xml_escape(fs::path(path).filename().string());
  const std::string N = std::to_string(nodes), T = std::to_string(tris);
  auto hdf = [&](const std::string& dims, const char* type, int precision,
                 const std::string& dataset) {
    return "<DataItem Dimensions=\"" + dims + "\" NumberType=\"" + type + "\" Precision=\"" +
           std::to_string(precision) + "\" Format=\"HDF\">" + h5 + ":" + dataset + "</DataItem>";
  };
  std::ostringstream x;
  x << "<?xml version=\"1.0\" ?>\n"
    << "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
    << "<Xdmf Version=\"3.0\">\n"
    << "  <Domain>\n";
  auto attribute = [&](const char* name, const char* type, const char* center,
                       const std::string& item) {
    x << "        <Attribute Name=\"" << name << "\" AttributeType=\"" << type << "\" Center=\""
      << center << "\">\n          " << item << "\n        </Attribute>\n";
  };
  auto grid = [&](const std::string& name, const double* time, const std::string& group) {
    x << "      <Grid Name=\"" << name << "\" GridType=\"Uniform\">\n";
    if (time != nullptr) x << "        <Time Value=\"" << format_time(*time) << "\" />\n";
    x << "        <Topology TopologyType=\"Triangle\" NumberOfElements=\"" << T
      << "\" NodesPerElement=\"3\">\n          " << hdf(T + " 3", "Int", 4, "/mesh/triangles")
      << "\n        </Topology>\n";
    // The reference mesh on every grid (one geometry: Warp By Vector on `displacement`
    // moves it).
    x << "        <Geometry GeometryType=\"XY\">\n          "
      << hdf(N + " 2", "Float", 8, "/mesh/nodes") << "\n        </Geometry>\n";
    attribute("block", "Scalar", "Cell", hdf(T, "Int", 4, "/mesh/block"));
    if (group.empty()) return;
    if (want_position)
      attribute("displacement", "Vector", "Node",
                hdf(N + " 3", "Float", 8, group + "/displacement"));
    if (want_velocity)
      attribute("velocity", "Vector", "Node", hdf(N + " 3", "Float", 8, group + "/velocity"));
    if (want_stress)
      for (const char* field : kStressNames)
        attribute(field, "Scalar", "Cell", hdf(T, "Float", 8, group + "/" + field));
  };
  if (snapshot_times.empty()) {
    // No snapshot: the reference mesh alone, so the file still opens.
    grid("mesh", nullptr, "");
    x << "      </Grid>\n";
  } else {
    x << "    <Grid Name=\"run\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
    for (std::size_t k = 0; k < snapshot_times.size(); ++k) {
      const std::string name = snapshot_name(static_cast<int>(k));
      grid("snapshot_" + name, &snapshot_times[k], "/snapshots/" + name);
      x << "      </Grid>\n";
    }
    x << "    </Grid>\n";
  }
  x << "  </Domain>\n</Xdmf>\n";

  const std::string out = xdmf_path_for(path), tmp_x = out + ".tmp";
  {
    std::ofstream f(tmp_x, std::ios::binary | std::ios::trunc);
    f << x.str();
    f.close();
    if (!f) throw OutputError("cannot write XDMF file '" + out + "'");
  }
  std::error_code ec;
  fs::rename(tmp_x, out, ec);
  if (ec) throw OutputError("cannot write XDMF file '" + out + "': " + ec.message());
}

}  // namespace voussoir

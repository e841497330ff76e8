#pragma once
// HDF5 output of one run (docs/reference/output.md), plus an XDMF file beside it for ParaView.
//
// File layout (all floating-point data float64, integers int32 unless said):
//   /                      attributes: complete (int32: 1 only once close_complete() ran),
//                          format = "voussoir-run", version, kind, out_of_plane [m],
//                          fields (comma list), snapshot_count, error (only if the run failed)
//   /mesh/nodes            N x 2   reference node positions [m]
//   /mesh/triangles        T x 3   node indices (0-based, counter-clockwise)
//   /mesh/block            T       owning block of each triangle
//   /mesh/node_block       N       owning block of each node
//   /mesh/fixed            B       1 if the block is fixed (support), else 0
//   /mesh/joint_blocks     J x 2   the two blocks a, b of each joint of the model (the joint
//                                  index of `check --mesh-out` and of the hinge reports)
//   /mesh/joint_ends       J x 4   reference ends a (x, y) and b (x, y) of each joint [m]
//                                  (a: the intrados end of arch joints)
//   /series/NAME           R       one row per append_series(): time [s], kinetic, strain,
//                                  contact, damping_dissipated, friction_dissipated,
//                                  external_work [J], max_displacement [m],
//                                  active_contacts (int64), energy_balance_error [-]
//   /series/control_displacement   R x C  (only if records carry control displacements;
//                                  C fixed by the first record; attribute columns)
//   /snapshots/NNNNNN/     attribute time [s] (simulation time; in the file of `capacity
//                          --movie`, time since the start of the lambda ramp); datasets of
//                          the requested `fields`:
//                            position: position (N x 2) [m] and displacement (N x 3: ux,
//                              uy, 0; position minus /mesh/nodes) [m],
//                            velocity: velocity (N x 3: vx, vy, 0) [m/s],
//                            stress: stress_xx, stress_yy, stress_xy, stress_1, stress_2
//                              (T each: Cauchy components, in-plane principal stresses
//                              s1 >= s2) [Pa];
//                          attribute lambda (only when the driver gives it: the horizontal
//                          load factor acting at that time);
//   /snapshots/NNNNNN/joints/  the joint resultants at that state (only when the driver gives
//                          them: `voussoir run`, `capacity --movie`; docs/thrust.md):
//                            normal_force (J) [N], compression positive; shear_force (J) [N];
//                            eccentricity (J) [-1 at end a, +1 at end b]; point (J x 2) [m],
//                            the centre of pressure; eccentricity and point are NaN for an
//                            open joint (no centre of pressure)
//
// XDMF (ParaView): a Temporal collection with a Time value on every grid; the geometry is the
// reference mesh (/mesh/nodes) and `displacement` a 3-component point vector, so ParaView's
// Warp By Vector on it draws the deformed blocks (scale factor 1 = true motion, more to
// magnify); `velocity` is a 3-component point vector; stress is five named cell scalars. Data
// items name the .h5 by its file name, resolved by the readers against the folder of the
// .xdmf, so the pair opens from any working directory and can be moved together. Checked with
// ParaView 5.11's XDMF Reader and Xdmf3ReaderS/T (tests/python/paraview_open.py) and with
// h5py (tests/python/xdmf_h5.py).
//
// Completeness contract (docs/design.md, "Output": no partial file left looking complete):
//   - open() removes any earlier `path` and its .xdmf, and writes to `path + ".tmp"` with
//     complete = 0;
//   - close_complete() closes the file, renames it to `path`, sets complete = 1 there and then
//     writes the XDMF (which names the final `path`);
//   - if the writer is destroyed (or close_incomplete() is called) first, the `.tmp` file is
//     KEPT with complete = 0 (and an `error` attribute when a reason is given): the partial
//     series and snapshots help to see what went wrong, and neither its name nor its flag
//     can be taken for a finished run. No XDMF is written for it.
//
// Non-finite values are refused (std::runtime_error naming the field, the item and the time):
// a NaN is never written silently. The one NaN the file holds on purpose is the open joint's
// eccentricity and point (both NaN together, never infinite). Errors of the HDF5 library or the
// file system throw OutputError (io/json.hpp) naming the file. Series rows are buffered in memory
// and written in blocks (every kSeriesBlock rows, at each snapshot and at close), so appending a
// row costs no HDF5 call in the common case.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/model.hpp"

namespace voussoir {

// One row of the time series.
struct SeriesRecord {
  double time = 0.0;                  // [s]
  double kinetic = 0.0;               // [J] (per the model's out_of_plane thickness)
  double strain = 0.0;                // [J]
  double contact = 0.0;               // [J] penalty energy stored in overlaps
  double damping_dissipated = 0.0;    // [J] cumulative: element damping and, for rigid
                                      // blocks, the contacts' impact damping
  double friction_dissipated = 0.0;   // [J] cumulative
  double external_work = 0.0;         // [J] cumulative (gravity, lambda g, base motion)
  double max_displacement = 0.0;      // [m] largest free-node displacement magnitude
  std::int64_t active_contacts = 0;   // contact pairs with overlap
  double energy_balance_error = 0.0;  // relative, see EnergyLedger
  // Optional: displacements of the control points, e.g. (ux, uy) of each point [m]. Empty =
  // none; otherwise every record of the run carries the same number of values.
  std::vector<double> control_displacements;
};

// Joint resultants of one snapshot, J values each (engine/thrust.hpp makes them).
struct SnapshotJoints {
  std::vector<double> normal_force;  // [N], compression positive
  std::vector<double> shear_force;   // [N]
  std::vector<double> eccentricity;  // [-]; NaN for an open joint
  std::vector<double> point;         // J x 2 interleaved [m]; NaN for an open joint
};

class RunWriter {
 public:
  RunWriter();
  ~RunWriter();  // not completed: keeps `path + ".tmp"` with complete = 0
  RunWriter(const RunWriter&) = delete;
  RunWriter& operator=(const RunWriter&) = delete;

  // Creates `path + ".tmp"` (and the parent folder if missing) and writes the mesh. `fields`
  // chooses the snapshot datasets among "position", "velocity", "stress".
  void open(const std::string& path, const Model& model, const std::vector<std::string>& fields);

  // Optional, before the first append: names of the control-displacement columns.
  void set_control_columns(const std::vector<std::string>& names);

  void append_series(const SeriesRecord& record);

  // Writes /snapshots/NNNNNN with the requested fields of the current model state.
  // `stress_xx_yy_xy` holds (sxx, syy, sxy) of each triangle, interleaved (size 3 T) [Pa],
  // written as the named scalars of the layout above;
  // it is read only when "stress" is among the fields (may be empty otherwise).
  void write_snapshot(double time, const Model& model, const std::vector<double>& stress_xx_yy_xy);

  // Optional, after write_snapshot and before the next one: the joint resultants of that
  // snapshot's state, under /snapshots/NNNNNN/joints (J = the model's joint count).
  void write_snapshot_joints(const SnapshotJoints& joints);

  // Optional, after write_snapshot: a scalar attribute of that snapshot (e.g. "lambda").
  void write_snapshot_attribute(const char* name, double value);

  // Finishes the run: the file appears at `path` with complete = 1, then the XDMF.
  void close_complete();

  // Error path made explicit: flushes what is buffered, records `reason` in the `error`
  // attribute and closes, leaving only the `.tmp` file (complete = 0). Never throws.
  void close_incomplete(const std::string& reason) noexcept;

  bool is_open() const;
  const std::string& path() const;  // the final path given to open()
  std::string tmp_path() const;     // path + ".tmp"
  std::string xdmf_path() const;    // path with its extension replaced by .xdmf
  int snapshot_count() const;
  std::int64_t series_rows() const;

  static constexpr std::size_t kSeriesBlock = 256;  // rows buffered before an HDF5 write

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// "run.h5" -> "run.xdmf" (a path without extension gets ".xdmf" appended).
std::string xdmf_path_for(const std::string& h5_path);

}  // namespace voussoir

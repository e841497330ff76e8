#pragma once
// Interfaces between rigid blocks, found from the block outlines alone (any model: arches,
// church, block stacks, user polygons), for limit analysis.
//
// Two blocks share an interface where an outline edge of one and an outline edge of the other
// are collinear, run in opposite directions (both outlines are counter-clockwise, so faces in
// contact are traversed against each other) and overlap by more than the tolerance. A meshed
// outline carries every boundary node, so one joint face is usually several collinear edges:
// the overlaps of one block pair on one line are merged into maximal segments, and each such
// segment is one interface with two ends. Tolerance: `rel_tol` times the diagonal of the
// bounding box of the whole model (1e-9 by default: generators give faces the very same
// doubles; user polygons may be off by rounding).
//
// Labels: an interface that lies on a joint of Model::joints (same pair of blocks, overlapping
// collinear segment) takes that joint's index, block order, end order (a = intrados / inner /
// left end, as the scene generators define it) and angular position. Any other interface has
// joint = -1, NaN position, ends ordered left to right (then bottom to top) and block_a the
// lower index. The geometric search is the reference: Model::joints only names what it finds.

#include <limits>
#include <vector>

#include "core/model.hpp"

namespace voussoir {

struct Interface {
  Index block_a = 0, block_b = 0;
  Vec2 a, b;         // ends [m]: a intrados/inner/left end, b the other
  Vec2 normal;       // unit normal pointing from block_a into block_b
  Index joint = -1;  // index of the matching Model::joints entry, -1 if none
  double position_deg = std::numeric_limits<double>::quiet_NaN();  // of the matching joint
  // Ends that carry no force: the LP fixes their cone edges at zero. Set for the open joints
  // of a structure whose supports moved, each kept as a point contact at its pivot
  // (commands/capacity.hpp moved_blocks, OpenJoints::Points); find_interfaces sets neither.
  bool open_a = false, open_b = false;
  double length() const;
};

// Every interface of the model (pairs of fixed blocks included; callers skip what they do not
// need). Deterministic order: by block pair (lower index first), then along the line.
std::vector<Interface> find_interfaces(const Model& model, double rel_tol = 1e-9);

// Area and centroid of a simple polygon (either orientation; the area returned is |A|) by the
// exact shoelace formulas: A = 1/2 sum (x_i y_j - x_j y_i), C = sum (p_i + p_j)(x_i y_j - x_j
// y_i) / (6 A), j = i + 1 cyclically. Coordinates are taken relative to the first vertex to
// keep the cancellation small for blocks far from the origin.
double polygon_centroid(const std::vector<Vec2>& polygon, Vec2* centroid);

}  // namespace voussoir

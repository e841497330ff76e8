#pragma once
// Rigid-body reading of a deformable block model: the best-fit translation and rotation of each
// block, and the opening and sliding of every joint. Used to classify capacity trials and to
// report hinges. Cheap (one pass over the nodes); called at samples, never inside the step.

#include <string>
#include <vector>

#include "core/model.hpp"

namespace voussoir {

struct BlockMotion {
  double ux = 0.0, uy = 0.0;    // centroid displacement [m]
  double rotation = 0.0;        // best-fit rotation, counter-clockwise [rad]
  double cx0 = 0.0, cy0 = 0.0;  // reference centroid [m]
};

// Mass-weighted centroid displacement and rotation of every block:
//   theta = atan2(sum m (r0 x r), sum m (r0 . r)), r0 = X - C0, r = x - C
// (the rotation that best aligns reference to current arms in the least-squares sense).
std::vector<BlockMotion> block_motions(const Model& model);

// What an analysis reads of the blocks whatever their kind (the bodies' state for rigid
// blocks, the nodes' for elastic ones), cheap enough for every step:
// x of block b's centroid now [m] (elastic: the nodes' mass centre, O(nodes of the block));
double block_centroid_x(const Model& model, int b);
// the sum over the free blocks of mass x centroid x [kg m] (true masses: the load's).
double free_mass_moment_x(const Model& model);

// Position of the reference point p of block b moved by the block's rigid motion.
Vec2 move_point(const BlockMotion& m, Vec2 p);

struct JointState {
  int joint = 0;           // index into Model::joints
  double opening_a = 0.0;  // normal gap at the intrados end a [m] (> 0: open)
  double opening_b = 0.0;  // normal gap at the extrados end b [m]
  double slip = 0.0;       // relative tangential displacement at the joint middle [m]
  double rotation = 0.0;   // relative rotation of the two blocks [rad]
};

std::vector<JointState> joint_states(const Model& model, const std::vector<BlockMotion>& motions);

// A hinge or a sliding joint, for reports and pictures.
struct Hinge {
  int joint = 0;
  int block_a = 0, block_b = 0;
  std::string kind;  // "hinge" or "sliding"
  std::string side;  // where the blocks keep touching: "intrados" or "extrados" ("" for sliding)
  double position_deg = 0.0;  // angular position of the joint (Joint::position_deg)
  double x = 0.0, y = 0.0;    // reference position of the pivot (or joint middle) [m]
  double opening = 0.0;       // largest normal gap of the joint [m]
  double slip = 0.0;          // [m]
};

// Joints whose largest gap exceeds `open_tol` (lowered to a quarter of the largest gap of the
// model when that is smaller, but not below open_tol / 10) become hinges (pivot at the closed end,
// or at the less-open end if both opened); joints whose slip exceeds `slip_tol` and that did not
// open become sliding joints. Joints between two fixed blocks are never reported. Sorted by joint
// index.
std::vector<Hinge> find_hinges(const Model& model, double open_tol, double slip_tol);

}  // namespace voussoir

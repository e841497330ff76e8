#pragma once
// Joint resultants: the line of thrust of a block structure from its contact forces
// (docs/reference/output.md, "joints"; docs/thrust.md).
//
// Source of the forces. ContactSystem::pair_forces evaluates every touching triangle pair at
// the current node positions and velocities on a copy of the contact system: the nodal forces
// (potential penalty, friction and impact damping) that the contact stage applies, without
// touching the run's state, its forces or the order of any sum in the step. Rigid blocks touch
// by their outlines: ContactSystem::block_pair_forces gives each touching block pair's force
// on its second block and the moment of it, the very force and moment that body gets, and the
// resultant below takes them as they are (their moment moved to O).
//
// Resultant of joint j between blocks A = block_a and B = block_b. The pairs between A and B
// give nodal forces on both blocks; their totals are equal and opposite, their moments differ
// by the lever of the overlap (~1e-9 of the element size at rest). We sum one side: the nodal
// forces on B's nodes, or on A's (negated) when B is fixed, i.e. always on a free block when
// there is one. That is exact in the sense that matters: it is the force and moment that the
// joint puts on that block's equations of motion (rigid blocks sum exactly these nodal forces
// into a force and a moment), so a block at rest balances them against its loads to the
// residual of the settle. So
//     F = sum_i f_i (force of A on B),   M = sum_i (x_i - O) x f_i   about the joint middle O.
// Joint line at the current configuration: a' and b' are the joint's ends a and b (a: the
// intrados end of arch joints) moved by the best-fit rigid motion of the summed block
// (engine/kinematics.hpp; a block's mesh need not have nodes there: a rigid buttress's minimal
// mesh drops the extrados springing point from its straight top), t = (b' - a')/L,
// n the unit normal pointing from A into B. Then
//     N = F . n (compression positive),   V = F . t,
// and the centre of pressure is the point P = O + s t of the joint line on the line of action
// of F: s (t x F) = M, s = M / (t x F); eccentricity e = s / (L / 2): -1 at end a (intrados),
// +1 at end b (extrados), 0 at the middle. An open joint (no touching pair) has N = V = 0 and
// no centre of pressure. Forces in N for the model's out-of-plane thickness.
//
// Only the joints of Model::joints are reported (their index is the one of `check --mesh-out`
// and of the hinges); blocks that come into contact elsewhere during a collapse have no joint
// line and are not reported.

#include <nlohmann/json.hpp>
#include <vector>

#include "contact/contact.hpp"
#include "core/model.hpp"
#include "engine/kinematics.hpp"
#include "io/hdf5_output.hpp"

namespace voussoir {

struct JointResultant {
  int joint = 0;  // index into Model::joints
  Index block_a = 0, block_b = 0;
  double normal_force = 0.0;  // N [N], compression positive
  double shear_force = 0.0;   // V [N], along a -> b, on block_b
  Vec2 force;                 // F = N n + V t, force of block_a on block_b [N]
  bool closed = false;        // some pair touches and the centre of pressure is defined
  double eccentricity = 0.0;  // e, -1 at end a, +1 at end b (when closed)
  Vec2 point;                 // centre of pressure, current configuration [m] (when closed)
};

// Resultants of every joint of `model` from the pair forces of `contact` at the current state.
std::vector<JointResultant> joint_resultants(const Model& model, const ContactSystem& contact,
                                             double dt);

// From pair forces already evaluated (the pure part, for tests).
std::vector<JointResultant> joint_resultants(const Model& model,
                                             const std::vector<TouchingPair>& forces);

// [{"joint": j, "blocks": [a, b], "normal_force": N, "shear_force": V, "eccentricity": e,
//   "point": [x, y], "force": [Fx, Fy]}]; e and point are null for an open joint; force is F,
// the force of block a on block b.
nlohmann::json joints_json(const std::vector<JointResultant>& joints);

// The same as the HDF5 writer takes them (io/hdf5_output.hpp): NaN eccentricity and point for
// an open joint.
SnapshotJoints snapshot_joints(const std::vector<JointResultant>& joints);

// Writes the joint resultants of the current state of (model, contact) into the writer's last
// snapshot, with the load factor `lambda` acting then as its attribute "lambda". Computed on a
// copy of the contact system: the run's state and results are untouched.
void write_snapshot_thrust(RunWriter& writer, const Model& model, const ContactSystem& contact,
                           double dt, double lambda);

// Abscissa of the free blocks' centre of weight (their reference outlines) [m].
double free_weight_x(const Model& model);

// The outward horizontal force of the structure on its supports [N]: at every joint of
// Model::joints with a fixed block, the horizontal component of the joint resultant on that
// block, taken outward (-x left of the free blocks' centre of weight, +x right of it).
struct SupportThrust {
  double left = 0.0, right = 0.0;
  double mean() const { return 0.5 * (left + right); }
};
SupportThrust support_thrust(const Model& model, const std::vector<JointResultant>& joints);

}  // namespace voussoir

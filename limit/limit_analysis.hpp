#pragma once
// Rigid-block limit analysis (lower-bound equilibrium LP, solved by GLPK) on the blocks of the
// FDEM model: the collapse load factor lambda_la of the horizontal body load lambda x weight,
// the collapse mechanism from the dual solution, and gravity-only admissibility. The
// formulation is derived at the top of limit_analysis.cpp and in docs/limit.md.
//
// Uses: `voussoir limit` (commands/limit.cpp); `voussoir capacity` seeds its bracket
// with lambda_la; `voussoir stability` cross-checks cells with the gravity-only test;
// `voussoir limit --thrust min|max` and `voussoir spread` compare the support thrust of a
// moved structure with the least and greatest thrust (limit_thrust).

#include <string>
#include <vector>

#include "core/model.hpp"
#include "limit/interfaces.hpp"

namespace voussoir {

// One joint of the collapse mechanism (fields as in the FDEM hinge report, engine/kinematics.hpp).
// LimitResult::mechanism is sorted by Model::joints index, interfaces without a joint last.
struct MechanismJoint {
  Index interface = 0;  // index into LimitResult::interfaces
  Index joint = -1;     // index into Model::joints (-1: interface not in Model::joints)
  Index block_a = 0, block_b = 0;
  std::string kind;           // "hinge" or "sliding"
  std::string side;           // hinge: the end that stays in contact, "intrados" (end a) or
                              // "extrados" (end b); "" for sliding
  double x = 0.0, y = 0.0;    // hinge: the pivot (the closed end); sliding: joint middle [m]
  double position_deg = 0.0;  // Interface::position_deg (NaN where the joint has none)
  // Virtual rates of the dual mechanism, normalised by the largest relative velocity of any
  // interface end (so 1 = the fastest-moving joint): normal opening at ends a and b, slip.
  double opening_a = 0.0, opening_b = 0.0, slip = 0.0;
};

// Rigid virtual velocity of a block in the dual mechanism (normalised like MechanismJoint):
// translation of the block centroid and rotation rate (counter-clockwise) [1/m in the same
// normalisation].
struct BlockVelocity {
  double ux = 0.0, uy = 0.0, omega = 0.0;
};

// Contact forces of the optimal (or admissible) equilibrium at the two ends of an interface,
// on block_b (block_a gets the opposite) [N, per out_of_plane]: normal N >= 0 along
// Interface::normal, shear S along the tangent (b - a) / |b - a|, |S| <= mu N.
struct InterfaceForces {
  double normal_a = 0.0, shear_a = 0.0, normal_b = 0.0, shear_b = 0.0;
};

struct LimitResult {
  // "optimal" (lambda_la found), "infeasible" (no admissible equilibrium at any lambda, or at
  // lambda = 0 when gravity_only), "unbounded" (no lambda makes it collapse), or "error".
  std::string status;
  bool gravity_only = false;
  double lambda_la = 0.0;   // maximal load factor (NaN unless status is "optimal")
  // limit_thrust: the least or greatest horizontal support thrust under gravity [N, per
  // out_of_plane] (NaN unless status is "optimal"); NaN for limit_analysis.
  double thrust = 0.0;
  bool admissible = false;  // an admissible equilibrium exists under self-weight alone
  bool exact = false;       // the optimal basis was confirmed in exact rational arithmetic
  std::vector<Interface> interfaces;      // every interface with at least one free block
  std::vector<InterfaceForces> forces;    // per interface (empty unless feasible)
  std::vector<MechanismJoint> mechanism;  // hinges and sliding joints (status "optimal")
  std::vector<BlockVelocity> velocities;  // per block (fixed blocks zero; "optimal" only)
  int free_blocks = 0;
  int rows = 0, columns = 0;  // size of the LP
  int iterations = 0;         // simplex iterations
  double wall_s = 0.0;        // interfaces + LP set-up + solve [s]
};

struct LimitOptions {
  // Confirm the simplex's status and basis with glp_exact (rational arithmetic, data read to
  // 1e-9 relative), then report floating-point values from that basis (limit_analysis.cpp).
  // A few ms on the arches, about 0.25-0.4 s of the church's 0.3-0.5 s.
  bool exact = true;
  // ... but only for LPs of at most this many rows (3 per free block): the rational check
  // grows about quadratically (0.4 s at 705 rows, 3.5 s at 2829 rows on the church).
  int exact_max_rows = 2000;
  // Relative threshold, against the largest relative velocity, below which an interface end
  // is taken as not moving in the mechanism.
  double motion_tol = 1e-6;
  double interface_tol = 1e-9;  // find_interfaces rel_tol
  // The interfaces to use instead of find_interfaces (null: found from the outlines). For
  // blocks whose outlines no longer meet face to face: a structure whose supports moved opens
  // its hinges, and its joints are then the reference ones carried with their blocks
  // (commands/capacity.hpp moved_blocks).
  const std::vector<Interface>* interfaces = nullptr;
};

// Maximises lambda such that every free block is in equilibrium under its weight W = rho A
// out_of_plane g (A and centroid of Block::polygon) and lambda W horizontally (+x) at its
// centroid, with contact forces at the ends of each interface: N >= 0, |S| <= mu N. With
// `gravity_only`, lambda is fixed at 0 and the LP only decides admissibility. Throws
// std::invalid_argument for mu < 0, gravity <= 0 or a model without free blocks.
LimitResult limit_analysis(const Model& model, double mu, double gravity, bool gravity_only);
LimitResult limit_analysis(const Model& model, double mu, double gravity, bool gravity_only,
                           const LimitOptions& options);

// Which extreme of the support thrust limit_thrust seeks.
enum class ThrustBound { Min, Max };

// The least (Min) or greatest (Max) horizontal thrust of the structure on its supports under
// gravity alone (lambda = 0): the same equilibrium LP as limit_analysis with the horizontal
// force on the supports as the objective (limit_analysis.cpp, "Thrust"). The thrust is the
// outward horizontal force on the supports whose interfaces lie left of the free blocks' centre
// of weight (under gravity alone it equals the outward force on those to its right). Status
// "optimal" (LimitResult::thrust and the forces of that equilibrium), "infeasible" (no
// admissible equilibrium under self-weight) or "unbounded" (Max: the thrust can grow without
// limit, e.g. a flat arch). Throws as limit_analysis.
LimitResult limit_thrust(const Model& model, double mu, double gravity, ThrustBound bound,
                         const LimitOptions& options = LimitOptions{});

}  // namespace voussoir

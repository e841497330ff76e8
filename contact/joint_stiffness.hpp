#pragma once
// Joint stiffness in engineering units and impact damping (docs/rigid.md and the
// `[contact]` keys normal_stiffness, shear_stiffness, restitution).
//
// From kn [N/m3] to a pair penalty. The potential contact force of triangles c and t is
//     f = Ep t_z integral over the overlap of (grad phi_c - grad phi_t) dA       (narrow_phase)
// On a dry joint the overlap is a thin strip of depth d along the two facing edges, inside the
// sub-triangles next to those edges, where |grad phi| = 3/h (h: the triangle's height over its
// facing edge; phi goes from 0 on the edge to 1 at the centroid, a third of the height away).
// Both gradients point across the strip, so over a contact length L
//     |f| = Ep t_z (3/h_c + 3/h_t) L d,
// a normal stiffness per unit joint area of Ep (3/h_c + 3/h_t). A joint of stiffness kn thus
// needs, for this pair,
//     Ep_pair = kn / (3/h_c + 3/h_t).
// The penalty stays constant for the pair's life (a function of the reference geometry only),
// so the contact is still a potential one: its energy is honest and the ledger exact. Corner
// contacts (a vertex pushed into a face) keep the potential's own law: the stiffness of a
// joint is what a flat joint gives, as in UDEC and 3DEC.
//
// Facing edges: of the boundary edges of c and of t, the two closest to each other, the most
// nearly opposite normals breaking ties, in the reference configuration (so a restart or a
// re-detection finds the same edges). Their lengths L_c, L_t and the triangles' heights h_c,
// h_t over them. (Rejected: each triangle's edge whose normal points most towards the other's
// centroid; under a block on a wide ground triangle it picked the block's side, a 25% softer
// joint.)
//
// Default for rigid blocks (no stiffness given): kn = kRigidJointFactor x E / L, with L the
// length of the joint: the shorter of the two blocks' extents along the facing edge (the
// free block's alone against a support with no outline). Why the joint's length and not the
// blocks' length l normal to the joint (E / l, UDEC practice, which lumps the blocks' uniform
// compression into the joints so that a column of rigid blocks is as stiff as the elastic
// one; rejected): what decides lambda* is the hinge, and a hinge does
// not compress a block uniformly. The thrust N crowds into a contact zone of width c at the
// pivot; on a joint of stiffness kn rotating by theta, N = kn theta c^2 / 2, so
//     c / L = sqrt(2 N / (theta kn L^2)) ~ sqrt(sigma / (theta kn L)),    sigma = N / L,
// and the lever arm the softness takes away, relative to the section, depends on kn L, not
// on kn l: for the same masonry the pivot moves as much whatever the blocks' length normal to
// the joint. (The rotational stiffness of a rigid strip of width L on an elastic half-space
// is ~E L^2 too, so E / L is also the joint that rotates like the blocks' own material.) So
// kn L = kRigidJointFactor x E at every joint. With E / l, thin blocks on a long joint (the
// churches' 0.08 m voussoirs on 0.5 m joints) got joints 6 times stiffer than an arch of
// squarer voussoirs, and a step 2.5 times shorter, for no gain in the hinge; tall blocks on a
// short joint (the buttresses, 3 m high on a 0.8 m base) got joints 4 times softer, and
// lambda* of the buttressed arches 1.1 to 1.9% below the elastic blocks' (now 0.3 to 0.8%).
// The factor: on the semicircular arch (docs/rigid.md) lambda* = 0.2814, 0.2890, 0.2934,
// 0.2945 at kn = 1, 10, 100, 1000 x E / l (l = 0.29 m, L = 0.2 m there) against 0.2945 with
// elastic blocks; 100 is the first decade within 1% of the elastic blocks. The default sets
// the step (dt ~ 1 / sqrt(kn)): a user who knows the joints gives contact.normal_stiffness.
//
// Shear: the friction law's tangential spring (contact/friction.hpp) acts at one point of the
// pair: kt = ks t_z min(L_c, L_t), the shear stiffness of the longest flat contact the two
// facing edges can make; ks = kTangentialStiffnessRatio x kn when not given.
//
// Impact damping for a coefficient of restitution e. A body of mass m falling flat onto a
// joint of length L bounces on the spring K = kn t_z L; a dashpot of damping ratio
//     zeta = -ln e / sqrt(pi^2 + ln^2 e)          (zeta = 1 at e = 0)
// returns it with e times its approach speed (the linear spring-dashpot result). The dashpot
// is stiffness-proportional: on each node of the pair it acts on the rate of that node's
// potential force,
//     f_d,i = beta df_i/dt,    beta = 2 zeta / omega,   omega^2 = kn t_z L / m_eff,
// i.e. beta K_c v for the pair's contact stiffness K_c: on the flat drop it is the dashpot
// c = 2 zeta sqrt(K m_eff) on the normal relative velocity, and it damps every motion the
// joint resists, the rocking of a block on its joint as well (the pressure moving across the
// joint with |f| unchanged). A rigid motion of a touching pair turns its forces and so costs
// beta omega_body |f|, small beside |f| as beta is of the order of the joint's period. m_eff = m_c m_t / (m_c + m_t)
// of the two blocks (m_c against a fixed block), L = min of the two blocks' extents along the
// facing edge. The rate is the backward difference (f_i^n - f_i^(n-1)) / dt, f^(n-1) = 0 when
// the pair did not touch, the damping at the lagging velocity, as the element damping of
// core/cst.hpp; the last forces are per-pair state, carried across re-detection and
// checkpoints. Its work is booked by the trapezoid over each position increment,
// 1/2 (f_d^n + f_d^(n-1)) . (x^n - x^(n-1)), per node (contact/contact.cpp), so the ledger
// stays exact to O(dt^2).
// Rejected: the same beta on the rate of the pair's force magnitude, along the
// force, d|f|/dt f / |f|. It left the rocking of a block on its joint undamped: a block
// rocking onto its corner kept 0.968 of its angular velocity at e = 0 (Housner: 0.912; now
// 0.941), and the sliding semicircular arch of the regression, whose joints chatter, gave
// lambda* 1.1650 at e = 0.5 and 1.1694 at e = 0 against 1.1825 with elastic blocks (now
// 1.1738 and 1.1781; docs/rigid.md).

#include <utility>
#include <vector>

#include "core/model.hpp"

namespace voussoir {

// kn = kRigidJointFactor x E / L for rigid blocks with no stiffness given (above).
inline constexpr double kRigidJointFactor = 100.0;

// Restitution of rigid blocks' joints when the deck gives none, in the physical runs (run,
// pulse, stability, capacity --dynamic). Undamped joints never come to rest: a rigid arch
// rings on them for good (joint forces off by 1e2 to 1e3 N and a lopsided line of thrust on a
// symmetric arch after 0.3 s), whereas at 0.5 its springings carry its weight to 1e-5 and
// mirror joints agree to 1e-4 by then (docs/rigid.md, "Joint damping by default"); 0.8 still
// does, 0.95 does not. 0.5 is the middle of the restitution measured
// for stone blocks rocking and bouncing (0.3 to 0.7). Cost: the damped step is
// kRigidDampedStepFraction (core/rigid.hpp), half the undamped one. The quasi-static phases
// (capacity and sweep trials, their settle) damp every motion by their own technique and take
// no dashpot unless the deck gives one (engine/load_trial.cpp settle).
inline constexpr double kRigidDefaultRestitution = 0.5;

// One triangle's facing edge (reference configuration).
struct FacingEdge {
  double length = 0.0;  // [m]
  double height = 0.0;  // triangle height over it [m]
  Vec2 normal;          // outward unit normal
};

// The facing edges of the pair (c, t) (above).
std::pair<FacingEdge, FacingEdge> facing_edges(const Model& model, Index c, Index t);

// Extent of a polygon along a unit direction (max - min of the projections) [m].
double extent_along(const std::vector<Vec2>& polygon, const Vec2& direction);

// Damping ratio of the restitution e in [0, 1] (above); 0 at e = 1.
double restitution_damping_ratio(double e);

// The rigid joints' dashpot pulls no block (no tension, contact/rigid_contact.hpp): a normal
// impact on a spring kn and a dashpot 2 zeta omega limited to compression ends when their
// force vanishes, before the overlap does, and rebounds with
//     e(zeta) = -exp(-zeta phi / s) (cos phi - zeta / s sin phi),  s = sqrt(1 - zeta^2),
//     phi = pi - atan2(2 zeta s, 1 - 2 zeta^2)                       (zeta < 1),
// exp(-2) = 0.135 at zeta = 1 (Schwager and Poeschel, Granular Matter 9, 2007, 465: the linear
// dashpot with the no-tension condition); more than exp(-pi zeta / s), the restitution of the
// dashpot that may pull (restitution_damping_ratio), at every zeta > 0.
double no_tension_restitution(double zeta);

// Its inverse: the damping ratio that gives the restitution e, 1 (the critical dashpot, whose
// restitution exp(-2) = 0.135 is the least) for any e <= exp(-2), 0 for e >= 1.
double no_tension_damping_ratio(double e);

// kn = kRigidJointFactor x E / L of a joint of unit normal `normal` between block a and block b
// (b == nullptr or without outline: a fixed support; L from a alone) [N/m3] (above).
double default_joint_stiffness(double young, const Block& a, const Block* b, const Vec2& normal);

// Joint frequency sqrt(kn t_z L / m_eff) [1/s] (above): L the shorter of the two blocks'
// extents along `tangent`, m_eff from their masses (a fixed block's does not count; b ==
// nullptr: a fixed support). kn_thickness = kn t_z [N/m3 m].
double joint_frequency(double kn_thickness, const Block& a, double mass_a, const Block* b,
                       double mass_b, const Vec2& tangent);

// Mapping and damping parameters of one pair (c, t).
struct PairJoint {
  double kn = 0.0;     // normal stiffness [N/m3]
  double ep = 0.0;     // pair penalty Ep_pair [Pa] (0 when the pair has no facing edge)
  double kt = 0.0;     // tangential spring [N/m] (times the out-of-plane thickness)
  double omega = 0.0;  // joint frequency [1/s] (above)
};

// kn_given > 0: that stiffness; else young > 0: 100 E / L (above); else penalty mode: kn from the
// single penalty Ep (kn = Ep (3/h_c + 3/h_t)). ks_given = 0: kTangentialStiffnessRatio x kn.
PairJoint pair_joint(const Model& model, Index c, Index t, double kn_given, double young,
                     double penalty, double ks_given, double thickness);

}  // namespace voussoir

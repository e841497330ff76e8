#pragma once
// Supports that move ([supports], docs/reference/deck.md): a fixed block's prescribed displacement
// and rotation, reached quasi-statically after the settle under gravity.
//
// Motion. Block b moves by u(t) = s(tau) (dx, dy) and turns by theta(t) = s(tau) R about its
// reference centroid c0, tau = (t - start) / ramp clamped to [0, 1], with the ramp
//     s(tau) = tau - sin(2 pi tau) / (2 pi),    s' = 1 - cos(2 pi tau),   s'' = 2 pi sin(2 pi tau):
// s, s' and s'' are 0 at tau = 0 and s = 1, s' = s'' = 0 at tau = 1, so the movement starts
// and stops without a jump in velocity or acceleration (no impact on the structure resting on
// the support); its peak speed is 2 |d| / ramp. A point X of the block goes to
//     x(t) = c0 + u(t) + R(theta(t)) (X - c0).
//
// Step. The supports are one more stage of engine/step.hpp (stage 7, after the integration):
// as for a free body, the state after step n is the pose at t^(n+1) and the half-step velocity
//     v^(n+1/2) = (x(t^(n+1)) - x(t^n)) / dt,
// so the next contact stage sees the support where it is and the joint friction and dashpots
// see its velocity (rigid blocks: the body's ux, uy, theta and vx, vy, omega; elastic blocks:
// the block's nodes). The velocity is the exact difference of two poses, so the support
// reaches the prescribed pose to round-off, never by accumulating increments.
//
// Energy. The supports do work on the structure through the contact forces F on the support
// (the sum of the pair forces on its outline; their moment T about its centroid for a rigid
// block). Over the increment x^n - x^(n-1) = dt v^(n-1/2), by the trapezoid as every other
// work in the ledger (engine/step.cpp),
//     W_supports += -dt/2 [(F^n + F^(n-1)) . v^(n-1/2) + (T^n + T^(n-1)) omega^(n-1/2)],
// booked as external work: the balance K + U + contact + dissipated = external work then holds
// with the supports moving (the friction and dashpot work of the contact stage includes the
// moving supports' velocities, so their dissipation is counted once). Elastic supports: the
// node forces F_i and velocities v_i of the block's nodes replace F, T. The integrator skips
// fixed blocks, so the supports' own motion has no kinetic energy in the ledger, as it has no
// place in the dynamics.
//
// Contact detection. A prescribed block takes part in detection as a free block does
// (contact/broad_phase: its nodes are watched against the buffer; contact/rigid_contact: its
// pose is), and never pairs with another fixed block.

#include <vector>

#include "core/energy.hpp"
#include "core/model.hpp"

namespace voussoir {

struct SupportMove {
  Index block = 0;
  double dx = 0.0, dy = 0.0;  // [m]
  double rotation = 0.0;      // [rad], counter-clockwise about the reference centroid
};

struct SupportMotion {
  std::vector<SupportMove> moves;  // the targets
  // Where each move starts from (the targets of the movement before; zero at first).
  std::vector<SupportMove> from;
  bool started = false;  // set by start_support_motion; until then the supports stay put
  double start = 0.0;    // [s] time the ramp starts
  double ramp = 0.0;     // [s]
  // Reference centroid of each moved block [m] (elastic blocks; rigid: RigidBodies::cx0).
  std::vector<Vec2> centroid;
  // Contact (and element) forces on the moved blocks at the previous step, for the trapezoid:
  // rigid, 3 per move (fx, fy, torque); elastic, 2 per node of the moved blocks in order.
  std::vector<double> previous_force;

  bool empty() const { return moves.empty(); }
};

// s(tau) of the header, tau clamped to [0, 1].
double support_ramp(double tau);

// Marks the moved blocks of `moves` as prescribed (Block::prescribed) and records them in
// `motion`. Call before the contact system is set up, so that detection follows them. Throws
// std::invalid_argument for a block that does not exist or is not fixed.
void prescribe_supports(Model& model, const std::vector<SupportMove>& moves, SupportMotion& motion);

// Starts the ramp at `time` [s] over `ramp` [s] (> 0).
void start_support_motion(SupportMotion& motion, double time, double ramp);

// Moves the supports on from the targets of the last movement (the reference when none
// started) to `targets` (the same blocks in the same order), by the ramp from `time` over
// `ramp`: x(t) = from + s(tau) (target - from) for displacement and rotation alike.
void retarget_support_motion(SupportMotion& motion, const std::vector<SupportMove>& targets,
                             double time, double ramp);

// Stage 7 of the step (header): the work the supports did on the structure over the step just
// taken [J] (to be added to the external work), then every moved block put at its pose at
// `time_next` with the half-step velocity over dt. Nothing (0) before the start.
double move_supports(Model& model, SupportMotion& motion, double time_next, double dt);

}  // namespace voussoir

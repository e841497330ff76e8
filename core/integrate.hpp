#pragma once
// Central-difference (leapfrog) integration: the velocities stored in Nodes are half-step
// velocities. Step n, with forces f^n evaluated at x^n (and the damping at v^(n-1/2)):
//     v^(n+1/2) = v^(n-1/2) + dt f^n / m,      x^(n+1) = x^n + dt v^(n+1/2)
// (velocity then position, docs/design.md, "The step"). Nodes of fixed blocks are never touched.
//
// Kinetic energy at step n (energy ledger). We book
//     K^n = 1/2 sum_i m_i v_i^(n-1/2) . v_i^(n+1/2)
// the product of the two half-step velocities. Reason: multiplying the velocity update by
// m (v^(n-1/2) + v^(n+1/2)) / 2 shows that, with this K and the potential energy U(x^n),
//     (K + U)^n - (K + U)^(n-1) = 1/2 (f^n + f^(n-1)) . (x^n - x^(n-1)) + U^n - U^(n-1),
// i.e. the trapezoidal work of the forces over the last position increment, which is exact
// for a quadratic U: a linear undamped system conserves K^n + U^n to round-off. Rejected:
// the mid-step velocity (v^- + v^+)/2 and the average of the half-step kinetic energies; both
// exceed the product by 1/8 m (dt a)^2, an O((omega dt)^2) oscillation (about 12% for the
// highest mesh mode at the usual step), which would show as a spurious balance error.
// K^n can dip below zero only when a velocity reverses within one step by more than it was.

#include <cmath>
#include <vector>

#include "core/model.hpp"

namespace voussoir {

// Cundall's local non-viscous damping (the static mode of UDEC and 3DEC), used by the
// quasi-static phases of `capacity` and `sweep` (docs/capacity.md, "Quasi-static decisions"):
// on every degree of freedom (a node's x and y; a rigid block's x, y and rotation) the
// unbalanced force f^n of the step gets a damping force
//     d^n = -alpha |f^n| sign(v^(n-1/2)),
// opposed to the motion and proportional to the force, not to the speed, so it damps every
// mode alike whatever its frequency, and vanishes at equilibrium. `outgoing` applies it only
// while the force opposes the motion (f . v < 0: the degree of freedom moves away from its
// equilibrium), where it equals alpha f: an oscillation still loses energy on every outgoing
// half-swing, but a mechanism that the load accelerates (f . v > 0) is not slowed down at all,
// where the full rule takes the fraction alpha of its driving force. The dissipated energy is
// the trapezoidal work of the ledger (integrate.hpp header):
//     D += -dt/2 (d^n + d^(n-1)) . v^(n-1/2)
// exact with the leapfrog K^n, so the balance still closes.
struct LocalDamping {
  double alpha = 0.0;                       // coefficient, 0 <= alpha < 1
  bool outgoing = true;                     // damp only while f . v < 0 (above)
  std::vector<double>* previous = nullptr;  // d^(n-1) per degree of freedom (sized on use)
  double dissipated = 0.0;                  // out: energy dissipated by this step [J]
};

// Kinetic damping (the velocity reset of dynamic relaxation), used with the local damping by
// the quasi-static phases of `capacity` and `sweep` (docs/capacity.md, "Kinetic damping"):
// the total kinetic energy K^n is followed step by step, and once it has fallen below
// (1 - drop) times its largest value since the last reset, the step is taken back to x^n
// with every free velocity set to zero (nodes, and the rigid bodies' translation and
// rotation). A structure swinging towards an equilibrium has its largest K where it crosses
// that equilibrium, so the reset stops it there instead of letting it overshoot, whatever the
// period of the swing; the outgoing local damping takes only 1 - 1/sqrt(1 + alpha) of a
// swing's speed per half-swing (26% at alpha = 0.8), which leaves the slow sway of a tall
// structure ringing for several periods. A mechanism that the load accelerates has a growing
// K and is never touched.
//
// Ledger: with v^(n+1/2) = 0 and x^(n+1) = x^n, the next step books K^(n+1) = 0, the same
// U and no work over the (empty) increment, so the reset takes exactly K^n out of the stored
// energy; K^n is booked as dissipated by the quasi-static damping (EnergyLedger::
// local_dissipated) and the balance closes. (Zeroing the velocities after the position update
// instead leaves the last increment's work unbooked: an O(1) balance error on a mode with a
// few steps per period.)
struct KineticDamping {
  double drop = 0.0;        // relative fall of K below its peak that triggers a reset; 0: off
  double* peak = nullptr;   // largest K since the last reset [J] (state kept by the caller)
  bool reset = false;       // out: this step reset the velocities
};

// Follows K^n = `kinetic` after the central-difference update of step n (of length dt); on a
// reset takes the positions back to x^n, sets every free velocity to zero and returns the
// kinetic energy removed (`kinetic`), otherwise 0.
double apply_kinetic_damping(Model& model, double kinetic, double dt, KineticDamping& damping);

// The damping force of one degree of freedom (above).
inline double local_damping_force(double alpha, bool outgoing, double force, double velocity) {
  if (outgoing) return force * velocity < 0.0 ? alpha * force : 0.0;
  if (velocity > 0.0) return -alpha * std::abs(force);
  if (velocity < 0.0) return alpha * std::abs(force);
  return 0.0;
}

// Clears the force accumulators of every node (on the OpenMP threads for large models).
void clear_forces(Nodes& nodes);

// Velocity then position update of the nodes of free blocks; returns K^n above [J]. Threaded
// above a size threshold, bit-identical for any thread count (integrate.cpp).
double integrate_central_difference(Model& model, double dt);

// Same with local damping (damping.alpha > 0); books damping.dissipated.
double integrate_central_difference(Model& model, double dt, LocalDamping& damping);

}  // namespace voussoir

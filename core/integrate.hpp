#pragma once
// Central-difference (leapfrog) integration: the velocities stored in Nodes are half-step
// velocities. Step n, with forces f^n evaluated at x^n (and the damping at v^(n-1/2)):
//     v^(n+1/2) = v^(n-1/2) + dt f^n / m,      x^(n+1) = x^n + dt v^(n+1/2)
// (velocity then position, SPEC section 1). Nodes of fixed blocks are never touched.
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

#include "core/model.hpp"

namespace voussoir {

// Clears the force accumulators of every node (on the OpenMP threads for large models).
void clear_forces(Nodes& nodes);

// Velocity then position update of the nodes of free blocks; returns K^n above [J]. Threaded
// above a size threshold, bit-identical for any thread count (integrate.cpp).
double integrate_central_difference(Model& model, double dt);

}  // namespace voussoir

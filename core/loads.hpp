#pragma once
// Body loads: a uniform body acceleration (ax, ay) on every node of a free block, applied as
// the force m (ax, ay). It carries gravity (ay = -g), the pseudo-static seismic load
// (ax = lambda g) and base motion in the frame of the fixed supports (-m a_g(t)); the driver
// sets ctx.body_ax/ay, this stage only applies them.
//
// External work (energy ledger). For the leapfrog kinetic energy of core/integrate.hpp the
// exact work increment of step n is the trapezoid 1/2 (f^n + f^(n-1)) . (x^n - x^(n-1)).
// For a uniform acceleration f_i = m_i a and x^n - x^(n-1) = dt v^(n-1/2), so
//     dW^n = dt/2 (a^n + a^(n-1)) . sum_i m_i v_i^(n-1/2)
// needs only the momentum of the free nodes before the velocity update, which this stage
// returns (it reads the velocities anyway). Exact for a constant load: f . dx per step.

#include "core/model.hpp"

namespace voussoir {

// Adds m (ax, ay) to the force of every node of a free block; returns the momentum
// sum_i m_i v_i of those nodes at the current (half-step) velocities [kg m/s].
Vec2 add_body_loads(Model& model, double ax, double ay);

}  // namespace voussoir

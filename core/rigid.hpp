#pragma once
// Rigid blocks (`material.model = "rigid"`; docs/rigid.md).
//
// A rigid block is one body: centroid c, rotation theta, velocity v and angular velocity
// omega. Its outline is what touches (contact/rigid_contact.hpp): the contact stage adds its
// forces and moments to the body's force F and moment T about c, the body loads add M a at c
// (engine/step.hpp), and the same central-difference scheme as the nodes (core/integrate.hpp)
// advances the body (STYLE.md "Body kinds sit side by side": the kinds differ in how forces
// become motion):
//     v^(n+1/2) = v^(n-1/2) + dt F^n / M,        c^(n+1) = c^n + dt v^(n+1/2),
//     w^(n+1/2) = w^(n-1/2) + dt T^n / I,        theta^(n+1) = theta^n + dt w^(n+1/2).
// In 2D the rotation has no gyroscopic term, so this is the leapfrog of a system with the
// constant mass matrix diag(M, M, I): the ledger argument of core/integrate.hpp holds with
//     K^n = 1/2 (M v^- . v^+ + I w^- w^+).
// The step touches only these per-body arrays. The block's nodes (its minimal mesh,
// mesh/minimal.hpp) are what outputs, pictures, hinges and motion measures read; they follow
// the body when a reader asks: sync_rigid_nodes sets x_i = c + R(theta) r_i (r_i the node's
// reference offset from the reference centroid, so a block never changes shape however far
// it rotates) and v_i = v + w x (x_i - c), the rigid velocity field of the half step.
//
// Mass and inertia come from the block's triangles: M = rho t_z A, c the area centroid, and
// I = rho t_z sum over triangles of A/6 (|p0|^2 + |p1|^2 + |p2|^2 + p0.p1 + p1.p2 + p2.p0),
// p_k the vertices relative to c (the exact polar moment of a uniform triangle). The lumped
// node masses (1/3 of each triangle) have the same total and the same centroid, so the body
// loads m_i a sum to M a with no moment about c and the node momentum is M v.
//
// The state lives in Model::rigid (core/model.hpp).

#include <cstdint>
#include <vector>

#include "core/integrate.hpp"
#include "core/model.hpp"

namespace voussoir {

// Steps per joint period. The joint bound (contact/contact.cpp rigid_body_bounds) is the
// exact highest frequency of the flat joints, not a bound 2 to 4 times above it as for elastic
// blocks, and a one-sided contact integrated near omega dt = 2 gains energy each time it
// opens and closes (a hinge opening, a block lifting off at the top of its bounce): the
// contact force switches on between steps. Measured on `cases/block.toml` with rigid blocks
// (a block resting on its undamped joint grazes the ground at each period, the worst case),
// largest ledger error over 1 s against the fraction of 2 / omega used (before
// solver.dt_safety 0.9): 0.2 -> 1.9e-4, 0.3 -> 1.7e-3, 0.4 -> 4.0e-3, 0.5 -> 3.0e-2, 0.7 -> the
// run stopped by the 5% guard (docs/rigid.md, "The stable step of rigid blocks"). So 0.4:
// omega dt = 0.72, about nine steps per period of the stiffest joint mode.
inline constexpr double kRigidStepFraction = 0.4;
// The quasi-static settle and trials of `capacity` and `sweep` take the same fraction. Rejected:
// 0.5 (omega dt = 0.9) there, which froze trials: the bound omega is
// per body, the joints couple the bodies into modes faster than it (about 1.3 times on the
// buttressed basket arch), and at 0.5 such a mode turns within one step (omega dt > 1). The
// kinetic damping then resets the velocities at every second step, and a structure that is
// not in equilibrium stands still and is called at rest. It happened on church B, and on the buttressed arches at beta 150, whose
// lambda* it raised by 0.37% (docs/capacity.md, "The step of the quasi-static phases").
// With impact damping (contact.restitution < 1) the dashpot, which acts on the rate of the
// normal force, must resolve the impact: at the fraction above a drop's rebound misses e^2 by
// more, so its steps stay at 0.2 (docs/rigid.md, "Impact damping").
inline constexpr double kRigidDampedStepFraction = 0.2;

// Makes every free block of the model a rigid body (the nodes' current positions must be the
// reference ones, as finalize_model leaves them). Fixed blocks stay fixed.
void make_blocks_rigid(Model& model);

// Sets the force and moment of every body to zero (the step's stage 2 for rigid blocks).
void clear_rigid_forces(RigidBodies& bodies);

// Adds the body loads M (ax, ay) at each free body's centroid (M: RigidBodies::load_mass) and
// returns the momentum sum M v^(n-1/2) before the update, for the external work (core/loads.hpp).
Vec2 add_rigid_body_loads(Model& model, double ax, double ay);

// Central-difference update of the rigid blocks from their force and moment of the step
// (RigidBodies::fx, fy, torque). Returns K^n [J] (above). The nodes are not moved.
double integrate_rigid_bodies(Model& model, double dt);

// Same with Cundall's local damping on each body's x, y and rotation (core/integrate.hpp
// LocalDamping; damping.alpha > 0): books damping.dissipated.
double integrate_rigid_bodies(Model& model, double dt, LocalDamping& damping);

// Puts the nodes of the rigid blocks where their bodies are, with the bodies' velocity field
// (above); their force accumulators read zero (rigid blocks' forces are per body). Call before
// reading node positions or velocities of a rigid model; nothing for an elastic one.
void sync_rigid_nodes(Model& model);

// The kinetic damping's reset for rigid blocks (core/integrate.hpp KineticDamping): every body
// back to c^n = c^(n+1) - dt v^(n+1/2) (and theta likewise) at rest.
void reset_rigid_step(Model& model, double dt);

// Places rigid block b at centroid (cx, cy) and rotation theta with velocity (vx, vy, omega),
// its nodes and their velocities with it (initial states of tests and studies).
void set_rigid_state(Model& model, Index b, double cx, double cy, double theta, double vx,
                     double vy, double omega);

// Polar moment of inertia of a uniform triangle of areal density rho_a [kg/m2] about the point
// (ox, oy) [kg m2].
double triangle_polar_inertia(double rho_a, const Vec2& p0, const Vec2& p1, const Vec2& p2,
                              const Vec2& o);

}  // namespace voussoir

#pragma once
// One step (STYLE.md "The step is one short function"): advance() calls the stages in order,
// each stage reads the per-step context, no stage calls another, no I/O. The stage functions
// come in one set per body kind and scheme (StepScheme), chosen once at set-up; advance() runs
// the set of the simulation's scheme and asks no other question of the body kind.
//
// The explicit schemes (elastic blocks, rigid blocks):
//
//   1. broad phase if some node (rigid blocks: some outline point) moved more than the buffer
//      allows
//   2. clear forces (of the nodes, or of the rigid bodies)
//   3. element forces (finite-strain CST + Munjiza damping)      core/cst; none for rigid blocks
//   4. contact forces (potential penalty, or the rigid blocks'     contact/
//      joint law between outlines, + Coulomb friction)
//   5. body loads (gravity, lambda g, base motion)                 core/loads, core/rigid
//   6. central-difference integration (v then x), kinetic energy   core/integrate, core/rigid
//      (with the local damping of the quasi-static phases when ctx.local_damping > 0, and
//      their kinetic damping when ctx.kinetic_damping > 0)
//   7. prescribed supports: their work over the step, then their   core/supports
//      pose at the step's end (only with [supports] moves)
//
// Rigid blocks by non-smooth contact dynamics (solver.scheme = "nscd", StepScheme::RigidNscd)
// take the other scheme, Moreau-Jean's theta-method (contact/nscd.hpp):
//   1. broad phase as above, then the contact points at the start of the step
//   2. prescribed supports: their pose at the step's end and their velocity over it
//   3. free velocities: v^- + h a(t + theta h) of the loads
//   4. contact impulses by non-linear Gauss-Seidel, which give v^+      contact/nscd
//   5. positions q^+ = q^- + h ((1 - theta) v^- + theta v^+); ledger from the impulses

#include <array>
#include <vector>

#include "contact/contact.hpp"
#include "core/cst.hpp"
#include "core/energy.hpp"
#include "core/model.hpp"
#include "core/supports.hpp"

namespace voussoir {

// The stage functions a step runs, one set per body kind and scheme: how forces become motion
// (element forces on the nodes, or a force and a moment on each body) and how the contact
// enters (forces of the joints, or impulses). Chosen once at set-up (choose_step_scheme),
// never by a question inside the step.
enum class StepScheme : unsigned char {
  ElasticExplicit,  // elastic blocks, central difference (the nodes)
  RigidExplicit,    // rigid blocks, central difference (the bodies)
  RigidNscd,        // rigid blocks, Moreau-Jean's theta-method (solver.scheme = "nscd")
};

// The scheme of a model's blocks: rigid bodies (Model::is_rigid) by non-smooth contact dynamics
// when nscd, else by the central difference; elastic blocks by the central difference (the deck
// refuses nscd for them).
StepScheme choose_step_scheme(const Model& model, bool nscd);

// Per-step context (Box2D b2StepContext): time step, body load, law constants.
struct StepContext {
  double dt = 0.0;           // [s]
  double time = 0.0;         // [s], time at the start of the step
  double body_ax = 0.0;      // body acceleration on free nodes [m/s2]: lambda g - a_g,x(t)
  double body_ay = -9.81;    // -g - a_g,y(t)
  double lame_lambda = 0.0;  // 2D law constants [Pa]
  double shear_modulus = 0.0;
  double eta = 0.0;  // Munjiza viscosity [Pa s]
  bool contact_on = true;
  // Rigid blocks: compute the joints' elastic energy (ledger.contact) at this step. The engine
  // asks for it at the steps whose ledger is read (samples, ends); between them ledger.contact
  // keeps its last value, which only max_energy reads (bounded by the external work anyway).
  // The joint energy is a third of a touching pair's cost. Tests that read the ledger at every
  // step keep the default.
  bool contact_energy = true;
  // Cundall's local damping coefficient alpha of the quasi-static phases (core/integrate.hpp
  // LocalDamping); 0 = off (every physical run)
  double local_damping = 0.0;
  bool local_damping_outgoing = true;  // LocalDamping::outgoing
  // Kinetic damping of the quasi-static phases (core/integrate.hpp KineticDamping): the
  // relative fall of the kinetic energy below its peak that sets the velocities to zero; 0 =
  // off (every physical run)
  double kinetic_damping = 0.0;
  // Body acceleration of the previous step, for the trapezoidal external work (core/loads.hpp);
  // set by advance(), not by drivers.
  double prev_body_ax = 0.0;
  double prev_body_ay = 0.0;
  // Non-smooth contact dynamics of rigid blocks (StepScheme::RigidNscd): the settings of
  // Moreau-Jean's theta-method (contact/nscd.hpp).
  NscdSettings nscd_settings;
  // The load program evaluates the loads at ctx.time + load_lead [s] (engine/trial.hpp
  // LoadProgram): theta h for nscd (the theta-method's load), 0 for the explicit scheme.
  double load_lead = 0.0;
};

// Wall-clock seconds spent per stage (accumulated).
struct StageTimers {
  double broad = 0.0, elements = 0.0, contact = 0.0, loads = 0.0, integrate = 0.0;
  bool enabled = false;
};

struct Simulation {
  Model model;
  // The step's set of stage functions (prepare_context sets the explicit scheme of the
  // model's blocks; engine/setup.cpp make_simulation then RigidNscd for solver.scheme = "nscd").
  StepScheme scheme = StepScheme::ElasticExplicit;
  ContactSystem contact;
  EnergyLedger ledger;
  StepContext ctx;
  StageTimers timers;
  long long step = 0;
  // V0 P_v of every triangle at the last damped step (layout in core/cst.hpp
  // add_element_forces) for the exact damping work of the ledger; sized by advance(), empty
  // when undamped.
  std::vector<double> viscous_piola;
  // Local damping force of the previous step per degree of freedom (core/integrate.hpp
  // LocalDamping); empty while ctx.local_damping is 0.
  std::vector<double> local_damping_previous;
  // Largest kinetic energy since the last kinetic-damping reset [J] (core/integrate.hpp
  // KineticDamping); 0 while ctx.kinetic_damping is 0.
  double kinetic_peak = 0.0;
  // Kinetic-damping resets so far: a diagnostic, read by the capacity trials (a trial whose
  // every step resets stands still, docs/capacity.md "The step of the quasi-static phases").
  long long kinetic_resets = 0;
  // Scratch of the threaded element stage (core/cst.hpp), built at the first large step.
  ElementWorkspace element_work;
  // Prescribed movement of fixed blocks ([supports]; empty: none), started by the drivers
  // after the settle under gravity (core/supports.hpp).
  SupportMotion supports;
  // Non-smooth contact dynamics: the solver's record over the run (iterations, unconverged
  // steps, residual, interpenetration) and the bodies' velocities at the start of the step
  // (scratch, 3 per block).
  NscdStats nscd_stats;
  std::vector<double> nscd_before;
};

// Fills ctx law constants and eta from the model material and damping factor, and chooses the
// explicit scheme of the model's blocks (sim.scheme).
void prepare_context(Simulation& sim, double damping_factor);

// Stable time step [s] of the model (elements and, when on, contact), before the safety factor.
double stable_time_step(const Simulation& sim);
// Rigid blocks: the stable limit of each block alone on its joints [s], with the step fraction
// of stable_time_step (whose value is the smallest of these); infinity for a fixed block or
// one without joints, empty for elastic blocks. For `check`: how far the blocks' own limits
// spread (mass scaling of the fast ones could only gain that much).
std::vector<double> rigid_body_stable_steps(const Simulation& sim);

// Mass scaling of the quasi-static phases (capacity and sweep with capacity.mass_scaling =
// "equalize"; docs/capacity.md "Mass scaling of the slow blocks"). Rigid blocks only: lowers
// the mass and rotational inertia of every free block whose own highest frequency on its
// joints (contact rigid_body_bounds) is below the model's highest, by the factor
// omega_b^2 / omega_max^2, so that every block then reaches the model's step and none sets a
// shorter one. The loads keep the true masses (they are the nodes' lumped masses; the scaled
// ones are only the bodies' inertia), so every equilibrium, and the static collapse load, is
// unchanged; the heavy blocks (piers, buttresses, courses) answer faster, and the trials need
// less simulated time. Not with impact damping (contact.restitution < 1), whose dashpots are
// tuned to the true masses, nor for elastic blocks. Returns how many blocks were scaled and
// the smallest factor (1 when none).
struct InertiaScaling {
  int blocks = 0;
  double smallest = 1.0;
};
InertiaScaling equalize_rigid_inertia(Simulation& sim);

// Advances the simulation by ctx.dt with the stage functions of sim.scheme. Energy ledger: strain
// and kinetic energy at the step (core/integrate.hpp for the leapfrog K), external work and damping
// dissipation by the trapezoid over the last position increment (exact for a linear system;
// engine/step.cpp). Contact energy and friction come from the contact stage. At the first step
// (sim.step == 0) the energy of the initial state (K + U + contact) is booked as external work:
// whoever set the initial state put it in, and balance_error() stays meaningful for runs from a
// disturbed state.
void advance(Simulation& sim);

}  // namespace voussoir

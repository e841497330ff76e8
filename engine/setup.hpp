#pragma once
// From a validated deck to a ready Simulation: build and mesh the scene, set the contact
// penalty, damping and time step. Shared by every subcommand, test and benchmark.

#include <stdexcept>
#include <string>
#include <vector>

#include "core/schema.hpp"
#include "engine/step.hpp"
#include "seismic/base_motion.hpp"

namespace voussoir {

// (RunError: core/schema.hpp.)

struct SetupInfo {
  double dt = 0.0;               // time step in use [s]
  double dt_stable = 0.0;        // stable limit before the safety factor [s]
  double penalty = 0.0;          // contact penalty Ep [Pa]
  double eta = 0.0;              // damping viscosity [Pa s]
  bool rigid = false;            // material.model = "rigid"
  bool joint_stiffness = false;  // pairs carry a joint stiffness (kn or 100 E / L)
  std::string dt_set_by;         // what sets the stable step
};

// Non-smooth contact dynamics (solver.scheme = "nscd"): the step of solver.dt = "auto" [s]
// (docs/nscd.md "The step": the convergence study that chose it) and the default restitution
// of the contact points, 0: plastic impacts. A rigid block's rocking loses its energy when its
// pivot changes, and with a plastic impact at the new pivot the theta-method gives Housner's
// loss of that impact itself; a restitution above 0 would add a bounce that dry masonry joints
// do not show (docs/nscd.md "Restitution").
inline constexpr double kNscdDefaultStep = 1e-3;
inline constexpr double kNscdDefaultRestitution = 0.0;

// Contact penalty of the deck: contact.penalty if given, else penalty_factor x Lamé's first
// constant of the material.
double contact_penalty(const Config& config);

// Builds the simulation. A user dt above the stable limit throws DeckError naming the limit.
Simulation make_simulation(const Config& config, SetupInfo* info = nullptr);

// The deck's [supports] moves marked on sim.model and recorded in sim.supports (core/
// supports.hpp; make_simulation calls it before the contact set-up). A move of a free or
// unknown block throws DeckError naming supports.moves[k].block and its value.
void prescribe_supports(const Config& config, Simulation& sim);

// Starts the deck's support movement at the simulation's current time, over supports.ramp:
// the drivers call it once the structure has settled under gravity. Nothing without moves.
void start_supports(const Config& config, Simulation& sim);

// Non-smooth contact dynamics: a step no longer than the sampling interval of a recorded base
// signal (the record's own detail is not stepped over). Nothing for the explicit scheme, whose
// stable step is far shorter, nor for an analytic pulse.
void fit_step_to_signal(Simulation& sim, const BaseSignal& signal);

// Sets the body load of the context: gravity down, lambda g horizontal.
void set_static_load(Simulation& sim, double gravity, double lambda);

// Cauchy stress (sxx, syy, sxy) of every triangle, interleaved, for output snapshots.
std::vector<double> triangle_stresses(const Simulation& sim);

}  // namespace voussoir

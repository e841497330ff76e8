#include "engine/setup.hpp"

#include <cmath>
#include <limits>
#include <sstream>

#include "contact/joint_stiffness.hpp"
#include "core/cst.hpp"
#include "core/rigid.hpp"
#include "core/supports.hpp"
#include "io/deck.hpp"
#include "mesh/minimal.hpp"
#include "mesh/scene.hpp"
#include "seismic/accelerogram.hpp"

namespace voussoir {

double contact_penalty(const Config& config) {
  if (config.contact.penalty > 0.0) return config.contact.penalty;
  Material m;
  m.young = config.material.young;
  m.poisson = config.material.poisson;
  return config.contact.penalty_factor * m.lame_lambda();
}

void set_static_load(Simulation& sim, double gravity, double lambda) {
  sim.ctx.body_ax = lambda * gravity;
  sim.ctx.body_ay = -gravity;
}

void prescribe_supports(const Config& config, Simulation& sim) {
  const std::vector<Block>& blocks = sim.model.blocks;
  std::vector<SupportMove> moves;
  for (std::size_t k = 0; k < config.supports.moves.size(); ++k) {
    const SupportMoveConfig& m = config.supports.moves[k];
    const bool exists = m.block >= 0 && std::size_t(m.block) < blocks.size();
    if (!exists || !blocks[std::size_t(m.block)].fixed) {
      std::ostringstream msg;
      msg << (m.where.empty() ? config.deck_path + ": " : m.where) << "supports.moves[" << k
          << "].block = " << m.block << ": expected a fixed block (";
      if (!exists)
        msg << "the model has blocks 0 to " << blocks.size() - 1;
      else
        msg << "block " << m.block << " is a free " << blocks[std::size_t(m.block)].role;
      msg << "; the fixed ones:";
      for (std::size_t b = 0; b < blocks.size(); ++b)
        if (blocks[b].fixed) msg << " " << b << " (" << blocks[b].role << ")";
      msg << ")";
      throw DeckError(msg.str());
    }
    moves.push_back({m.block, m.dx, m.dy, m.rotation * M_PI / 180.0});
  }
  prescribe_supports(sim.model, moves, sim.supports);
}

void start_supports(const Config& config, Simulation& sim) {
  if (!sim.supports.empty()) start_support_motion(sim.supports, sim.ctx.time, config.supports.ramp);
}

Simulation make_simulation(const Config& config, SetupInfo* info) {
  Simulation sim;
  sim.model = build_model(scene_params(config));
  const bool rigid = config.material.model == "rigid";
  if (rigid) {
    // Only the outline matters to a rigid block: the fewest triangles (mesh/minimal.hpp).
    sim.model = minimal_model(sim.model, config.mesh.chord_tolerance);
    make_blocks_rigid(sim.model);
  }
  prescribe_supports(config, sim);
  ContactParams cp;
  cp.penalty = contact_penalty(config);
  cp.friction = config.contact.friction;
  cp.buffer = config.contact.buffer;
  cp.normal_stiffness = config.contact.normal_stiffness;
  cp.shear_stiffness = config.contact.shear_stiffness;
  cp.restitution = config.contact.restitution;
  const bool nscd = config.solver.scheme == "nscd";
  cp.nscd = nscd;
  if (rigid && !config.contact.has("restitution"))
    cp.restitution = nscd ? kNscdDefaultRestitution : kRigidDefaultRestitution;
  // Rigid blocks with neither a stiffness nor a penalty given: kn = 100 E / L per joint (L:
  // its length; contact/joint_stiffness.hpp).
  if (rigid && !(cp.normal_stiffness > 0.0) && !config.contact.has("penalty") &&
      !config.contact.has("penalty_factor"))
    cp.joint_young = config.material.young;
  sim.contact.setup(sim.model, cp);
  prepare_context(sim, config.solver.damping_factor);
  set_static_load(sim, config.load.gravity, config.load.lambda);
  if (nscd) {
    // Moreau-Jean's step is not limited by any stiffness: the deck's, or kNscdDefaultStep, no
    // longer than a record's sampling interval (fit_step_to_signal).
    sim.scheme = choose_step_scheme(sim.model, true);
    sim.ctx.nscd_settings = {config.solver.theta, config.solver.tolerance,
                             config.solver.max_iterations, cp.friction, cp.restitution};
    sim.ctx.dt = config.solver.dt > 0.0 ? config.solver.dt : kNscdDefaultStep;
    sim.ctx.load_lead = config.solver.theta * sim.ctx.dt;
    if (config.solver.dt == 0.0 && config.load.base.signal == "file")
      fit_step_to_signal(sim, make_base_signal(config.load.base, config.load.gravity));
    if (info) {
      info->dt = sim.ctx.dt;
      info->dt_stable = std::numeric_limits<double>::infinity();
      info->penalty = 0.0;
      info->eta = 0.0;
      info->rigid = true;
      info->joint_stiffness = false;
      info->dt_set_by = config.solver.dt > 0.0
                            ? "solver.dt (non-smooth contact dynamics)"
                            : "non-smooth contact dynamics (solver.dt = \"auto\")";
    }
    return sim;
  }

  const double dt_stable = stable_time_step(sim);
  // Infinite when nothing can vibrate (no free block); zero or NaN only when the material,
  // mesh, damping or penalty overflow double precision, and below kMinStableStep only for
  // absurd values of them (a damping factor of 9e18 gave 1.9e-25 s, a fuzzing finding): a
  // microsecond of such a run is 1e9 steps. Refused, never run.
  constexpr double kMinStableStep = 1e-15;  // [s]; masonry models sit at 1e-8 to 1e-5 s
  if (!(dt_stable >= kMinStableStep)) {
    std::ostringstream msg;
    msg << config.deck_path << ": the stable time step of this model is " << dt_stable
        << " s (at least " << kMinStableStep
        << " s needed): the material (young = " << config.material.young
        << " Pa, density = " << config.material.density
        << " kg/m3), solver.damping_factor = " << config.solver.damping_factor
        << ", the mesh or the contact penalty (" << cp.penalty << " Pa) are out of range";
    throw DeckError(msg.str());
  }
  double dt = config.solver.dt_safety * dt_stable;
  if (config.solver.dt > 0.0) {
    if (config.solver.dt > dt_stable) {
      std::ostringstream msg;
      msg << config.deck_path << ": solver.dt = " << config.solver.dt
          << " s is above the stable limit " << dt_stable
          << " s of this model (use dt = \"auto\" or a value below the limit)";
      throw DeckError(msg.str());
    }
    dt = config.solver.dt;
  }
  sim.ctx.dt = dt;
  if (info) {
    info->dt = dt;
    info->dt_stable = dt_stable;
    info->penalty = cp.penalty;
    info->eta = sim.ctx.eta;
    info->rigid = rigid;
    info->joint_stiffness = sim.contact.joint_stiffness_mode();
    info->dt_set_by = rigid ? "rigid bodies on their joints (mass, inertia, joint stiffness)"
                            : "elements and contact penalty";
  }
  return sim;
}

void fit_step_to_signal(Simulation& sim, const BaseSignal& signal) {
  if (sim.scheme != StepScheme::RigidNscd || signal.kind() != BaseSignal::Kind::Table) return;
  if (!(signal.sample_dt() < sim.ctx.dt)) return;
  sim.ctx.dt = signal.sample_dt();
  sim.ctx.load_lead = sim.ctx.nscd_settings.theta * sim.ctx.dt;
}

std::vector<double> triangle_stresses(const Simulation& sim) {
  const CstLaw law{sim.ctx.lame_lambda, sim.ctx.shear_modulus, sim.ctx.eta};
  std::vector<double> s(3 * static_cast<size_t>(sim.model.tris.size()));
  if (sim.model.is_rigid()) return s;  // rigid blocks carry no element stress (not written)
  for (Index e = 0; e < sim.model.tris.size(); ++e) {
    const Stress2 st = triangle_cauchy_stress(sim.model, e, law);
    s[3 * e] = st.xx;
    s[3 * e + 1] = st.yy;
    s[3 * e + 2] = st.xy;
  }
  return s;
}

}  // namespace voussoir

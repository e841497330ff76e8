// One explicit step: the stages of engine/step.hpp in order, plus the set-up of the per-step
// context and the stable time step.

#include "engine/step.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "core/cst.hpp"
#include "core/integrate.hpp"
#include "core/loads.hpp"
#include "core/rigid.hpp"
#include "core/supports.hpp"

namespace voussoir {

namespace {

// Accumulates wall-clock time into StageTimers fields; free when timers are disabled.
class StageClock {
 public:
  explicit StageClock(bool enabled) : enabled_(enabled) {
    if (enabled_) last_ = std::chrono::steady_clock::now();
  }
  void stamp(double& seconds) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    seconds += std::chrono::duration<double>(now - last_).count();
    last_ = now;
  }

 private:
  bool enabled_;
  std::chrono::steady_clock::time_point last_;
};

CstLaw law_of(const StepContext& ctx) {
  return CstLaw{ctx.lame_lambda, ctx.shear_modulus, ctx.eta};
}

}  // namespace

// eta = damping_factor x 2 h sqrt(E rho), h the smallest triangle height of the free blocks
// (docs/design.md, "The step"): Munjiza's scaling of critical damping for the shortest element
// modes (at factor 1 the breathing mode of an equilateral triangle, nu = 0.2, has damping
// ratio 1.8; the low structural modes are damped in proportion to h / their wavelength).
void prepare_context(Simulation& sim, double damping_factor) {
  const Material& mat = sim.model.material;
  sim.ctx.lame_lambda = mat.lame_lambda_2d();
  sim.ctx.shear_modulus = mat.shear_modulus();
  const double h = min_triangle_height(sim.model);
  sim.ctx.eta =
      std::isfinite(h) ? damping_factor * 2.0 * h * std::sqrt(mat.young * mat.density) : 0.0;
  if (sim.model.is_rigid()) sim.ctx.eta = 0.0;  // no element stage, nothing to damp there
  sim.scheme = choose_step_scheme(sim.model, false);
}

// Stable step = 2 / (g + sqrt(omega^2 + g^2)) (core/cst.hpp damped_stable_step) with
//   omega^2 = max_e omega_e^2 + omega_contact^2,  g = max_e (c/m)_e / 2.
// The element terms are rigorous upper bounds (element eigenvalue theorem, cst.hpp). Contact
// springs act on the same nodes as the elements, so their stiffnesses add: the sum of the two
// omega^2 bounds the combined system, whereas the smaller of the two separate limits
// (min(2/omega_el, 2/omega_c)) can exceed the true limit by up to sqrt(2).
//
// Rigid blocks have no element modes: the bound is the contact one over the bodies' mass and
// rotational inertia, block by block (contact/contact.hpp rigid_body_bounds; the smallest of
// rigid_body_stable_steps), the damping rate that of the contact's impact damping
// (restitution < 1), if any, times kRigidStepFraction, or
// kRigidDampedStepFraction with impact damping (core/rigid.hpp: the joints' one-sided contact
// and their dashpots must be resolved, not only kept stable).
double stable_time_step(const Simulation& sim) {
  if (sim.model.is_rigid()) {
    const std::vector<double> steps = rigid_body_stable_steps(sim);
    return steps.empty() ? std::numeric_limits<double>::infinity()
                         : *std::min_element(steps.begin(), steps.end());
  }
  const CstFrequencyBound el = max_frequency_bound(sim.model, law_of(sim.ctx));
  double omega_squared = el.omega_squared;
  if (sim.ctx.contact_on) omega_squared += sim.contact.max_omega_squared(sim.model);
  if (!(omega_squared > 0.0) && !(el.damping_rate > 0.0))
    return std::numeric_limits<double>::infinity();
  return damped_stable_step(omega_squared, el.damping_rate);
}

std::vector<double> rigid_body_stable_steps(const Simulation& sim) {
  if (!sim.model.is_rigid()) return {};
  std::vector<double> steps(sim.model.blocks.size(), std::numeric_limits<double>::infinity());
  if (!sim.ctx.contact_on) return steps;
  const std::vector<ContactFrequencyBound> bounds = sim.contact.rigid_body_bounds(sim.model);
  for (std::size_t b = 0; b < bounds.size(); ++b) {
    const ContactFrequencyBound& c = bounds[b];
    if (!(c.omega_squared > 0.0)) continue;
    const double fraction = c.damping_rate > 0.0 ? kRigidDampedStepFraction : kRigidStepFraction;
    steps[b] = fraction * damped_stable_step(c.omega_squared, c.damping_rate);
  }
  return steps;
}

InertiaScaling equalize_rigid_inertia(Simulation& sim) {
  InertiaScaling out;
  if (!sim.model.is_rigid() || !sim.ctx.contact_on || sim.contact.params().restitution < 1.0)
    return out;
  const std::vector<ContactFrequencyBound> bounds = sim.contact.rigid_body_bounds(sim.model);
  double top = 0.0;
  for (const ContactFrequencyBound& c : bounds)
    if (std::isfinite(c.omega_squared)) top = std::max(top, c.omega_squared);
  if (!(top > 0.0)) return out;
  RigidBodies& r = sim.model.rigid;
  for (std::size_t b = 0; b < bounds.size(); ++b) {
    const double factor = bounds[b].omega_squared / top;
    if (!(factor > 0.0) || !(factor < 1.0)) continue;  // fixed, jointless, or the fastest
    r.mass[b] *= factor;
    r.inertia[b] *= factor;
    ++out.blocks;
    out.smallest = std::min(out.smallest, factor);
  }
  return out;
}

namespace {

// Moreau-Jean's theta-method for rigid blocks (engine/step.hpp; the impulses and their work:
// contact/nscd.hpp). Ledger: the kinetic energy at the end of the step; the loads' work over
// the step's displacement, h M a . ((1 - theta) v^- + theta v^+); the impulses' work booked
// as impact and friction dissipation and the supports' work as external work (nscd.hpp
// "Energy"); and the theta-method's own dissipation, the loads' work less h M a . (v^- + v^+)
// / 2 (zero at theta = 1/2), as damping dissipation. The balance then holds to round-off.
void advance_nscd(Simulation& sim) {
  Model& model = sim.model;
  StepContext& ctx = sim.ctx;
  EnergyLedger& ledger = sim.ledger;
  StageTimers& timers = sim.timers;
  StageClock clock(timers.enabled);
  RigidBodies& r = model.rigid;
  const double h = ctx.dt, theta = ctx.nscd_settings.theta;
  const std::size_t nb = model.blocks.size();

  // 1. broad phase when due, then the contact points at the start of the step
  if (ctx.contact_on && sim.contact.needs_detection(model)) sim.contact.detect(model);
  if (ctx.contact_on) sim.contact.build_contact_points(model);
  clock.stamp(timers.broad);

  // 2. prescribed supports: pose at the step's end and velocity over the step (no forces act
  //    on the bodies here, so move_supports books no work; the impulses give it below)
  if (!sim.supports.empty()) move_supports(model, sim.supports, ctx.time + h, h);

  // 3. velocities at the start of the step, then the loads' impulse
  std::vector<double>& before = sim.nscd_before;
  before.resize(3 * nb);
  double k0 = 0.0;
  for (std::size_t b = 0; b < nb; ++b) {
    before[3 * b] = r.vx[b], before[3 * b + 1] = r.vy[b], before[3 * b + 2] = r.omega[b];
    if (model.blocks[b].fixed) continue;
    k0 += r.mass[b] * (r.vx[b] * r.vx[b] + r.vy[b] * r.vy[b]) +
          r.inertia[b] * r.omega[b] * r.omega[b];
    r.vx[b] += h * ctx.body_ax;
    r.vy[b] += h * ctx.body_ay;
  }
  k0 *= 0.5;
  clock.stamp(timers.loads);

  // 4. contact impulses (v^+)
  NscdStepResult solved;
  if (ctx.contact_on)
    solved =
        sim.contact.solve_impulses(model, before, h, {ctx.body_ax, ctx.body_ay}, ctx.nscd_settings);
  sim.nscd_stats.add(solved);
  clock.stamp(timers.contact);

  // 5. positions, kinetic energy, the loads' work
  double k1 = 0.0, load_work = 0.0, mid_work = 0.0;
  for (std::size_t b = 0; b < nb; ++b) {
    if (model.blocks[b].fixed) continue;
    const double* v0 = &before[3 * b];
    const double mx = (1.0 - theta) * v0[0] + theta * r.vx[b];
    const double my = (1.0 - theta) * v0[1] + theta * r.vy[b];
    const double mw = (1.0 - theta) * v0[2] + theta * r.omega[b];
    r.ux[b] += h * mx;
    r.uy[b] += h * my;
    r.cx[b] = r.cx0[b] + r.ux[b];
    r.cy[b] = r.cy0[b] + r.uy[b];
    r.theta[b] += h * mw;
    const double m = r.mass[b];
    k1 += m * (r.vx[b] * r.vx[b] + r.vy[b] * r.vy[b]) + r.inertia[b] * r.omega[b] * r.omega[b];
    load_work += h * m * (ctx.body_ax * mx + ctx.body_ay * my);
    mid_work += 0.5 * h * m * (ctx.body_ax * (v0[0] + r.vx[b]) + ctx.body_ay * (v0[1] + r.vy[b]));
  }
  clock.stamp(timers.integrate);

  if (sim.step == 0) ledger.external_work += k0;  // the initial state's energy (advance())
  ledger.kinetic = 0.5 * k1;
  ledger.strain = 0.0;
  ledger.contact = 0.0;
  ledger.external_work += load_work + solved.support_work;
  ledger.impact_dissipated += solved.impact_dissipated;
  ledger.friction_dissipated += solved.friction_dissipated;
  ledger.damping_dissipated += load_work - mid_work;
  ledger.update_max();

  ctx.prev_body_ax = ctx.body_ax;
  ctx.prev_body_ay = ctx.body_ay;
  ctx.time += h;
  ++sim.step;
}

// The body kinds of the explicit scheme: how forces become motion. Elastic blocks: element
// forces on the nodes (CST + Munjiza damping at the half-step velocities), the nodes' loads and
// central difference. Rigid blocks: no element stage; a force and a moment on each body, the
// bodies' central difference (core/rigid.hpp).
struct ElasticBlocks {
  static void clear(Model& model) { clear_forces(model.nodes); }
  static ElementStageResult element_forces(Simulation& sim, const CstLaw& law) {
    if (law.eta > 0.0) {
      sim.viscous_piola.resize(4 * std::size_t(sim.model.tris.size()), 0.0);  // once
    } else {
      sim.viscous_piola.clear();
    }
    return add_element_forces(sim.model, law, law.eta > 0.0 ? sim.viscous_piola.data() : nullptr,
                              &sim.element_work);
  }
  static Vec2 body_loads(Model& model, double ax, double ay) {
    return add_body_loads(model, ax, ay);
  }
  static double integrate(Model& model, double dt) {
    return integrate_central_difference(model, dt);
  }
  static double integrate(Model& model, double dt, LocalDamping& damping) {
    return integrate_central_difference(model, dt, damping);
  }
};

struct RigidBlocks {
  static void clear(Model& model) { clear_rigid_forces(model.rigid); }
  static ElementStageResult element_forces(Simulation& sim, const CstLaw&) {
    sim.viscous_piola.clear();
    return ElementStageResult{};
  }
  static Vec2 body_loads(Model& model, double ax, double ay) {
    return add_rigid_body_loads(model, ax, ay);
  }
  static double integrate(Model& model, double dt) { return integrate_rigid_bodies(model, dt); }
  static double integrate(Model& model, double dt, LocalDamping& damping) {
    return integrate_rigid_bodies(model, dt, damping);
  }
};

// The explicit step of engine/step.hpp for the blocks of kind Blocks.
template <class Blocks>
void advance_explicit(Simulation& sim) {
  Model& model = sim.model;
  StepContext& ctx = sim.ctx;
  EnergyLedger& ledger = sim.ledger;
  StageTimers& timers = sim.timers;
  StageClock clock(timers.enabled);
  const bool first = sim.step == 0;

  // 1. broad phase, only when some node (rigid blocks: some outline point) moved more than the
  //    buffer allows
  if (ctx.contact_on && sim.contact.needs_detection(model)) sim.contact.detect(model);
  clock.stamp(timers.broad);

  // 2. clear forces (of the nodes, or of the rigid bodies)
  Blocks::clear(model);

  // 3. element forces (CST + Munjiza damping at the half-step velocities); none for rigid
  //    blocks
  const ElementStageResult el = Blocks::element_forces(sim, law_of(ctx));
  clock.stamp(timers.elements);

  // 4. contact forces (sets ledger.contact, accumulates friction dissipation)
  if (ctx.contact_on) {
    sim.contact.add_forces(model, ctx.dt, ledger, ctx.contact_energy);
  } else {
    ledger.contact = 0.0;
  }
  clock.stamp(timers.contact);

  // 5. body loads; the momentum before the update gives the exact external work
  const Vec2 momentum = Blocks::body_loads(model, ctx.body_ax, ctx.body_ay);
  clock.stamp(timers.loads);

  // 6. central difference: v then x (of the nodes, or of the rigid bodies)
  double kinetic = 0.0;
  if (ctx.local_damping > 0.0) {
    LocalDamping damping{ctx.local_damping, ctx.local_damping_outgoing,
                         &sim.local_damping_previous};
    kinetic = Blocks::integrate(model, ctx.dt, damping);
    ledger.local_dissipated += damping.dissipated;
  } else {
    kinetic = Blocks::integrate(model, ctx.dt);
  }
  if (ctx.kinetic_damping > 0.0) {
    KineticDamping kd{ctx.kinetic_damping, &sim.kinetic_peak};
    const double removed = apply_kinetic_damping(model, kinetic, ctx.dt, kd);
    if (kd.reset) ++sim.kinetic_resets;
    ledger.local_dissipated += removed;
    kinetic -= removed;
  }
  clock.stamp(timers.integrate);

  // 7. prescribed supports: their work over the step, then their pose at t^(n+1)
  if (!sim.supports.empty())
    ledger.external_work += move_supports(model, sim.supports, ctx.time + ctx.dt, ctx.dt);

  // Energy ledger.
  ledger.kinetic = kinetic;
  ledger.strain = el.strain_energy;
  // Work over the last position increment x^n - x^(n-1) = dt v^(n-1/2), by the trapezoid
  // 1/2 (f^n + f^(n-1)) that makes the leapfrog ledger exact (core/integrate.hpp):
  //   body load:  dt/2 (a^n + a^(n-1)) . sum m v^(n-1/2)                     (core/loads.hpp)
  //   damping:    -dt/2 (f_v^n + f_v^(n-1)) . v^(n-1/2)
  //             =  dt/2 (sum V0 J eta D:D + sum V0 P_v^(n-1) : Fdot(v^(n-1/2)))
  // (the second sum uses the viscous stress kept from the previous step; dt is taken constant
  // from step to step, as the drivers use it). At the first step
  // there is no such increment and the initial state's energy is booked as input instead.
  if (first) {
    ledger.external_work += ledger.stored();
  } else {
    ledger.external_work += 0.5 * ctx.dt *
                            ((ctx.body_ax + ctx.prev_body_ax) * momentum.x +
                             (ctx.body_ay + ctx.prev_body_ay) * momentum.y);
    ledger.damping_dissipated += 0.5 * ctx.dt * (el.damping_power + el.previous_damping_power);
  }
  ledger.update_max();

  ctx.prev_body_ax = ctx.body_ax;
  ctx.prev_body_ay = ctx.body_ay;
  ctx.time += ctx.dt;
  ++sim.step;
}

}  // namespace

StepScheme choose_step_scheme(const Model& model, bool nscd) {
  if (!model.is_rigid()) return StepScheme::ElasticExplicit;
  return nscd ? StepScheme::RigidNscd : StepScheme::RigidExplicit;
}

void advance(Simulation& sim) {
  using StepFunction = void (*)(Simulation&);
  static constexpr StepFunction kSteps[] = {
      advance_explicit<ElasticBlocks>,  // StepScheme::ElasticExplicit
      advance_explicit<RigidBlocks>,    // StepScheme::RigidExplicit
      advance_nscd,                     // StepScheme::RigidNscd
  };
  kSteps[static_cast<int>(sim.scheme)](sim);
}

}  // namespace voussoir

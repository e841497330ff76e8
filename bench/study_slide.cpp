// Study program (not a benchmark): one capacity-style trial of a deck at a given
// lambda -- settle under gravity, ramp lambda g over 0.1 s, the trial's stop rules reported
// but not stopping the run -- with a time series on stdout: kinetic energy, largest node speed,
// largest block motion, the ledger's external work and friction / local / impact dissipation,
// and for chosen joints the slip, the openings at both ends and the joint resultants N, V and
// |V| / (mu N) (engine/thrust.hpp). At the end: block motions, every joint's state and, with
// --avg-from, time averages of the joint resultants and of each free block's residual
// (joint forces + weight + lambda weight: zero for a block in static equilibrium; in a steady
// creep it is the mean force that something else -- the local damping -- supplies).
// Written to diagnose the sliding semicircular arch at beta = 120, mu = 0.6 (rigid against
// elastic blocks, physical against quasi-static trials). Each sample also gives the
// unbalanced-force ratio R (after "R=": the largest out-of-balance load of a free block over
// its weight, below), the block it is largest on, and the steps since the last sample that
// ended with the kinetic damping's peak cleared ("resets="): the study of an unbalanced-force
// rest rule, docs/capacity.md "The step of the quasi-static phases", its last paragraph.
//
//   build/study_slide DECK LAMBDA [--set KEY=VALUE ...] [--end T] [--every T]
//       [--qs-settle A] [--qs-trial A] [--mode outgoing|full] [--qs-off T] [--kd-off T]
//       [--avg-from T] [--joint J ...]
// --qs-settle A / --qs-trial A: Cundall local damping coefficient of the settle / of the trial
// (0, the default: physical); --qs-off T: the trial's local damping switched off at trial time
// T; --kd-off T: its kinetic damping switched off at trial time T; --end: trial length [s]
// (default 1.5); --every: sampling period [s] (default 0.01); --joint: joints to print (default:
// the two springings). With --qs-settle, the kinetic damping of the deck's capacity.kinetic_damping
// acts in the settle and the trial as in `capacity` (--set capacity.kinetic_damping=0: the local
// damping alone), and the rest rule refuses a creep as there.

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "commands/capacity.hpp"
#include "engine/kinematics.hpp"
#include "engine/thrust.hpp"
#include "engine/trial.hpp"
#include "io/deck.hpp"

using namespace voussoir;

namespace {

// How far the free blocks are from static equilibrium: per rigid block, its resultant force
// and its moment over its radius of gyration, each against the block's weight (the nodes'
// lumped masses: the true weight, whatever the quasi-static mass scaling did to the body);
// per free node of elastic blocks, its force against its weight. The forces are those of the
// last step (contact, elements and body loads; the local damping is added inside the update
// and is not in them): zero in equilibrium.
struct Unbalance {
  double ratio = 0.0;                // the largest of the two ratios over the blocks (nodes)
  std::size_t where = 0;             // the block (rigid) or node (elastic) where it is largest
  double force = 0.0, moment = 0.0;  // its two ratios there (rigid)
};

Unbalance unbalanced_force_ratio(const Model& m, double g) {
  const Nodes& n = m.nodes;
  Unbalance u;
  if (!m.is_rigid()) {
    for (Index i = 0; i < n.size(); ++i) {
      if (n.inv_mass[i] == 0.0) continue;
      const double r = std::hypot(n.fx[i], n.fy[i]) / (n.mass[i] * g);
      if (r > u.ratio) u.ratio = u.force = r, u.where = std::size_t(i);
    }
    return u;
  }
  for (std::size_t b = 0; b < m.blocks.size(); ++b) {
    const Block& blk = m.blocks[b];
    if (blk.fixed || !(m.rigid.mass[b] > 0.0)) continue;
    double fx = 0.0, fy = 0.0, torque = 0.0, mass = 0.0;
    for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i) {
      fx += n.fx[i];
      fy += n.fy[i];
      torque += (n.x[i] - m.rigid.cx[b]) * n.fy[i] - (n.y[i] - m.rigid.cy[b]) * n.fx[i];
      mass += n.mass[i];
    }
    const double gyration = std::sqrt(m.rigid.inertia[b] / m.rigid.mass[b]);
    const double force = std::hypot(fx, fy) / (mass * g);
    const double moment = std::abs(torque) / (gyration * mass * g);
    if (std::max(force, moment) > u.ratio) u = {std::max(force, moment), b, force, moment};
  }
  return u;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: study_slide DECK LAMBDA [options]\n");
    return 2;
  }
  const std::string deck = argv[1];
  const double lambda = std::atof(argv[2]);
  double qs_settle = 0.0, qs_trial = 0.0, end = 1.5, every = 0.01, qs_off = 1e30, avg_from = 1e30,
         kd_off = 1e30;
  std::string mode = "outgoing";
  std::vector<std::string> sets;
  std::vector<int> show_joints;
  for (int i = 3; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--qs-settle") qs_settle = std::atof(argv[++i]);
    else if (a == "--qs-trial") qs_trial = std::atof(argv[++i]);
    else if (a == "--end") end = std::atof(argv[++i]);
    else if (a == "--every") every = std::atof(argv[++i]);
    else if (a == "--mode") mode = argv[++i];
    else if (a == "--qs-off") qs_off = std::atof(argv[++i]);
    else if (a == "--avg-from") avg_from = std::atof(argv[++i]);
    else if (a == "--kd-off") kd_off = std::atof(argv[++i]);
    else if (a == "--set") sets.push_back(argv[++i]);
    else if (a == "--joint") show_joints.push_back(std::atoi(argv[++i]));
    else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }
  Config config = load_deck(deck, sets);
  const double mu = config.contact.friction;
  TrialCriteria crit;
  crit.quasi_static = qs_settle > 0.0;
  config.capacity.local_damping = qs_settle > 0.0 ? qs_settle : config.capacity.local_damping;
  config.capacity.local_damping_mode = mode;
  SettledState s = settle(config, crit, true);
  std::printf("# settled=%d time=%.4f dt=%.4g l_ref=%.4f steps=%lld\n", int(s.settled),
              s.settle_time, s.sim.ctx.dt, s.l_ref, s.steps);
  Simulation sim = s.sim;
  sim.ctx.local_damping = qs_trial;
  sim.ctx.local_damping_outgoing = mode == "outgoing";
  const Model& m = sim.model;
  if (show_joints.empty()) show_joints = {0, int(m.joints.size()) - 1};
  const std::vector<BlockMotion> base = block_motions(sim.model);

  const double g = s.gravity;
  const double v_rest = crit.rest_speed * std::sqrt(g * s.l_ref);
  const double d_collapse = crit.collapse_displacement * s.l_ref;
  RunSpec spec;
  spec.label = "study";
  spec.loads = LoadProgram{};
  spec.loads->gravity = g;
  spec.loads->lambda = lambda;
  spec.loads->lambda_ramp = crit.ramp_time;
  spec.loads->start = sim.ctx.time;
  spec.track_motion = true;
  spec.limits.drift_limit = 0.5;
  spec.rules.push_back(std::make_unique<CollapseRule>(d_collapse, crit.collapse_rotation));
  {
    // As capacity's quasi-static trials: the rest rule refuses a creep.
    auto rest = std::make_unique<RestRule>(v_rest, crit.hold_time, crit.ramp_time);
    if (qs_trial > 0.0) rest->refuse_creep(d_collapse, crit.collapse_rotation, kCreepTolerance);
    spec.rules.push_back(std::move(rest));
  }
  spec.rules.push_back(std::make_unique<TrendRule>(d_collapse, crit.collapse_rotation, 0.0,
                                                   crit.ramp_time, crit.max_time));
  spec.min_time = end;
  spec.end_time = end;
  spec.sample_at_start = true;
  if (every < kSampleTime) spec.sample_every = every;
  double next = 0.0;
  std::printf("# lambda=%g mu=%g d_collapse=%.4g v_rest=%.4g joints=%zu blocks=%zu\n", lambda,
              mu, d_collapse, v_rest, m.joints.size(), m.blocks.size());
  std::printf("# t  KE  speed  maxdisp  maxrot  | per joint: slip  open_a  open_b  N  V  V/(muN)\n");
  long avg_n = 0;
  // Steps that end with the kinetic damping's peak cleared: the step of a reset and the one
  // after it (its kinetic energy is 0).
  long resets = 0;
  std::vector<double> res_x(m.blocks.size(), 0.0), res_y(m.blocks.size(), 0.0);
  std::vector<double> jn(m.joints.size(), 0.0), jv(m.joints.size(), 0.0);
  spec.on_sample = [&](const Simulation& S, const Probe& p) {
    if (p.time < next - 0.5 * S.ctx.dt) return true;
    next += every;
    const auto mot = block_motions(S.model);
    const auto js = joint_states(S.model, mot);
    // motions relative to the settled state
    std::vector<BlockMotion> rel = mot;
    for (std::size_t b = 0; b < rel.size(); ++b) {
      rel[b].ux -= base[b].ux, rel[b].uy -= base[b].uy, rel[b].rotation -= base[b].rotation;
    }
    const auto jr = joint_resultants(S.model, S.contact, S.ctx.dt);
    if (p.time >= avg_from) {
      ++avg_n;
      for (std::size_t j = 0; j < jr.size(); ++j) {
        const std::size_t a = std::size_t(jr[j].block_a), b = std::size_t(jr[j].block_b);
        res_x[b] += jr[j].force.x, res_y[b] += jr[j].force.y;
        res_x[a] -= jr[j].force.x, res_y[a] -= jr[j].force.y;
        jn[j] += jr[j].normal_force, jv[j] += jr[j].shear_force;
      }
    }
    const Unbalance unbalance = unbalanced_force_ratio(S.model, g);
    std::printf("%.4f %.3e R=%.3e %.3e %.4e %.4e W=%.4e Df=%.4e Dl=%.4e Di=%.4e |", p.time,
                S.ledger.kinetic, unbalance.ratio, p.speed, p.motion.displacement,
                p.motion.rotation, S.ledger.external_work, S.ledger.friction_dissipated,
                S.ledger.local_dissipated, S.ledger.impact_dissipated);
    for (int j : show_joints) {
      const JointState& st = js[std::size_t(j)];
      const JointResultant& r = jr[std::size_t(j)];
      std::printf(" j%d %.4e %.3e %.3e %.5e %.5e %.4f |", j, st.slip, st.opening_a, st.opening_b,
                  r.normal_force, r.shear_force,
                  r.normal_force > 0 ? std::abs(r.shear_force) / (mu * r.normal_force) : 0.0);
    }
    std::printf(" worst %s %zu F/W=%.3e M/(W rg)=%.3e", S.model.is_rigid() ? "block" : "node",
                unbalance.where, unbalance.force, unbalance.moment);
    std::printf(" resets=%ld\n", resets);
    resets = 0;
    std::fflush(stdout);
    return true;
  };
  spec.on_step = [&](const Simulation& S, const StepInfo&) {
    if (S.ctx.kinetic_damping > 0.0 && S.kinetic_peak == 0.0) ++resets;
    if (S.ctx.time - spec.loads->start >= kd_off && S.ctx.kinetic_damping > 0.0) {
      const_cast<Simulation&>(S).ctx.kinetic_damping = 0.0;  // study: kinetic damping off
      std::printf("# kinetic damping switched off at %.4f\n", S.ctx.time - spec.loads->start);
    }
    if (S.ctx.time - spec.loads->start >= qs_off && S.ctx.local_damping > 0.0) {
      const_cast<Simulation&>(S).ctx.local_damping = 0.0;  // study: damping off from qs_off on
      std::printf("# local damping switched off at %.4f\n", S.ctx.time - spec.loads->start);
    }
  };
  Outcome o = run_engine(sim, spec);
  std::printf("# verdict decided=%d collapsed=%d reason=%s at %.4f s; end motion %.4e m %.4e rad\n",
              int(o.decided), int(o.collapsed), o.reason.c_str(), o.decided_at,
              o.motion.displacement, o.motion.rotation);
  // Final block motions
  const auto mot = block_motions(sim.model);
  for (std::size_t b = 0; b < mot.size(); ++b)
    std::printf("# block %zu fixed=%d ux=%.4e uy=%.4e rot=%.4e\n", b, int(m.blocks[b].fixed),
                mot[b].ux - base[b].ux, mot[b].uy - base[b].uy, mot[b].rotation - base[b].rotation);
  const auto js = joint_states(sim.model, mot);
  const auto jr = joint_resultants(sim.model, sim.contact, sim.ctx.dt);
  for (std::size_t j = 0; j < js.size(); ++j)
    std::printf("# joint %zu blocks %d-%d slip=%.4e open_a=%.3e open_b=%.3e rot=%.4e N=%.5e V=%.5e V/muN=%.4f e=%.3f\n", j,
                int(m.joints[j].block_a), int(m.joints[j].block_b), js[j].slip, js[j].opening_a,
                js[j].opening_b, js[j].rotation, jr[j].normal_force, jr[j].shear_force,
                jr[j].normal_force > 0 ? std::abs(jr[j].shear_force) / (mu * jr[j].normal_force) : 0.0,
                jr[j].eccentricity);
  if (avg_n > 0) {
    std::printf("# time averages over %ld samples from %.3f s: per free block the mean of "
                "(joint forces + weight + lambda weight), against the weight\n", avg_n, avg_from);
    for (std::size_t b = 0; b < m.blocks.size(); ++b) {
      if (m.blocks[b].fixed) continue;
      double mass = 0.0;
      for (Index i = m.blocks[b].first_node; i < m.blocks[b].first_node + m.blocks[b].node_count; ++i)
        mass += m.nodes.mass[i];
      const double rx = res_x[b] / avg_n + mass * g * lambda, ry = res_y[b] / avg_n - mass * g;
      std::printf("# avg block %zu weight=%.1f residual=(%.2f, %.2f) |r|/W=%.4f\n", b, mass * g, rx, ry,
                  std::hypot(rx, ry) / (mass * g));
    }
    for (std::size_t j = 0; j < m.joints.size(); ++j)
      std::printf("# avg joint %zu N=%.1f V=%.1f |V|/(mu N)=%.4f\n", j, jn[j] / avg_n, jv[j] / avg_n,
                  std::abs(jv[j]) / (mu * jn[j]));
  }
  return 0;
}

// Prescribed movement of fixed blocks (math in core/supports.hpp).

#include "core/supports.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace voussoir {

namespace {

constexpr double kTwoPi = 6.283185307179586;

// Pose of a move at ramp fraction s: centroid displacement and rotation.
struct Pose {
  double ux, uy, theta;
};

Pose pose_of(const SupportMove& from, const SupportMove& to, double s) {
  return {from.dx + s * (to.dx - from.dx), from.dy + s * (to.dy - from.dy),
          from.rotation + s * (to.rotation - from.rotation)};
}

}  // namespace

double support_ramp(double tau) {
  const double t = std::clamp(tau, 0.0, 1.0);
  return t - std::sin(kTwoPi * t) / kTwoPi;
}

void prescribe_supports(Model& model, const std::vector<SupportMove>& moves,
                        SupportMotion& motion) {
  motion = SupportMotion{};
  for (const SupportMove& m : moves) {
    if (m.block < 0 || m.block >= static_cast<Index>(model.blocks.size()))
      throw std::invalid_argument("block " + std::to_string(m.block) + " does not exist (the " +
                                  "model has blocks 0 to " +
                                  std::to_string(model.blocks.size() - 1) + ")");
    Block& blk = model.blocks[std::size_t(m.block)];
    if (!blk.fixed)
      throw std::invalid_argument("block " + std::to_string(m.block) + " (" + blk.role +
                                  ") is free: only a fixed block can be moved");
    blk.prescribed = true;
    const Nodes& n = model.nodes;
    double mass = 0.0, mx = 0.0, my = 0.0;
    for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i) {
      mass += n.mass[i];
      mx += n.mass[i] * n.x0[i];
      my += n.mass[i] * n.y0[i];
    }
    motion.centroid.push_back(mass > 0.0 ? Vec2{mx / mass, my / mass} : Vec2{});
    motion.moves.push_back(m);
  }
}

void start_support_motion(SupportMotion& motion, double time, double ramp) {
  motion.from.resize(motion.moves.size(), SupportMove{});
  for (std::size_t k = 0; k < motion.moves.size(); ++k)
    motion.from[k].block = motion.moves[k].block;
  motion.started = true;
  motion.start = time;
  motion.ramp = ramp;
}

void retarget_support_motion(SupportMotion& motion, const std::vector<SupportMove>& targets,
                             double time, double ramp) {
  if (targets.size() != motion.moves.size())
    throw std::invalid_argument("retarget_support_motion: the moved blocks differ");
  const bool was = motion.started;
  const std::vector<SupportMove> reached = motion.moves;
  start_support_motion(motion, time, ramp);
  if (was) motion.from = reached;
  motion.moves = targets;
}

double move_supports(Model& model, SupportMotion& motion, double time_next, double dt) {
  if (!motion.started || motion.empty()) return 0.0;
  const double s = support_ramp((time_next - motion.start) / motion.ramp);
  const double inv_dt = 1.0 / dt;
  double work = 0.0;  // of the contact forces on the supports over the last increment
  if (model.is_rigid()) {
    RigidBodies& r = model.rigid;
    motion.previous_force.resize(3 * motion.moves.size(), 0.0);
    for (std::size_t k = 0; k < motion.moves.size(); ++k) {
      const Index b = motion.moves[k].block;
      double* prev = &motion.previous_force[3 * k];
      work += (r.fx[b] + prev[0]) * r.vx[b] + (r.fy[b] + prev[1]) * r.vy[b] +
              (r.torque[b] + prev[2]) * r.omega[b];
      prev[0] = r.fx[b], prev[1] = r.fy[b], prev[2] = r.torque[b];
      const Pose p = pose_of(motion.from[k], motion.moves[k], s);
      r.vx[b] = (p.ux - r.ux[b]) * inv_dt;
      r.vy[b] = (p.uy - r.uy[b]) * inv_dt;
      r.omega[b] = (p.theta - r.theta[b]) * inv_dt;
      r.ux[b] = p.ux, r.uy[b] = p.uy, r.theta[b] = p.theta;
      r.cx[b] = r.cx0[b] + p.ux;
      r.cy[b] = r.cy0[b] + p.uy;
    }
    return -0.5 * dt * work;
  }
  Nodes& n = model.nodes;
  std::size_t slot = 0;
  for (std::size_t k = 0; k < motion.moves.size(); ++k) {
    const Block& blk = model.blocks[std::size_t(motion.moves[k].block)];
    motion.previous_force.resize(
        std::max(motion.previous_force.size(), slot + 2 * std::size_t(blk.node_count)), 0.0);
    const Pose p = pose_of(motion.from[k], motion.moves[k], s);
    const Vec2 c0 = motion.centroid[k];
    const double cs = std::cos(p.theta), sn = std::sin(p.theta);
    for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i, slot += 2) {
      double* prev = &motion.previous_force[slot];
      work += (n.fx[i] + prev[0]) * n.vx[i] + (n.fy[i] + prev[1]) * n.vy[i];
      prev[0] = n.fx[i], prev[1] = n.fy[i];
      const double rx = n.x0[i] - c0.x, ry = n.y0[i] - c0.y;
      const double x = c0.x + p.ux + cs * rx - sn * ry, y = c0.y + p.uy + sn * rx + cs * ry;
      n.vx[i] = (x - n.x[i]) * inv_dt;
      n.vy[i] = (y - n.y[i]) * inv_dt;
      n.x[i] = x, n.y[i] = y;
    }
  }
  return -0.5 * dt * work;
}

}  // namespace voussoir

// Rigid-block stage (math in core/rigid.hpp).

#include "core/rigid.hpp"

#include <algorithm>
#include <cmath>

#include "core/integrate.hpp"

namespace voussoir {

double triangle_polar_inertia(double rho_a, const Vec2& p0, const Vec2& p1, const Vec2& p2,
                              const Vec2& o) {
  const double ax = p0.x - o.x, ay = p0.y - o.y;
  const double bx = p1.x - o.x, by = p1.y - o.y;
  const double cx = p2.x - o.x, cy = p2.y - o.y;
  const double area = 0.5 * std::abs((bx - ax) * (cy - ay) - (by - ay) * (cx - ax));
  const double sum = ax * ax + ay * ay + bx * bx + by * by + cx * cx + cy * cy +
                     (ax * bx + ay * by) + (bx * cx + by * cy) + (cx * ax + cy * ay);
  return rho_a * area / 6.0 * sum;
}

void make_blocks_rigid(Model& model) {
  const Nodes& n = model.nodes;
  const Triangles& t = model.tris;
  RigidBodies& r = model.rigid;
  const std::size_t nb = model.blocks.size();
  for (auto* v : {&r.cx, &r.cy, &r.ux, &r.uy, &r.theta, &r.vx, &r.vy, &r.omega, &r.fx, &r.fy,
                  &r.torque, &r.cx0, &r.cy0, &r.mass, &r.inertia, &r.load_mass})
    v->assign(nb, 0.0);
  r.rx.assign(n.x.size(), 0.0);
  r.ry.assign(n.x.size(), 0.0);
  const double rho_a = model.material.density * model.out_of_plane;
  for (std::size_t b = 0; b < nb; ++b) {
    const Block& blk = model.blocks[b];
    // Centroid of the lumped node masses (= the area centroid of the triangles).
    double m = 0.0, mx = 0.0, my = 0.0;
    for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i) {
      m += n.mass[i];
      mx += n.mass[i] * n.x0[i];
      my += n.mass[i] * n.y0[i];
    }
    if (!(m > 0.0)) continue;
    const Vec2 c{mx / m, my / m};
    double inertia = 0.0;
    for (Index e = blk.first_tri; e < blk.first_tri + blk.tri_count; ++e) {
      const Vec2 p0{n.x0[t.n0[e]], n.y0[t.n0[e]]};
      const Vec2 p1{n.x0[t.n1[e]], n.y0[t.n1[e]]};
      const Vec2 p2{n.x0[t.n2[e]], n.y0[t.n2[e]]};
      inertia += triangle_polar_inertia(rho_a, p0, p1, p2, c);
    }
    r.cx[b] = r.cx0[b] = c.x;
    r.cy[b] = r.cy0[b] = c.y;
    r.mass[b] = r.load_mass[b] = m;
    r.inertia[b] = inertia;
    for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i) {
      r.rx[i] = n.x0[i] - c.x;
      r.ry[i] = n.y0[i] - c.y;
    }
  }
}

void set_rigid_state(Model& model, Index b, double cx, double cy, double theta, double vx,
                     double vy, double omega) {
  RigidBodies& r = model.rigid;
  Nodes& n = model.nodes;
  const Block& blk = model.blocks[std::size_t(b)];
  r.cx[b] = cx, r.cy[b] = cy, r.theta[b] = theta;
  r.ux[b] = cx - r.cx0[b], r.uy[b] = cy - r.cy0[b];
  r.vx[b] = vx, r.vy[b] = vy, r.omega[b] = omega;
  const double cs = std::cos(theta), sn = std::sin(theta);
  for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i) {
    const double ox = cs * r.rx[i] - sn * r.ry[i], oy = sn * r.rx[i] + cs * r.ry[i];
    n.x[i] = cx + ox;
    n.y[i] = cy + oy;
    n.vx[i] = vx - omega * oy;
    n.vy[i] = vy + omega * ox;
  }
}

namespace {

// The body update of integrate_rigid_bodies; `damping` (3 per body: x, y, rotation) when the
// local damping is on (core/integrate.hpp LocalDamping), books its work into `dissipated`.
double update_rigid_bodies(Model& model, double dt, double alpha, bool outgoing, double* previous,
                           double& dissipated) {
  RigidBodies& r = model.rigid;
  double twice_kinetic = 0.0;
  const Index nb = static_cast<Index>(model.blocks.size());
  for (Index b = 0; b < nb; ++b) {
    if (model.blocks[b].fixed || !(r.mass[b] > 0.0)) continue;
    double fx = r.fx[b], fy = r.fy[b], torque = r.torque[b];
    if (previous) {
      double* d_prev = previous + 3 * b;
      const double dx = local_damping_force(alpha, outgoing, fx, r.vx[b]);
      const double dy = local_damping_force(alpha, outgoing, fy, r.vy[b]);
      const double dr = local_damping_force(alpha, outgoing, torque, r.omega[b]);
      dissipated -= 0.5 * dt *
                    ((dx + d_prev[0]) * r.vx[b] + (dy + d_prev[1]) * r.vy[b] +
                     (dr + d_prev[2]) * r.omega[b]);
      d_prev[0] = dx, d_prev[1] = dy, d_prev[2] = dr;
      fx += dx, fy += dy, torque += dr;
    }
    const double ux = r.vx[b] + dt * fx / r.mass[b];
    const double uy = r.vy[b] + dt * fy / r.mass[b];
    const double w = r.omega[b] + dt * torque / r.inertia[b];
    twice_kinetic += r.mass[b] * (r.vx[b] * ux + r.vy[b] * uy) + r.inertia[b] * r.omega[b] * w;
    r.vx[b] = ux;
    r.vy[b] = uy;
    r.omega[b] = w;
    r.ux[b] += dt * ux;
    r.uy[b] += dt * uy;
    r.cx[b] = r.cx0[b] + r.ux[b];
    r.cy[b] = r.cy0[b] + r.uy[b];
    r.theta[b] += dt * w;
  }
  return 0.5 * twice_kinetic;
}

}  // namespace

void clear_rigid_forces(RigidBodies& r) {
  std::fill(r.fx.begin(), r.fx.end(), 0.0);
  std::fill(r.fy.begin(), r.fy.end(), 0.0);
  std::fill(r.torque.begin(), r.torque.end(), 0.0);
}

Vec2 add_rigid_body_loads(Model& model, double ax, double ay) {
  RigidBodies& r = model.rigid;
  double px = 0.0, py = 0.0;
  const std::size_t nb = model.blocks.size();
  for (std::size_t b = 0; b < nb; ++b) {
    if (model.blocks[b].fixed) continue;
    const double m = r.load_mass[b];
    r.fx[b] += m * ax;
    r.fy[b] += m * ay;
    px += m * r.vx[b];
    py += m * r.vy[b];
  }
  return {px, py};
}

void sync_rigid_nodes(Model& model) {
  if (!model.is_rigid()) return;
  Nodes& n = model.nodes;
  const RigidBodies& r = model.rigid;
  for (std::size_t b = 0; b < model.blocks.size(); ++b) {
    const Block& blk = model.blocks[b];
    if ((blk.fixed && !blk.prescribed) || !(r.mass[b] > 0.0)) continue;  // supports that move
    const double cs = std::cos(r.theta[b]), sn = std::sin(r.theta[b]);
    for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i) {
      const double ox = cs * r.rx[i] - sn * r.ry[i], oy = sn * r.rx[i] + cs * r.ry[i];
      n.x[i] = r.cx[b] + ox;
      n.y[i] = r.cy[b] + oy;
      n.vx[i] = r.vx[b] - r.omega[b] * oy;
      n.vy[i] = r.vy[b] + r.omega[b] * ox;
      n.fx[i] = n.fy[i] = 0.0;
    }
  }
}

void reset_rigid_step(Model& model, double dt) {
  RigidBodies& r = model.rigid;
  for (std::size_t b = 0; b < model.blocks.size(); ++b) {
    if (model.blocks[b].fixed || !(r.mass[b] > 0.0)) continue;
    r.ux[b] -= dt * r.vx[b];
    r.uy[b] -= dt * r.vy[b];
    r.cx[b] = r.cx0[b] + r.ux[b];
    r.cy[b] = r.cy0[b] + r.uy[b];
    r.theta[b] -= dt * r.omega[b];
    r.vx[b] = r.vy[b] = r.omega[b] = 0.0;
  }
}

double integrate_rigid_bodies(Model& model, double dt) {
  double unused = 0.0;
  return update_rigid_bodies(model, dt, 0.0, false, nullptr, unused);
}

double integrate_rigid_bodies(Model& model, double dt, LocalDamping& damping) {
  damping.previous->resize(3 * model.blocks.size(), 0.0);
  damping.dissipated = 0.0;
  return update_rigid_bodies(model, dt, damping.alpha, damping.outgoing,
                             damping.previous->data(), damping.dissipated);
}

}  // namespace voussoir

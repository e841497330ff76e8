#include "engine/kinematics.hpp"

#include <algorithm>
#include <cmath>

namespace voussoir {

double block_centroid_x(const Model& m, int b) {
  if (m.is_rigid()) return m.rigid.cx0[b] + m.rigid.ux[b];
  const Block& blk = m.blocks[b];
  double mx = 0.0, mass = 0.0;
  for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i) {
    mx += m.nodes.mass[i] * m.nodes.x[i];
    mass += m.nodes.mass[i];
  }
  return mx / mass;
}

double free_mass_moment_x(const Model& m) {
  double s = 0.0;
  if (m.is_rigid()) {
    const RigidBodies& r = m.rigid;
    for (std::size_t b = 0; b < m.blocks.size(); ++b)
      if (!m.blocks[b].fixed) s += r.load_mass[b] * (r.cx0[b] + r.ux[b]);
    return s;
  }
  for (Index i = 0; i < m.nodes.size(); ++i)
    if (m.nodes.inv_mass[i] != 0.0) s += m.nodes.mass[i] * m.nodes.x[i];
  return s;
}

std::vector<BlockMotion> block_motions(const Model& model) {
  const Nodes& n = model.nodes;
  std::vector<BlockMotion> out(model.blocks.size());
  for (size_t b = 0; b < model.blocks.size(); ++b) {
    const Block& blk = model.blocks[b];
    double m = 0.0, cx0 = 0.0, cy0 = 0.0, cx = 0.0, cy = 0.0;
    for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i) {
      m += n.mass[i];
      cx0 += n.mass[i] * n.x0[i];
      cy0 += n.mass[i] * n.y0[i];
      cx += n.mass[i] * n.x[i];
      cy += n.mass[i] * n.y[i];
    }
    BlockMotion& bm = out[b];
    if (m <= 0.0) continue;
    cx0 /= m, cy0 /= m, cx /= m, cy /= m;
    double cross = 0.0, dot = 0.0;
    for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i) {
      const double rx0 = n.x0[i] - cx0, ry0 = n.y0[i] - cy0;
      const double rx = n.x[i] - cx, ry = n.y[i] - cy;
      cross += n.mass[i] * (rx0 * ry - ry0 * rx);
      dot += n.mass[i] * (rx0 * rx + ry0 * ry);
    }
    bm.cx0 = cx0;
    bm.cy0 = cy0;
    bm.ux = cx - cx0;
    bm.uy = cy - cy0;
    bm.rotation = std::atan2(cross, dot);
  }
  return out;
}

Vec2 move_point(const BlockMotion& m, Vec2 p) {
  const double c = std::cos(m.rotation), s = std::sin(m.rotation);
  const double rx = p.x - m.cx0, ry = p.y - m.cy0;
  return {m.cx0 + m.ux + c * rx - s * ry, m.cy0 + m.uy + s * rx + c * ry};
}

std::vector<JointState> joint_states(const Model& model, const std::vector<BlockMotion>& motions) {
  std::vector<JointState> out;
  out.reserve(model.joints.size());
  for (size_t j = 0; j < model.joints.size(); ++j) {
    const Joint& jt = model.joints[j];
    const BlockMotion &ma = motions[jt.block_a], &mb = motions[jt.block_b];
    // Joint frame: tangent t from a to b, normal n; the gap is measured along n between the
    // images of the same reference point carried by either block (sign-free: magnitude of the
    // normal separation, positive).
    const double lx = jt.b.x - jt.a.x, ly = jt.b.y - jt.a.y;
    const double len = std::hypot(lx, ly);
    const double tx = lx / len, ty = ly / len, nx = -ty, ny = tx;
    auto separation = [&](Vec2 p) {
      const Vec2 pa = move_point(ma, p), pb = move_point(mb, p);
      return Vec2{pb.x - pa.x, pb.y - pa.y};
    };
    const Vec2 da = separation(jt.a), db = separation(jt.b);
    const Vec2 mid{0.5 * (jt.a.x + jt.b.x), 0.5 * (jt.a.y + jt.b.y)};
    const Vec2 dm = separation(mid);
    JointState s;
    s.joint = static_cast<int>(j);
    // Penetration is prevented by contact, so |normal separation| is the opening.
    s.opening_a = std::abs(da.x * nx + da.y * ny);
    s.opening_b = std::abs(db.x * nx + db.y * ny);
    s.slip = std::abs(dm.x * tx + dm.y * ty);
    s.rotation = mb.rotation - ma.rotation;
    out.push_back(s);
  }
  return out;
}

std::vector<Hinge> find_hinges(const Model& model, double open_tol, double slip_tol) {
  const auto motions = block_motions(model);
  const auto states = joint_states(model, motions);
  // Joints of one mechanism open at different rates (the springing hinge of an arch opens
  // less than the crown one): a joint counts when its gap reaches `open_tol` or a quarter of
  // the largest gap of the model, whichever is smaller, but never below open_tol / 10.
  // A joint between two fixed blocks is no hinge: it moves only as [supports] prescribe (a
  // settled pier sinks into its ground), and carries no contact.
  auto between_supports = [&model](const JointState& s) {
    const Joint& jt = model.joints[std::size_t(s.joint)];
    return model.blocks[std::size_t(jt.block_a)].fixed &&
           model.blocks[std::size_t(jt.block_b)].fixed;
  };
  double largest = 0.0;
  for (const JointState& s : states)
    if (!between_supports(s)) largest = std::max({largest, s.opening_a, s.opening_b});
  open_tol = std::max(0.1 * open_tol, std::min(open_tol, 0.25 * largest));
  std::vector<Hinge> out;
  for (const JointState& s : states) {
    if (between_supports(s)) continue;
    const Joint& jt = model.joints[s.joint];
    const double opening = std::max(s.opening_a, s.opening_b);
    Hinge h;
    h.joint = s.joint;
    h.block_a = jt.block_a;
    h.block_b = jt.block_b;
    h.position_deg = jt.position_deg;
    h.opening = opening;
    h.slip = s.slip;
    if (opening > open_tol) {
      h.kind = "hinge";
      // The blocks keep touching at the less open end: that is the pivot.
      const bool pivot_a = s.opening_a < s.opening_b;
      h.side = pivot_a ? "intrados" : "extrados";
      h.x = pivot_a ? jt.a.x : jt.b.x;
      h.y = pivot_a ? jt.a.y : jt.b.y;
    } else if (s.slip > slip_tol) {
      h.kind = "sliding";
      h.x = 0.5 * (jt.a.x + jt.b.x);
      h.y = 0.5 * (jt.a.y + jt.b.y);
    } else {
      continue;
    }
    out.push_back(h);
  }
  return out;
}

}  // namespace voussoir

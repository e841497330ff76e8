// Joint stiffness mapping and impact damping (math in contact/joint_stiffness.hpp).

#include "contact/joint_stiffness.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "contact/friction.hpp"

namespace voussoir {

Vec2 reference_centroid(const Model& model, Index e) {
  const Nodes& n = model.nodes;
  const Triangles& t = model.tris;
  return {(n.x0[t.n0[e]] + n.x0[t.n1[e]] + n.x0[t.n2[e]]) / 3.0,
          (n.y0[t.n0[e]] + n.y0[t.n1[e]] + n.y0[t.n2[e]]) / 3.0};
}

FacingEdge facing_edge(const Model& model, Index e, const Vec2& toward) {
  const Nodes& n = model.nodes;
  const Triangles& t = model.tris;
  const Index v[3] = {t.n0[e], t.n1[e], t.n2[e]};
  const Vec2 g = reference_centroid(model, e);
  double dx = toward.x - g.x, dy = toward.y - g.y;
  const double dl = std::hypot(dx, dy);
  if (dl > 0.0) dx /= dl, dy /= dl;
  FacingEdge best;
  double best_dot = -std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    if (!(t.boundary[e] & (1u << k))) continue;
    const Index i0 = v[k], i1 = v[(k + 1) % 3];
    const double ex = n.x0[i1] - n.x0[i0], ey = n.y0[i1] - n.y0[i0];
    const double len = std::hypot(ex, ey);
    if (!(len > 0.0)) continue;
    const Vec2 normal{ey / len, -ex / len};  // outward for a counter-clockwise triangle
    const double dot = normal.x * dx + normal.y * dy;
    if (dot > best_dot) {
      best_dot = dot;
      best.length = len;
      best.height = 2.0 * t.area0[e] / len;
      best.normal = normal;
      best.mid = {0.5 * (n.x0[i0] + n.x0[i1]), 0.5 * (n.y0[i0] + n.y0[i1])};
    }
  }
  return best;
}

double extent_along(const std::vector<Vec2>& polygon, const Vec2& d) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Vec2& p : polygon) {
    const double s = p.x * d.x + p.y * d.y;
    lo = std::min(lo, s);
    hi = std::max(hi, s);
  }
  return polygon.empty() ? 0.0 : hi - lo;
}

double restitution_damping_ratio(double e) {
  if (!(e < 1.0)) return 0.0;
  if (!(e > 0.0)) return 1.0;
  const double l = std::log(e);
  return -l / std::sqrt(std::numbers::pi * std::numbers::pi + l * l);
}

PairJoint pair_joint(const Model& model, Index c, Index t, double kn_given, double young,
                     double penalty, double ks_given, double thickness) {
  PairJoint r;
  const FacingEdge fc = facing_edge(model, c, reference_centroid(model, t));
  const FacingEdge ft = facing_edge(model, t, reference_centroid(model, c));
  if (!(fc.length > 0.0) || !(ft.length > 0.0)) return r;
  const Block& bc = model.blocks[model.tris.block[c]];
  const Block& bt = model.blocks[model.tris.block[t]];
  const double g = 3.0 / fc.height + 3.0 / ft.height;  // [1/m]
  if (kn_given > 0.0) {
    r.kn = kn_given;
  } else if (young > 0.0) {
    const double lc = extent_along(bc.polygon, fc.normal);
    const double lt = extent_along(bt.polygon, fc.normal);
    double l = 0.5 * (lc + lt);
    if (bc.fixed != bt.fixed) l = bc.fixed ? lt : lc;
    r.kn = young / l;
  } else {
    r.kn = penalty * g;
  }
  r.ep = r.kn / g;
  const double ks = ks_given > 0.0 ? ks_given : kTangentialStiffnessRatio * r.kn;
  r.kt = ks * thickness * std::min(fc.length, ft.length);
  // Joint frequency: the lighter body on the shorter face.
  const Vec2 tangent{-fc.normal.y, fc.normal.x};
  const double face =
      std::min(extent_along(bc.polygon, tangent), extent_along(bt.polygon, tangent));
  double m_eff = 0.0;
  if (!bc.fixed && !bt.fixed)
    m_eff = bc.mass * bt.mass / (bc.mass + bt.mass);
  else
    m_eff = bc.fixed ? bt.mass : bc.mass;
  if (m_eff > 0.0) r.omega = std::sqrt(r.kn * thickness * face / m_eff);
  return r;
}

}  // namespace voussoir

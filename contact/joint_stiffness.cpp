// Joint stiffness mapping and impact damping (math in contact/joint_stiffness.hpp).

#include "contact/joint_stiffness.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "contact/friction.hpp"

namespace voussoir {

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

double no_tension_restitution(double zeta) {
  if (!(zeta > 0.0)) return 1.0;
  if (!(zeta < 1.0)) return std::exp(-2.0);  // critical: the force vanishes at w t = 2
  // x = (v0 / wd) exp(-zeta w t) sin(wd t): the force w^2 x + 2 zeta w x' vanishes at
  // phi = wd t_e with tan(phi) = -2 zeta s / (1 - 2 zeta^2), s = sqrt(1 - zeta^2), phi in
  // (0, pi); e = -x'(t_e) / v0.
  const double s = std::sqrt(1.0 - zeta * zeta);
  const double phi = std::numbers::pi - std::atan2(2.0 * zeta * s, 1.0 - 2.0 * zeta * zeta);
  return -std::exp(-zeta * phi / s) * (std::cos(phi) - zeta / s * std::sin(phi));
}

double no_tension_damping_ratio(double e) {
  if (!(e < 1.0)) return 0.0;
  if (!(e > std::exp(-2.0))) return 1.0;
  // no_tension_restitution falls from 1 at zeta = 0 to exp(-2) at 1: bisection.
  double lo = 0.0, hi = 1.0;
  for (int k = 0; k < 200 && hi - lo > 1e-15; ++k) {
    const double mid = 0.5 * (lo + hi);
    (no_tension_restitution(mid) > e ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

namespace {

// The boundary edges of triangle e in the reference configuration.
std::vector<std::pair<Vec2, Vec2>> boundary_edges(const Model& model, Index e) {
  const Nodes& n = model.nodes;
  const Triangles& t = model.tris;
  const Index v[3] = {t.n0[e], t.n1[e], t.n2[e]};
  std::vector<std::pair<Vec2, Vec2>> out;
  for (int k = 0; k < 3; ++k)
    if (t.boundary[e] & (1u << k))
      out.push_back({{n.x0[v[k]], n.y0[v[k]]}, {n.x0[v[(k + 1) % 3]], n.y0[v[(k + 1) % 3]]}});
  return out;
}

FacingEdge edge_of(const Model& model, Index e, const std::pair<Vec2, Vec2>& edge) {
  FacingEdge f;
  const double ex = edge.second.x - edge.first.x, ey = edge.second.y - edge.first.y;
  f.length = std::hypot(ex, ey);
  f.height = 2.0 * model.tris.area0[e] / f.length;
  f.normal = {ey / f.length, -ex / f.length};
  return f;
}

}  // namespace

// Facing edges of a pair: of the boundary edges of c and of t, the two that lie closest to
// each other (segment distance), the most nearly opposite normals breaking ties (a joint's two
// faces touch along their length with opposite normals; a face and the side that meets it at a
// corner touch only at that corner and are not opposite).
std::pair<FacingEdge, FacingEdge> facing_edges(const Model& model, Index c, Index t) {
  const auto ec = boundary_edges(model, c), et = boundary_edges(model, t);
  std::pair<FacingEdge, FacingEdge> best;
  double best_score = std::numeric_limits<double>::infinity();
  for (const auto& a : ec)
    for (const auto& b : et) {
      const FacingEdge fa = edge_of(model, c, a), fb = edge_of(model, t, b);
      if (!(fa.length > 0.0) || !(fb.length > 0.0)) continue;
      const double dist = std::min({distance_to_segment(a.first, b.first, b.second),
                                    distance_to_segment(a.second, b.first, b.second),
                                    distance_to_segment(b.first, a.first, a.second),
                                    distance_to_segment(b.second, a.first, a.second)});
      const double opposite = 1.0 + fa.normal.x * fb.normal.x + fa.normal.y * fb.normal.y;
      const double score = dist + 1e-3 * std::max(fa.length, fb.length) * opposite;
      if (score < best_score) best_score = score, best = {fa, fb};
    }
  return best;
}

double default_joint_stiffness(double young, const Block& a, const Block* b, const Vec2& normal) {
  const Vec2 tangent{-normal.y, normal.x};
  double length = extent_along(a.polygon, tangent);
  if (b != nullptr && !b->polygon.empty())
    length = std::min(length, extent_along(b->polygon, tangent));
  return kRigidJointFactor * young / length;
}

double joint_frequency(double kn_thickness, const Block& a, double mass_a, const Block* b,
                       double mass_b, const Vec2& tangent) {
  double face = extent_along(a.polygon, tangent);
  if (b != nullptr) face = std::min(face, extent_along(b->polygon, tangent));
  double m_eff = mass_a;
  if (b != nullptr && !b->fixed) m_eff = a.fixed ? mass_b : mass_a * mass_b / (mass_a + mass_b);
  return m_eff > 0.0 ? std::sqrt(kn_thickness * face / m_eff) : 0.0;
}

PairJoint pair_joint(const Model& model, Index c, Index t, double kn_given, double young,
                     double penalty, double ks_given, double thickness) {
  PairJoint r;
  const auto [fc, ft] = facing_edges(model, c, t);
  if (!(fc.length > 0.0) || !(ft.length > 0.0)) return r;
  const Block& bc = model.blocks[model.tris.block[c]];
  const Block& bt = model.blocks[model.tris.block[t]];
  const double g = 3.0 / fc.height + 3.0 / ft.height;  // [1/m]
  if (kn_given > 0.0) {
    r.kn = kn_given;
  } else if (young > 0.0) {
    r.kn = default_joint_stiffness(young, bc, &bt, fc.normal);
  } else {
    r.kn = penalty * g;
  }
  r.ep = r.kn / g;
  const double ks = ks_given > 0.0 ? ks_given : kTangentialStiffnessRatio * r.kn;
  r.kt = ks * thickness * std::min(fc.length, ft.length);
  r.omega =
      joint_frequency(r.kn * thickness, bc, bc.mass, &bt, bt.mass, Vec2{-fc.normal.y, fc.normal.x});
  return r;
}

}  // namespace voussoir

// Interfaces between blocks from their outlines (see interfaces.hpp for the contract).
//
// For blocks i < j whose bounding boxes meet (within tol), every edge e = p -> q of i is
// tested against every edge f = c -> d of j:
//   collinear:   |t x (c - p)| <= tol and |t x (d - p)| <= tol, t = (q - p) / |q - p|;
//   facing:      t . (d - c) < 0 (counter-clockwise outlines run against each other);
//   overlapping: [max(0, min(s_c, s_d)), min(|q - p|, max(s_c, s_d))] longer than tol,
//                s_c = t . (c - p), s_d = t . (d - p).
// The overlap pieces of one pair are grouped by line (both ends within tol of the group's
// line, same facing), sorted along it and merged where they touch (gap <= tol). The outward
// normal of a counter-clockwise outline along t is (t_y, -t_x): it points from i into j.
// Cost: O(E_i E_j) per pair of touching boxes, E the outline edge counts (a few hundred at
// most for a meshed support), negligible beside meshing.

#include "limit/interfaces.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace voussoir {

namespace {

double dot2(Vec2 a, Vec2 b) {
  return a.x * b.x + a.y * b.y;
}
double cross2(Vec2 a, Vec2 b) {
  return a.x * b.y - a.y * b.x;
}
Vec2 sub(Vec2 a, Vec2 b) {
  return {a.x - b.x, a.y - b.y};
}
double dist(Vec2 a, Vec2 b) {
  return std::hypot(a.x - b.x, a.y - b.y);
}

struct Box {
  double x0, x1, y0, y1;
};

Box outline_box(const std::vector<Vec2>& poly) {
  Box b{INFINITY, -INFINITY, INFINITY, -INFINITY};
  for (const Vec2& p : poly) {
    b.x0 = std::min(b.x0, p.x);
    b.x1 = std::max(b.x1, p.x);
    b.y0 = std::min(b.y0, p.y);
    b.y1 = std::max(b.y1, p.y);
  }
  return b;
}

bool boxes_meet(const Box& a, const Box& b, double tol) {
  return a.x0 <= b.x1 + tol && b.x0 <= a.x1 + tol && a.y0 <= b.y1 + tol && b.y0 <= a.y1 + tol;
}

// One overlap of an edge of block i with an edge of block j: from u to v along t.
struct Piece {
  Vec2 u, v, t;
};

// Overlap pieces of the outlines of blocks i and j.
std::vector<Piece> overlap_pieces(const std::vector<Vec2>& pi, const std::vector<Vec2>& pj,
                                  const Box& box_j, double tol) {
  std::vector<Piece> out;
  const std::size_t ni = pi.size(), nj = pj.size();
  for (std::size_t e = 0; e < ni; ++e) {
    const Vec2 p = pi[e], q = pi[(e + 1) % ni];
    // Skip edges far from the other block.
    if (std::max(p.x, q.x) < box_j.x0 - tol || std::min(p.x, q.x) > box_j.x1 + tol ||
        std::max(p.y, q.y) < box_j.y0 - tol || std::min(p.y, q.y) > box_j.y1 + tol)
      continue;
    const double len = dist(p, q);
    if (len <= tol) continue;
    const Vec2 t{(q.x - p.x) / len, (q.y - p.y) / len};
    for (std::size_t f = 0; f < nj; ++f) {
      const Vec2 c = pj[f], d = pj[(f + 1) % nj];
      if (std::abs(cross2(t, sub(c, p))) > tol || std::abs(cross2(t, sub(d, p))) > tol) continue;
      if (dot2(t, sub(d, c)) >= 0.0) continue;
      const double sc = dot2(t, sub(c, p)), sd = dot2(t, sub(d, p));
      const double lo = std::max(0.0, std::min(sc, sd)), hi = std::min(len, std::max(sc, sd));
      if (hi - lo <= tol) continue;
      // Keep the very points of the outlines where the overlap ends on one of them.
      auto at = [&](double s) -> Vec2 {
        if (s == 0.0) return p;
        if (s == len) return q;
        if (s == sc) return c;
        if (s == sd) return d;
        return {p.x + s * t.x, p.y + s * t.y};
      };
      out.push_back({at(lo), at(hi), t});
    }
  }
  return out;
}

// Merges the pieces of one block pair into interfaces (block_a = i, normal from i into j).
void merge_pieces(const std::vector<Piece>& pieces, Index i, Index j, double tol,
                  std::vector<Interface>* out) {
  std::vector<bool> used(pieces.size(), false);
  for (std::size_t g = 0; g < pieces.size(); ++g) {
    if (used[g]) continue;
    const Vec2 origin = pieces[g].u, t = pieces[g].t;
    // (s along t, point) of every end of the group's pieces, as intervals.
    std::vector<std::pair<std::pair<double, Vec2>, std::pair<double, Vec2>>> iv;
    for (std::size_t k = g; k < pieces.size(); ++k) {
      if (used[k]) continue;
      const Piece& pc = pieces[k];
      if (dot2(pc.t, t) <= 0.0) continue;
      if (std::abs(cross2(t, sub(pc.u, origin))) > tol ||
          std::abs(cross2(t, sub(pc.v, origin))) > tol)
        continue;
      used[k] = true;
      double su = dot2(t, sub(pc.u, origin)), sv = dot2(t, sub(pc.v, origin));
      Vec2 u = pc.u, v = pc.v;
      if (su > sv) std::swap(su, sv), std::swap(u, v);
      iv.push_back({{su, u}, {sv, v}});
    }
    std::sort(iv.begin(), iv.end(),
              [](const auto& a, const auto& b) { return a.first.first < b.first.first; });
    const Vec2 normal{t.y, -t.x};
    std::size_t k = 0;
    while (k < iv.size()) {
      auto lo = iv[k].first, hi = iv[k].second;
      ++k;
      while (k < iv.size() && iv[k].first.first <= hi.first + tol) {
        if (iv[k].second.first > hi.first) hi = iv[k].second;
        ++k;
      }
      Interface f;
      f.block_a = i;
      f.block_b = j;
      f.a = lo.second;
      f.b = hi.second;
      f.normal = normal;
      out->push_back(f);
    }
  }
}

// Distance from point p to the infinite line through a with unit direction t.
double line_distance(Vec2 p, Vec2 a, Vec2 t) {
  return std::abs(cross2(t, sub(p, a)));
}

// Names interface f after joint jt when they lie on one another (see the header).
bool matches(const Interface& f, const Joint& jt, double tol) {
  const double len = f.length();
  const Vec2 t{(f.b.x - f.a.x) / len, (f.b.y - f.a.y) / len};
  if (line_distance(jt.a, f.a, t) > tol || line_distance(jt.b, f.a, t) > tol) return false;
  const double s0 = dot2(t, sub(jt.a, f.a)), s1 = dot2(t, sub(jt.b, f.a));
  const double overlap = std::min(len, std::max(s0, s1)) - std::max(0.0, std::min(s0, s1));
  return overlap > tol;
}

}  // namespace

double Interface::length() const {
  return dist(a, b);
}

double polygon_centroid(const std::vector<Vec2>& polygon, Vec2* centroid) {
  const std::size_t n = polygon.size();
  if (n < 3) {
    *centroid = n ? polygon[0] : Vec2{};
    return 0.0;
  }
  const Vec2 o = polygon[0];
  double a2 = 0.0, cx = 0.0, cy = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const Vec2 p = sub(polygon[k], o), q = sub(polygon[(k + 1) % n], o);
    const double w = p.x * q.y - q.x * p.y;
    a2 += w;
    cx += (p.x + q.x) * w;
    cy += (p.y + q.y) * w;
  }
  *centroid = a2 != 0.0 ? Vec2{o.x + cx / (3.0 * a2), o.y + cy / (3.0 * a2)} : o;
  return 0.5 * std::abs(a2);
}

std::vector<Interface> find_interfaces(const Model& model, double rel_tol) {
  const std::size_t nb = model.blocks.size();
  std::vector<Box> boxes(nb);
  Box all{INFINITY, -INFINITY, INFINITY, -INFINITY};
  for (std::size_t i = 0; i < nb; ++i) {
    boxes[i] = outline_box(model.blocks[i].polygon);
    all.x0 = std::min(all.x0, boxes[i].x0);
    all.x1 = std::max(all.x1, boxes[i].x1);
    all.y0 = std::min(all.y0, boxes[i].y0);
    all.y1 = std::max(all.y1, boxes[i].y1);
  }
  std::vector<Interface> out;
  if (nb < 2) return out;
  const double tol = rel_tol * std::hypot(all.x1 - all.x0, all.y1 - all.y0);

  for (std::size_t i = 0; i < nb; ++i)
    for (std::size_t j = i + 1; j < nb; ++j) {
      if (!boxes_meet(boxes[i], boxes[j], tol)) continue;
      const auto pieces =
          overlap_pieces(model.blocks[i].polygon, model.blocks[j].polygon, boxes[j], tol);
      if (!pieces.empty())
        merge_pieces(pieces, static_cast<Index>(i), static_cast<Index>(j), tol, &out);
    }

  // Names from Model::joints.
  std::map<std::pair<Index, Index>, std::vector<Index>> by_pair;
  for (std::size_t k = 0; k < model.joints.size(); ++k) {
    const Joint& jt = model.joints[k];
    by_pair[{std::min(jt.block_a, jt.block_b), std::max(jt.block_a, jt.block_b)}].push_back(
        static_cast<Index>(k));
  }
  for (Interface& f : out) {
    const auto it = by_pair.find({f.block_a, f.block_b});
    Index found = -1;
    if (it != by_pair.end())
      for (Index k : it->second)
        if (matches(f, model.joints[k], tol)) {
          found = k;
          break;
        }
    if (found < 0) {
      if (f.b.x < f.a.x || (f.b.x == f.a.x && f.b.y < f.a.y)) std::swap(f.a, f.b);
      continue;
    }
    const Joint& jt = model.joints[found];
    f.joint = found;
    f.position_deg = jt.position_deg;
    if (jt.block_a != f.block_a) {
      std::swap(f.block_a, f.block_b);
      f.normal = {-f.normal.x, -f.normal.y};
    }
    if (dist(f.b, jt.a) < dist(f.a, jt.a)) std::swap(f.a, f.b);
  }
  return out;
}

}  // namespace voussoir

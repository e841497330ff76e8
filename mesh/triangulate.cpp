// Structured band meshing, symmetric meshing by mirroring, and mesh utilities (the CGAL part
// is in triangulate_cgal.cpp). Contracts in triangulate.hpp.

#include "mesh/triangulate.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "mesh/geometry.hpp"

namespace voussoir {

TriMesh mesh_band(const std::vector<std::vector<Vec2>>& columns) {
  const Index m = static_cast<Index>(columns.size()) - 1;
  if (m < 1) throw std::invalid_argument("mesh_band: needs at least two columns");
  const Index n = static_cast<Index>(columns[0].size()) - 1;
  if (n < 1) throw std::invalid_argument("mesh_band: needs at least two rows");
  for (const auto& c : columns)
    if (static_cast<Index>(c.size()) != n + 1)
      throw std::invalid_argument("mesh_band: columns of different lengths");

  TriMesh mesh;
  mesh.points.reserve((m + 1) * (n + 1) + n);
  for (const auto& c : columns) mesh.points.insert(mesh.points.end(), c.begin(), c.end());
  auto id = [n](Index j, Index i) { return j * (n + 1) + i; };

  for (Index j = 0; j < m; ++j) {
    for (Index i = 0; i < n; ++i) {
      // Cell corners: p00 (column j, row i), p01 (column j+1, row i), p10, p11 one row up.
      const Index p00 = id(j, i), p01 = id(j + 1, i), p10 = id(j, i + 1), p11 = id(j + 1, i + 1);
      if (2 * j + 1 < m) {  // first half: diagonal p00-p11
        mesh.tris.push_back({p00, p01, p11});
        mesh.tris.push_back({p00, p11, p10});
      } else if (2 * j + 1 > m) {  // second half: the mirrored diagonal p01-p10
        mesh.tris.push_back({p00, p01, p10});
        mesh.tris.push_back({p01, p11, p10});
      } else {
        // Middle cell (m odd): centre node and four triangles. Summing the mirrored pairs
        // first, (p00 + p01) + (p10 + p11), makes the centre's x exactly 0 when column j+1 is
        // the exact mirror of column j in x = 0.
        const Vec2 a = mesh.points[p00], b = mesh.points[p01];
        const Vec2 c = mesh.points[p10], d = mesh.points[p11];
        const Vec2 centre = 0.25 * ((a + b) + (c + d));
        const Index k = static_cast<Index>(mesh.points.size());
        mesh.points.push_back(centre);
        mesh.tris.push_back({p00, p01, k});
        mesh.tris.push_back({p01, p11, k});
        mesh.tris.push_back({p11, p10, k});
        mesh.tris.push_back({p10, p00, k});
      }
    }
  }
  return mesh;
}

TriMesh triangulate_symmetric(const std::vector<Vec2>& right_chain, double size,
                              std::size_t max_triangles) {
  const std::size_t n = right_chain.size();
  if (n < 3 || right_chain.front().x != 0.0 || right_chain.back().x != 0.0)
    throw std::invalid_argument("triangulate_symmetric: the chain must start and end on x = 0");
  for (std::size_t i = 1; i + 1 < n; ++i)
    if (!(right_chain[i].x > 0.0))
      throw std::invalid_argument("triangulate_symmetric: inner chain points must have x > 0");

  // Close the half along the axis, from the chain's last point down to its first.
  std::vector<Vec2> half = right_chain;
  std::vector<Vec2> axis;
  append_segment(axis, right_chain.back(), right_chain.front(), size);
  half.insert(half.end(), axis.begin() + 1, axis.end());
  TriMesh mesh = triangulate_polygon(half, size, max_triangles);

  // Mirror: nodes on the axis (x == 0 exactly: input points and snapped axis points) are
  // shared, the others get a mirror twin.
  const Index np = static_cast<Index>(mesh.points.size());
  std::vector<Index> twin(np);
  for (Index i = 0; i < np; ++i) {
    const Vec2 p = mesh.points[i];
    if (p.x < 0.0) throw std::logic_error("triangulate_symmetric: node left of the axis");
    if (p.x == 0.0) {
      twin[i] = i;
    } else {
      twin[i] = static_cast<Index>(mesh.points.size());
      mesh.points.push_back(mirror_x(p));
    }
  }
  const std::size_t nt = mesh.tris.size();
  for (std::size_t e = 0; e < nt; ++e) {
    const auto t = mesh.tris[e];
    mesh.tris.push_back({twin[t[0]], twin[t[2]], twin[t[1]]});
  }
  return mesh;
}

TriMesh mirror_mesh(const TriMesh& mesh) {
  TriMesh out;
  out.points.reserve(mesh.points.size());
  for (const Vec2& p : mesh.points) out.points.push_back(mirror_x(p));
  out.tris.reserve(mesh.tris.size());
  for (const auto& t : mesh.tris) out.tris.push_back({t[0], t[2], t[1]});
  return out;
}

void rotate_mesh(TriMesh& mesh, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  for (Vec2& p : mesh.points) p = {c * p.x - s * p.y, s * p.x + c * p.y};
}

std::vector<Vec2> boundary_loop(const TriMesh& mesh) {
  // Boundary edges are the edges used by one triangle only; directed as in the triangle made
  // counter-clockwise, they chain into the counter-clockwise outer loop. The edges are found
  // by sorting them on their end nodes (a mesh of millions of triangles: std::map took a
  // third of `check`'s time).
  struct Edge {
    Index lo, hi;    // end nodes, smaller first: the key
    Index from, to;  // as directed in the counter-clockwise triangle
  };
  std::vector<Edge> edges;
  edges.reserve(3 * mesh.tris.size());
  for (const auto& t : mesh.tris) {
    std::array<Index, 3> v = t;
    const Vec2 a = mesh.points[v[0]], b = mesh.points[v[1]], c = mesh.points[v[2]];
    if (cross(b - a, c - a) < 0.0) std::swap(v[1], v[2]);
    for (int k = 0; k < 3; ++k) {
      const Index p = v[k], q = v[(k + 1) % 3];
      edges.push_back({std::min(p, q), std::max(p, q), p, q});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const Edge& l, const Edge& r) {
    return l.lo < r.lo || (l.lo == r.lo && l.hi < r.hi);
  });
  constexpr Index kNone = -1;
  std::vector<Index> next(mesh.points.size(), kNone);
  std::size_t count = 0;
  Index start = kNone;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi) ++j;
    if (j == i + 1) {
      const Edge& e = edges[i];
      if (next[e.from] != kNone)
        throw std::invalid_argument("mesh boundary touches itself at a node");
      next[e.from] = e.to;
      ++count;
      if (start == kNone || e.from < start) start = e.from;
    }
    i = j;
  }
  if (count == 0) throw std::invalid_argument("mesh has no boundary");
  std::vector<Vec2> loop;
  Index cur = start;
  do {
    loop.push_back(mesh.points[cur]);
    if (next[cur] == kNone) throw std::invalid_argument("mesh boundary is not closed");
    cur = next[cur];
    if (loop.size() > count) throw std::invalid_argument("mesh boundary is not a simple loop");
  } while (cur != start);
  if (loop.size() != count)
    throw std::invalid_argument("mesh boundary has " + std::string("several loops (a hole or ") +
                                "several pieces)");
  return loop;
}

void append_segment(std::vector<Vec2>& out, Vec2 a, Vec2 b, double h) {
  const double len = distance(a, b);
  const int parts = std::max(1, static_cast<int>(std::ceil(len / h - 1e-9)));
  out.push_back(a);
  for (int k = 1; k < parts; ++k) {
    const double s = static_cast<double>(k) / parts;
    out.push_back({a.x + s * (b.x - a.x), a.y + s * (b.y - a.y)});
  }
}

double mesh_overlap_area(const TriMesh& a, const TriMesh& b) {
  // Bounding boxes of b's triangles, sorted by their left edge, so that each triangle of a
  // is compared only with the triangles of b whose box meets its own.
  struct Box {
    double x0, x1, y0, y1;
    std::size_t tri;
  };
  auto box_of = [](const TriMesh& m, std::size_t e) {
    const Vec2 p = m.points[m.tris[e][0]], q = m.points[m.tris[e][1]], r = m.points[m.tris[e][2]];
    return Box{std::min({p.x, q.x, r.x}), std::max({p.x, q.x, r.x}), std::min({p.y, q.y, r.y}),
               std::max({p.y, q.y, r.y}), e};
  };
  std::vector<Box> boxes;
  boxes.reserve(b.tris.size());
  for (std::size_t e = 0; e < b.tris.size(); ++e) boxes.push_back(box_of(b, e));
  std::sort(boxes.begin(), boxes.end(), [](const Box& l, const Box& r) { return l.x0 < r.x0; });
  double widest = 0.0;
  for (const Box& bx : boxes) widest = std::max(widest, bx.x1 - bx.x0);
  double area = 0.0;
  for (std::size_t e = 0; e < a.tris.size(); ++e) {
    const Box ba = box_of(a, e);
    const std::array<Vec2, 3> ta{a.points[a.tris[e][0]], a.points[a.tris[e][1]],
                                 a.points[a.tris[e][2]]};
    auto it = std::lower_bound(boxes.begin(), boxes.end(), ba.x0 - widest,
                               [](const Box& l, double v) { return l.x0 < v; });
    for (; it != boxes.end() && it->x0 <= ba.x1; ++it) {
      if (it->x1 < ba.x0 || it->y1 < ba.y0 || it->y0 > ba.y1) continue;
      const auto& t = b.tris[it->tri];
      area += triangle_overlap_area(ta, {b.points[t[0]], b.points[t[1]], b.points[t[2]]});
    }
  }
  return area;
}

double triangle_min_angle_deg(Vec2 a, Vec2 b, Vec2 c) {
  // Angle at each vertex from atan2(|cross|, dot): accurate for small and obtuse angles.
  auto angle = [](Vec2 p, Vec2 q, Vec2 r) {
    const Vec2 u = q - p, v = r - p;
    return std::atan2(std::abs(cross(u, v)), dot(u, v));
  };
  const double m = std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)});
  return m * 180.0 / std::numbers::pi;
}

}  // namespace voussoir

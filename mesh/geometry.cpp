#include "mesh/geometry.hpp"

#include <algorithm>

namespace voussoir {

double outline_area(const Outline& outline) {
  const std::size_t n = outline.size();
  double twice = 0.0, segments = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const OutlineEdge& e = outline[i];
    const Vec2 q = outline[(i + 1) % n].start;
    twice += cross(e.start, q);
    if (e.radius > 0.0) segments += 0.5 * e.radius * e.radius * (e.sweep - std::sin(e.sweep));
  }
  return 0.5 * twice + segments;
}

Outline polygon_outline(const std::vector<Vec2>& vertices) {
  Outline out;
  out.reserve(vertices.size());
  for (const Vec2& p : vertices) out.push_back(OutlineEdge{p, 0.0, {}, 0.0});
  return out;
}

Outline mirror_outline(const Outline& outline) {
  // Edge i runs p_i -> p_{i+1}. Mirrored and reversed (to stay counter-clockwise) it runs
  // M(p_{i+1}) -> M(p_i): mirroring flips the sweep's sign and reversing flips it back.
  const std::size_t n = outline.size();
  Outline out;
  out.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = n - 1 - k;
    const OutlineEdge& e = outline[i];
    OutlineEdge m;
    m.start = mirror_x(outline[(i + 1) % n].start);
    m.radius = e.radius;
    m.centre = mirror_x(e.centre);
    m.sweep = e.sweep;
    out.push_back(m);
  }
  return out;
}

double polygon_area(const std::vector<Vec2>& polygon) {
  double twice = 0.0;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) twice += cross(polygon[i], polygon[(i + 1) % n]);
  return 0.5 * twice;
}

namespace {

// Clips the convex polygon `poly` by the half-plane left of a->b.
std::vector<Vec2> clip_left(const std::vector<Vec2>& poly, Vec2 a, Vec2 b) {
  std::vector<Vec2> out;
  const std::size_t n = poly.size();
  const Vec2 ab = b - a;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 p = poly[i], q = poly[(i + 1) % n];
    const double sp = cross(ab, p - a), sq = cross(ab, q - a);
    if (sp >= 0.0) out.push_back(p);
    if ((sp > 0.0 && sq < 0.0) || (sp < 0.0 && sq > 0.0)) {
      const double s = sp / (sp - sq);
      out.push_back(p + s * (q - p));
    }
  }
  return out;
}

}  // namespace

double triangle_overlap_area(const std::array<Vec2, 3>& t1, const std::array<Vec2, 3>& t2) {
  std::vector<Vec2> poly(t1.begin(), t1.end());
  if (polygon_area(poly) < 0.0) std::swap(poly[1], poly[2]);
  std::array<Vec2, 3> clip = t2;
  if (cross(clip[1] - clip[0], clip[2] - clip[0]) < 0.0) std::swap(clip[1], clip[2]);
  for (int k = 0; k < 3 && poly.size() >= 3; ++k)
    poly = clip_left(poly, clip[k], clip[(k + 1) % 3]);
  return poly.size() >= 3 ? std::max(0.0, polygon_area(poly)) : 0.0;
}

std::vector<Vec2> merge_collinear(const std::vector<Vec2>& polygon, double rel_tol) {
  const std::size_t n = polygon.size();
  if (n <= 3) return polygon;
  // Start at the lexicographically smallest vertex: an extreme point, never inside a side.
  std::size_t first = 0;
  double x0 = polygon[0].x, x1 = x0, y0 = polygon[0].y, y1 = y0;
  for (std::size_t k = 1; k < n; ++k) {
    const Vec2 p = polygon[k], f = polygon[first];
    if (p.x < f.x || (p.x == f.x && p.y < f.y)) first = k;
    x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
  }
  const double tol = rel_tol * std::hypot(x1 - x0, y1 - y0);
  std::vector<Vec2> out{polygon[first]};
  for (std::size_t k = 1; k < n; ++k) {
    const Vec2 v = polygon[(first + k) % n], w = polygon[(first + k + 1) % n];
    const Vec2 u = out.back();
    // v goes when it lies on the segment from the last corner kept to the next vertex.
    const double len = norm(w - u);
    const bool on_line = len > tol && std::abs(cross(w - u, v - u)) / len <= tol &&
                         dot(v - u, w - u) > 0.0 && dot(v - w, u - w) > 0.0;
    if (!on_line) out.push_back(v);
  }
  return out.size() >= 3 ? out : polygon;
}

}  // namespace voussoir

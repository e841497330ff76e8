// Minimal meshes for rigid blocks (rules in mesh/minimal.hpp).

#include "mesh/minimal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "mesh/triangulate.hpp"

namespace voussoir {

namespace {

// Twice the signed area of the triangle o, a, b (> 0 counter-clockwise).
double turn(const Vec2& o, const Vec2& a, const Vec2& b) {
  return cross(a - o, b - o);
}

// Above this many vertices an outline takes the fast paths below, whose cost grows as n log n
// instead of n^2 or more. The shipped decks' blocks have at most 88 vertices (a buttress at
// embrace 120), so they never take them; a fuzzed arch of radius 2000 m has thousands, and its
// `check` took 61 s before the fast paths.
constexpr std::size_t kFastOutline = 256;

// Smallest width of the convex hull (rotating calipers: it lies across the normal of a hull
// side, and the farthest vertex from side i moves forward with i).
double hull_width(const std::vector<Vec2>& poly) {
  const std::vector<Vec2> h = convex_hull(poly);
  const std::size_t m = h.size();
  if (m < 3) return 0.0;
  double width = std::numeric_limits<double>::infinity();
  std::size_t j = 1;
  for (std::size_t i = 0; i < m; ++i) {
    const Vec2 &a = h[i], &b = h[(i + 1) % m];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    while (turn(a, b, h[(j + 1) % m]) > turn(a, b, h[j])) j = (j + 1) % m;
    width = std::min(width, turn(a, b, h[j]) / len);
  }
  return width;
}

// Smallest extent of the polygon across the normals of its sides [m].
double smallest_width(const std::vector<Vec2>& poly) {
  if (poly.size() > kFastOutline) return hull_width(poly);
  double width = std::numeric_limits<double>::infinity();
  const std::size_t n = poly.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Vec2 &a = poly[k], &b = poly[(k + 1) % n];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    if (!(len > 0.0)) continue;
    const double nx = (b.y - a.y) / len, ny = -(b.x - a.x) / len;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Vec2& p : poly) {
      const double s = p.x * nx + p.y * ny;
      lo = std::min(lo, s), hi = std::max(hi, s);
    }
    width = std::min(width, hi - lo);
  }
  return width;
}

double min_angle_deg(const Vec2& a, const Vec2& b, const Vec2& c) {
  auto angle = [](const Vec2& o, const Vec2& p, const Vec2& q) {
    const double ux = p.x - o.x, uy = p.y - o.y, vx = q.x - o.x, vy = q.y - o.y;
    return std::atan2(std::abs(ux * vy - uy * vx), ux * vx + uy * vy);
  };
  return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)}) * 180.0 / M_PI;
}

}  // namespace

std::vector<Vec2> simplify_outline(const std::vector<Vec2>& outline, double chord_tolerance) {
  const std::size_t n = outline.size();
  if (n <= 3) return outline;
  const double tol = chord_tolerance * smallest_width(outline);
  // Deviation of the original points strictly between kept vertices a and b from chord a-b.
  auto deviation = [&](std::size_t a, std::size_t b) {
    double d = 0.0;
    for (std::size_t k = (a + 1) % n; k != b; k = (k + 1) % n)
      d = std::max(d, distance_to_segment(outline[k], outline[a], outline[b]));
    return d;
  };
  std::vector<std::size_t> kept;
  if (n <= kFastOutline) {
    kept.resize(n);
    for (std::size_t k = 0; k < n; ++k) kept[k] = k;
  } else {
    // Fast path: Douglas-Peucker first (every point it drops lies within tol of the chord of
    // the vertices it keeps around it), from vertex 0 and the vertex farthest from it; the
    // removal below then goes on from what it keeps, with the same test on the original points.
    std::size_t far = 0;
    double far_d = -1.0;
    for (std::size_t k = 1; k < n; ++k) {
      const double d = std::hypot(outline[k].x - outline[0].x, outline[k].y - outline[0].y);
      if (d > far_d) far_d = d, far = k;
    }
    std::vector<char> keep(n, 0);
    keep[0] = keep[far] = 1;
    std::vector<std::pair<std::size_t, std::size_t>> stack = {{0, far}, {far, 0}};
    while (!stack.empty()) {
      const auto [a, b] = stack.back();
      stack.pop_back();
      std::size_t worst = n;
      double worst_d = tol;
      for (std::size_t k = (a + 1) % n; k != b; k = (k + 1) % n) {
        const double d = distance_to_segment(outline[k], outline[a], outline[b]);
        if (d > worst_d) worst_d = d, worst = k;
      }
      if (worst == n) continue;
      keep[worst] = 1;
      stack.push_back({a, worst});
      stack.push_back({worst, b});
    }
    for (std::size_t k = 0; k < n; ++k)
      if (keep[k]) kept.push_back(k);
  }
  while (kept.size() > 3) {
    std::size_t best = kept.size();
    double best_dev = std::numeric_limits<double>::infinity();
    const std::size_t m = kept.size();
    for (std::size_t k = 0; k < m; ++k) {
      const std::size_t prev = kept[(k + m - 1) % m], next = kept[(k + 1) % m];
      const double dev = deviation(prev, next);
      if (dev < best_dev) best_dev = dev, best = k;
    }
    if (best == kept.size() || best_dev > tol) break;
    kept.erase(kept.begin() + std::ptrdiff_t(best));
  }
  std::vector<Vec2> out;
  for (std::size_t k : kept) out.push_back(outline[k]);
  return out;
}

std::vector<std::array<Index, 3>> ear_clip(const std::vector<Vec2>& poly) {
  std::vector<Index> ring(poly.size());
  for (std::size_t k = 0; k < poly.size(); ++k) ring[k] = Index(k);
  std::vector<std::array<Index, 3>> tris;
  while (ring.size() > 3) {
    const std::size_t m = ring.size();
    std::size_t best = m;
    double best_angle = -1.0;
    for (std::size_t k = 0; k < m; ++k) {
      const Vec2 &a = poly[ring[(k + m - 1) % m]], &b = poly[ring[k]], &c = poly[ring[(k + 1) % m]];
      if (!(turn(a, b, c) > 0.0)) continue;  // reflex or flat: not an ear
      bool empty = true;
      for (std::size_t j = 0; j < m && empty; ++j) {
        if (j == k || j == (k + 1) % m || j == (k + m - 1) % m) continue;
        const Vec2& p = poly[ring[j]];
        empty = !(turn(a, b, p) >= 0.0 && turn(b, c, p) >= 0.0 && turn(c, a, p) >= 0.0);
      }
      if (!empty) continue;
      const double angle = min_angle_deg(a, b, c);
      if (angle > best_angle) best_angle = angle, best = k;
    }
    if (best == m) throw std::invalid_argument("ear_clip: polygon is not simple");
    tris.push_back({ring[(best + m - 1) % m], ring[best], ring[(best + 1) % m]});
    ring.erase(ring.begin() + std::ptrdiff_t(best));
  }
  tris.push_back({ring[0], ring[1], ring[2]});
  return tris;
}

Model minimal_model(const Model& model, double chord_tolerance) {
  Model out;
  out.material = model.material;
  out.out_of_plane = model.out_of_plane;
  out.kind = model.kind;
  out.joints = model.joints;
  for (const Block& b : model.blocks) {
    const std::vector<Vec2> outline = simplify_outline(b.polygon, chord_tolerance);
    add_block(out, outline, outline, ear_clip(outline), b.fixed, b.role);
    out.blocks.back().name = b.name;
  }
  finalize_model(out);
  return out;
}

}  // namespace voussoir

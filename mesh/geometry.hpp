#pragma once
// Plane geometry used by the scene generators and their tests: small vector helpers, exact
// block outlines made of straight and circular edges, polygon area and simplicity, and the
// overlap area of two triangles.
//
// Exact outlines. A voussoir's intrados and extrados are circular arcs; its meshed outline is
// the polygon through nodes placed exactly on those arcs, so the meshed area falls short of the
// true area by the circular segments cut off by the chords (relative error ~ phi^2 / 12 for a
// chord subtending phi). The generators therefore also record each block's exact outline
// (edges that are straight or circular, with centre, radius and signed sweep) and
// `outline_area` integrates it in closed form:
//   A = shoelace(vertices) + sum over arc edges of (R^2 / 2) (phi - sin phi),
// phi the signed sweep (counter-clockwise positive) of the arc from its start vertex to the
// next vertex. The segment term is positive where the arc bulges out of a counter-clockwise
// outline (phi > 0) and negative where it bulges in (phi < 0), so one formula serves both.

#include <array>
#include <cmath>
#include <vector>

#include "core/model.hpp"

namespace voussoir {

// Mirror image in the vertical axis x = 0 (exact: only the sign bit changes).
inline Vec2 mirror_x(Vec2 p) {
  return {-p.x, p.y};
}
// Point at angle `theta` [rad] on the circle (centre, radius). Explicit fma so that the
// rounding is the same wherever it is inlined (GCC's default -ffp-contract=fast fuses
// a + r cos at some call sites and not at others).
inline Vec2 on_circle(Vec2 centre, double radius, double theta) {
  return {std::fma(radius, std::cos(theta), centre.x), std::fma(radius, std::sin(theta), centre.y)};
}

// One edge of an exact outline: from `start` to the next edge's start (cyclically).
struct OutlineEdge {
  Vec2 start;
  double radius = 0.0;  // 0 = straight edge; else a circular arc of this radius [m]
  Vec2 centre;          // arc centre [m]
  double sweep = 0.0;   // signed angle swept from start to end about the centre [rad]
};
using Outline = std::vector<OutlineEdge>;

// Area enclosed by a counter-clockwise exact outline [m2] (formula at the top of the file).
double outline_area(const Outline& outline);
// The straight-edged outline through the given vertices.
Outline polygon_outline(const std::vector<Vec2>& vertices);
// Mirror image in x = 0, still counter-clockwise.
Outline mirror_outline(const Outline& outline);

// Signed area of a polygon (positive when counter-clockwise) [m2].
double polygon_area(const std::vector<Vec2>& polygon);
// True when no two non-adjacent edges of the closed polygon touch or cross, no edge has zero
// length and no edge folds back onto its neighbour. Exact (CGAL's sweep, O(n log n));
// defined in mesh/triangulate_cgal.cpp, where CGAL is confined.
bool polygon_is_simple(const std::vector<Vec2>& polygon);

// The corners of a closed polygon: every vertex that lies on the straight line through its
// neighbours (within `rel_tol` x the polygon's size, and between them) is dropped, so a side
// drawn or meshed with points along it becomes one edge. The joint search (mesh/
// scenes_polygons.cpp) works on these, so one physical interface is one joint however many
// mesh nodes lie on it. Never returns fewer than 3 vertices.
std::vector<Vec2> merge_collinear(const std::vector<Vec2>& polygon, double rel_tol = 1e-9);

// Area of the intersection of two triangles (each given in either orientation) [m2]:
// Sutherland-Hodgman clipping of one convex polygon by the other.
double triangle_overlap_area(const std::array<Vec2, 3>& t1, const std::array<Vec2, 3>& t2);

}  // namespace voussoir

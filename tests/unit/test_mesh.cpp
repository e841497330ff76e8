// Unit tests of the meshers and plane geometry (mesh/geometry, mesh/triangulate): exact
// outline areas, structured band meshes, constrained quality meshes of convex and non-convex
// polygons, symmetric meshing, boundary loops and overlap areas.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "mesh/geometry.hpp"
#include "mesh/triangulate.hpp"

namespace voussoir {
namespace {

constexpr double kPi = std::numbers::pi;

double mesh_area(const TriMesh& m) {
  double a = 0.0;
  for (const auto& t : m.tris)
    a += 0.5 * std::abs(cross(m.points[t[1]] - m.points[t[0]], m.points[t[2]] - m.points[t[0]]));
  return a;
}

double mesh_min_angle(const TriMesh& m) {
  double w = 180.0;
  for (const auto& t : m.tris)
    w = std::min(w, triangle_min_angle_deg(m.points[t[0]], m.points[t[1]], m.points[t[2]]));
  return w;
}

double mesh_max_edge(const TriMesh& m) {
  double e = 0.0;
  for (const auto& t : m.tris)
    for (int k = 0; k < 3; ++k) e = std::max(e, distance(m.points[t[k]], m.points[t[(k + 1) % 3]]));
  return e;
}

bool has_point_exactly(const TriMesh& m, Vec2 p) {
  return std::any_of(m.points.begin(), m.points.end(),
                     [&](Vec2 q) { return q.x == p.x && q.y == p.y; });
}

// Every node's mirror image in x = 0 is a node, bit for bit.
bool mirrors_exactly(const TriMesh& m) {
  return std::all_of(m.points.begin(), m.points.end(),
                     [&](Vec2 p) { return has_point_exactly(m, mirror_x(p)); });
}

double distance_to_polygon(Vec2 p, const std::vector<Vec2>& poly) {
  double d = 1e300;
  for (std::size_t i = 0; i < poly.size(); ++i)
    d = std::min(d, distance_to_segment(p, poly[i], poly[(i + 1) % poly.size()]));
  return d;
}

TEST(Geometry, OutlineAreaOfDiscAndAnnularSector) {
  // Unit disc as four quarter arcs (CCW, sweep +90 deg each): pi.
  Outline disc;
  for (int k = 0; k < 4; ++k)
    disc.push_back(OutlineEdge{on_circle({0, 0}, 1.0, k * kPi / 2), 1.0, {0, 0}, kPi / 2});
  EXPECT_NEAR(outline_area(disc), kPi, 1e-14);
  // Annular sector 1 <= r <= 2 over 30..100 deg: outer arc CCW, inner arc CW.
  const double a0 = 30 * kPi / 180, a1 = 100 * kPi / 180;
  Outline sector = {OutlineEdge{on_circle({0, 0}, 1, a0), 0, {}, 0},
                    OutlineEdge{on_circle({0, 0}, 2, a0), 2, {0, 0}, a1 - a0},
                    OutlineEdge{on_circle({0, 0}, 2, a1), 0, {}, 0},
                    OutlineEdge{on_circle({0, 0}, 1, a1), 1, {0, 0}, -(a1 - a0)}};
  EXPECT_NEAR(outline_area(sector), 0.5 * (4.0 - 1.0) * (a1 - a0), 1e-14);
  // Mirroring keeps the area and the orientation.
  EXPECT_NEAR(outline_area(mirror_outline(sector)), outline_area(sector), 1e-14);
  EXPECT_NEAR(outline_area(polygon_outline({{0, 0}, {2, 0}, {2, 1}, {0, 1}})), 2.0, 1e-15);
}

TEST(Geometry, SimplePolygons) {
  EXPECT_TRUE(polygon_is_simple({{0, 0}, {1, 0}, {1, 1}, {0, 1}}));
  EXPECT_TRUE(polygon_is_simple({{0, 0}, {2, 0}, {2, 2}, {1, 1}, {0, 2}}));  // non-convex
  EXPECT_FALSE(polygon_is_simple({{0, 0}, {1, 1}, {1, 0}, {0, 1}}));         // bow tie
  EXPECT_FALSE(polygon_is_simple({{0, 0}, {1, 0}, {1, 0}, {0, 1}}));         // repeated vertex
  EXPECT_FALSE(polygon_is_simple({{0, 0}, {2, 0}, {1, 0}, {1, 1}}));         // folds back
  EXPECT_FALSE(polygon_is_simple({{0, 0}, {2, 0}, {2, 2}, {1, 0}, {0, 2}}));  // vertex on an edge
  // A needle: the outline of a 16 km block tapering to a 1.5e-5 rad tip, cut at 1 m. The
  // inexact pairwise test that came before the sweep called it crossed: two pieces of its
  // slanted long edge, 1 km apart and collinear but for rounding, got opposite orientation
  // signs (pieces 17157 and 18183).
  const std::vector<Vec2> corners = {{16384, 0}, {0.25, 0}, {0.25, 1}, {-0.25, 1}, {-1.75, -0.25}};
  std::vector<Vec2> needle;
  for (std::size_t k = 0; k < corners.size(); ++k)
    append_segment(needle, corners[k], corners[(k + 1) % corners.size()], 1.0);
  EXPECT_GT(needle.size(), 32000u);
  EXPECT_TRUE(polygon_is_simple(needle));
  EXPECT_NEAR(polygon_area({{0, 0}, {2, 0}, {2, 2}, {1, 1}, {0, 2}}), 3.0, 1e-15);
}

TEST(Geometry, TriangleOverlapArea) {
  // (0,0),(2,0),(0,2) and the same shifted by 1 in x overlap in (1,0),(2,0),(1,1): 0.5.
  EXPECT_NEAR(triangle_overlap_area({{{0, 0}, {2, 0}, {0, 2}}}, {{{1, 0}, {3, 0}, {1, 2}}}), 0.5,
              1e-15);
  // Orientation does not matter.
  EXPECT_NEAR(triangle_overlap_area({{{0, 0}, {0, 2}, {2, 0}}}, {{{1, 2}, {3, 0}, {1, 0}}}), 0.5,
              1e-15);
  // Sharing an edge or a vertex only: zero.
  EXPECT_EQ(triangle_overlap_area({{{0, 0}, {1, 0}, {0, 1}}}, {{{1, 0}, {0, 1}, {1, 1}}}), 0.0);
  EXPECT_EQ(triangle_overlap_area({{{0, 0}, {1, 0}, {0, 1}}}, {{{1, 0}, {2, 0}, {2, 1}}}), 0.0);
  // One inside the other: the smaller area.
  EXPECT_NEAR(triangle_overlap_area({{{0, 0}, {4, 0}, {0, 4}}}, {{{1, 1}, {2, 1}, {1, 2}}}), 0.5,
              1e-15);
}

TEST(MeshBand, RectangleCountsAreaAndMirror) {
  // Rectangle [-1, 1] x [0, 1] with m = 5 columns of cells and n = 3 rows: 2 triangles per
  // cell, 4 in each middle cell (m odd) -> 3 * (4 * 2 + 4) = 36 triangles, 6 * 4 + 3 nodes.
  const int m = 5, n = 3;
  std::vector<std::vector<Vec2>> cols;
  for (int j = 0; j <= m; ++j) {
    std::vector<Vec2> c;
    for (int i = 0; i <= n; ++i) c.push_back({(2 * j - m) * (1.0 / m), i / 3.0});
    cols.push_back(c);
  }
  const TriMesh mesh = mesh_band(cols);
  EXPECT_EQ(mesh.tris.size(), 36u);
  EXPECT_EQ(mesh.points.size(), 27u);
  EXPECT_NEAR(mesh_area(mesh), 2.0, 1e-14);
  EXPECT_TRUE(mirrors_exactly(mesh));
  // Cells 0.4 x 0.333: halves of a cell have angles atan(0.333 / 0.4) = 39.8 deg.
  EXPECT_NEAR(mesh_min_angle(mesh), std::atan((1.0 / 3.0) / 0.4) * 180 / kPi, 1e-9);
  // Even m: no centre nodes, 2 triangles per cell, still mirror-symmetric.
  cols.pop_back();
  for (std::size_t j = 0; j < cols.size(); ++j)
    for (Vec2& p : cols[j]) p.x = (2.0 * j - 4.0) * 0.2;  // columns at -0.8 .. 0.8
  const TriMesh even = mesh_band(cols);
  EXPECT_EQ(even.tris.size(), 2u * 4 * 3);
  EXPECT_TRUE(mirrors_exactly(even));
  // The mirrored triangles are present too (centroids mirror onto centroids).
  for (const auto& t : even.tris) {
    const Vec2 c = (1.0 / 3.0) * ((even.points[t[0]] + even.points[t[1]]) + even.points[t[2]]);
    bool found = false;
    for (const auto& u : even.tris) {
      const Vec2 d = (1.0 / 3.0) * ((even.points[u[0]] + even.points[u[1]]) + even.points[u[2]]);
      found = found || distance(d, mirror_x(c)) < 1e-14;
    }
    EXPECT_TRUE(found);
  }
}

TEST(Triangulate, NonConvexPolygonKeepsBoundaryAndQuality) {
  // L-shape (one reflex corner) and a pointed-crown-like block whose intrados has a notch.
  const std::vector<Vec2> ell = {{0, 0}, {2, 0}, {2, 0.7}, {0.6, 0.7}, {0.6, 1.9}, {0, 1.9}};
  const std::vector<Vec2> crown = {{0.3, 0.0},   {0.45, 0.5}, {0.0, 0.62},
                                   {-0.45, 0.5}, {-0.3, 0.0}, {0.0, 0.12}};
  for (const std::vector<Vec2>* poly : {&ell, &crown}) {
    const double size = 0.1;
    const TriMesh mesh = triangulate_polygon(*poly, size);
    EXPECT_NEAR(mesh_area(mesh), polygon_area(*poly), 1e-12 * polygon_area(*poly));
    for (const Vec2& p : *poly) EXPECT_TRUE(has_point_exactly(mesh, p));
    // Every boundary node lies on the polygon (Steiner points snapped onto their edge).
    for (const Vec2& p : boundary_loop(mesh)) EXPECT_LT(distance_to_polygon(p, *poly), 1e-15);
    // CGAL criteria: longest edge <= size, angles >= 20.7 deg (input corners >= 60 deg).
    EXPECT_LE(mesh_max_edge(mesh), size * (1 + 1e-12));
    EXPECT_GE(mesh_min_angle(mesh), 20.0);
    EXPECT_GT(mesh.tris.size(), 20u);
  }
  // Clockwise or self-crossing input is refused.
  std::vector<Vec2> cw(ell.rbegin(), ell.rend());
  EXPECT_THROW(triangulate_polygon(cw, 0.1), std::invalid_argument);
  EXPECT_THROW(triangulate_polygon({{0, 0}, {1, 1}, {1, 0}, {0, 1}}, 0.1), std::invalid_argument);
}

TEST(Triangulate, GrowthPastTheCapIsRefused) {
  // A strip 100 times longer than thick, meshed at 10 times its thickness: quality triangles
  // must be about as small as the thickness, far more than its area calls for.
  const std::vector<Vec2> strip = {{0, 0}, {1, 0}, {1, 0.01}, {0, 0.01}};
  const TriMesh free = triangulate_polygon(strip, 0.1);
  ASSERT_GT(free.tris.size(), 100u);
  // A cap well above the mesh's size does not change it; one at half its size stops the mesher.
  const TriMesh capped = triangulate_polygon(strip, 0.1, 10 * free.tris.size());
  ASSERT_EQ(capped.tris.size(), free.tris.size());
  ASSERT_EQ(capped.points.size(), free.points.size());
  for (std::size_t k = 0; k < free.points.size(); ++k) {
    EXPECT_EQ(capped.points[k].x, free.points[k].x);
    EXPECT_EQ(capped.points[k].y, free.points[k].y);
  }
  EXPECT_THROW(triangulate_polygon(strip, 0.1, free.tris.size() / 2), std::runtime_error);
}

TEST(Triangulate, HorizontalEdgeSteinerPointsAreExactlyOnTheEdge) {
  // A long flat rectangle: the mesher must split the long edges; the points it adds on them
  // keep y exactly (snapping onto an axis-parallel edge is exact).
  const std::vector<Vec2> rect = {{0, 0.1}, {3, 0.1}, {3, 0.3}, {0, 0.3}};
  const TriMesh mesh = triangulate_polygon(rect, 0.05);
  int on_bottom = 0;
  for (const Vec2& p : boundary_loop(mesh)) {
    const bool bottom = p.y == 0.1, top = p.y == 0.3, side = p.x == 0.0 || p.x == 3.0;
    EXPECT_TRUE(bottom || top || side) << p.x << " " << p.y;
    on_bottom += bottom;
  }
  EXPECT_GE(on_bottom, 3.0 / 0.05);  // edges of at most 0.05 along the bottom
}

TEST(Triangulate, SymmetricPolygonMirrorsExactly) {
  // Right half of a symmetric pointed-crown block: from the intrados apex (0, 0.12) down the
  // intrados, up the joint, up the extrados to the extrados apex (0, 0.62).
  const std::vector<Vec2> right = {{0.0, 0.12}, {0.3, 0.0}, {0.45, 0.5}, {0.0, 0.62}};
  const TriMesh mesh = triangulate_symmetric(right, 0.08);
  EXPECT_TRUE(mirrors_exactly(mesh));
  const std::vector<Vec2> whole = {{0.3, 0.0},   {0.45, 0.5}, {0.0, 0.62},
                                   {-0.45, 0.5}, {-0.3, 0.0}, {0.0, 0.12}};
  EXPECT_NEAR(mesh_area(mesh), polygon_area(whole), 1e-13);
  EXPECT_NEAR(polygon_area(boundary_loop(mesh)), polygon_area(whole), 1e-13);
  EXPECT_GE(mesh_min_angle(mesh), 20.0);
  // Nodes on the axis are shared, not doubled.
  int on_axis = 0;
  for (const Vec2& p : mesh.points) on_axis += p.x == 0.0;
  EXPECT_GE(on_axis, 2);
  for (std::size_t i = 0; i < mesh.points.size(); ++i)
    for (std::size_t j = i + 1; j < mesh.points.size(); ++j)
      EXPECT_GT(distance(mesh.points[i], mesh.points[j]), 1e-9);
}

TEST(Triangulate, BoundaryLoopRefusesHoles) {
  // A square ring of 8 triangles around a hole: two boundary loops.
  TriMesh ring;
  ring.points = {{0, 0}, {3, 0}, {3, 3}, {0, 3}, {1, 1}, {2, 1}, {2, 2}, {1, 2}};
  ring.tris = {{0, 1, 5}, {0, 5, 4}, {1, 2, 6}, {1, 6, 5},
               {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  EXPECT_THROW(boundary_loop(ring), std::invalid_argument);
  // Without the hole's triangles removed, i.e. a plain square, one CCW loop of area 9.
  TriMesh sq;
  sq.points = {{0, 0}, {3, 0}, {3, 3}, {0, 3}};
  sq.tris = {{0, 2, 1}, {0, 3, 2}};  // clockwise input
  EXPECT_NEAR(polygon_area(boundary_loop(sq)), 9.0, 1e-15);
}

TEST(Triangulate, MeshOverlapArea) {
  const TriMesh a = triangulate_polygon({{0, 0}, {1, 0}, {1, 1}, {0, 1}}, 0.2);
  const TriMesh touching = triangulate_polygon({{1, 0}, {2, 0}, {2, 1}, {1, 1}}, 0.2);
  const TriMesh shifted =
      triangulate_polygon({{0.75, 0.5}, {1.75, 0.5}, {1.75, 1.5}, {0.75, 1.5}}, 0.2);
  EXPECT_LT(mesh_overlap_area(a, touching), 1e-15);
  EXPECT_NEAR(mesh_overlap_area(a, shifted), 0.25 * 0.5, 1e-13);
}

TEST(Triangulate, AppendSegmentCutsEvenly) {
  std::vector<Vec2> pts;
  append_segment(pts, {0, 0}, {1, 0}, 0.3);  // ceil(1 / 0.3) = 4 parts, b not appended
  ASSERT_EQ(pts.size(), 4u);
  EXPECT_EQ(pts[2].x, 0.5);
  pts.clear();
  append_segment(pts, {0, 0}, {1, 0}, 0.25);  // exactly 4 parts, not 5
  EXPECT_EQ(pts.size(), 4u);
}

}  // namespace
}  // namespace voussoir

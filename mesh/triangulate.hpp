#pragma once
// Meshing of one block into three-node triangles.
//
// Two meshers:
//   - `mesh_band`: structured mesh of a voussoir-like block given as columns of nodes (column 0
//     is one joint face, column m the other; row 0 the intrados, row n the extrados). Each
//     quadrilateral cell is split along a diagonal; cells in the first half of the columns use
//     one diagonal and cells in the second half the mirrored one, and when m is odd the middle
//     cell gets a centre node and four triangles. The pattern is therefore symmetric under
//     column j <-> m - j, so a block whose columns mirror each other gets a mesh that mirrors
//     onto itself exactly.
//   - `triangulate_polygon`: constrained Delaunay quality mesh of any simple polygon (convex or
//     not) by CGAL 5.5 (Constrained_Delaunay_triangulation_2 + Delaunay_mesher_2 with
//     Delaunay_mesh_size_criteria_2(0.125, size): smallest angle about 20.7 degrees away from
//     sharper input corners, longest edge <= size). Every boundary point given is a node,
//     bit for bit; points the mesher adds on a boundary edge are snapped back onto that edge
//     (exact for horizontal and vertical edges, within one rounding otherwise).
//     `triangulate_symmetric` meshes the half x >= 0 of a polygon symmetric about x = 0 and
//     mirrors it, merging the nodes on the axis, so the mesh mirrors onto itself exactly.
// CGAL is confined to mesh/triangulate_cgal.cpp (it compiles slowly).

#include <array>
#include <stdexcept>
#include <vector>

#include "core/model.hpp"

namespace voussoir {

struct TriMesh {
  std::vector<Vec2> points;
  std::vector<std::array<Index, 3>> tris;  // indices into points; any orientation
};

// Structured mesh of a band of (m + 1) columns of (n + 1) nodes each (m, n >= 1).
TriMesh mesh_band(const std::vector<std::vector<Vec2>>& columns);

// A triangulation that grew past its `max_triangles` (the caller says why that bound was set).
struct MeshTooLarge : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Quality mesh of a simple counter-clockwise polygon; `size` bounds the longest edge [m].
// Throws std::invalid_argument if the polygon is not simple, and MeshTooLarge once the
// triangulation grows past `max_triangles` (0: no limit; the count includes the faces
// between the polygon and its convex hull, and one per hull edge).
TriMesh triangulate_polygon(const std::vector<Vec2>& boundary, double size,
                            std::size_t max_triangles = 0);

// Convex hull of a point set, counter-clockwise, without collinear points (CGAL::convex_hull_2;
// here because CGAL is confined to mesh/triangulate_cgal.cpp).
std::vector<Vec2> convex_hull(const std::vector<Vec2>& points);

// Quality mesh of the polygon symmetric about x = 0 whose right half is bounded by
// `right_chain` (counter-clockwise, from a point with x == 0 through points with x > 0 to
// another point with x == 0) and by the axis between those two points; the mesh of the left
// half is the exact mirror image.
// `max_triangles` bounds the half's mesh as in triangulate_polygon.
TriMesh triangulate_symmetric(const std::vector<Vec2>& right_chain, double size,
                              std::size_t max_triangles = 0);

// Mirror image of a mesh in x = 0 (same node and triangle order).
TriMesh mirror_mesh(const TriMesh& mesh);

// Rotates every point about the origin by `angle` [rad] counter-clockwise.
void rotate_mesh(TriMesh& mesh, double angle);

// The boundary of the mesh as one counter-clockwise loop of node positions, starting at the
// boundary node with the smallest index. Throws std::invalid_argument when the boundary is
// not a single loop (holes, several pieces, non-manifold vertices).
std::vector<Vec2> boundary_loop(const TriMesh& mesh);

// Appends `a` and the points that cut segment a-b into ceil(|ab| / h) equal parts (b itself is
// not appended: it starts the next segment).
void append_segment(std::vector<Vec2>& out, Vec2 a, Vec2 b, double h);

// Area of the overlap of two meshes [m2] (sum over triangle pairs; exact-touching pairs give
// zero up to rounding).
double mesh_overlap_area(const TriMesh& a, const TriMesh& b);

// Smallest interior angle of a triangle [deg].
double triangle_min_angle_deg(Vec2 a, Vec2 b, Vec2 c);

}  // namespace voussoir

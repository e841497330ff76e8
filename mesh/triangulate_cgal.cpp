// The only file that includes CGAL: quality constrained Delaunay meshing of a simple polygon,
// the convex hull that mesh/minimal.cpp takes the width of long outlines from (contracts in
// triangulate.hpp), and the exact simplicity test of mesh/geometry.hpp.
//
// Kernel: exact predicates, inexact constructions. Input points are stored as given, so every
// boundary point becomes a node bit for bit. The mesher adds Steiner points: circumcentres
// inside, and midpoints of encroached boundary sub-segments on the boundary. The latter are
// computed in floating point and may sit one rounding off the input edge; they are snapped
// back by projection onto the input edge they lie on (p = a + s (b - a), which is exact for
// horizontal and vertical edges, the case of symmetry axes).
//
// Criteria: Delaunay_mesh_size_criteria_2(B = 0.125, size): B bounds sin^2 of the smallest
// angle (0.125 <-> 20.7 degrees, CGAL's termination limit); `size` bounds the longest edge.
// Near input corners sharper than about 60 degrees the angle bound may not be met.

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/convex_hull_2.h>

#include <iterator>
#include <sstream>
#include <stdexcept>

#include "mesh/geometry.hpp"
#include "mesh/triangulate.hpp"

namespace voussoir {

namespace {

// What the mesher's vertices carry: the node number given when the mesh is read out, and, for
// a point the mesher added on the boundary, the input edge it lies on.
struct Mark {
  Index node = -1;
  Index input_edge = -1;
};

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<Mark, Kernel,
                                                       CGAL::Delaunay_mesh_vertex_base_2<Kernel>>;
using Fb = CGAL::Delaunay_mesh_face_base_2<Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds>;
using Criteria = CGAL::Delaunay_mesh_size_criteria_2<Cdt>;
using Mesher = CGAL::Delaunay_mesher_2<Cdt, Criteria>;
using Point = Cdt::Point;
using VertexHandle = Cdt::Vertex_handle;

constexpr double kShapeBound = 0.125;  // sin^2(min angle): 20.7 degrees

std::vector<VertexHandle> constrained_neighbours(const Cdt& cdt, VertexHandle v) {
  std::vector<VertexHandle> out;
  auto e = cdt.incident_edges(v), end = e;
  do {
    if (cdt.is_infinite(*e) || !cdt.is_constrained(*e)) continue;
    const auto& [f, k] = *e;
    const VertexHandle a = f->vertex(Cdt::cw(k)), b = f->vertex(Cdt::ccw(k));
    out.push_back(a == v ? b : a);
  } while (++e != end);
  return out;
}

// Marks every point the mesher added on input edge i with i: the chain of constrained
// sub-edges that edge became is walked from input point i to input point i + 1.
void mark_boundary_points(const Cdt& cdt, const std::vector<VertexHandle>& input,
                          const std::vector<Vec2>& boundary) {
  const std::size_t nb = input.size();
  for (std::size_t i = 0; i < nb; ++i) {
    const VertexHandle a = input[i], b = input[(i + 1) % nb];
    const Vec2 ab = boundary[(i + 1) % nb] - boundary[i];
    // From a, the sub-edge along a -> b; the other one runs back along edge i - 1.
    VertexHandle prev = a, cur = b;
    double best = -2.0;
    for (VertexHandle w : constrained_neighbours(cdt, a)) {
      const Vec2 aw = Vec2{w->point().x(), w->point().y()} - boundary[i];
      const double c = dot(aw, ab) / (norm(aw) * norm(ab));
      if (c > best) best = c, cur = w;
    }
    while (cur != b) {
      if (cur->info().input_edge >= 0 || cur->info().node >= 0)
        throw std::logic_error("triangulate_polygon: the boundary chains cross");
      cur->info().input_edge = static_cast<Index>(i);
      VertexHandle next = cur;
      for (VertexHandle w : constrained_neighbours(cdt, cur))
        if (w != prev) next = w;
      if (next == cur) throw std::logic_error("triangulate_polygon: a boundary chain ends");
      prev = cur;
      cur = next;
    }
  }
}

}  // namespace

bool polygon_is_simple(const std::vector<Vec2>& polygon) {
  const std::size_t n = polygon.size();
  if (n < 3) return false;
  std::vector<Kernel::Point_2> p;
  p.reserve(n);
  for (const Vec2& v : polygon) p.emplace_back(v.x, v.y);
  // CGAL's sweep with exact predicates, O(n log n): refined outlines have up to millions of
  // points. A repeated vertex or an edge folding back onto its neighbour is not simple.
  return CGAL::is_simple_2(p.begin(), p.end(), Kernel());
}

TriMesh triangulate_polygon(const std::vector<Vec2>& boundary, double size,
                            std::size_t max_triangles) {
  if (!(size > 0.0)) throw std::invalid_argument("triangulate_polygon: size must be > 0");
  if (!polygon_is_simple(boundary))
    throw std::invalid_argument("triangulate_polygon: the outline is not a simple polygon");
  if (polygon_area(boundary) <= 0.0)
    throw std::invalid_argument("triangulate_polygon: the outline is not counter-clockwise");

  Cdt cdt;
  const std::size_t nb = boundary.size();
  std::vector<VertexHandle> input(nb);
  for (std::size_t i = 0; i < nb; ++i) input[i] = cdt.insert(Point(boundary[i].x, boundary[i].y));
  for (std::size_t i = 0; i < nb; ++i) cdt.insert_constraint(input[i], input[(i + 1) % nb]);

  // Refine one point at a time, so that an outline much thinner than `size` somewhere (a
  // sliver, a needle corner, a narrow slot), whose quality mesh grows without bound there, or
  // a mesh larger than the deck allows, is refused at the budget instead of meshed for minutes.
  Mesher mesher(cdt, Criteria(kShapeBound, size));
  mesher.init();
  while (!mesher.is_refinement_done()) {
    mesher.step_by_step_refine_mesh();
    // The data structure's count, O(1), includes the faces on the infinite vertex (one per
    // convex-hull edge); the triangulation's own count walks them at every call.
    if (max_triangles > 0 && cdt.tds().number_of_faces() > max_triangles) {
      std::ostringstream why;
      why << "its quality mesh at element size " << size << " m exceeds " << max_triangles
          << " triangles";
      throw MeshTooLarge(why.str());
    }
  }

  for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v) v->info() = {};
  for (std::size_t i = 0; i < nb; ++i) input[i]->info().node = static_cast<Index>(i);
  mark_boundary_points(cdt, input, boundary);

  // Number the nodes: input points first, in order, then the Steiner points in the order the
  // faces meet them.
  TriMesh mesh = {boundary, {}};
  auto node = [&](VertexHandle v) {
    Mark& m = v->info();
    if (m.node >= 0) return m.node;
    Vec2 p{v->point().x(), v->point().y()};
    if (m.input_edge >= 0) {
      // A Steiner point on the boundary: snapped onto its input edge.
      const Vec2 a = boundary[m.input_edge], ab = boundary[(m.input_edge + 1) % nb] - a;
      const double s = dot(p - a, ab) / dot(ab, ab);
      p = {a.x + s * ab.x, a.y + s * ab.y};
    }
    m.node = static_cast<Index>(mesh.points.size());
    mesh.points.push_back(p);
    return m.node;
  };
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (!f->is_in_domain()) continue;
    mesh.tris.push_back({node(f->vertex(0)), node(f->vertex(1)), node(f->vertex(2))});
  }
  return mesh;
}

std::vector<Vec2> convex_hull(const std::vector<Vec2>& points) {
  std::vector<Kernel::Point_2> in, out;
  in.reserve(points.size());
  for (const Vec2& p : points) in.emplace_back(p.x, p.y);
  CGAL::convex_hull_2(in.begin(), in.end(), std::back_inserter(out));
  std::vector<Vec2> hull;
  hull.reserve(out.size());
  for (const Kernel::Point_2& p : out) hull.push_back({p.x(), p.y()});
  return hull;
}

}  // namespace voussoir

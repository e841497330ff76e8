// The only file that includes CGAL: quality constrained Delaunay meshing of a simple polygon,
// and the convex hull that mesh/minimal.cpp takes the width of long outlines from (contracts
// in triangulate.hpp).
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
#include <CGAL/convex_hull_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <iterator>
#include <limits>
#include <map>
#include <stdexcept>

#include "mesh/geometry.hpp"
#include "mesh/triangulate.hpp"

namespace voussoir {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Delaunay_mesh_vertex_base_2<Kernel>;
using Fb = CGAL::Delaunay_mesh_face_base_2<Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds>;
using Criteria = CGAL::Delaunay_mesh_size_criteria_2<Cdt>;
using Point = Cdt::Point;
using VertexHandle = Cdt::Vertex_handle;

constexpr double kShapeBound = 0.125;  // sin^2(min angle): 20.7 degrees

}  // namespace

TriMesh triangulate_polygon(const std::vector<Vec2>& boundary, double size) {
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

  CGAL::refine_Delaunay_mesh_2(cdt, Criteria(kShapeBound, size));

  // Number the nodes: input points first, in order, then the Steiner points.
  std::map<VertexHandle, Index> index;
  TriMesh mesh;
  for (std::size_t i = 0; i < nb; ++i) {
    index.emplace(input[i], static_cast<Index>(i));
    mesh.points.push_back(boundary[i]);
  }
  auto node = [&](VertexHandle v) {
    const auto [it, fresh] = index.emplace(v, static_cast<Index>(mesh.points.size()));
    if (fresh) {
      Vec2 p{v->point().x(), v->point().y()};
      // A Steiner point with a constrained incident edge lies on the boundary: snap it onto
      // the input edge it belongs to (the nearest one).
      bool on_boundary = false;
      auto e = cdt.incident_edges(v), end = e;
      do {
        if (!cdt.is_infinite(*e) && cdt.is_constrained(*e)) on_boundary = true;
      } while (++e != end && !on_boundary);
      if (on_boundary) {
        double best = std::numeric_limits<double>::infinity();
        Vec2 snapped = p;
        for (std::size_t i = 0; i < nb; ++i) {
          const Vec2 a = boundary[i], b = boundary[(i + 1) % nb];
          const double d = distance_to_segment(p, a, b);
          if (d < best) {
            best = d;
            const Vec2 ab = b - a;
            const double s = dot(p - a, ab) / dot(ab, ab);
            snapped = {a.x + s * ab.x, a.y + s * ab.y};
          }
        }
        p = snapped;
      }
      mesh.points.push_back(p);
    }
    return it->second;
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

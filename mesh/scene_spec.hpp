#pragma once
// A scene before meshing: the blocks of a deck's [model] with their exact outlines, how each
// is to be meshed, and the joints between them. `build_model` (mesh/scene.hpp) is
// `mesh_scene(build_scene(params), params)`; tests use the two halves separately (exact
// outline areas, centreline geometry).
//
// Conventions shared by every generator (docs/reference/deck.md, [model]):
//   - a key the deck did not give (ModelConfig::given) takes the default of the scene kind
//     where the published geometry gives one that differs from core/schema.hpp's: the church's
//     thickness is 0.5 m and a block's height 1.0 m;
//   - lengths in m, angles in the deck in degrees, here in radians unless the name says deg;
//   - a scene that is mirror-symmetric has its axis at x = 0; the blocks of its left half are
//     built as exact mirror images (sign of x flipped) of those of its right half, and blocks
//     that straddle the axis are meshed half and mirrored, so the whole mesh mirrors onto
//     itself bit for bit;
//   - blocks that share a joint face get the very same doubles for the face's points (computed
//     once), so faces coincide exactly and never overlap;
//   - Joint::a is the intrados end and Joint::b the extrados end of an arch joint; for a
//     course joint a is the end on the arch side (inner face); for a joint with the ground and
//     between stacked blocks a is the left end. Joint::position_deg is the turning angle of an
//     arch joint from the left springing joint of its arch, in degrees (0 at the left
//     springing, the embrace at the right one; for a pointed church arch 0 .. 180); joints that
//     are not arch joints (courses, ground, stacks, polygon files) carry NaN — their height is
//     Joint::a.y.

#include <string>
#include <vector>

#include "core/model.hpp"
#include "core/schema.hpp"
#include "mesh/geometry.hpp"
#include "mesh/triangulate.hpp"

namespace voussoir {

struct BlockSpec {
  enum class Mesher {
    Band,              // structured: `columns` (mesh_band)
    Polygon,           // CGAL: `boundary` (counter-clockwise), longest edge <= `size`
    SymmetricPolygon,  // CGAL on the right half: `boundary` is the right chain (see
                       // triangulate_symmetric), mirrored onto the left half
    Mirror,            // the mirror image in x = 0 of block `mirror_of`'s mesh
    Given,             // `mesh` already filled (gmsh import)
  };
  std::string role;  // voussoir, crown, abutment, buttress, pier, ground, block
  std::string name;  // gmsh import: the block's physical name; empty otherwise
  bool fixed = false;
  Outline outline;  // exact outline, counter-clockwise (arcs where the block has arcs)
  Mesher mesher = Mesher::Polygon;
  std::vector<std::vector<Vec2>> columns;
  std::vector<Vec2> boundary;
  double size = 0.0;
  Index mirror_of = -1;
  TriMesh mesh;  // filled by mesh_scene (or by the generator for Given)
};

// One circular piece of an arch centreline, traversed from `start` by the signed `sweep` [rad]
// (negative: clockwise, left to right over the arch).
struct ArcPiece {
  Vec2 centre;
  double radius = 0.0;
  double start = 0.0;
  double sweep = 0.0;
};

struct Scene {
  std::string kind;
  std::vector<BlockSpec> blocks;
  std::vector<Joint> joints;
  bool symmetric = false;     // mirror-symmetric about x = 0
  double element_size = 0.0;  // target element size h used [m]
  // Rotation about the origin [rad, counter-clockwise] applied to every mesh after meshing
  // (block scene on an incline); outlines and joints are stored already rotated.
  double rotation = 0.0;
  // User-drawn blocks (polygons): refuse the model if two blocks overlap after meshing.
  bool check_overlaps = false;
  // Arch scenes: the centreline from the left springing to the right one, its length and the
  // (intrados-to-extrados) thickness. Empty for other scenes.
  std::vector<ArcPiece> centreline;
  double centreline_length = 0.0;
  double arch_thickness = 0.0;
  int through_thickness = 0;  // cells across the arch thickness (arch scenes)
  int cells_along = 0;        // cells along each voussoir (arch scenes)
};

// Builds the scene of the deck's [model] (not yet meshed). Throws DeckError for a geometry
// the keys cannot make, naming the key, its value and what is wrong.
Scene build_scene(const SceneParams& params);

// Meshes every block of the scene, builds the Model (material, out_of_plane, joints) and
// finalizes it. Fills BlockSpec::mesh of every block. Throws DeckError naming
// mesh.max_triangles when the scene's estimate, one block's mesh while it is refined, or the
// finished mesh exceeds it.
Model mesh_scene(Scene& scene, const SceneParams& params);

// Point of the centreline at arc length s from the left springing.
Vec2 centreline_point(const Scene& scene, double s);

// Collects boundary points, dropping a point equal to the previous one, so chains of segments
// and shared faces can be appended end to end.
struct PointChain {
  std::vector<Vec2> points;
  void add(Vec2 p) {
    if (points.empty() || p.x != points.back().x || p.y != points.back().y) points.push_back(p);
  }
  void add(const std::vector<Vec2>& ps) {
    for (const Vec2& p : ps) add(p);
  }
  void add_reversed(const std::vector<Vec2>& ps) {
    for (auto it = ps.rbegin(); it != ps.rend(); ++it) add(*it);
  }
  // Segment a-b cut into parts no longer than h (both ends added).
  void segment(Vec2 a, Vec2 b, double h) {
    std::vector<Vec2> cut;
    append_segment(cut, a, b, h);
    add(cut);
    add(b);
  }
  // The closed loop (the last point dropped when it repeats the first).
  std::vector<Vec2> loop() const {
    std::vector<Vec2> out = points;
    if (out.size() > 1 && out.front().x == out.back().x && out.front().y == out.back().y)
      out.pop_back();
    return out;
  }
};

// Generators (mesh/scenes_*.cpp), one per SceneBuilder of core/scene_kinds.hpp.
Scene build_arch_scene(const SceneParams& params);      // circular_arch, basket_arch, buttressed
Scene build_church_scene(const SceneParams& params);    // church
Scene build_block_scene(const SceneParams& params);     // block
Scene build_polygons_scene(const SceneParams& params);  // polygons

// Element size h of the scene: mesh.size if given, else `reference / mesh.through_thickness`
// (reference: the arch thickness; the block scene's min(width, height); the smallest free
// polygon's narrowest side). h is the side of a structured cell (cells are then adjusted to
// an aspect within 1 : 1.8, see choose_band_cells); blocks meshed by CGAL get a longest-edge
// bound of sqrt(2) h, the diagonal of such a cell, with their boundary cut every h; fixed
// blocks are three times coarser inside (3 sqrt(2) h) but keep the nodes of the free blocks'
// faces on theirs.
double element_size(const SceneParams& params, double reference);

// Throws DeckError naming mesh.size (or mesh.through_thickness) when a mesh of about
// `estimate` triangles would exceed mesh.max_triangles. Generators call it before allocating a
// structured mesh; mesh_scene calls it for the whole scene and holds each polygon block, and
// the finished mesh, to the same limit.
void check_triangle_budget(const SceneParams& params, double estimate);

// Throws DeckError "<deck>: model.<key> = <value>: <why>".
[[noreturn]] void geometry_error(const SceneParams& params, const std::string& key, double value,
                                 const std::string& why);
[[noreturn]] void geometry_error(const SceneParams& params, const std::string& key,
                                 const std::string& value, const std::string& why);

// Throws DeckError naming model.fixed when one of its indices is not a block of the `nb`
// blocks of `what` ("the file", "the model").
void check_fixed_indices(const SceneParams& params, std::size_t nb, const std::string& what);

// Chooses the cells of a voussoir-like band: n across the thickness t, m along the centreline
// length L, from element size h, then refines whichever direction is too long so that the
// cell aspect (along the intrados and the extrados, whose lengths are L (1 -+ q) with
// q = t / (2 R) for the tightest centreline radius R; q = 0 for straight bands) stays within
// 1 : 1.8, which keeps every triangle angle above about 25 degrees.
void choose_band_cells(double t, double length, double curvature_ratio, double h, int* n, int* m);

}  // namespace voussoir

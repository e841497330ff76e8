// build_model: scene parameters -> scene (the generator of the kind, core/scene_kinds.hpp and
// mesh/scenes_*.cpp) -> meshed, finalized Model. Also the shared helpers of the generators
// (element size, band cell choice, geometry errors) and the mesh quality figure reported by
// `voussoir check`.

#include "mesh/scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <new>
#include <sstream>
#include <stdexcept>

#include "core/scene_kinds.hpp"
#include "core/schema.hpp"
#include "mesh/scene_spec.hpp"

namespace voussoir {

namespace {

// The mesh of one polygon block is refused once it grows past this many times the estimate of
// the triangle budget (5 area / size^2), plus a floor for small blocks: a quality mesh grows far
// beyond its area's share only where the outline is much thinner than the element size (a
// sliver, a needle corner, a narrow slot), and there it may not stop (docs/robustness.md, "Open
// findings"). The largest polygon block of a shipped deck uses 8% of its cap. Never above
// mesh.max_triangles.
constexpr double kPolygonMeshSlack = 10.0;
constexpr double kPolygonMeshFloor = 1e4;

double polygon_mesh_slack_cap(const BlockSpec& b) {
  const double estimate = 5.0 * std::abs(outline_area(b.outline)) / (b.size * b.size);
  return kPolygonMeshSlack * estimate + kPolygonMeshFloor;
}

std::string format_number(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

}  // namespace

[[noreturn]] void geometry_error(const SceneParams& params, const std::string& key, double value,
                                 const std::string& why) {
  geometry_error(params, key, format_number(value), why);
}

[[noreturn]] void geometry_error(const SceneParams& params, const std::string& key,
                                 const std::string& value, const std::string& why) {
  const std::string where = params.deck_path.empty() ? std::string() : params.deck_path + ": ";
  throw DeckError(where + key + " = " + value + ": " + why);
}

double element_size(const SceneParams& params, double reference) {
  if (params.mesh.size > 0.0) return params.mesh.size;
  const int n = params.mesh.through_thickness;
  if (n < 1)
    geometry_error(params, VOUSSOIR_KEY(mesh.through_thickness), n, "expected an integer >= 1");
  return reference / n;
}

void choose_band_cells(double t, double length, double curvature_ratio, double h, int* n, int* m) {
  // Cell: b = t / n across, a = L / m along the centreline; along the intrados and extrados
  // the cell is a (1 -+ q) long, q = t / (2 R) the curvature ratio of the tightest arc.
  constexpr double kAspect = 1.8;  // largest side ratio accepted
  constexpr double kTarget = 1.2;  // side ratio aimed at when refining
  const double q = std::clamp(curvature_ratio, 0.0, 0.9);
  *n = std::max(1, static_cast<int>(std::lround(t / h)));
  *m = std::max(1, static_cast<int>(std::lround(length / h)));
  const double a_in = length * (1.0 - q) / *m, a_out = length * (1.0 + q) / *m;
  const double b = t / *n;
  if (b > kAspect * a_in) {
    *n = static_cast<int>(std::ceil(t / (kTarget * a_in)));
  } else if (a_out > kAspect * b) {
    *m = static_cast<int>(std::ceil(length * (1.0 + q) / (kTarget * b)));
  }
}

void check_triangle_budget(const SceneParams& params, double estimate) {
  if (estimate <= params.mesh.max_triangles) return;
  std::ostringstream why;
  why << "would make about " << static_cast<long long>(estimate) << " triangles (limit "
      << VOUSSOIR_KEY(mesh.max_triangles) << " = " << params.mesh.max_triangles
      << "); use a coarser mesh";
  if (params.mesh.size > 0.0)
    geometry_error(params, VOUSSOIR_KEY(mesh.size), params.mesh.size, why.str());
  geometry_error(params, VOUSSOIR_KEY(mesh.through_thickness), params.mesh.through_thickness,
                 why.str());
}

Scene build_scene(const SceneParams& params) {
  const std::string& kind = params.model.kind;
  const SceneKind* entry = find_scene_kind(kind);
  if (entry == nullptr) {
    std::string names;
    for (const std::string& n : scene_kind_names()) names += (names.empty() ? "" : ", ") + n;
    geometry_error(params, VOUSSOIR_KEY(model.kind), "\"" + kind + "\"",
                   "unknown scene (" + names + ")");
  }
  Scene scene;
  switch (entry->builder) {
    case SceneBuilder::Arch:
      scene = build_arch_scene(params);
      break;
    case SceneBuilder::Church:
      scene = build_church_scene(params);
      break;
    case SceneBuilder::Block:
      scene = build_block_scene(params);
      break;
    case SceneBuilder::Polygons:
      scene = build_polygons_scene(params);
      break;
  }
  scene.kind = kind;
  return scene;
}

Model mesh_scene(Scene& scene, const SceneParams& params) {
  // Refuse meshes that would not fit in memory before building them.
  double estimate = 0.0;
  for (const BlockSpec& b : scene.blocks) {
    if (b.mesher == BlockSpec::Mesher::Polygon || b.mesher == BlockSpec::Mesher::SymmetricPolygon) {
      const double area = std::abs(outline_area(b.outline));
      estimate += 5.0 * area / (b.size * b.size);  // CGAL triangles ~ 0.2 size^2 each
    } else if (b.mesher == BlockSpec::Mesher::Band && !b.columns.empty()) {
      estimate += 2.0 * static_cast<double>(b.columns.size()) * b.columns[0].size();
    }
  }
  check_triangle_budget(params, estimate);

  // Mesh every block that is not a mirror first, then the mirrors.
  const double limit = params.mesh.max_triangles;
  for (std::size_t i = 0; i < scene.blocks.size(); ++i) {
    BlockSpec& b = scene.blocks[i];
    const bool polygon =
        b.mesher == BlockSpec::Mesher::Polygon || b.mesher == BlockSpec::Mesher::SymmetricPolygon;
    const double slack_cap = polygon ? polygon_mesh_slack_cap(b) : 0.0;
    const std::size_t cap = polygon ? static_cast<std::size_t>(std::min(slack_cap, limit)) : 0;
    try {
      switch (b.mesher) {
        case BlockSpec::Mesher::Band:
          b.mesh = mesh_band(b.columns);
          break;
        case BlockSpec::Mesher::Polygon:
          b.mesh = triangulate_polygon(b.boundary, b.size, cap);
          break;
        case BlockSpec::Mesher::SymmetricPolygon:
          b.mesh = triangulate_symmetric(b.boundary, b.size, cap);
          break;
        case BlockSpec::Mesher::Mirror:
        case BlockSpec::Mesher::Given:
          break;
      }
    } catch (const MeshTooLarge& e) {
      if (slack_cap < limit)
        throw std::runtime_error("block " + std::to_string(i) + ": " + e.what() +
                                 ": the outline is far thinner than the element size somewhere "
                                 "(a sliver, a needle corner or a narrow slot)");
      geometry_error(params, VOUSSOIR_KEY(mesh.max_triangles), params.mesh.max_triangles,
                     "block " + std::to_string(i) + ": " + e.what() +
                         "; use a coarser mesh or raise " + VOUSSOIR_KEY(mesh.max_triangles));
    } catch (const std::exception& e) {
      // The block is named in build_model's report; a deck error and a mesh that does not fit
      // in memory keep their own reports there.
      if (dynamic_cast<const DeckError*>(&e) || dynamic_cast<const std::bad_alloc*>(&e) ||
          dynamic_cast<const std::length_error*>(&e))
        throw;
      throw std::runtime_error("block " + std::to_string(i) + ": " + e.what());
    }
  }
  for (BlockSpec& b : scene.blocks) {
    if (b.mesher != BlockSpec::Mesher::Mirror) continue;
    const BlockSpec& src = scene.blocks.at(b.mirror_of);
    if (src.mesher == BlockSpec::Mesher::Mirror)
      throw std::logic_error("mesh_scene: a mirror of a mirror");
    b.mesh = mirror_mesh(src.mesh);
  }

  if (scene.rotation != 0.0)
    for (BlockSpec& b : scene.blocks) rotate_mesh(b.mesh, scene.rotation);

  // The estimates above are approximate (a long thin fixed block meshes finer than its area
  // says): the finished mesh is held to the limit too, before a model is built from it.
  std::size_t triangles = 0;
  for (const BlockSpec& b : scene.blocks) triangles += b.mesh.tris.size();
  if (static_cast<double>(triangles) > limit)
    geometry_error(params, VOUSSOIR_KEY(mesh.max_triangles), params.mesh.max_triangles,
                   "the mesh has " + std::to_string(triangles) +
                       " triangles, more than the limit; use a coarser mesh or raise " +
                       VOUSSOIR_KEY(mesh.max_triangles));

  if (scene.check_overlaps) {
    // User-drawn blocks must not overlap: compare every pair whose boxes meet.
    const std::size_t nb = scene.blocks.size();
    std::vector<std::array<double, 4>> box(nb);
    for (std::size_t i = 0; i < nb; ++i) {
      box[i] = {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
      for (const Vec2& p : scene.blocks[i].mesh.points) {
        box[i][0] = std::min(box[i][0], p.x);
        box[i][1] = std::max(box[i][1], p.x);
        box[i][2] = std::min(box[i][2], p.y);
        box[i][3] = std::max(box[i][3], p.y);
      }
    }
    for (std::size_t i = 0; i < nb; ++i)
      for (std::size_t j = i + 1; j < nb; ++j) {
        if (box[i][1] < box[j][0] || box[j][1] < box[i][0] || box[i][3] < box[j][2] ||
            box[j][3] < box[i][2])
          continue;
        const double area = mesh_overlap_area(scene.blocks[i].mesh, scene.blocks[j].mesh);
        const double ai = std::abs(outline_area(scene.blocks[i].outline));
        const double aj = std::abs(outline_area(scene.blocks[j].outline));
        if (area > 1e-9 * std::min(ai, aj)) {
          std::ostringstream why;
          why << "blocks " << i << " and " << j << " overlap (area " << area
              << " m2); blocks may touch but not overlap";
          geometry_error(params, VOUSSOIR_KEY(model.file), "'" + params.model.file + "'",
                         why.str());
        }
      }
  }

  Model model;
  model.kind = scene.kind;
  for (const BlockSpec& b : scene.blocks) {
    add_block(model, boundary_loop(b.mesh), b.mesh.points, b.mesh.tris, b.fixed, b.role);
    model.blocks.back().name = b.name;
  }
  model.joints = scene.joints;
  model.material.density = params.material.density;
  model.material.young = params.material.young;
  model.material.poisson = params.material.poisson;
  model.material.plane_stress = params.material.plane == "stress";
  model.out_of_plane = params.model.out_of_plane;
  finalize_model(model);
  return model;
}

void check_fixed_indices(const SceneParams& params, std::size_t nb, const std::string& what) {
  for (int f : params.model.fixed)
    if (f < 0 || static_cast<std::size_t>(f) >= nb)
      geometry_error(params, VOUSSOIR_KEY(model.fixed), f,
                     "no such block: " + what + " has " + std::to_string(nb) +
                         " blocks (indices 0.." + std::to_string(nb - 1) + ")");
}

namespace {

// model.fixed on a generated scene (the polygons kind reads it itself): the listed blocks are
// fixed as well as the scene's own supports, e.g. a church pier that is to settle with its
// foundation ([supports], docs/supports.md). Every block fixed is refused as for polygons.
void fix_listed_blocks(Scene& scene, const SceneParams& params) {
  const ModelConfig& mc = params.model;
  if (mc.kind == "polygons" || mc.fixed.empty()) return;
  check_fixed_indices(params, scene.blocks.size(), "the model");
  for (int f : mc.fixed) scene.blocks[std::size_t(f)].fixed = true;
  std::size_t free = 0;
  for (const BlockSpec& b : scene.blocks) free += b.fixed ? 0 : 1;
  if (free == 0)
    geometry_error(params, VOUSSOIR_KEY(model.fixed), mc.fixed.front(),
                   "every block of the model would be fixed; leave at least one free");
}

}  // namespace

Model build_model(const SceneParams& params) {
  // The checks of build_scene and the triangle budget catch the usual bad values; what still
  // fails inside the meshers (outlines that degenerate at extreme values, sizes whose boundary
  // subdivision overflows memory, found by tests/unit/test_fuzz.cpp) is a bad deck too, and
  // is reported as one (exit status 2), naming what went wrong.
  const std::string where = params.deck_path.empty() ? std::string() : params.deck_path + ": ";
  try {
    Scene scene = build_scene(params);
    fix_listed_blocks(scene, params);
    return mesh_scene(scene, params);
  } catch (const DeckError&) {
    throw;
  } catch (const std::length_error&) {
    throw DeckError(where +
                    "the mesh of this model does not fit in memory: check the [model] "
                    "dimensions against " +
                    VOUSSOIR_KEY(mesh.size) + " / " + VOUSSOIR_KEY(mesh.through_thickness));
  } catch (const std::bad_alloc&) {
    throw DeckError(where +
                    "the mesh of this model does not fit in memory: check the [model] "
                    "dimensions against " +
                    VOUSSOIR_KEY(mesh.size) + " / " + VOUSSOIR_KEY(mesh.through_thickness));
  } catch (const std::exception& e) {
    throw DeckError(where + "the model cannot be meshed (" + e.what() +
                    "): check the [model] values (angles, dimensions) for degenerate blocks");
  }
}

Vec2 centreline_point(const Scene& scene, double s) {
  double start = 0.0;
  for (std::size_t k = 0; k < scene.centreline.size(); ++k) {
    const ArcPiece& p = scene.centreline[k];
    const double len = p.radius * std::abs(p.sweep);
    if (s <= start + len || k + 1 == scene.centreline.size()) {
      const double theta = p.start + std::copysign((s - start) / p.radius, p.sweep);
      return on_circle(p.centre, p.radius, theta);
    }
    start += len;
  }
  throw std::logic_error("centreline_point: the scene has no centreline");
}

double worst_triangle_angle_deg(const Model& model) {
  const Nodes& n = model.nodes;
  const Triangles& t = model.tris;
  double worst = t.size() > 0 ? 180.0 : std::numeric_limits<double>::quiet_NaN();
  for (Index e = 0; e < t.size(); ++e) {
    const Vec2 a{n.x0[t.n0[e]], n.y0[t.n0[e]]}, b{n.x0[t.n1[e]], n.y0[t.n1[e]]},
        c{n.x0[t.n2[e]], n.y0[t.n2[e]]};
    worst = std::min(worst, triangle_min_angle_deg(a, b, c));
  }
  return worst;
}

}  // namespace voussoir

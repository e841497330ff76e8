// The polygons scene (docs/reference/deck.md, [model]): blocks read from a file, fixed ones listed
// by `model.fixed` (0-based block indices).
//
// Two file formats, told apart by content (a gmsh file starts with `$MeshFormat`):
//
// 1. Polygon text file. One vertex `x y` per line (a comma may separate them); a block ends at
//    a blank line or at a line `block`, which may also start the file; `#` starts a comment;
//    a last vertex repeating the first is dropped. Each block must be a simple polygon (any
//    orientation, convex or not) with at least three vertices and no corner sharper than 1
//    degree (nor a notch narrower); blocks may touch and share edges but not overlap. Blocks are
//    numbered from 0 in file order. Example:
//        # ground, then a block on it
//        block
//        -2 -0.5
//         2 -0.5
//         2  0
//        -2  0
//        block
//        -0.25 0
//         0.25 0
//         0.25 1
//        -0.25 1
//    Each block is meshed by the constrained quality mesher with elements about mesh.size (or,
//    without it, the smallest free block's narrowest bounding-box side / through_thickness).
//    A vertex of one block lying on an edge of another (a T-junction) becomes a node of both,
//    and edges are cut from their lexicographically smaller end, so two blocks that share a
//    face get the same nodes on it.
//
// 2. gmsh MSH 4.1 ASCII. Every 3-node triangle (element type 2) on a surface belongs to the
//    block of that surface's (first) physical tag; blocks are numbered in ascending physical
//    tag order. If no surface has a physical tag, each surface is one block (ascending surface
//    tag). Lines and points are ignored; any other surface element (quadrangles, second-order
//    triangles) is refused, and so is a block whose triangles do not form one piece without
//    holes. The mesh is used as is (mesh.size does not apply). Each block keeps the name of
//    its physical surface ($PhysicalNames; "physical TAG" when unnamed, "surface TAG" without
//    physical tags), which `check` prints beside the block index. docs/gmsh.md is the user's
//    guide.
//
// Joints: every pair of blocks whose outlines share a straight piece (collinear edges,
// opposite directions, overlapping over more than 1e-9 of the edge) gets a Joint for the
// shared piece (a = its end with the smaller x, then smaller y; position NaN). The outlines
// are first reduced to their corners (merge_collinear, mesh/geometry.hpp): a gmsh block's
// boundary has a node every mesh edge along a straight side, and a polygon file may give
// points along a side; either way one physical interface is one joint. (Before, a 3 x 2
// gmsh wall on a ground had 46 joints, one per pair of facing mesh edges; now 10.)

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "mesh/scene_spec.hpp"

namespace voussoir {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kFixedCoarsening = 3.0;

struct FileError {
  std::string what;
};

std::string trim(const std::string& s) {
  std::size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

// ---- polygon text files ----

// A corner sharper than this, or a notch narrower (interior angle above 360 degrees minus it),
// is refused: near it the two edges run closer than any element size for a long way, and the
// constrained triangulation of the refined outline grows without bound there (slow fuzz tier:
// a vertex moved to x = 65536 made a 4e-6 rad needle that kept `check` busy for
// minutes). Drawn masonry has no such corners; a stray or mistyped vertex does.
constexpr double kMinCornerDeg = 1.0;

void check_corners(const std::vector<Vec2>& p, const std::vector<int>& lines,
                   const std::string& name, std::size_t block) {
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 u = p[(i + 1) % n] - p[i], v = p[(i + n - 1) % n] - p[i];
    double interior = std::atan2(cross(u, v), dot(u, v)) * 180.0 / std::numbers::pi;
    if (interior < 0.0) interior += 360.0;  // counter-clockwise polygon: a reflex corner
    if (interior >= kMinCornerDeg && interior <= 360.0 - kMinCornerDeg) continue;
    std::ostringstream why;
    why.precision(6);
    why << name << ":" << lines[i] << ": block " << block << ": the corner at vertex (" << p[i].x
        << ", " << p[i].y << ") is " << (interior < 180.0 ? "a needle of " : "a notch of ")
        << (interior < 180.0 ? interior : 360.0 - interior)
        << " degrees; corners and notches under " << kMinCornerDeg
        << " degree cannot be meshed (check that vertex and its neighbours)";
    throw FileError{why.str()};
  }
}

std::vector<std::vector<Vec2>> read_polygon_text(const std::string& text, const std::string& name) {
  std::vector<std::vector<Vec2>> blocks;
  std::vector<std::vector<int>> vertex_lines;
  std::vector<Vec2> cur;
  std::vector<int> cur_lines;
  auto close = [&]() {
    if (!cur.empty()) {
      blocks.push_back(cur);
      vertex_lines.push_back(cur_lines);
      cur.clear();
      cur_lines.clear();
    }
  };
  std::istringstream in(text);
  std::string line;
  for (int ln = 1; std::getline(in, line); ++ln) {
    const std::size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    const std::string s = trim(line);
    if (s.empty()) {
      close();
      continue;
    }
    std::string lower = s;
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    if (lower.rfind("block", 0) == 0) {
      if (trim(lower.substr(5)).size() != 0)
        throw FileError{name + ":" + std::to_string(ln) + ": expected 'block' alone on its line"};
      close();
      continue;
    }
    std::string xy = s;
    std::replace(xy.begin(), xy.end(), ',', ' ');
    std::istringstream v(xy);
    double x = 0.0, y = 0.0;
    std::string extra;
    if (!(v >> x >> y) || (v >> extra) || !std::isfinite(x) || !std::isfinite(y))
      throw FileError{name + ":" + std::to_string(ln) + ": expected a vertex 'x y', got '" + s +
                      "'"};
    cur.push_back({x, y});
    cur_lines.push_back(ln);
  }
  close();
  if (blocks.empty()) throw FileError{name + ": no blocks (expected lines 'x y')"};
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    std::vector<Vec2>& p = blocks[b];
    std::vector<int>& lines = vertex_lines[b];
    if (p.size() > 1 && p.front().x == p.back().x && p.front().y == p.back().y) {
      p.pop_back();
      lines.pop_back();
    }
    const std::string where =
        name + ":" + std::to_string(lines.front()) + ": block " + std::to_string(b) + ": ";
    if (p.size() < 3)
      throw FileError{where + "a block needs at least 3 vertices, got " + std::to_string(p.size())};
    if (!polygon_is_simple(p))
      throw FileError{where +
                      "the polygon is not simple (edges cross or touch, or a vertex repeats)"};
    if (polygon_area(p) < 0.0) {
      std::reverse(p.begin(), p.end());
      std::reverse(lines.begin(), lines.end());
    }
    check_corners(p, lines, name, b);
  }
  return blocks;
}

// ---- gmsh MSH 4.1 ASCII ----

struct GmshBlocks {
  std::vector<TriMesh> meshes;
  std::vector<int> tags;
  std::vector<std::string> names;  // physical name, "physical TAG" or "surface TAG"
};

// The sections of an MSH 4.1 ASCII file that make blocks: the physical tags and names of the
// surfaces, the nodes, the triangles of each surface.
struct GmshSections {
  std::map<int, int> surface_physical;        // surface tag -> first physical tag (absent: none)
  std::map<int, std::string> physical_names;  // physical surface tag -> its name
  std::map<std::size_t, std::array<double, 3>> nodes;
  std::map<int, std::vector<std::array<std::size_t, 3>>> surface_tris;
};

GmshSections read_gmsh_sections(const std::string& text, const std::string& name) {
  std::istringstream in(text);
  std::string tok;
  auto fail = [&](const std::string& why) { throw FileError{name + ": " + why}; };
  GmshSections sections;
  auto& [surface_physical, physical_names, nodes, surface_tris] = sections;
  bool format_ok = false;
  while (in >> tok) {
    if (tok == "$MeshFormat") {
      double version = 0.0;
      int binary = 0, dsize = 0;
      if (!(in >> version >> binary >> dsize)) fail("unreadable $MeshFormat");
      if (version < 4.1 || version >= 5.0)
        fail("gmsh format " + std::to_string(version).substr(0, 3) +
             " is not supported; save as MSH 4.1 ASCII (Mesh.MshFileVersion = 4.1)");
      if (binary != 0) fail("binary gmsh files are not supported; save as ASCII");
      format_ok = true;
      in >> tok;  // $EndMeshFormat
    } else if (tok == "$PhysicalNames") {
      std::size_t count = 0;
      if (!(in >> count)) fail("unreadable $PhysicalNames");
      for (std::size_t k = 0; k < count; ++k) {
        int dim = 0, tag = 0;
        std::string rest;
        if (!(in >> dim >> tag) || !std::getline(in, rest)) fail("unreadable physical name");
        rest = trim(rest);
        if (rest.size() >= 2 && rest.front() == '"' && rest.back() == '"')
          rest = rest.substr(1, rest.size() - 2);
        if (dim == 2) physical_names[tag] = rest;
      }
      in >> tok;  // $EndPhysicalNames
    } else if (tok == "$Entities") {
      std::size_t np = 0, nc = 0, nsurf = 0, nvol = 0;
      if (!(in >> np >> nc >> nsurf >> nvol)) fail("unreadable $Entities");
      for (std::size_t i = 0; i < np; ++i) {
        int tag, nphys;
        double x, y, z;
        if (!(in >> tag >> x >> y >> z >> nphys)) fail("unreadable point entity");
        for (int k = 0; k < nphys; ++k) in >> tag;
      }
      for (std::size_t i = 0; i < nc + nsurf + nvol; ++i) {
        int tag, nphys, nbound;
        double bb[6];
        if (!(in >> tag >> bb[0] >> bb[1] >> bb[2] >> bb[3] >> bb[4] >> bb[5] >> nphys))
          fail("unreadable entity in $Entities");
        for (int k = 0; k < nphys; ++k) {
          int phys;
          in >> phys;
          if (i >= nc && i < nc + nsurf && k == 0) surface_physical[tag] = phys;
        }
        if (!(in >> nbound)) fail("unreadable entity in $Entities");
        for (int k = 0; k < nbound; ++k) in >> tok;
      }
      in >> tok;  // $EndEntities
    } else if (tok == "$Nodes") {
      std::size_t nblocks = 0, nnodes = 0, mintag = 0, maxtag = 0;
      if (!(in >> nblocks >> nnodes >> mintag >> maxtag)) fail("unreadable $Nodes");
      for (std::size_t b = 0; b < nblocks; ++b) {
        int dim, tag, parametric;
        std::size_t count;
        if (!(in >> dim >> tag >> parametric >> count)) fail("unreadable node block");
        std::vector<std::size_t> ids(count);
        for (auto& id : ids) in >> id;
        for (std::size_t k = 0; k < count; ++k) {
          std::array<double, 3> p{};
          if (!(in >> p[0] >> p[1] >> p[2])) fail("unreadable node coordinates");
          for (int q = 0; parametric && q < dim; ++q) in >> tok;
          nodes[ids[k]] = p;
        }
      }
      in >> tok;  // $EndNodes
    } else if (tok == "$Elements") {
      std::size_t nblocks = 0, nel = 0, mintag = 0, maxtag = 0;
      if (!(in >> nblocks >> nel >> mintag >> maxtag)) fail("unreadable $Elements");
      static const std::map<int, int> nodes_of = {{1, 2},   {2, 3},  {3, 4},  {4, 4},  {8, 3},
                                                  {9, 6},   {10, 9}, {15, 1}, {16, 8}, {20, 9},
                                                  {21, 10}, {26, 4}, {27, 5}, {28, 6}};
      for (std::size_t b = 0; b < nblocks; ++b) {
        int dim, tag, type;
        std::size_t count;
        if (!(in >> dim >> tag >> type >> count)) fail("unreadable element block");
        const auto it = nodes_of.find(type);
        if (it == nodes_of.end()) fail("unknown element type " + std::to_string(type));
        if (dim == 2 && type != 2)
          fail("surface " + std::to_string(tag) + " has elements of type " + std::to_string(type) +
               "; only 3-node triangles (type 2) are supported");
        if (dim == 3) fail("3D elements found; voussoir reads 2D triangle meshes");
        for (std::size_t k = 0; k < count; ++k) {
          std::size_t id;
          in >> id;
          std::array<std::size_t, 3> tri{};
          for (int q = 0; q < it->second; ++q) {
            std::size_t v;
            if (!(in >> v)) fail("unreadable element");
            if (dim == 2 && q < 3) tri[q] = v;
          }
          if (dim == 2) surface_tris[tag].push_back(tri);
        }
      }
      in >> tok;  // $EndElements
    } else if (tok.size() > 1 && tok[0] == '$' && tok.rfind("$End", 0) != 0) {
      const std::string end = "$End" + tok.substr(1);
      while (in >> tok && tok != end) {
      }
    }
  }
  if (!format_ok) fail("no $MeshFormat section");
  if (surface_tris.empty()) fail("no triangles on any surface");
  return sections;
}

GmshBlocks read_gmsh(const std::string& text, const std::string& name) {
  auto fail = [&](const std::string& why) { throw FileError{name + ": " + why}; };
  const GmshSections sections = read_gmsh_sections(text, name);
  const auto& [surface_physical, physical_names, nodes, surface_tris] = sections;

  // Surfaces -> blocks.
  bool any_phys = false, all_phys = true;
  for (const auto& [s, tris] : surface_tris) {
    const bool has = surface_physical.count(s) != 0;
    any_phys = any_phys || has;
    all_phys = all_phys && has;
  }
  if (any_phys && !all_phys)
    fail("some surfaces have a physical tag and some do not; give each block a Physical Surface");
  std::map<int, std::vector<std::array<std::size_t, 3>>> by_block;
  for (const auto& [s, tris] : surface_tris) {
    auto& dst = by_block[any_phys ? surface_physical.at(s) : s];
    dst.insert(dst.end(), tris.begin(), tris.end());
  }
  double scale = 0.0;
  for (const auto& [id, p] : nodes) scale = std::max({scale, std::abs(p[0]), std::abs(p[1])});
  GmshBlocks out;
  for (const auto& [tag, tris] : by_block) {
    TriMesh mesh;
    std::map<std::size_t, Index> local;
    for (const auto& t : tris) {
      std::array<Index, 3> tri{};
      for (int q = 0; q < 3; ++q) {
        const auto it = nodes.find(t[q]);
        if (it == nodes.end())
          fail("element refers to node " + std::to_string(t[q]) + " not in $Nodes");
        if (std::abs(it->second[2]) > 1e-9 * std::max(scale, 1.0))
          fail("node " + std::to_string(t[q]) + " has z = " + std::to_string(it->second[2]) +
               "; the mesh must lie in the plane z = 0");
        const auto [pos, fresh] = local.emplace(t[q], static_cast<Index>(mesh.points.size()));
        if (fresh) mesh.points.push_back({it->second[0], it->second[1]});
        tri[q] = pos->second;
      }
      const Vec2 a = mesh.points[tri[0]], b = mesh.points[tri[1]], c = mesh.points[tri[2]];
      if (cross(b - a, c - a) == 0.0)
        fail("block with tag " + std::to_string(tag) + " has a degenerate triangle");
      mesh.tris.push_back(tri);
    }
    out.meshes.push_back(std::move(mesh));
    out.tags.push_back(tag);
    const auto named = physical_names.find(tag);
    out.names.push_back(!any_phys ? "surface " + std::to_string(tag)
                        : named != physical_names.end() && !named->second.empty()
                            ? named->second
                            : "physical " + std::to_string(tag));
  }
  return out;
}

// Shared straight pieces between the outlines of blocks i < j.
void find_joints(Scene& scene, const std::vector<std::vector<Vec2>>& outlines) {
  const std::size_t nb = outlines.size();
  for (std::size_t i = 0; i < nb; ++i) {
    for (std::size_t j = i + 1; j < nb; ++j) {
      const auto& p = outlines[i];
      const auto& q = outlines[j];
      for (std::size_t e = 0; e < p.size(); ++e) {
        const Vec2 a = p[e], b = p[(e + 1) % p.size()];
        const Vec2 ab = b - a;
        const double len = norm(ab);
        for (std::size_t f = 0; f < q.size(); ++f) {
          const Vec2 c = q[f], d = q[(f + 1) % q.size()];
          const double tol = 1e-9 * std::max(len, distance(c, d));
          if (std::abs(cross(ab, c - a)) / len > tol || std::abs(cross(ab, d - a)) / len > tol)
            continue;
          if (dot(ab, d - c) >= 0.0) continue;  // same direction: not facing each other
          // Overlap of the parameter intervals along a-b.
          const double sc = dot(c - a, ab) / (len * len), sd = dot(d - a, ab) / (len * len);
          const double lo = std::max(0.0, std::min(sc, sd)), hi = std::min(1.0, std::max(sc, sd));
          if ((hi - lo) * len <= tol) continue;
          Vec2 u = lo == 0.0 ? a : (lo == sc ? c : (lo == sd ? d : a + lo * ab));
          Vec2 v = hi == 1.0 ? b : (hi == sc ? c : (hi == sd ? d : a + hi * ab));
          if (v.x < u.x || (v.x == u.x && v.y < u.y)) std::swap(u, v);
          scene.joints.push_back(Joint{static_cast<Index>(i), static_cast<Index>(j), u, v, kNaN});
        }
      }
    }
  }
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError{"cannot open '" + path + "'"};
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

Scene build_polygons_scene(const SceneParams& params) {
  const ModelConfig& mc = params.model;
  namespace fs = std::filesystem;
  if (mc.file.empty())
    geometry_error(
        params, VOUSSOIR_KEY(model.file), "\"\"",
        std::string(VOUSSOIR_KEY(model.kind)) + " = \"polygons\" needs a file of blocks");
  fs::path path(mc.file);
  if (path.is_relative() && !fs::exists(path) && !params.deck_dir.empty())
    path = fs::path(params.deck_dir) / path;
  const std::string shown = "'" + mc.file + "'";

  Scene scene;
  scene.check_overlaps = true;
  std::vector<std::vector<Vec2>> outlines;
  try {
    const std::string text = read_file(path.string());
    const std::size_t first = text.find_first_not_of(" \t\r\n");
    const bool gmsh = first != std::string::npos && text.compare(first, 11, "$MeshFormat") == 0;
    if (gmsh) {
      GmshBlocks g = read_gmsh(text, path.string());
      for (std::size_t b = 0; b < g.meshes.size(); ++b) {
        std::vector<Vec2> loop;
        try {
          loop = boundary_loop(g.meshes[b]);
        } catch (const std::invalid_argument& e) {
          throw FileError{path.string() + ": block with tag " + std::to_string(g.tags[b]) +
                          ": its triangles do not form one piece without holes (" + e.what() + ")"};
        }
        BlockSpec spec;
        spec.mesher = BlockSpec::Mesher::Given;
        spec.mesh = std::move(g.meshes[b]);
        spec.outline = polygon_outline(loop);
        spec.name = g.names[b];
        outlines.push_back(loop);
        scene.blocks.push_back(std::move(spec));
      }
    } else {
      outlines = read_polygon_text(text, path.string());
      for (const auto& p : outlines) {
        BlockSpec spec;
        spec.mesher = BlockSpec::Mesher::Polygon;
        spec.outline = polygon_outline(p);
        scene.blocks.push_back(std::move(spec));
      }
    }
  } catch (const FileError& e) {
    geometry_error(params, VOUSSOIR_KEY(model.file), shown, e.what);
  }

  const std::size_t nb = scene.blocks.size();
  check_fixed_indices(params, nb, "the file");
  for (std::size_t b = 0; b < nb; ++b) {
    const bool fixed =
        std::find(mc.fixed.begin(), mc.fixed.end(), static_cast<int>(b)) != mc.fixed.end();
    scene.blocks[b].fixed = fixed;
    scene.blocks[b].role = fixed ? "ground" : "block";
  }
  // A model with nothing free cannot run (no trial can move, limit analysis has no unknown):
  // refused here, for every command, as a bad deck.
  if (mc.fixed.size() >= nb) {
    std::string list = "[";
    for (std::size_t k = 0; k < mc.fixed.size(); ++k)
      list += (k ? ", " : "") + std::to_string(mc.fixed[k]);
    geometry_error(params, VOUSSOIR_KEY(model.fixed), list + "]",
                   "every block of the file is fixed (it has " + std::to_string(nb) +
                       "); leave at least one block out of " + VOUSSOIR_KEY(model.fixed));
  }

  // Element size from the smallest free block (all blocks if none is free).
  double reference = std::numeric_limits<double>::infinity();
  bool any_free = false;
  for (const BlockSpec& b : scene.blocks) any_free = any_free || !b.fixed;
  for (std::size_t b = 0; b < nb; ++b) {
    if (any_free && scene.blocks[b].fixed) continue;
    double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
    for (const Vec2& p : outlines[b]) {
      x0 = std::min(x0, p.x);
      x1 = std::max(x1, p.x);
      y0 = std::min(y0, p.y);
      y1 = std::max(y1, p.y);
    }
    reference = std::min({reference, x1 - x0, y1 - y0});
  }
  const double h = element_size(params, reference);
  scene.element_size = h;
  // Refuse too fine a mesh before outlining: every edge is cut at the element size below, so a
  // mistyped coordinate (2147483648 for 2, a fuzzing finding) made billions of boundary points
  // and exhausted memory before mesh_scene's triangle budget could see the areas. Same
  // estimate as there (~5 triangles per size^2), plus one per boundary point.
  double estimate = 0.0;
  for (std::size_t b = 0; b < nb; ++b) {
    if (scene.blocks[b].mesher != BlockSpec::Mesher::Polygon) continue;
    const double size = (scene.blocks[b].fixed ? kFixedCoarsening : 1.0) * std::sqrt(2.0) * h;
    const auto& p = outlines[b];
    double perimeter = 0.0;
    for (std::size_t e = 0; e < p.size(); ++e) perimeter += norm(p[(e + 1) % p.size()] - p[e]);
    estimate += perimeter / h + 5.0 * std::abs(polygon_area(p)) / (size * size);
  }
  check_triangle_budget(params, estimate);
  // Conforming faces: a vertex of another block lying on an edge (a T-junction, e.g. a block
  // standing on a longer ground edge) is inserted into that edge, so both blocks get a node
  // there; then every edge is cut from its lexicographically smaller end so that a face shared
  // by two blocks gets the same nodes on both.
  for (std::size_t b = 0; b < nb; ++b) {
    BlockSpec& spec = scene.blocks[b];
    if (spec.mesher != BlockSpec::Mesher::Polygon) continue;
    const auto& p = outlines[b];
    spec.size = (spec.fixed ? kFixedCoarsening : 1.0) * std::sqrt(2.0) * h;
    for (std::size_t e = 0; e < p.size(); ++e) {
      const Vec2 a = p[e], c = p[(e + 1) % p.size()];
      const Vec2 ac = c - a;
      const double len2 = dot(ac, ac), tol = 1e-9 * std::sqrt(len2);
      std::vector<std::pair<double, Vec2>> stops;  // (parameter along a-c, point)
      for (std::size_t o = 0; o < nb; ++o) {
        if (o == b) continue;
        for (const Vec2& q : outlines[o]) {
          const double s = dot(q - a, ac) / len2;
          if (s * std::sqrt(len2) <= tol || (1.0 - s) * std::sqrt(len2) <= tol) continue;
          if (distance_to_segment(q, a, c) <= tol) stops.emplace_back(s, q);
        }
      }
      std::sort(stops.begin(), stops.end(),
                [](const auto& l, const auto& r) { return l.first < r.first; });
      std::vector<Vec2> corners{a};
      for (const auto& st : stops)
        if (st.second.x != corners.back().x || st.second.y != corners.back().y)
          corners.push_back(st.second);
      corners.push_back(c);
      for (std::size_t k = 0; k + 1 < corners.size(); ++k) {
        const Vec2 u = corners[k], v = corners[k + 1];
        const bool forward = u.x < v.x || (u.x == v.x && u.y < v.y);
        std::vector<Vec2> cut;
        append_segment(cut, forward ? u : v, forward ? v : u, h);
        if (!forward) {
          cut.push_back(u);  // v .. u inclusive; reversed it runs u .. v, then v is dropped
          std::reverse(cut.begin(), cut.end());
          cut.pop_back();
        }
        spec.boundary.insert(spec.boundary.end(), cut.begin(), cut.end());
      }
    }
  }
  std::vector<std::vector<Vec2>> corners;
  for (const auto& p : outlines) corners.push_back(merge_collinear(p));
  find_joints(scene, corners);
  return scene;
}

}  // namespace voussoir

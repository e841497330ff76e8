// Scene tests (docs/reference/deck.md, [model]): arch areas against the analytic
// centreline length x thickness, the basket crown height, mirror symmetry of every symmetric
// scene, buttress and church dimensions and block counts, coincident joint faces without
// overlap, polygon-file and gmsh imports against the built-in block, geometry validation
// messages, and the shipped decks (load, mesh quality).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "core/scene_kinds.hpp"
#include "io/deck.hpp"
#include "mesh/rectangle.hpp"
#include "mesh/scene.hpp"
#include "mesh/scene_spec.hpp"

namespace voussoir {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

// The scene parameters of a deck text (mesh/ reads only these).
SceneParams make_deck(const std::string& text) {
  return scene_params(parse_deck(text, "test.toml", {}, VOUSSOIR_SOURCE_DIR "/tests/data"));
}

std::string arch_deck(const std::string& kind, double embrace, int through = 2) {
  return "[model]\nkind = \"" + kind +
         "\"\nradius = 1.0\nthickness = 0.2\nembrace = " + std::to_string(embrace) +
         "\nvoussoirs = 11\noffset = 0.5\nsmall_radius = 0.5\n[mesh]\nthrough_thickness = " +
         std::to_string(through) + "\n";
}

// Analytic centreline length of the shipped arches (independent of the generator's code path).
double analytic_length(const std::string& shape, double rc, double d, double r, double beta_deg) {
  const double beta = beta_deg * kDeg;
  if (shape == "circular") return rc * beta;
  const double g = 0.5 * (kPi - beta);
  const double o3x = (rc - r) * std::cos(g), o3y = (rc - r) * std::sin(g);
  const double r1 = std::hypot(o3x, o3y + d) + r;  // O1 = (0, -d)
  const double psi = std::atan2(o3y + d, o3x);     // direction O1 -> O3
  return 2.0 * (r1 * (0.5 * kPi - psi) + r * (psi - g));
}

double model_size(const Model& m) {
  double s = 0.0;
  for (Index i = 0; i < m.nodes.size(); ++i)
    s = std::max({s, std::abs(m.nodes.x0[i]), std::abs(m.nodes.y0[i])});
  return s;
}

// Largest distance from the mirror image of a node to the nearest node (0 for a perfectly
// symmetric mesh).
double mirror_error(const Model& m) {
  std::vector<Vec2> p;
  for (Index i = 0; i < m.nodes.size(); ++i) p.push_back({m.nodes.x0[i], m.nodes.y0[i]});
  std::vector<Vec2> sorted = p;
  std::sort(sorted.begin(), sorted.end(), [](Vec2 a, Vec2 b) { return a.x < b.x; });
  const double probe = 1e-9 * model_size(m);
  double worst = 0.0;
  for (const Vec2& q : p) {
    const Vec2 mq = mirror_x(q);
    auto it = std::lower_bound(sorted.begin(), sorted.end(), mq.x - probe,
                               [](Vec2 a, double v) { return a.x < v; });
    double best = std::numeric_limits<double>::infinity();
    for (; it != sorted.end() && it->x <= mq.x + probe; ++it)
      best = std::min(best, distance(*it, mq));
    worst = std::max(worst, best);
  }
  return worst;
}

TriMesh block_mesh(const Model& m, Index b) {
  const Block& blk = m.blocks[b];
  TriMesh t;
  for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i)
    t.points.push_back({m.nodes.x0[i], m.nodes.y0[i]});
  for (Index e = blk.first_tri; e < blk.first_tri + blk.tri_count; ++e)
    t.tris.push_back({m.tris.n0[e] - blk.first_node, m.tris.n1[e] - blk.first_node,
                      m.tris.n2[e] - blk.first_node});
  return t;
}

// How far the boundary path of `poly` between the vertices at a and b strays from segment
// a-b (the straighter of the two ways round); infinity if a or b is not a vertex within tol.
double face_gap(const std::vector<Vec2>& poly, Vec2 a, Vec2 b, double tol) {
  std::size_t ia = 0, ib = 0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    if (distance(poly[i], a) < distance(poly[ia], a)) ia = i;
    if (distance(poly[i], b) < distance(poly[ib], b)) ib = i;
  }
  if (distance(poly[ia], a) > tol || distance(poly[ib], b) > tol)
    return std::numeric_limits<double>::infinity();
  const std::size_t n = poly.size();
  double forward = std::max(distance(poly[ia], a), distance(poly[ib], b)), backward = forward;
  for (std::size_t i = (ia + 1) % n; i != ib; i = (i + 1) % n)
    forward = std::max(forward, distance_to_segment(poly[i], a, b));
  for (std::size_t i = (ia + n - 1) % n; i != ib; i = (i + n - 1) % n)
    backward = std::max(backward, distance_to_segment(poly[i], a, b));
  return std::min(forward, backward);
}

struct JointReport {
  double worst_gap = 0.0;      // [m]
  double worst_overlap = 0.0;  // [m2], over every pair of blocks
  std::size_t joints = 0;
};

JointReport check_joints(const Model& m) {
  JointReport r;
  const double size = model_size(m);
  for (const Joint& j : m.joints) {
    ++r.joints;
    for (Index b : {j.block_a, j.block_b})
      r.worst_gap = std::max(r.worst_gap, face_gap(m.blocks[b].polygon, j.a, j.b, 1e-9 * size));
  }
  // Overlap of every pair of blocks whose boxes meet (joint pairs and any others).
  const std::size_t nb = m.blocks.size();
  std::vector<TriMesh> meshes;
  std::vector<std::array<double, 4>> box;
  for (std::size_t b = 0; b < nb; ++b) {
    meshes.push_back(block_mesh(m, static_cast<Index>(b)));
    std::array<double, 4> bx = {1e300, -1e300, 1e300, -1e300};
    for (const Vec2& p : meshes.back().points)
      bx = {std::min(bx[0], p.x), std::max(bx[1], p.x), std::min(bx[2], p.y), std::max(bx[3], p.y)};
    box.push_back(bx);
  }
  for (std::size_t a = 0; a < nb; ++a)
    for (std::size_t b = a + 1; b < nb; ++b) {
      if (box[a][1] < box[b][0] || box[b][1] < box[a][0] || box[a][3] < box[b][2] ||
          box[b][3] < box[a][2])
        continue;
      r.worst_overlap = std::max(r.worst_overlap, mesh_overlap_area(meshes[a], meshes[b]));
    }
  return r;
}

// ---------------------------------------------------------------------------------------------

TEST(Scenes, ArchExactAreaEqualsCentrelineLengthTimesThickness) {
  // The exact block outlines (arcs included) of the free blocks enclose L x t to 1e-9.
  for (const std::string kind : {"circular_arch", "basket_arch"})
    for (double beta : {120.0, 150.0, 180.0}) {
      const SceneParams c = make_deck(arch_deck(kind, beta));
      const Scene s = build_scene(c);
      const double length =
          analytic_length(kind == "circular_arch" ? "circular" : "basket", 1.0, 0.5, 0.5, beta);
      double area = 0.0;
      int voussoirs = 0;
      for (const BlockSpec& b : s.blocks) {
        if (b.fixed) continue;
        const double a = outline_area(b.outline);
        // Equal centreline lengths: every voussoir encloses (L / N) t.
        EXPECT_NEAR(a, length / 11 * 0.2, 1e-9 * a) << kind << " beta " << beta;
        area += a;
        ++voussoirs;
      }
      EXPECT_EQ(voussoirs, 11);
      EXPECT_NEAR(s.centreline_length, length, 1e-12 * length);
      EXPECT_NEAR(area, length * 0.2, 1e-9 * length * 0.2) << kind << " beta " << beta;
    }
}

TEST(Scenes, CircularArchMeshedAreaIsTheChordPolygonAndConverges) {
  // Nodes sit exactly on the intrados and extrados arcs, so the meshed area of a circular
  // arch is L t sin(phi) / phi, phi = beta / (N m) the angle of one chord; it converges to
  // the exact L t as the mesh is refined.
  for (double beta : {120.0, 150.0, 180.0}) {
    double previous = 1.0, first = 0.0;
    for (int through : {1, 2, 4, 8}) {
      SceneParams c = make_deck(arch_deck("circular_arch", beta, through));
      Scene s = build_scene(c);
      const Model m = mesh_scene(s, c);
      const double exact = beta * kDeg * 0.2;
      const double phi = beta * kDeg / (11 * s.cells_along);
      EXPECT_NEAR(free_area(m), exact * std::sin(phi) / phi, 1e-12 * exact);
      const double error = (exact - free_area(m)) / exact;
      EXPECT_GT(error, 0.0);
      EXPECT_LT(error, previous);
      previous = error;
      if (through == 1) first = error;
      if (through == 8) {
        EXPECT_LT(error, first / 40.0);  // m grows ~8x (1 -> 8 or 11 cells): second order
      }
    }
  }
}

TEST(Scenes, BasketArchMeshedAreaConverges) {
  for (double beta : {120.0, 150.0, 180.0}) {
    const double exact = analytic_length("basket", 1.0, 0.5, 0.5, beta) * 0.2;
    std::vector<double> errors;
    for (int through : {1, 2, 4, 8}) {
      const Model m = build_model(make_deck(arch_deck("basket_arch", beta, through)));
      errors.push_back((exact - free_area(m)) / exact);
    }
    for (std::size_t k = 1; k < errors.size(); ++k) EXPECT_LT(errors[k], errors[k - 1]);
    EXPECT_GT(errors.back(), 0.0);
    EXPECT_LT(errors.back(), errors.front() / 20.0);  // second order: 8x finer, ~64x smaller
    EXPECT_LT(errors.back(), 2e-4);
  }
}

TEST(Scenes, BasketCrownHeight) {
  // Rc = 1, d = r = 0.5, beta = 180: R1 = |O1 O3| + r = sqrt(0.5) + 0.5, crown at
  // -d + R1 = 0.70711.
  const Scene s = build_scene(make_deck(arch_deck("basket_arch", 180.0)));
  const Vec2 crown = centreline_point(s, 0.5 * s.centreline_length);
  EXPECT_NEAR(crown.y, 0.70711, 5e-6);
  EXPECT_NEAR(crown.x, 0.0, 1e-12);
  // The springings lie on the reference circle at height 0 (g = 0).
  const Vec2 left = centreline_point(s, 0.0), right = centreline_point(s, s.centreline_length);
  EXPECT_NEAR(left.x, -1.0, 1e-12);
  EXPECT_NEAR(right.x, 1.0, 1e-12);
  EXPECT_NEAR(right.y, 0.0, 1e-12);
  // Tangency: the centreline turns smoothly (second differences small everywhere).
  const int n = 2000;
  double worst_kink = 0.0;
  for (int k = 1; k < n; ++k) {
    const double ds = s.centreline_length / n;
    const Vec2 a = centreline_point(s, (k - 1) * ds), b = centreline_point(s, k * ds),
               c = centreline_point(s, (k + 1) * ds);
    // Turning angle over one step: at most ds / r_min = ds / 0.5 on a smooth curve.
    const double turn = std::abs(std::atan2(cross(b - a, c - b), dot(b - a, c - b)));
    worst_kink = std::max(worst_kink, turn / (ds / 0.5));
  }
  EXPECT_LT(worst_kink, 1.0 + 1e-6);
  // beta = 120: the springings are on the reference circle at g = 30 deg above the horizontal.
  const Scene s120 = build_scene(make_deck(arch_deck("basket_arch", 120.0)));
  const Vec2 sr = centreline_point(s120, s120.centreline_length);
  EXPECT_NEAR(sr.x, std::cos(30 * kDeg), 1e-12);
  EXPECT_NEAR(sr.y, std::sin(30 * kDeg), 1e-12);
}

TEST(Scenes, SymmetricScenesMirrorOntoThemselves) {
  std::vector<std::string> decks;
  for (double beta : {120.0, 150.0, 180.0}) {
    decks.push_back(arch_deck("circular_arch", beta));
    decks.push_back(arch_deck("basket_arch", beta));
  }
  for (const char* shape : {"circular", "basket"})
    for (double courses : {0.0, 0.4})
      for (double beta : {120.0, 180.0})
        decks.push_back("[model]\nkind = \"buttressed_arch\"\nshape = \"" + std::string(shape) +
                        "\"\nembrace = " + std::to_string(beta) + "\ncourses = " +
                        std::to_string(courses) + "\n[mesh]\nthrough_thickness = 2\n");
  decks.push_back("[model]\nkind = \"church\"\ncourses = 0.26\n");
  decks.push_back("[model]\nkind = \"church\"\n");
  decks.push_back("[model]\nkind = \"church\"\nspans = [5.0, 3.0, 3.0, 5.0]\n");  // middle pier
  decks.push_back("[model]\nkind = \"block\"\nwidth = 0.5\nheight = 1.0\nstack = 3\n");
  decks.push_back(
      "[model]\nkind = \"block\"\nwidth = 0.5\nheight = 1.0\n[mesh]\nthrough_thickness = 3\n");
  for (const std::string& d : decks) {
    const Model m = build_model(make_deck(d));
    std::printf("%-16s nodes %5d  largest mirror distance %.3g m\n", m.kind.c_str(), m.nodes.size(),
                mirror_error(m));
    EXPECT_LT(mirror_error(m), 1e-12 * model_size(m)) << d;
    // Same for triangle centroids: the triangles themselves mirror.
    Model centroids;
    for (Index e = 0; e < m.tris.size(); ++e) {
      const double cx =
          (m.nodes.x0[m.tris.n0[e]] + m.nodes.x0[m.tris.n1[e]] + m.nodes.x0[m.tris.n2[e]]) / 3;
      const double cy =
          (m.nodes.y0[m.tris.n0[e]] + m.nodes.y0[m.tris.n1[e]] + m.nodes.y0[m.tris.n2[e]]) / 3;
      centroids.nodes.x0.push_back(cx);
      centroids.nodes.y0.push_back(cy);
      centroids.nodes.x.push_back(cx);
    }
    EXPECT_LT(mirror_error(centroids), 1e-12 * model_size(m)) << d;
  }
}

TEST(Scenes, ButtressDimensions) {
  // Buttressed circular arch, Rc = 1, t = 0.2, B = 0.8, H1 = 3, monolithic: blocks are the
  // 11 voussoirs, left buttress, right buttress, ground = 14 (13 free).
  for (double beta : {120.0, 150.0, 180.0}) {
    const SceneParams c = make_deck(
        "[model]\nkind = \"buttressed_arch\"\nshape = \"circular\"\nradius = 1.0\n"
        "thickness = 0.2\nembrace = " +
        std::to_string(beta) + "\nvoussoirs = 11\nbuttress_width = 0.8\nbase_depth = 3.0\n");
    const Model m = build_model(c);
    ASSERT_EQ(m.blocks.size(), 14u);
    EXPECT_EQ(m.blocks[11].role, "buttress");
    EXPECT_EQ(m.blocks[13].role, "ground");
    EXPECT_FALSE(m.blocks[11].fixed);
    EXPECT_FALSE(m.blocks[12].fixed);
    EXPECT_TRUE(m.blocks[13].fixed);
    const double g = 0.5 * (180.0 - beta) * kDeg;
    const double xi = 0.9 * std::cos(g), yi = 0.9 * std::sin(g);  // intrados springing
    const double xe = 1.1 * std::cos(g), ye = 1.1 * std::sin(g);  // extrados springing
    // The published geometry: inner face x = xi, ground y = -H1, outer face x = xi + B, top along
    // the joint to (xe, ye) then horizontal.
    const std::vector<Vec2> expected = {
        {xi, -3.0}, {xi + 0.8, -3.0}, {xi + 0.8, ye}, {xe, ye}, {xi, yi}};
    const Block& r = m.blocks[12];
    double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
    for (const Vec2& p : r.polygon) {
      x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y),
      y1 = std::max(y1, p.y);
      EXPECT_LT(std::min(distance_to_segment(p, expected[0], expected[1]),
                         std::min({distance_to_segment(p, expected[1], expected[2]),
                                   distance_to_segment(p, expected[2], expected[3]),
                                   distance_to_segment(p, expected[3], expected[4]),
                                   distance_to_segment(p, expected[4], expected[0])})),
                1e-12);
    }
    EXPECT_NEAR(x0, xi, 1e-12);
    EXPECT_NEAR(x1, xi + 0.8, 1e-12);
    EXPECT_NEAR(y0, -3.0, 1e-12);
    EXPECT_NEAR(y1, ye, 1e-12);
    EXPECT_NEAR(r.area, polygon_area(expected), 1e-12);
    EXPECT_NEAR(m.blocks[11].area, r.area, 1e-12);  // the left one is its mirror
    // The ground's top face is the line y = -H1.
    double ground_top = -1e9;
    for (const Vec2& p : m.blocks[13].polygon) ground_top = std::max(ground_top, p.y);
    EXPECT_EQ(ground_top, -3.0);
  }
  // Coursed: courses of 0.5 from y = -3 up to the springing at y = 0 (beta = 180): 6 courses
  // per buttress -> 11 + 2 x 6 + 1 = 24 blocks, 5 course joints per side.
  const Model m = build_model(make_deck(
      "[model]\nkind = \"buttressed_arch\"\nembrace = 180.0\nbase_depth = 3.0\ncourses = 0.5\n"));
  EXPECT_EQ(m.blocks.size(), 24u);
  int course_joints = 0;
  for (const Joint& j : m.joints)
    if (m.blocks[j.block_a].role == "buttress" && m.blocks[j.block_b].role == "buttress") {
      ++course_joints;
      EXPECT_NEAR(std::fmod(j.a.y + 3.0, 0.5), 0.0, 1e-12);
      EXPECT_TRUE(std::isnan(j.position_deg));
    }
  EXPECT_EQ(course_joints, 10);
}

TEST(Scenes, ChurchSupportsAndBlockCounts) {
  // Defaults: spans 4, 6, 4; pier 1.0; outer 1.2; width W = 2(1.2) + 14 + 2(1.0) = 18.4,
  // centred: supports [-9.2, -8.0], [-4, -3], [3, 4], [8, 9.2], from y = 0 to 5.
  // Voussoirs per half: theta_i = acos(e / (1 + e)) = acos(0.2) = 78.46 deg (the same for
  // every span), floor(78.46 / 2) = 39 leaves 0.46 deg < 1 deg, so 38 (see scenes_church.cpp):
  // 2 x 38 + 1 crown = 77 blocks per span, 231 arch blocks.
  // Scheme B: 231 + 4 supports + 1 ground = 236. Scheme A (courses 0.26): 5 / 0.26 = 19.2, so
  // 19 courses of 0.26 and a top course of 0.06 = 20 per support: 231 + 80 + 1 = 312.
  const double faces[4][2] = {{-9.2, -8.0}, {-4.0, -3.0}, {3.0, 4.0}, {8.0, 9.2}};
  const char* roles[4] = {"buttress", "pier", "pier", "buttress"};
  for (int scheme = 0; scheme < 2; ++scheme) {
    const Model m =
        build_model(make_deck(scheme == 0 ? "[model]\nkind = \"church\"\ncourses = 0.26\n"
                                          : "[model]\nkind = \"church\"\ncourses = 0.0\n"));
    const int per_support = scheme == 0 ? 20 : 1;
    ASSERT_EQ(m.blocks.size(), scheme == 0 ? 312u : 236u);
    int voussoirs = 0, crowns = 0, fixed = 0;
    for (const Block& b : m.blocks) {
      voussoirs += b.role == "voussoir";
      crowns += b.role == "crown";
      fixed += b.fixed;
    }
    EXPECT_EQ(voussoirs, 228);
    EXPECT_EQ(crowns, 3);
    EXPECT_EQ(fixed, 1);
    for (int s = 0; s < 4; ++s) {
      double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
      for (int k = 0; k < per_support; ++k) {
        const Block& b = m.blocks[s * per_support + k];
        EXPECT_EQ(b.role, roles[s]);
        for (const Vec2& p : b.polygon)
          x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y),
          y1 = std::max(y1, p.y);
      }
      EXPECT_NEAR(x0, faces[s][0], 1e-12);
      EXPECT_NEAR(x1, faces[s][1], 1e-12);
      EXPECT_NEAR(y0, 0.0, 1e-12);
      EXPECT_NEAR(y1, 5.0, 1e-12);
    }
    if (scheme == 0) {  // the top course of the first support is 0.06 high
      double y0 = 1e9;
      for (const Vec2& p : m.blocks[19].polygon) y0 = std::min(y0, p.y);
      EXPECT_NEAR(5.0 - y0, 0.06, 1e-12);
    }
    // Springings exactly at the support faces, and apex heights: intrados 5 + sqrt(Ri^2 - c^2),
    // extrados 5 + sqrt(Re^2 - c^2); centre span Ri = 3.75, c = 0.75; outer Ri = 2.5, c = 0.5.
    int springings = 0;
    for (const Joint& j : m.joints)
      if (j.position_deg == 0.0 || j.position_deg == 180.0) {
        ++springings;
        EXPECT_EQ(j.a.y, 5.0);
        bool on_face = false;
        for (const auto& f : faces)
          on_face = on_face || std::abs(j.a.x - f[0]) < 1e-12 || std::abs(j.a.x - f[1]) < 1e-12;
        EXPECT_TRUE(on_face) << j.a.x;
        EXPECT_NEAR(distance(j.a, j.b), 0.5, 1e-12);
      }
    EXPECT_EQ(springings, 6);
    std::vector<double> apex;
    for (const Block& b : m.blocks)
      if (b.role == "crown") {
        double top = -1e9;
        for (const Vec2& p : b.polygon) top = std::max(top, p.y);
        apex.push_back(top);
      }
    ASSERT_EQ(apex.size(), 3u);
    EXPECT_NEAR(apex[0], 5.0 + std::sqrt(3.0 * 3.0 - 0.5 * 0.5), 1e-12);
    EXPECT_NEAR(apex[1], 5.0 + std::sqrt(4.25 * 4.25 - 0.75 * 0.75), 1e-12);
    EXPECT_NEAR(apex[2], apex[0], 1e-12);
  }
}

TEST(Scenes, JointFacesCoincideWithoutOverlap) {
  std::vector<std::string> decks = {
      arch_deck("circular_arch", 120.0),
      arch_deck("circular_arch", 180.0),
      arch_deck("basket_arch", 150.0),
      "[model]\nkind = \"buttressed_arch\"\nshape = \"basket\"\nembrace = 130.0\ncourses = 0.35\n",
      "[model]\nkind = \"buttressed_arch\"\nembrace = 150.0\n",
      "[model]\nkind = \"church\"\ncourses = 0.26\n",
      "[model]\nkind = \"church\"\nspans = [3.0, 5.0]\npier_width = 1.3\n",
      "[model]\nkind = \"block\"\nheight = 1.0\nstack = 3\nincline = 25.0\n",
      "[model]\nkind = \"polygons\"\nfile = \"two_blocks.txt\"\nfixed = [1]\n",
      "[model]\nkind = \"polygons\"\nfile = \"t_junction.txt\"\nfixed = [0]\n[mesh]\nsize = 0.15\n",
  };
  for (const std::string& d : decks) {
    const Model m = build_model(make_deck(d));
    const JointReport r = check_joints(m);
    const double size = model_size(m);
    std::printf("%-12s joints %3zu  worst face gap %.3g m  worst overlap %.3g m2 (size %.3g m)\n",
                m.kind.c_str(), r.joints, r.worst_gap, r.worst_overlap, size);
    EXPECT_GT(r.joints, 0u) << d;
    EXPECT_LT(r.worst_gap, 1e-12 * size) << d;
    EXPECT_LT(r.worst_overlap, 1e-12 * size * size) << d;
    // Every pair of blocks that should touch is listed: each free block has a joint.
    for (Index b = 0; b < static_cast<Index>(m.blocks.size()); ++b) {
      bool listed = false;
      for (const Joint& j : m.joints) listed = listed || j.block_a == b || j.block_b == b;
      EXPECT_TRUE(listed) << "block " << b << " in " << d;
    }
  }
}

TEST(Scenes, ArchJointsPositionsAndEnds) {
  // Circular arch, beta = 150, 11 voussoirs: 12 joints at k x 150 / 11 degrees from the left
  // springing; a on the intrados (radius 0.9), b on the extrados (radius 1.1).
  const Model m = build_model(make_deck(arch_deck("circular_arch", 150.0)));
  ASSERT_EQ(m.joints.size(), 12u);
  for (std::size_t k = 0; k < 12; ++k) {
    const Joint& j = m.joints[k];
    EXPECT_NEAR(j.position_deg, k * 150.0 / 11.0, 1e-9);
    EXPECT_NEAR(norm(j.a), 0.9, 1e-12);
    EXPECT_NEAR(norm(j.b), 1.1, 1e-12);
    // Radial joint at 15 + position degrees... measured from the left: polar angle
    // 180 - 15 - position.
    const double polar = (165.0 - j.position_deg) * kDeg;
    EXPECT_NEAR(std::atan2(j.a.y, j.a.x), polar, 1e-12);
  }
  EXPECT_EQ(m.blocks[m.joints.front().block_a].role, "abutment");
  EXPECT_EQ(m.blocks[m.joints.back().block_b].role, "abutment");
  // The abutments' top face is exactly the springing joint: their highest points are a, b.
  for (Index b : {m.joints.front().block_a, m.joints.back().block_b}) {
    const Joint& j = b == m.joints.front().block_a ? m.joints.front() : m.joints.back();
    for (const Vec2& p : m.blocks[b].polygon) EXPECT_LE(p.y, std::max(j.a.y, j.b.y) + 1e-15);
  }
}

struct Summary {
  std::size_t blocks = 0;
  int free_blocks = 0;
  double free_area = 0, mass = 0, total_area = 0;
  std::vector<std::array<double, 4>> boxes;
  std::vector<bool> fixed;
};

Summary summarize(const Model& m) {
  Summary s;
  s.blocks = m.blocks.size();
  for (const Block& b : m.blocks) {
    s.free_blocks += !b.fixed;
    s.total_area += b.area;
    s.fixed.push_back(b.fixed);
    std::array<double, 4> bx = {1e300, -1e300, 1e300, -1e300};
    for (const Vec2& p : b.polygon)
      bx = {std::min(bx[0], p.x), std::max(bx[1], p.x), std::min(bx[2], p.y), std::max(bx[3], p.y)};
    s.boxes.push_back(bx);
  }
  s.free_area = free_area(m);
  s.mass = free_mass(m);
  return s;
}

TEST(Scenes, PolygonFileTJunctions) {
  // Ground edge from -1 to 1 under two blocks [-0.5, 0] and [0, 0.5]: three joints (each
  // block on the ground, and the blocks' common face), the ground has nodes at -0.5, 0, 0.5.
  const Model m = build_model(
      make_deck("[model]\nkind = \"polygons\"\nfile = \"t_junction.txt\"\nfixed = [0]\n"));
  ASSERT_EQ(m.joints.size(), 3u);
  for (double x : {-0.5, 0.0, 0.5}) {
    bool found = false;
    for (const Vec2& p : m.blocks[0].polygon) found = found || (p.x == x && p.y == 0.0);
    EXPECT_TRUE(found) << x;
  }
  EXPECT_NEAR(m.joints[0].a.x, -0.5, 1e-15);
  EXPECT_NEAR(m.joints[0].b.x, 0.0, 1e-15);
  EXPECT_NEAR(distance(m.joints[2].a, Vec2{0.0, 0.0}), 0.0, 1e-15);
  EXPECT_NEAR(distance(m.joints[2].b, Vec2{0.0, 1.0}), 0.0, 1e-15);
  EXPECT_EQ(m.blocks[0].role, "ground");
  EXPECT_TRUE(m.blocks[0].fixed);
  EXPECT_NEAR(free_area(m), 1.0, 1e-14);
}

TEST(Scenes, PolygonFileAndGmshMatchBuiltInBlock) {
  // tests/data/two_blocks.{txt,msh}: the block scene (width 0.5, height 1.0: a ground
  // reaching 1.75 each side, 0.25 deep) drawn by hand, block 0 free, block 1 fixed.
  const Model builtin =
      build_model(make_deck("[model]\nkind = \"block\"\nwidth = 0.5\nheight = 1.0\n"));
  const Summary ref = summarize(builtin);
  EXPECT_EQ(ref.blocks, 2u);
  EXPECT_NEAR(ref.free_area, 0.5, 1e-15);
  EXPECT_NEAR(ref.mass, 1000.0, 1e-9);
  for (const char* file : {"two_blocks.txt", "two_blocks.msh"}) {
    const Model m = build_model(make_deck(std::string("[model]\nkind = \"polygons\"\nfile = \"") +
                                          file + "\"\nfixed = [1]\n"));
    const Summary s = summarize(m);
    EXPECT_EQ(s.blocks, ref.blocks) << file;
    EXPECT_EQ(s.free_blocks, ref.free_blocks) << file;
    EXPECT_EQ(s.fixed, ref.fixed) << file;
    EXPECT_NEAR(s.free_area, ref.free_area, 1e-12) << file;
    EXPECT_NEAR(s.mass, ref.mass, 1e-9) << file;
    EXPECT_NEAR(s.total_area, ref.total_area, 1e-12) << file;
    for (std::size_t b = 0; b < s.boxes.size(); ++b)
      for (int k = 0; k < 4; ++k) EXPECT_NEAR(s.boxes[b][k], ref.boxes[b][k], 1e-12) << file;
    // The same single joint: the block's base on the ground.
    ASSERT_EQ(m.joints.size(), builtin.joints.size()) << file;
    EXPECT_NEAR(distance(m.joints[0].a, builtin.joints[0].a), 0.0, 1e-15) << file;
    EXPECT_NEAR(distance(m.joints[0].b, builtin.joints[0].b), 0.0, 1e-15) << file;
  }
  // gmsh: the triangles are used as given (2 per rectangle... 2 + 4).
  const Model g =
      build_model(make_deck("[model]\nkind = \"polygons\"\nfile = \"two_blocks.msh\"\n"));
  EXPECT_EQ(g.tris.size(), 6);
  EXPECT_EQ(g.blocks[0].tri_count, 2);
}

TEST(Scenes, GeometryErrorsNameTheKey) {
  struct Bad {
    std::string deck, key, why;
  };
  const std::vector<Bad> bad = {
      {"[model]\nkind = \"circular_arch\"\nradius = 1.0\nthickness = 2.0\n", "model.thickness",
       "twice"},
      {"[model]\nkind = \"basket_arch\"\nradius = 1.0\nsmall_radius = 1.0\n", "model.small_radius",
       "inside"},
      {"[model]\nkind = \"basket_arch\"\nradius = 1.0\noffset = 0.0\n", "model.offset", "tangent"},
      {"[model]\nkind = \"basket_arch\"\nsmall_radius = 0.1\nthickness = 0.2\n", "model.thickness",
       "small_radius"},
      {"[model]\nkind = \"buttressed_arch\"\nembrace = 120.0\nbuttress_width = 0.1\n",
       "model.buttress_width", "extrados"},
      {"[model]\nkind = \"buttressed_arch\"\nembrace = 240.0\nbase_depth = 0.3\n",
       "model.base_depth", "below"},
      {"[model]\nkind = \"church\"\npier_width = 0.9\n", "model.pier_width", "two springings"},
      {"[model]\nkind = \"church\"\nouter_width = 0.4\n", "model.outer_width", "springing"},
      {"[model]\nkind = \"block\"\nheight = 100000\n", "model.height = 100000",
       "200000 times taller than wide (at most 2000)"},
      {"[model]\nkind = \"block\"\nwidth = 0.0001\n", "model.width",
       "10000 times taller than wide (at most 2000)"},
      {"[model]\nkind = \"circular_arch\"\n[mesh]\nsize = 1e-5\n", "mesh.size", "triangles"},
      {"[model]\nkind = \"polygons\"\nfile = \"two_blocks.txt\"\nfixed = [2]\n", "model.fixed",
       "2 blocks"},
      {"[model]\nkind = \"polygons\"\nfile = \"bad_bowtie.txt\"\n", "model.file", "not simple"},
      {"[model]\nkind = \"polygons\"\nfile = \"bad_overlap.txt\"\n", "model.file", "overlap"},
      {"[model]\nkind = \"polygons\"\nfile = \"bad_line.txt\"\n", "model.file", "bad_line.txt:3"},
  };
  for (const Bad& b : bad) {
    try {
      build_model(make_deck(b.deck));
      ADD_FAILURE() << "accepted: " << b.deck;
    } catch (const DeckError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(b.key), std::string::npos) << msg;
      EXPECT_NE(msg.find(b.why), std::string::npos) << msg;
    }
  }
  // Parameters built by hand (no deck validation): too few voussoirs.
  SceneParams c = make_deck(arch_deck("circular_arch", 180.0));
  c.model.voussoirs = 0;
  EXPECT_THROW(build_model(c), DeckError);
}

// mesh.max_triangles holds at the three places mesh_scene checks it: the scene's estimate
// before meshing, a polygon block while its quality mesh is refined, and the finished mesh.
// The block deck makes 24 triangles (12 estimated: the ground is a thin strip, meshed finer
// than its area says); a polygon ground 20 m long and 1 cm deep makes 2594 with the default
// limit; 1 mm deep, it runs past the runaway cap of its block (10 x its estimate + 1e4) and is
// refused as an outline far thinner than the element size, as before the key existed.
TEST(Scenes, MeshMaxTrianglesHoldsBeforeWhileAndAfterMeshing) {
  const std::string block = "[model]\nkind = \"block\"\n[mesh]\nmax_triangles = ";
  auto refusal = [](const std::string& deck) {
    try {
      const Model m = build_model(make_deck(deck));
      return "accepted, " + std::to_string(m.tris.size()) + " triangles";
    } catch (const DeckError& e) {
      return std::string(e.what());
    }
  };
  EXPECT_EQ(build_model(make_deck(block + "24\n")).tris.size(), 24);
  EXPECT_NE(
      refusal(block + "10\n").find("would make about 12 triangles (limit mesh.max_triangles = 10)"),
      std::string::npos)
      << refusal(block + "10\n");
  EXPECT_NE(refusal(block + "23\n").find("mesh.max_triangles = 23: the mesh has 24 triangles"),
            std::string::npos)
      << refusal(block + "23\n");

  const std::string dir = ::testing::TempDir();
  auto strip = [&](const std::string& depth, const std::string& limit) {
    const std::string file = dir + "voussoir_strip_" + depth + ".txt";
    std::FILE* f = std::fopen(file.c_str(), "w");
    std::fprintf(
        f, "block\n-0.25 0\n0.25 0\n0.25 0.5\n-0.25 0.5\nblock\n-10 -%s\n10 -%s\n10 0\n-10 0\n",
        depth.c_str(), depth.c_str());
    std::fclose(f);
    const std::string r = refusal("[model]\nkind = \"polygons\"\nfile = \"" + file +
                                  "\"\nfixed = [1]\n[mesh]\nmax_triangles = " + limit + "\n");
    std::remove(file.c_str());
    return r;
  };
  EXPECT_EQ(strip("0.01", "4000000"), "accepted, 2594 triangles");
  const std::string capped = strip("0.01", "1000");
  EXPECT_NE(capped.find("mesh.max_triangles = 1000: block 1: its quality mesh at element size "
                        "2.12132 m exceeds 1000 triangles"),
            std::string::npos)
      << capped;
  const std::string thin = strip("0.0001", "4000000");
  EXPECT_NE(thin.find("exceeds 10000 triangles: the outline is far thinner"), std::string::npos)
      << thin;
  EXPECT_EQ(thin.find("mesh.max_triangles"), std::string::npos) << thin;
}

TEST(Scenes, ShippedDecksLoadAndMeshWell) {
  // Every deck of cases/ loads, meshes with no triangle angle under 20 degrees at its own
  // (default) mesh settings, and mirrors onto itself (all shipped scenes are symmetric).
  const char* names[] = {"circular_arch",     "basket_arch", "buttressed_circular",
                         "buttressed_basket", "church_a",    "church_b",
                         "gilbert_arch",      "scaled_arch", "block"};
  for (const char* name : names) {
    const SceneParams c =
        scene_params(load_deck(std::string(VOUSSOIR_SOURCE_DIR) + "/cases/" + name + ".toml"));
    const Model m = build_model(c);
    const double worst = worst_triangle_angle_deg(m);
    int free_blocks = 0;
    for (const Block& b : m.blocks) free_blocks += !b.fixed;
    std::printf("%-20s blocks %4zu (%3d free) triangles %5d worst angle %.2f deg\n", name,
                m.blocks.size(), free_blocks, m.tris.size(), worst);
    EXPECT_GE(worst, 20.0) << name;
    EXPECT_GT(free_blocks, 0) << name;
    EXPECT_LT(mirror_error(m), 1e-12 * model_size(m)) << name;
  }
}

TEST(SceneKinds, TheDeckReaderAndTheBuilderFollowTheRegistry) {
  // Every kind of core/scene_kinds.hpp is accepted by the deck reader, which asks for its
  // required keys by name; an arch kind builds a scene with a centreline, the others none.
  for (const SceneKind& kind : scene_kinds()) {
    const std::string deck = arch_deck(kind.name, 150.0);
    if (!kind.required.empty()) {
      try {
        make_deck(deck);
        ADD_FAILURE() << kind.name << ": a deck without " << kind.required[0].key << " loaded";
      } catch (const DeckError& e) {
        EXPECT_NE(std::string(e.what()).find(kind.required[0].key), std::string::npos) << e.what();
      }
      continue;
    }
    const Scene s = build_scene(make_deck(deck));
    EXPECT_EQ(s.kind, kind.name);
    EXPECT_EQ(!s.centreline.empty(), kind.arch) << kind.name;
    EXPECT_EQ(is_arch_kind(kind.name), kind.arch) << kind.name;
  }
  EXPECT_FALSE(is_arch_kind("no_such_kind"));
  EXPECT_EQ(find_scene_kind("no_such_kind"), nullptr);
}

TEST(GridRectangle, LayoutDiagonalsAndOutline) {
  // mesh/rectangle.hpp: node (i, j) at index j (nx + 1) + i; cell (1, 0) of the alternating
  // grid takes the other diagonal; both patterns tile the rectangle; the outline is the four
  // corners or every boundary node.
  const TriMesh alt = mesh_grid_rectangle(1.0, 2.0, 2.0, 1.0, 2, 1);
  const TriMesh uni = mesh_grid_rectangle(1.0, 2.0, 2.0, 1.0, 2, 1, GridDiagonals::Uniform);
  ASSERT_EQ(alt.points.size(), 6u);
  EXPECT_EQ(alt.points[4].x, 2.0);
  EXPECT_EQ(alt.points[4].y, 3.0);
  ASSERT_EQ(alt.tris.size(), 4u);
  EXPECT_EQ(alt.tris[2], (std::array<Index, 3>{1, 2, 4}));
  EXPECT_EQ(uni.tris[2], (std::array<Index, 3>{1, 2, 5}));
  for (const TriMesh* m : {&alt, &uni}) {
    double area = 0.0;
    for (const auto& t : m->tris)
      area += std::abs(polygon_area({m->points[t[0]], m->points[t[1]], m->points[t[2]]}));
    EXPECT_DOUBLE_EQ(area, 2.0);
  }
  Model model;
  add_grid_rectangle(model, 0.0, 0.0, 2.0, 1.0, 2, 1, false, "a");
  add_grid_rectangle(model, 0.0, 1.0, 2.0, 1.0, 2, 1, true, "b", GridDiagonals::Uniform,
                     GridOutline::Nodes);
  EXPECT_EQ(model.blocks[0].polygon.size(), 4u);
  EXPECT_EQ(model.blocks[1].polygon.size(), 6u);
  EXPECT_TRUE(model.blocks[1].fixed);
}

}  // namespace
}  // namespace voussoir

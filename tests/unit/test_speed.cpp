// Speed-pass checks that could fail: the METIS locality ordering (core/ordering.hpp) must
// change nothing but the numbering; the separating-axis pre-test the contact stage runs before
// the narrow-phase kernel (contact/narrow_phase.hpp overlap_negligible) may only reject pairs
// whose kernel result is zero, and it must actually reject the pairs that are apart and the
// corner touches across a joint.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include "bench/wall.hpp"
#include "contact/narrow_phase.hpp"
#include "core/cst.hpp"
#include "core/ordering.hpp"

using namespace voussoir;

namespace {

// Counter-clockwise random triangle near `centre` of size ~`size`.
std::array<Vec2, 3> random_triangle(std::mt19937_64& rng, Vec2 centre, double size) {
  std::uniform_real_distribution<double> u(-size, size);
  for (;;) {
    std::array<Vec2, 3> t;
    for (auto& v : t) v = {centre.x + u(rng), centre.y + u(rng)};
    const double a2 = (t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[1].y - t[0].y) * (t[2].x - t[0].x);
    if (std::abs(a2) < 1e-3 * size * size) continue;
    if (a2 < 0.0) std::swap(t[1], t[2]);
    return t;
  }
}

}  // namespace

TEST(Speed, SeparatingAxisRejectsOnlyPairsWithoutContact) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> offset(-2.0, 2.0);
  int separated = 0, kernel_zero = 0, touching = 0;
  for (int k = 0; k < 20000; ++k) {
    const auto c = random_triangle(rng, {0.0, 0.0}, 1.0);
    const auto t = random_triangle(rng, {offset(rng), offset(rng)}, 1.0);
    const PairForce f = triangle_pair_force(c, t, 1e9);
    const bool sep = overlap_negligible(c, t);
    if (sep) {
      ++separated;
      EXPECT_EQ(f.area, 0.0) << "pair " << k;
      EXPECT_EQ(f.energy, 0.0) << "pair " << k;
    }
    if (f.area > 0.0)
      ++touching;
    else
      ++kernel_zero;
  }
  // Two triangles that do not overlap always have a separating line among their six edge
  // lines (2D separating-axis theorem for convex polygons), so every zero result with a
  // genuinely empty intersection is rejected; the only exceptions are overlaps below the
  // kernel's negligible-area cut, which random pairs essentially never produce.
  std::printf("separated %d, kernel zero %d, touching %d of 20000\n", separated, kernel_zero,
              touching);
  EXPECT_GT(touching, 1000);
  EXPECT_EQ(separated, kernel_zero);
}

namespace {

// Distance between two points sets given as triangles, by brute force: the smallest
// point-to-segment distance over the 18 vertex-edge couples (exact for disjoint triangles).
double triangle_distance(const std::array<Vec2, 3>& a, const std::array<Vec2, 3>& b) {
  auto point_segment = [](Vec2 p, Vec2 s0, Vec2 s1) {
    const double ex = s1.x - s0.x, ey = s1.y - s0.y;
    double u = ((p.x - s0.x) * ex + (p.y - s0.y) * ey) / (ex * ex + ey * ey);
    u = std::min(1.0, std::max(0.0, u));
    return std::hypot(p.x - s0.x - u * ex, p.y - s0.y - u * ey);
  };
  double d = 1e300;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      d = std::min(d, point_segment(a[i], b[j], b[(j + 1) % 3]));
      d = std::min(d, point_segment(b[i], a[j], a[(j + 1) % 3]));
    }
  return d;
}

}  // namespace

// The contact stage skips a pair while its blocks have moved less than half its separation
// bound (contact/contact.cpp note_apart): the bound must never exceed the true distance, must
// be 0 for overlapping pairs, and must see most of the clearance of pairs that are apart (or
// the skip would save nothing). Then any rigid motion of the pair by less than half the bound
// leaves the kernel at zero.
TEST(Speed, SeparationBoundIsALowerBoundOfTheDistance) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> offset(-3.0, 3.0), angle(-0.05, 0.05), unit(-1.0, 1.0);
  int apart = 0, seen = 0;
  double worst_ratio = 1.0;
  for (int k = 0; k < 20000; ++k) {
    const auto c = random_triangle(rng, {0.0, 0.0}, 1.0);
    const auto t = random_triangle(rng, {offset(rng), offset(rng)}, 1.0);
    const double bound = separation_lower_bound(c, t);
    const PairForce f = triangle_pair_force(c, t, 1e9);
    ASSERT_GE(bound, 0.0);
    if (f.area > 0.0) {
      EXPECT_EQ(bound, 0.0) << "pair " << k << " overlaps";
      continue;
    }
    const double distance = triangle_distance(c, t);
    EXPECT_LE(bound, distance * (1.0 + 1e-12)) << "pair " << k;
    if (distance > 1e-3) {
      ++apart;
      seen += bound > 0.0 ? 1 : 0;
      worst_ratio = std::min(worst_ratio, bound / distance);
    }
    if (!(bound > 0.0)) continue;
    // Move t rigidly by less than half the bound (a rotation about its first vertex and a
    // shift, every point by at most 0.49 bound): still no contact.
    const double phi = angle(rng);
    double reach = 0.0;
    for (const Vec2& v : t) reach = std::max(reach, std::hypot(v.x - t[0].x, v.y - t[0].y));
    const double turn = std::min(std::abs(phi), 0.24 * bound / reach);
    const double th = phi < 0.0 ? -turn : turn;
    const double sx = unit(rng), sy = unit(rng), len = std::hypot(sx, sy) + 1e-300;
    const double shift = 0.24 * bound;
    std::array<Vec2, 3> moved;
    for (int i = 0; i < 3; ++i) {
      const double rx = t[i].x - t[0].x, ry = t[i].y - t[0].y;
      moved[i] = {t[0].x + std::cos(th) * rx - std::sin(th) * ry + shift * sx / len,
                  t[0].y + std::sin(th) * rx + std::cos(th) * ry + shift * sy / len};
    }
    EXPECT_EQ(triangle_pair_force(c, moved, 1e9).area, 0.0) << "pair " << k;
  }
  std::printf("apart %d, with a positive bound %d, smallest bound / distance %.3f\n", apart, seen,
              worst_ratio);
  EXPECT_GT(apart, 5000);
  // Every disjoint pair has a separating edge line (2D separating-axis theorem).
  EXPECT_EQ(seen, apart);
}

// Edge and vertex contacts: a triangle sharing an edge or a vertex with another (exact zero
// overlap area) is reported separated, as the kernel reports no contact.
TEST(Speed, SeparatingAxisOnSharedEdgeAndVertex) {
  const std::array<Vec2, 3> c{Vec2{0.0, 0.0}, Vec2{1.0, 0.0}, Vec2{0.0, 1.0}};
  const std::array<Vec2, 3> shared_edge{Vec2{1.0, 0.0}, Vec2{1.0, 1.0}, Vec2{0.0, 1.0}};
  const std::array<Vec2, 3> shared_vertex{Vec2{1.0, 0.0}, Vec2{2.0, 0.0}, Vec2{2.0, 1.0}};
  const std::array<Vec2, 3> overlapping{Vec2{0.2, 0.2}, Vec2{1.2, 0.2}, Vec2{0.2, 1.2}};
  EXPECT_TRUE(overlap_negligible(c, shared_edge));
  EXPECT_TRUE(overlap_negligible(c, shared_vertex));
  EXPECT_FALSE(overlap_negligible(c, overlapping));
  EXPECT_GT(triangle_pair_force(c, overlapping, 1e9).area, 0.0);
}

// Pairs across a joint, as in a settled arch: c above the joint line with a face on it, t
// below with a face (face to face) or only a vertex (corner neighbour) on it, the blocks
// pressed together by a depth d from 1e-14 to 1e-2 of the size, the joint's ends often shared,
// the whole scene rotated and shifted. overlap_negligible must never reject a pair the kernel
// gives an overlap for, and must reject most corner touches the kernel discards.
TEST(Speed, NegligibleOverlapRejectsOnlyDiscardedCornerTouches) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int kernel_zero = 0, rejected = 0, touching = 0;
  for (int k = 0; k < 40000; ++k) {
    const double size = std::pow(10.0, -2.0 + 3.0 * u(rng));  // 0.01 to 10 m
    const double d = size * std::pow(10.0, -14.0 + 12.0 * u(rng));
    auto along = [&] { return size * (2.0 * u(rng) - 1.0); };
    double a0 = along(), a1 = along();
    if (a1 < a0) std::swap(a0, a1);
    if (a1 - a0 < 0.05 * size) continue;
    // c: face (a0, a1) on y = -d (pressed down into t), apex above.
    std::array<Vec2, 3> c{Vec2{a0, -d}, Vec2{a1, -d}, Vec2{along(), size * (0.2 + u(rng))}};
    // t: a vertex at a joint end or anywhere on y = 0, the rest below (or a second on y = 0).
    const double pick = u(rng);
    const double b0 = pick < 0.3 ? a0 : (pick < 0.6 ? a1 : along());
    std::array<Vec2, 3> t;
    if (u(rng) < 0.5) {  // corner neighbour: one vertex on the joint line
      t = {Vec2{b0, 0.0}, Vec2{along(), -size * (0.2 + u(rng))},
           Vec2{along(), -size * (0.2 + u(rng))}};
    } else {  // face on the joint line
      t = {Vec2{b0, 0.0}, Vec2{along(), 0.0}, Vec2{along(), -size * (0.2 + u(rng))}};
    }
    auto twice_area = [](const std::array<Vec2, 3>& p) {
      return (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x);
    };
    if (twice_area(t) < 0.0) std::swap(t[1], t[2]);
    if (std::abs(twice_area(t)) < 1e-3 * size * size) continue;
    // Rotate and shift the scene (the arch's joints lie at every angle, far from the origin).
    const double th = 6.283185307179586 * u(rng), co = std::cos(th), si = std::sin(th);
    const Vec2 shift{10.0 * along(), 10.0 * along()};
    for (auto* p : {&c, &t})
      for (Vec2& v : *p) v = {shift.x + co * v.x - si * v.y, shift.y + si * v.x + co * v.y};
    const PairForce f = triangle_pair_force(c, t, 1e9);
    const bool reject = overlap_negligible(c, t);
    if (reject) {
      ++rejected;
      EXPECT_EQ(f.area, 0.0) << "pair " << k << " depth " << d << " size " << size;
      EXPECT_EQ(f.energy, 0.0) << "pair " << k;
    }
    if (f.area > 0.0)
      ++touching;
    else
      ++kernel_zero;
  }
  std::printf("rejected %d, kernel zero %d, touching %d\n", rejected, kernel_zero, touching);
  EXPECT_GT(touching, 5000);
  EXPECT_GT(rejected, kernel_zero * 9 / 10);
}

// order_for_locality renumbers nodes and triangles inside blocks and nothing else: block
// ranges, masses, areas, orientation and boundary edges are kept, and the element stage gives
// the same strain energy for the same deformation (to round-off: the summation order changes).
TEST(Speed, LocalityOrderingOnlyRenumbers) {
  Model m;
  add_grid_rectangle(m, 0.0, 0.0, 0.6, 0.4, 30, 20, false, "big");   // 651 nodes: ordered
  add_grid_rectangle(m, 0.0, -0.1, 0.6, 0.1, 6, 1, true, "ground");  // 14 nodes: kept
  finalize_model(m);
  Model o = m;
  order_for_locality(o);
  ASSERT_EQ(o.nodes.size(), m.nodes.size());
  ASSERT_EQ(o.tris.size(), m.tris.size());
  bool moved = false;
  for (Index i = 0; i < m.nodes.size(); ++i) moved = moved || o.nodes.x0[i] != m.nodes.x0[i];
  EXPECT_TRUE(moved);
  auto boundary_edges = [](const Model& x) {
    int n = 0;
    for (const std::uint8_t b : x.tris.boundary) n += (b & 1) + ((b >> 1) & 1) + ((b >> 2) & 1);
    return n;
  };
  EXPECT_EQ(boundary_edges(o), boundary_edges(m));
  for (std::size_t b = 0; b < m.blocks.size(); ++b) {
    EXPECT_EQ(o.blocks[b].first_node, m.blocks[b].first_node);
    EXPECT_EQ(o.blocks[b].first_tri, m.blocks[b].first_tri);
    EXPECT_NEAR(o.blocks[b].mass, m.blocks[b].mass, 1e-12 * m.blocks[b].mass);
    for (Index i = m.blocks[b].first_node; i < m.blocks[b].first_node + m.blocks[b].node_count; ++i)
      EXPECT_EQ(o.nodes.block[i], Index(b));
  }
  for (Index e = 0; e < o.tris.size(); ++e) EXPECT_GT(o.tris.area0[e], 0.0);
  // Same smooth deformation on both numberings.
  for (Model* x : {&m, &o})
    for (Index i = 0; i < x->nodes.size(); ++i) {
      const double X = x->nodes.x0[i], Y = x->nodes.y0[i];
      x->nodes.x[i] = X + 1e-4 * X * Y;
      x->nodes.y[i] = Y - 2e-4 * X * X;
    }
  const CstLaw law{10e9, 15e9, 0.0};
  const double um = add_element_forces(m, law).strain_energy;
  const double uo = add_element_forces(o, law).strain_energy;
  EXPECT_GT(um, 0.0);
  EXPECT_NEAR(uo, um, 1e-12 * um);
}

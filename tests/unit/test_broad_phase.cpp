// Broad phase (contact/broad_phase.hpp): the NBS candidate set equals the brute-force set
// (same criterion) on random layouts; the participant filter; laziness never misses a contact.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "contact/broad_phase.hpp"
#include "contact/narrow_phase.hpp"

using namespace voussoir;

namespace {

using Rng = std::mt19937_64;

// Appends one block of a random shape: a triangle, a sliver, a quad (2 triangles), a fan
// around a centre node (4 triangles) or a midpoint-subdivided triangle (4 triangles, the middle
// one without a boundary edge). Size s [m], centre (cx, cy), rotation theta.
void add_random_block(Model& m, Rng& rng, double cx, double cy, double s, bool fixed) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double th = 2.0 * std::numbers::pi * u(rng);
  const int shape = static_cast<int>(u(rng) * 5.0);
  std::vector<Vec2> pts;
  std::vector<std::array<Index, 3>> tris;
  switch (shape) {
    case 0:
      pts = {{-0.5, -0.3}, {0.5, -0.2}, {0.1, 0.6}};
      tris = {{0, 1, 2}};
      break;
    case 1:  // sliver: height 1e-3 of its length
      pts = {{-0.5, 0.0}, {0.5, 0.0}, {0.2 * u(rng), 1e-3}};
      tris = {{0, 1, 2}};
      break;
    case 2:
      pts = {{-0.5, -0.35}, {0.5, -0.35}, {0.5, 0.35}, {-0.5, 0.35}};
      tris = {{0, 1, 2}, {0, 2, 3}};
      break;
    case 3:
      pts = {{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}, {0.05, -0.02}};
      tris = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
      break;
    default:
      pts = {{-0.5, -0.4}, {0.5, -0.4}, {0.0, 0.5}, {0.0, -0.4}, {0.25, 0.05}, {-0.25, 0.05}};
      tris = {{0, 3, 5}, {3, 1, 4}, {5, 4, 2}, {3, 4, 5}};
      break;
  }
  for (Vec2& p : pts) {
    const double x = s * p.x, y = s * p.y;
    p = {cx + std::cos(th) * x - std::sin(th) * y, cy + std::sin(th) * x + std::cos(th) * y};
  }
  add_block(m, pts, pts, tris, fixed, fixed ? "ground" : "voussoir");
}

Model random_layout(Rng& rng, int blocks, double spread) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Model m;
  for (int b = 0; b < blocks; ++b) {
    const double s = std::exp(std::log(0.02) + u(rng) * std::log(1.0 / 0.02));  // 0.02..1 m
    add_random_block(m, rng, spread * u(rng), spread * u(rng), s, u(rng) < 0.3);
  }
  // Sometimes a large fixed ground triangle under everything (exercises the "large" path).
  if (u(rng) < 0.3) {
    const std::vector<Vec2> g = {{-5.0, -2.0}, {spread + 5.0, -2.0}, {0.5 * spread, 0.4 * spread}};
    add_block(m, g, g, {{0, 1, 2}}, true, "ground");
  }
  finalize_model(m);
  // Deform a little (current positions differ from the reference ones).
  std::normal_distribution<double> noise(0.0, 0.003);
  for (Index i = 0; i < m.nodes.size(); ++i) {
    m.nodes.x[i] += noise(rng);
    m.nodes.y[i] += noise(rng);
  }
  return m;
}

std::vector<IndexPair> nbs(const Model& m, double buffer) {
  BroadPhase bp;
  bp.setup(m, buffer);
  std::vector<IndexPair> out;
  bp.detect(m.nodes, out);
  return out;
}

}  // namespace

TEST(BroadPhase, NbsEqualsBruteForceOnRandomLayouts) {
  Rng rng(2024);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::int64_t total_pairs = 0, layouts_with_pairs = 0;
  for (int layout = 0; layout < 1200; ++layout) {
    const int blocks = 2 + static_cast<int>(u(rng) * 12);
    const Model m = random_layout(rng, blocks, 0.3 + 2.0 * u(rng));
    const Participants parts = select_participants(m);
    const double buffer = u(rng) < 0.2 ? 0.0 : default_buffer(m, parts) * (1.0 + 4.0 * u(rng));
    const std::vector<IndexPair> got = nbs(m, buffer);
    const std::vector<IndexPair> want = brute_force_candidates(m, buffer);
    ASSERT_EQ(got, want) << "layout " << layout;
    ASSERT_TRUE(std::is_sorted(got.begin(), got.end(), [](const IndexPair& p, const IndexPair& q) {
      return p.a < q.a || (p.a == q.a && p.b < q.b);
    }));
    for (const IndexPair& p : got) {
      ASSERT_LT(p.a, p.b);
      ASSERT_NE(m.tris.block[p.a], m.tris.block[p.b]);
      ASSERT_FALSE(m.blocks[m.tris.block[p.a]].fixed && m.blocks[m.tris.block[p.b]].fixed);
      ASSERT_NE(m.tris.boundary[p.a], 0);
      ASSERT_NE(m.tris.boundary[p.b], 0);
    }
    total_pairs += static_cast<std::int64_t>(got.size());
    layouts_with_pairs += got.empty() ? 0 : 1;
  }
  // The layouts are dense enough to make the comparison meaningful.
  EXPECT_GT(layouts_with_pairs, 900);
  EXPECT_GT(total_pairs, 20000);
}

// Many blocks, some flown far away: the grid caps its rows/columns and still agrees.
TEST(BroadPhase, LargeAndElongatedLayouts) {
  Rng rng(7);
  for (int rep = 0; rep < 4; ++rep) {
    Model m = random_layout(rng, 1500, 12.0);
    if (rep % 2 == 1) {  // move one block 1e4 m away: the domain becomes very elongated
      const Block& b = m.blocks[3];
      for (Index i = b.first_node; i < b.first_node + b.node_count; ++i) m.nodes.x[i] += 1e4;
    }
    const double buffer = 0.01;
    const auto got = nbs(m, buffer);
    EXPECT_EQ(got, brute_force_candidates(m, buffer));
    EXPECT_GT(got.size(), 1000u);
  }
}

TEST(BroadPhase, ParticipantFilter) {
  Model m;
  // Block 0: midpoint-subdivided triangle; triangle 3 is interior (no boundary edge).
  const std::vector<Vec2> p = {{0, 0}, {2, 0}, {1, 2}, {1, 0}, {1.5, 1}, {0.5, 1}};
  add_block(m, p, p, {{0, 3, 5}, {3, 1, 4}, {5, 4, 2}, {3, 4, 5}}, false, "voussoir");
  // Blocks 1 and 2: fixed, overlapping each other and block 0.
  const std::vector<Vec2> q = {{-1, -1}, {3, -1}, {1, 1.5}};
  add_block(m, q, q, {{0, 1, 2}}, true, "ground");
  add_block(m, q, q, {{0, 1, 2}}, true, "ground");
  finalize_model(m);
  const Participants parts = select_participants(m);
  EXPECT_EQ(parts.size(), 5);  // 3 boundary triangles of block 0 and the two fixed ones
  EXPECT_EQ(std::count(parts.tri.begin(), parts.tri.end(), 3), 0);
  const auto pairs = nbs(m, 0.05);
  for (const IndexPair& pr : pairs) {
    EXPECT_NE(pr.a, 3);
    EXPECT_FALSE(pr.a == 4 && pr.b == 5);  // fixed-fixed
  }
  EXPECT_EQ(pairs, brute_force_candidates(m, 0.05));
  EXPECT_EQ(pairs.size(), 6u);  // every boundary triangle of block 0 with both fixed ones
  // All blocks fixed: nothing takes part.
  for (Block& b : m.blocks) b.fixed = true;
  EXPECT_EQ(select_participants(m).size(), 0);
}

// Laziness: random small motions, re-detection only when needs_detection says so; every pair
// of triangles that actually overlaps (positive overlap area) is always among the candidates.
TEST(BroadPhase, LazyDetectionNeverMissesAContact) {
  Rng rng(99);
  std::normal_distribution<double> step(0.0, 1.0);
  std::int64_t overlaps_seen = 0, detections = 0;
  for (int layout = 0; layout < 30; ++layout) {
    Model m = random_layout(rng, 12, 0.6);
    const Participants parts = select_participants(m);
    const double buffer = default_buffer(m, parts);
    BroadPhase bp;
    bp.setup(m, buffer);
    std::vector<IndexPair> cand;
    // Rigid-ish random drift of each free block plus node jitter.
    std::vector<Vec2> vel(m.blocks.size());
    for (Vec2& v : vel) v = {step(rng), step(rng)};
    for (int it = 0; it < 300; ++it) {
      if (bp.needs_detection(m.nodes)) {
        bp.detect(m.nodes, cand);
        ++detections;
      }
      ASSERT_FALSE(bp.needs_detection(m.nodes));
      for (Index i = 0; i < parts.size(); ++i)
        for (Index j = i + 1; j < parts.size(); ++j) {
          const Index a = parts.tri[i], b = parts.tri[j];
          if (parts.block[i] == parts.block[j] || (parts.fixed[i] && parts.fixed[j])) continue;
          auto tri = [&](Index e) {
            return std::array<Vec2, 3>{Vec2{m.nodes.x[m.tris.n0[e]], m.nodes.y[m.tris.n0[e]]},
                                       Vec2{m.nodes.x[m.tris.n1[e]], m.nodes.y[m.tris.n1[e]]},
                                       Vec2{m.nodes.x[m.tris.n2[e]], m.nodes.y[m.tris.n2[e]]}};
          };
          if (triangle_pair_force(tri(a), tri(b), 1.0).area > 0.0) {
            ++overlaps_seen;
            ASSERT_TRUE(std::binary_search(cand.begin(), cand.end(), IndexPair{a, b},
                                           [](const IndexPair& p, const IndexPair& q) {
                                             return p.a < q.a || (p.a == q.a && p.b < q.b);
                                           }))
                << "missed pair " << a << "," << b << " at iteration " << it;
          }
        }
      // Move: each free node by its block's drift (0.15 buffer per step) plus jitter.
      for (Index i = 0; i < m.nodes.size(); ++i) {
        if (m.nodes.inv_mass[i] == 0.0) continue;
        const Vec2 v = vel[m.nodes.block[i]];
        m.nodes.x[i] += 0.15 * buffer * v.x + 0.02 * buffer * step(rng);
        m.nodes.y[i] += 0.15 * buffer * v.y + 0.02 * buffer * step(rng);
      }
    }
  }
  EXPECT_GT(overlaps_seen, 1000);
  EXPECT_GT(detections, 30 * 5);    // it did re-detect
  EXPECT_LT(detections, 30 * 300);  // and not at every step
}

TEST(BroadPhase, NeedsDetectionThreshold) {
  Model m;
  const std::vector<Vec2> a = {{0, 0}, {1, 0}, {0, 1}};
  const std::vector<Vec2> g = {{-1, -1}, {2, -1}, {0.5, -0.01}};
  add_block(m, a, a, {{0, 1, 2}}, false, "voussoir");
  add_block(m, g, g, {{0, 1, 2}}, true, "ground");
  finalize_model(m);
  BroadPhase bp;
  bp.setup(m, 0.1);
  EXPECT_TRUE(bp.needs_detection(m.nodes));  // never detected
  std::vector<IndexPair> out;
  bp.detect(m.nodes, out);
  EXPECT_EQ(out.size(), 1u);
  m.nodes.x[1] += 0.049;
  EXPECT_FALSE(bp.needs_detection(m.nodes));
  m.nodes.y[1] += 0.011;  // |d| = 0.0502 > b/2
  EXPECT_TRUE(bp.needs_detection(m.nodes));
  m.nodes.x[3] += 10.0;  // fixed nodes are not watched
  bp.detect(m.nodes, out);
  m.nodes.x[4] += 10.0;
  EXPECT_FALSE(bp.needs_detection(m.nodes));
}

#include "core/model.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

namespace voussoir {

Index add_block(Model& model, const std::vector<Vec2>& outline, const std::vector<Vec2>& points,
                const std::vector<std::array<Index, 3>>& triangles, bool fixed,
                const std::string& role) {
  Nodes& n = model.nodes;
  Triangles& t = model.tris;
  Block b;
  b.fixed = fixed;
  b.role = role;
  b.polygon = outline;
  b.first_node = n.size();
  b.node_count = static_cast<Index>(points.size());
  b.first_tri = t.size();
  b.tri_count = static_cast<Index>(triangles.size());
  const Index id = static_cast<Index>(model.blocks.size());
  for (const Vec2& p : points) {
    n.x.push_back(p.x);
    n.y.push_back(p.y);
    n.x0.push_back(p.x);
    n.y0.push_back(p.y);
    n.vx.push_back(0.0);
    n.vy.push_back(0.0);
    n.fx.push_back(0.0);
    n.fy.push_back(0.0);
    n.mass.push_back(0.0);
    n.inv_mass.push_back(0.0);
    n.block.push_back(id);
  }
  for (const auto& tri : triangles) {
    Index a = tri[0], c1 = tri[1], c2 = tri[2];
    const Vec2 &pa = points[a], &pb = points[c1], &pc = points[c2];
    const double cross = (pb.x - pa.x) * (pc.y - pa.y) - (pb.y - pa.y) * (pc.x - pa.x);
    if (cross < 0.0) std::swap(c1, c2);
    t.n0.push_back(b.first_node + a);
    t.n1.push_back(b.first_node + c1);
    t.n2.push_back(b.first_node + c2);
    t.block.push_back(id);
  }
  model.blocks.push_back(std::move(b));
  return id;
}

void finalize_model(Model& model) {
  Nodes& n = model.nodes;
  Triangles& t = model.tris;
  const Index nt = t.size();
  // add_block grows the arrays by push_back (capacity up to twice the size): trim once.
  for (auto* v : {&n.x, &n.y, &n.vx, &n.vy, &n.fx, &n.fy, &n.inv_mass, &n.x0, &n.y0, &n.mass})
    v->shrink_to_fit();
  for (auto* v : {&n.block, &t.n0, &t.n1, &t.n2, &t.block}) v->shrink_to_fit();
  t.b00.assign(nt, 0.0);
  t.b01.assign(nt, 0.0);
  t.b10.assign(nt, 0.0);
  t.b11.assign(nt, 0.0);
  t.area0.assign(nt, 0.0);
  t.boundary.assign(nt, 0);
  std::fill(n.mass.begin(), n.mass.end(), 0.0);
  const double rho = model.material.density * model.out_of_plane;

  for (Index e = 0; e < nt; ++e) {
    const Index i0 = t.n0[e], i1 = t.n1[e], i2 = t.n2[e];
    // Reference edge matrix M = [X1-X0, X2-X0]; store M^-1.
    const double m00 = n.x0[i1] - n.x0[i0], m01 = n.x0[i2] - n.x0[i0];
    const double m10 = n.y0[i1] - n.y0[i0], m11 = n.y0[i2] - n.y0[i0];
    const double det = m00 * m11 - m01 * m10;
    assert(det > 0.0);
    t.b00[e] = m11 / det;
    t.b01[e] = -m01 / det;
    t.b10[e] = -m10 / det;
    t.b11[e] = m00 / det;
    t.area0[e] = 0.5 * det;
    const double m3 = rho * t.area0[e] / 3.0;
    n.mass[i0] += m3;
    n.mass[i1] += m3;
    n.mass[i2] += m3;
  }

  // An edge is on the block boundary when no other triangle shares it (nodes belong to one
  // block, so a sharing triangle is of the same block). Sorted edge keys rather than a
  // std::map: a map node per edge (~64 B x 1.5 edges per triangle) stayed in the resident
  // set after being freed (docs/performance.md, memory per triangle).
  auto key = [](Index a, Index b) {
    const auto lo = std::uint64_t(std::uint32_t(std::min(a, b)));
    const auto hi = std::uint64_t(std::uint32_t(std::max(a, b)));
    return (lo << 32) | hi;
  };
  std::vector<std::uint64_t> edges;
  edges.reserve(3 * std::size_t(nt));
  for (Index e = 0; e < nt; ++e) {
    const Index v[3] = {t.n0[e], t.n1[e], t.n2[e]};
    for (int k = 0; k < 3; ++k) edges.push_back(key(v[k], v[(k + 1) % 3]));
  }
  std::sort(edges.begin(), edges.end());
  auto shared = [&edges](std::uint64_t k) {
    const auto it = std::lower_bound(edges.begin(), edges.end(), k);
    return it + 1 != edges.end() && *(it + 1) == k;
  };
  for (Index e = 0; e < nt; ++e) {
    const Index v[3] = {t.n0[e], t.n1[e], t.n2[e]};
    std::uint8_t mask = 0;
    for (int k = 0; k < 3; ++k)
      if (!shared(key(v[k], v[(k + 1) % 3]))) mask |= std::uint8_t(1u << k);
    t.boundary[e] = mask;
  }

  for (Block& b : model.blocks) {
    b.area = 0.0;
    for (Index e = b.first_tri; e < b.first_tri + b.tri_count; ++e) b.area += t.area0[e];
    b.mass = rho * b.area;
    for (Index i = b.first_node; i < b.first_node + b.node_count; ++i) {
      n.inv_mass[i] = (b.fixed || n.mass[i] <= 0.0) ? 0.0 : 1.0 / n.mass[i];
      n.x[i] = n.x0[i];
      n.y[i] = n.y0[i];
      n.vx[i] = n.vy[i] = n.fx[i] = n.fy[i] = 0.0;
    }
  }
}

double distance_to_segment(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 ab = b - a;
  const double len2 = dot(ab, ab);
  if (len2 == 0.0) return distance(p, a);
  const double s = std::clamp(dot(p - a, ab) / len2, 0.0, 1.0);
  return distance(p, a + s * ab);
}

double min_triangle_height(const Model& model) {
  const Nodes& n = model.nodes;
  const Triangles& t = model.tris;
  bool any_free = false;
  for (const Block& b : model.blocks) any_free = any_free || !b.fixed;
  double h = std::numeric_limits<double>::infinity();
  for (Index e = 0; e < t.size(); ++e) {
    if (any_free && model.blocks[t.block[e]].fixed) continue;
    const Index v[3] = {t.n0[e], t.n1[e], t.n2[e]};
    double longest = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double dx = n.x0[v[(k + 1) % 3]] - n.x0[v[k]];
      const double dy = n.y0[v[(k + 1) % 3]] - n.y0[v[k]];
      longest = std::max(longest, std::hypot(dx, dy));
    }
    // Smallest height = 2 A / longest edge.
    h = std::min(h, 2.0 * t.area0[e] / longest);
  }
  return h;
}

namespace {

// Sum of field(b) over the free blocks b, in block order.
template <class T, class F>
T sum_over_free_blocks(const Model& model, F field) {
  T sum{};
  for (const Block& b : model.blocks)
    if (!b.fixed) sum += field(b);
  return sum;
}

}  // namespace

double free_area(const Model& model) {
  return sum_over_free_blocks<double>(model, [](const Block& b) { return b.area; });
}

double free_mass(const Model& model) {
  return sum_over_free_blocks<double>(model, [](const Block& b) { return b.mass; });
}

Index free_node_count(const Model& model) {
  return sum_over_free_blocks<Index>(model, [](const Block& b) { return b.node_count; });
}

}  // namespace voussoir

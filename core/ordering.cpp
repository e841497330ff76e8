// Cache-locality ordering (contract in ordering.hpp).

#include "core/ordering.hpp"

#include <metis.h>

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <vector>

namespace voussoir {

namespace {

// Blocks with at most this many nodes are left alone (their data fits in L1: 64 nodes x 80 B).
constexpr Index kOrderMinNodes = 256;
// Nodes per METIS part: ~128 nodes x 80 B = 10 KiB of node data per part, well inside L1.
constexpr Index kOrderPartNodes = 128;

// New local order of the nodes of one block: local node -> rank.
std::vector<Index> block_node_rank(const Model& model, const Block& b) {
  const Index n = b.node_count, first = b.first_node;
  const Triangles& t = model.tris;
  // Node graph in CSR (each triangle edge once per direction, duplicates removed).
  std::vector<std::vector<idx_t>> adj(static_cast<std::size_t>(n));
  for (Index e = b.first_tri; e < b.first_tri + b.tri_count; ++e) {
    const Index v[3] = {t.n0[e] - first, t.n1[e] - first, t.n2[e] - first};
    for (int k = 0; k < 3; ++k) {
      adj[v[k]].push_back(v[(k + 1) % 3]);
      adj[v[(k + 1) % 3]].push_back(v[k]);
    }
  }
  std::vector<idx_t> xadj(std::size_t(n) + 1, 0), adjncy;
  for (Index i = 0; i < n; ++i) {
    std::sort(adj[i].begin(), adj[i].end());
    adj[i].erase(std::unique(adj[i].begin(), adj[i].end()), adj[i].end());
    adjncy.insert(adjncy.end(), adj[i].begin(), adj[i].end());
    xadj[i + 1] = idx_t(adjncy.size());
  }
  idx_t nvtxs = n, ncon = 1,
        nparts = std::max<idx_t>(2, (n + kOrderPartNodes - 1) / kOrderPartNodes);
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = 1;
  idx_t objval = 0;
  std::vector<idx_t> part(std::size_t(n), 0);
  const int status =
      METIS_PartGraphRecursive(&nvtxs, &ncon, xadj.data(), adjncy.data(), nullptr, nullptr, nullptr,
                               &nparts, nullptr, nullptr, options, &objval, part.data());
  if (status != METIS_OK) throw std::runtime_error("METIS_PartGraphRecursive failed");
  std::vector<Index> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](Index a, Index c) { return part[a] < part[c]; });
  std::vector<Index> rank(static_cast<std::size_t>(n));
  for (Index r = 0; r < n; ++r) rank[order[r]] = r;
  return rank;
}

template <class T>
void permute(std::vector<T>& v, const std::vector<Index>& new_of_old) {
  if (v.empty()) return;
  std::vector<T> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) out[new_of_old[i]] = v[i];
  v.swap(out);
}

}  // namespace

void renumber_model(Model& model, const std::vector<Index>& node_new,
                    const std::vector<Index>& tri_new) {
  Nodes& nodes = model.nodes;
  Triangles& t = model.tris;
  for (auto* v : {&nodes.x, &nodes.y, &nodes.vx, &nodes.vy, &nodes.fx, &nodes.fy, &nodes.inv_mass,
                  &nodes.x0, &nodes.y0, &nodes.mass})
    permute(*v, node_new);
  permute(nodes.block, node_new);
  for (auto* v : {&t.n0, &t.n1, &t.n2})
    for (Index& i : *v) i = node_new[i];
  for (auto* v : {&t.n0, &t.n1, &t.n2, &t.block}) permute(*v, tri_new);
  finalize_model(model);
}

void order_for_locality(Model& model) {
  const Triangles& t = model.tris;
  std::vector<Index> node_new(static_cast<std::size_t>(model.nodes.size()));
  std::iota(node_new.begin(), node_new.end(), 0);
  for (const Block& b : model.blocks) {
    if (b.node_count <= kOrderMinNodes) continue;
    const std::vector<Index> rank = block_node_rank(model, b);
    for (Index i = 0; i < b.node_count; ++i) node_new[b.first_node + i] = b.first_node + rank[i];
  }
  // Triangles of each block by their smallest new node index (stable: ties keep their order).
  std::vector<Index> tri_new(static_cast<std::size_t>(t.size()));
  for (const Block& b : model.blocks) {
    std::vector<Index> order(static_cast<std::size_t>(b.tri_count));
    std::iota(order.begin(), order.end(), b.first_tri);
    auto key = [&](Index e) {
      return std::min({node_new[t.n0[e]], node_new[t.n1[e]], node_new[t.n2[e]]});
    };
    std::stable_sort(order.begin(), order.end(), [&](Index a, Index c) { return key(a) < key(c); });
    for (Index r = 0; r < b.tri_count; ++r) tri_new[order[r]] = b.first_tri + r;
  }
  renumber_model(model, node_new, tri_new);
}

}  // namespace voussoir

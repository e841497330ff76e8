#pragma once
// Deterministic threaded scatter: per-slot force buffers gathered per node in a fixed order.
//
// A one-thread loop adds item contributions into the node forces, fx[i] += slot value, in item
// order. The threaded element stage (core/cst.cpp) instead lets each item write its
// contributions to its own slots of flat buffers, in parallel, and then lets each node sum its
// slots in the order the one-thread loop would have added them, also in parallel (each node is
// written by one thread only). That is the same sequence of floating-point additions onto
// fx[i]: bit-identical to the one-thread loop for any thread count, with no atomics and no
// per-thread force arrays. (The contact stage, where few of the candidate pairs carry forces,
// walks only the touching pairs instead: contact/contact.cpp.)
//
// Layout (CSR over the nodes that receive at least one contribution):
//   node[k]: the k-th such node, ascending ids;
//   begin[k] .. begin[k + 1]: its entries in slot[], in the one-thread loop's order.
// A slot that must add nothing holds -0.0 (x + -0.0 == x bit for bit, for every x).

#include <cstdint>
#include <vector>

#include "core/model.hpp"

namespace voussoir {

struct NodeSlots {
  std::vector<Index> node, begin, slot;
};

// Builds s from visit(add), which must call add(node, slot) for every contribution in the
// order of the one-thread loop; node_count: number of nodes of the model.
template <class Visit>
void build_node_slots(Index node_count, Visit&& visit, NodeSlots& s) {
  std::vector<Index> count(std::size_t(node_count) + 1, 0);
  visit([&count](Index i, Index) { ++count[i + 1]; });
  for (Index i = 0; i < node_count; ++i) count[i + 1] += count[i];
  s.slot.resize(std::size_t(count[node_count]));
  s.node.clear();
  s.begin.clear();
  for (Index i = 0; i < node_count; ++i) {
    if (count[i + 1] == count[i]) continue;
    s.node.push_back(i);
    s.begin.push_back(count[i]);
  }
  s.begin.push_back(count[node_count]);
  visit([&count, &s](Index i, Index slot) { s.slot[std::size_t(count[i]++)] = slot; });
}

// Node count of the gather (the parallel loop runs over k in [0, gathered_nodes(s))).
inline std::int64_t gathered_nodes(const NodeSlots& s) {
  return std::int64_t(s.node.size());
}

// fx[node[k]] += its slots of sfx in order, and fy from sfy.
inline void gather_node_slots(const NodeSlots& s, std::int64_t k, const double* __restrict sfx,
                              const double* __restrict sfy, double* __restrict fx,
                              double* __restrict fy) {
  const Index* __restrict slot = s.slot.data();
  const Index i = s.node[k], j0 = s.begin[k], j1 = s.begin[k + 1];
  double x = fx[i], y = fy[i];
  for (Index j = j0; j < j1; ++j) {
    const Index at = slot[j];
    x += sfx[at], y += sfy[at];
  }
  fx[i] = x, fy[i] = y;
}

}  // namespace voussoir

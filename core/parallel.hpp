#pragma once
// Threading helpers shared by the stages (core/cst.cpp, core/integrate.cpp, core/loads.cpp,
// contact/contact.cpp). Every threaded stage gives results that do not depend on the thread
// count: per-item slots gathered in a fixed order (core/node_slots.hpp), or sums per chunk of
// a size fixed by the model, added in chunk order.

#include <cstdint>
#include <type_traits>
#include <vector>

#include "core/model.hpp"

namespace voussoir {

// Free nodes from which the node stages (loads, integration) sum per chunk and run on threads;
// the same scale as the element stage's kParallelTriangles (core/cst.cpp).
constexpr Index kParallelNodes = 8192;
// Nodes per chunk of those stages.
constexpr Index kNodeChunk = 2048;

// More than one OpenMP thread and no enclosing parallel region (capacity trials, sweeps and
// stability maps run serial simulations side by side on the threads).
bool threads_available();

struct NodeRange {
  Index begin, end;
};

// Free node ranges (contiguous free blocks merged), cut into pieces of at most kNodeChunk, in
// node order.
std::vector<NodeRange> free_node_chunks(const Model& model);

// The node stages' loop (core/loads.cpp, core/integrate.cpp): body(begin, end, sum) over the
// free nodes, returning the total of the sums. Below kParallelNodes free nodes: one running
// sum over the free blocks in order. From there: one sum per kNodeChunk chunk, the chunks on
// the threads, the chunk sums added in chunk order (a grouping fixed by the model, so the
// total does not depend on the thread count). T: double or Vec2.
template <class T, class Body>
T sum_over_free_nodes(const Model& model, Body&& body) {
  T total{};
  if (model.nodes.size() < kParallelNodes || free_node_count(model) < kParallelNodes) {
    for (const Block& b : model.blocks)
      if (!b.fixed) body(b.first_node, b.first_node + b.node_count, total);
    return total;
  }
  // One small allocation per step on this path (a few hundred bytes against ~1 ms of work).
  const std::vector<NodeRange> chunks = free_node_chunks(model);
  std::vector<T> sums(chunks.size(), T{});
  const std::int64_t count = std::int64_t(chunks.size());
#pragma omp parallel for schedule(static) if (threads_available())
  for (std::int64_t k = 0; k < count; ++k) body(chunks[k].begin, chunks[k].end, sums[k]);
  for (const T& s : sums) {
    if constexpr (std::is_same_v<T, Vec2>) {
      total.x += s.x, total.y += s.y;
    } else {
      total += s;
    }
  }
  return total;
}

}  // namespace voussoir

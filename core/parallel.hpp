#pragma once
// Threading helpers shared by the stages (core/cst.cpp, core/integrate.cpp, core/loads.cpp,
// contact/contact.cpp). Every threaded stage gives results that do not depend on the thread
// count: per-item slots gathered in a fixed order (core/node_slots.hpp), or sums per chunk of
// a size fixed by the model, added in chunk order.

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

}  // namespace voussoir

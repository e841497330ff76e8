// Threading helpers (core/parallel.hpp).

#include "core/parallel.hpp"

#include <omp.h>

#include <algorithm>

namespace voussoir {

bool threads_available() {
  return omp_get_max_threads() > 1 && !omp_in_parallel();
}

std::vector<NodeRange> free_node_chunks(const Model& model) {
  std::vector<NodeRange> runs;
  for (const Block& b : model.blocks) {
    if (b.fixed || b.node_count == 0) continue;
    if (!runs.empty() && runs.back().end == b.first_node)
      runs.back().end += b.node_count;
    else
      runs.push_back({b.first_node, b.first_node + b.node_count});
  }
  std::vector<NodeRange> chunks;
  for (const NodeRange& r : runs)
    for (Index i = r.begin; i < r.end; i += kNodeChunk)
      chunks.push_back({i, std::min(r.end, i + kNodeChunk)});
  return chunks;
}

}  // namespace voussoir

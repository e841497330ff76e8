// Body-load stage (math and the external-work bookkeeping in loads.hpp).
//
// Threads. Models with at least kParallelNodes free nodes (core/parallel.hpp) sum the momentum
// per chunk of kNodeChunk nodes and add the chunk sums in chunk order, as the integration
// stage sums its kinetic energy; the chunks run on the OpenMP threads when there are several.
// The grouping depends on the model size only, so results are bit-identical for any thread
// count (the forces are per node anyway). Smaller models keep the single running sum.

#include "core/loads.hpp"

#include <cstdint>
#include <vector>

#include "core/parallel.hpp"

namespace voussoir {

namespace {

// Adds m (ax, ay) to the forces of nodes [begin, end) and their momentum into p.
inline void load_nodes(Nodes& nodes, double ax, double ay, Index begin, Index end, Vec2& p) {
  double* __restrict fx = nodes.fx.data();
  double* __restrict fy = nodes.fy.data();
  const double* __restrict vx = nodes.vx.data();
  const double* __restrict vy = nodes.vy.data();
  const double* __restrict mass = nodes.mass.data();
  double px = p.x, py = p.y;
  for (Index i = begin; i < end; ++i) {
    const double m = mass[i];
    fx[i] += m * ax;
    fy[i] += m * ay;
    px += m * vx[i];
    py += m * vy[i];
  }
  p = Vec2{px, py};
}

}  // namespace

Vec2 add_body_loads(Model& model, double ax, double ay) {
  Vec2 momentum{0.0, 0.0};
  if (model.nodes.size() < kParallelNodes || free_node_count(model) < kParallelNodes) {
    for (const Block& block : model.blocks) {
      if (block.fixed) continue;
      load_nodes(model.nodes, ax, ay, block.first_node, block.first_node + block.node_count,
                 momentum);
    }
    return momentum;
  }
  const std::vector<NodeRange> chunks = free_node_chunks(model);
  std::vector<Vec2> sums(chunks.size(), Vec2{0.0, 0.0});
  const std::int64_t count = std::int64_t(chunks.size());
#pragma omp parallel for schedule(static) if (threads_available())
  for (std::int64_t k = 0; k < count; ++k)
    load_nodes(model.nodes, ax, ay, chunks[k].begin, chunks[k].end, sums[k]);
  for (const Vec2& s : sums) momentum.x += s.x, momentum.y += s.y;
  return momentum;
}

}  // namespace voussoir

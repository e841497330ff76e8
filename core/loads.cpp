// Body-load stage (math and the external-work bookkeeping in loads.hpp).
//
// Threads. Models with at least kParallelNodes free nodes (core/parallel.hpp) sum the momentum
// per chunk of kNodeChunk nodes and add the chunk sums in chunk order, as the integration
// stage sums its kinetic energy; the chunks run on the OpenMP threads when there are several.
// The grouping depends on the model size only, so results are bit-identical for any thread
// count (the forces are per node anyway). Smaller models keep the single running sum.

#include "core/loads.hpp"

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
  return sum_over_free_nodes<Vec2>(model, [&model, ax, ay](Index begin, Index end, Vec2& p) {
    load_nodes(model.nodes, ax, ay, begin, end, p);
  });
}

}  // namespace voussoir

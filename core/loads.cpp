// Body-load stage (math and the external-work bookkeeping in loads.hpp).

#include "core/loads.hpp"

namespace voussoir {

Vec2 add_body_loads(Model& model, double ax, double ay) {
  Nodes& nodes = model.nodes;
  double* __restrict fx = nodes.fx.data();
  double* __restrict fy = nodes.fy.data();
  const double* __restrict vx = nodes.vx.data();
  const double* __restrict vy = nodes.vy.data();
  const double* __restrict mass = nodes.mass.data();
  double px = 0.0, py = 0.0;
  for (const Block& block : model.blocks) {
    if (block.fixed) continue;
    const Index begin = block.first_node, end = block.first_node + block.node_count;
    for (Index i = begin; i < end; ++i) {
      const double m = mass[i];
      fx[i] += m * ax;
      fy[i] += m * ay;
      px += m * vx[i];
      py += m * vy[i];
    }
  }
  return Vec2{px, py};
}

}  // namespace voussoir

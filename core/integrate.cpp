// Central-difference integration stage (math and the kinetic-energy choice in integrate.hpp).

#include "core/integrate.hpp"

#include <algorithm>

namespace voussoir {

void clear_forces(Nodes& nodes) {
  std::fill(nodes.fx.begin(), nodes.fx.end(), 0.0);
  std::fill(nodes.fy.begin(), nodes.fy.end(), 0.0);
}

double integrate_central_difference(Model& model, double dt) {
  Nodes& nodes = model.nodes;
  double* __restrict x = nodes.x.data();
  double* __restrict y = nodes.y.data();
  double* __restrict vx = nodes.vx.data();
  double* __restrict vy = nodes.vy.data();
  const double* __restrict fx = nodes.fx.data();
  const double* __restrict fy = nodes.fy.data();
  const double* __restrict inv_mass = nodes.inv_mass.data();
  const double* __restrict mass = nodes.mass.data();

  double twice_kinetic = 0.0;
  // Nodes of one block are contiguous: one flat loop per free block.
  for (const Block& block : model.blocks) {
    if (block.fixed) continue;
    const Index begin = block.first_node, end = block.first_node + block.node_count;
    for (Index i = begin; i < end; ++i) {
      const double h = dt * inv_mass[i];
      const double ux = vx[i] + h * fx[i];
      const double uy = vy[i] + h * fy[i];
      twice_kinetic += mass[i] * (vx[i] * ux + vy[i] * uy);
      vx[i] = ux;
      vy[i] = uy;
      x[i] += dt * ux;
      y[i] += dt * uy;
    }
  }
  return 0.5 * twice_kinetic;
}

}  // namespace voussoir

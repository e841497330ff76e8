// Central-difference integration stage (math and the kinetic-energy choice in integrate.hpp).
//
// Threads. Models with at least kParallelNodes free nodes sum the kinetic energy per chunk of
// kNodeChunk nodes (chunks of the free node ranges, in node order) and add the chunk sums in
// chunk order; the chunks run on the OpenMP threads when there are several and no enclosing
// parallel region. The summation order depends on the model size only, never on the thread
// count, so results are bit-identical for any thread count. Smaller models keep the single
// running sum (one thread).

#include "core/integrate.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/parallel.hpp"
#include "core/rigid.hpp"

namespace voussoir {

namespace {

// Hot node arrays (STYLE.md "Hot loops").
struct NodeArrays {
  double *x, *y, *vx, *vy;
  const double *fx, *fy, *inv_mass, *mass;
};

NodeArrays arrays_of(Nodes& n) {
  return NodeArrays{n.x.data(),  n.y.data(),  n.vx.data(),       n.vy.data(),
                    n.fx.data(), n.fy.data(), n.inv_mass.data(), n.mass.data()};
}

// Velocity then position update of nodes [begin, end); adds m v^- . v^+ into twice_kinetic.
inline void update_nodes(const NodeArrays& a, double dt, Index begin, Index end,
                         double& twice_kinetic) {
  double* __restrict x = a.x;
  double* __restrict y = a.y;
  double* __restrict vx = a.vx;
  double* __restrict vy = a.vy;
  const double* __restrict fx = a.fx;
  const double* __restrict fy = a.fy;
  const double* __restrict inv_mass = a.inv_mass;
  const double* __restrict mass = a.mass;
  double k2 = twice_kinetic;
  for (Index i = begin; i < end; ++i) {
    const double h = dt * inv_mass[i];
    const double ux = vx[i] + h * fx[i];
    const double uy = vy[i] + h * fy[i];
    k2 += mass[i] * (vx[i] * ux + vy[i] * uy);
    vx[i] = ux;
    vy[i] = uy;
    x[i] += dt * ux;
    y[i] += dt * uy;
  }
  twice_kinetic = k2;
}

// update_nodes with local damping: force f + d (integrate.hpp LocalDamping), d^(n-1) in
// `previous` (2 per node); adds m v^- . v^+ into sums.x and the dissipated energy into sums.y.
inline void update_nodes_damped(const NodeArrays& a, double dt, double alpha, bool outgoing,
                                double* previous, Index begin, Index end, Vec2& sums) {
  double k2 = sums.x, work = sums.y;
  for (Index i = begin; i < end; ++i) {
    const double dx = local_damping_force(alpha, outgoing, a.fx[i], a.vx[i]);
    const double dy = local_damping_force(alpha, outgoing, a.fy[i], a.vy[i]);
    work -= 0.5 * dt * ((dx + previous[2 * i]) * a.vx[i] + (dy + previous[2 * i + 1]) * a.vy[i]);
    previous[2 * i] = dx;
    previous[2 * i + 1] = dy;
    const double h = dt * a.inv_mass[i];
    const double ux = a.vx[i] + h * (a.fx[i] + dx);
    const double uy = a.vy[i] + h * (a.fy[i] + dy);
    k2 += a.mass[i] * (a.vx[i] * ux + a.vy[i] * uy);
    a.vx[i] = ux;
    a.vy[i] = uy;
    a.x[i] += dt * ux;
    a.y[i] += dt * uy;
  }
  sums = Vec2{k2, work};
}

}  // namespace

void clear_forces(Nodes& nodes) {
  const std::int64_t n = nodes.size();
  if (n < kParallelNodes || !threads_available()) {  // no OpenMP runtime call on small models
    std::fill(nodes.fx.begin(), nodes.fx.end(), 0.0);
    std::fill(nodes.fy.begin(), nodes.fy.end(), 0.0);
    return;
  }
  double* __restrict fx = nodes.fx.data();
  double* __restrict fy = nodes.fy.data();
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) fx[i] = fy[i] = 0.0;
}

double integrate_central_difference(Model& model, double dt) {
  const NodeArrays a = arrays_of(model.nodes);
  // Nodes of one block are contiguous: flat loops over free blocks or chunks of them.
  return 0.5 * sum_over_free_nodes<double>(model, [&a, dt](Index begin, Index end, double& k2) {
           update_nodes(a, dt, begin, end, k2);
         });
}

double integrate_central_difference(Model& model, double dt, LocalDamping& damping) {
  const NodeArrays a = arrays_of(model.nodes);
  std::vector<double>& previous = *damping.previous;
  previous.resize(2 * model.nodes.x.size(), 0.0);
  double* prev = previous.data();
  const double alpha = damping.alpha;
  const bool outgoing = damping.outgoing;
  const Vec2 sums = sum_over_free_nodes<Vec2>(
      model, [&a, dt, alpha, outgoing, prev](Index begin, Index end, Vec2& s) {
        update_nodes_damped(a, dt, alpha, outgoing, prev, begin, end, s);
      });
  damping.dissipated = sums.y;
  return 0.5 * sums.x;
}

double apply_kinetic_damping(Model& model, double kinetic, double dt, KineticDamping& damping) {
  double& peak = *damping.peak;
  if (kinetic > peak) {
    peak = kinetic;
    return 0.0;
  }
  if (!(kinetic < (1.0 - damping.drop) * peak)) return 0.0;
  peak = 0.0;
  damping.reset = true;
  if (model.is_rigid()) {
    reset_rigid_step(model, dt);
    return kinetic;
  }
  Nodes& n = model.nodes;
  for (std::size_t b = 0; b < model.blocks.size(); ++b) {
    const Block& blk = model.blocks[b];
    if (blk.fixed) continue;
    for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i) {
      n.x[i] -= dt * n.vx[i];
      n.y[i] -= dt * n.vy[i];
      n.vx[i] = n.vy[i] = 0.0;
    }
  }
  return kinetic;
}

}  // namespace voussoir

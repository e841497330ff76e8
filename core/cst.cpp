// Element stage: finite-strain CST forces over the triangles of free blocks (math in cst.hpp).

#include "core/cst.hpp"

#include <cstddef>

namespace voussoir {

Stress2 triangle_cauchy_stress(const Model& model, Index e, const CstLaw& law) {
  return cst_cauchy_stress(triangle_state(model, e), edge_inverse(model.tris, e), law);
}

namespace {

// The element loop; kViscous: read and update the per-triangle viscous Piola buffer.
template <bool kViscous>
ElementStageResult element_loop(Model& model, const CstLaw& law, double* __restrict viscous) {
  Nodes& nodes = model.nodes;
  const Triangles& tris = model.tris;
  // Hot arrays as local pointers (STYLE.md "Hot loops").
  const double* __restrict x = nodes.x.data();
  const double* __restrict y = nodes.y.data();
  const double* __restrict vx = nodes.vx.data();
  const double* __restrict vy = nodes.vy.data();
  double* __restrict fx = nodes.fx.data();
  double* __restrict fy = nodes.fy.data();
  const Index* __restrict n0 = tris.n0.data();
  const Index* __restrict n1 = tris.n1.data();
  const Index* __restrict n2 = tris.n2.data();
  const double* __restrict b00 = tris.b00.data();
  const double* __restrict b01 = tris.b01.data();
  const double* __restrict b10 = tris.b10.data();
  const double* __restrict b11 = tris.b11.data();
  const double* __restrict area0 = tris.area0.data();
  const double thickness = model.out_of_plane;

  double energy = 0.0, power = 0.0, previous_power = 0.0;
  // Triangles of one block are contiguous: one flat loop per free block.
  for (const Block& block : model.blocks) {
    if (block.fixed) continue;
    const Index begin = block.first_tri, end = block.first_tri + block.tri_count;
    for (Index e = begin; e < end; ++e) {
      const Index i0 = n0[e], i1 = n1[e], i2 = n2[e];
      TriangleState s;
      s.x[0] = x[i0], s.x[1] = x[i1], s.x[2] = x[i2];
      s.y[0] = y[i0], s.y[1] = y[i1], s.y[2] = y[i2];
      s.vx[0] = vx[i0], s.vx[1] = vx[i1], s.vx[2] = vx[i2];
      s.vy[0] = vy[i0], s.vy[1] = vy[i1], s.vy[2] = vy[i2];
      const EdgeInverse b{b00[e], b01[e], b10[e], b11[e]};
      const CstForce f = cst_force(s, b, area0[e] * thickness, law);
      fx[i0] += f.fx[0], fx[i1] += f.fx[1], fx[i2] += f.fx[2];
      fy[i0] += f.fy[0], fy[i1] += f.fy[1], fy[i2] += f.fy[2];
      energy += f.energy;
      power += f.damping_power;
      if constexpr (kViscous) {
        double* __restrict pv = viscous + 4 * std::size_t(e);
        previous_power +=
            pv[0] * f.rate[0] + pv[1] * f.rate[1] + pv[2] * f.rate[2] + pv[3] * f.rate[3];
        pv[0] = f.viscous[0], pv[1] = f.viscous[1], pv[2] = f.viscous[2], pv[3] = f.viscous[3];
      }
    }
  }
  ElementStageResult out;
  out.strain_energy = energy;
  out.damping_power = power;
  out.previous_damping_power = previous_power;
  return out;
}

}  // namespace

ElementStageResult add_element_forces(Model& model, const CstLaw& law, double* viscous) {
  if (viscous != nullptr && law.eta > 0.0) return element_loop<true>(model, law, viscous);
  return element_loop<false>(model, law, nullptr);
}

CstFrequencyBound max_frequency_bound(const Model& model, const CstLaw& law) {
  const Triangles& t = model.tris;
  bool any_free = false;
  for (const Block& b : model.blocks) any_free = any_free || !b.fixed;
  CstFrequencyBound out;
  for (Index e = 0; e < t.size(); ++e) {
    if (any_free && model.blocks[t.block[e]].fixed) continue;
    const CstFrequencyBound b =
        cst_frequency_bound(edge_inverse(t, e), model.material.density, law);
    out.omega_squared = std::max(out.omega_squared, b.omega_squared);
    out.damping_rate = std::max(out.damping_rate, b.damping_rate);
  }
  return out;
}

}  // namespace voussoir

// Element stage: finite-strain CST forces over the triangles of free blocks (math in cst.hpp).

#include "core/cst.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/node_slots.hpp"
#include "core/parallel.hpp"

namespace voussoir {

Stress2 triangle_cauchy_stress(const Model& model, Index e, const CstLaw& law) {
  return cst_cauchy_stress(triangle_state(model, e), edge_inverse(model.tris, e), law);
}

namespace {

// Threads. The one-thread loop runs over chunks of kElementChunk triangles (of the runs of
// contiguous free blocks, for_each_chunk): gather node data
// into small local arrays, run the kernel over the chunk (no indirect writes, so it
// vectorizes: 4 triangles per AVX2 op), then scatter the forces into fx, fy. Measured ~1.5x
// over the plain gather-compute-scatter loop (damped, 1e5 triangles); 16, 32 and 64 perform
// alike. The threaded path runs the same chunks (same function, so the same code and the same
// order of the in-chunk sums) on the threads, each chunk writing its corner forces to its own
// slots of ElementWorkspace::corner_fx/fy; then each node sums its corner slots in ascending
// triangle order (core/node_slots.hpp). That is exactly the sequence of additions the
// scatter makes into fx[i], and the chunk sums are added in chunk order: every force and
// energy is bit-identical to the one-thread loop for any thread count, with no atomics.
// Rejected: colouring (a different addition order from the one-thread loop, so the small
// scenes, which stay on one thread, would change results), per-thread force arrays (the
// reduction order would depend on the thread count).
//
// Fewer free triangles than this stay on one thread: a parallel region costs a few
// microseconds idle, much more when the cores are shared (contact/contact.cpp
// kParallelPairs); 8192 triangles are ~150 us of one-thread work.
constexpr Index kParallelTriangles = 8192;
constexpr int kChunk = kElementChunk;

// Hot arrays of the element stage as flat pointers (STYLE.md "Hot loops").
struct ElementArrays {
  const double *x, *y, *vx, *vy;
  const Index *n0, *n1, *n2;
  const double *b00, *b01, *b10, *b11, *area0;
  double thickness;
  std::size_t nt;
};

ElementArrays arrays_of(const Model& model) {
  const Nodes& n = model.nodes;
  const Triangles& t = model.tris;
  return ElementArrays{n.x.data(),         n.y.data(),           n.vx.data(),  n.vy.data(),
                       t.n0.data(),        t.n1.data(),          t.n2.data(),  t.b00.data(),
                       t.b01.data(),       t.b10.data(),         t.b11.data(), t.area0.data(),
                       model.out_of_plane, std::size_t(t.size())};
}

struct ChunkSums {
  double energy = 0.0, power = 0.0, previous_power = 0.0;
};

// Forces on the corners of triangles [c0, c0 + len) into cfx/cfy (layout [corner][j]) and
// the chunk's energy sums; kViscous: read and update the viscous Piola buffer (ledger).
// kDamped: evaluate the viscous term (law.eta > 0). Not inlined, so that both paths run the
// very same code (same in-chunk summation order).
template <bool kViscous, bool kDamped>
[[gnu::noinline]] ChunkSums chunk_forces(const ElementArrays& a, const CstLaw& law,
                                         double* __restrict viscous, Index c0, int len,
                                         double* __restrict cfx, double* __restrict cfy) {
  const double* __restrict x = a.x;
  const double* __restrict y = a.y;
  const double* __restrict vx = a.vx;
  const double* __restrict vy = a.vy;
  const Index* __restrict n0 = a.n0;
  const Index* __restrict n1 = a.n1;
  const Index* __restrict n2 = a.n2;
  const double* __restrict b00 = a.b00;
  const double* __restrict b01 = a.b01;
  const double* __restrict b10 = a.b10;
  const double* __restrict b11 = a.b11;
  const double* __restrict area0 = a.area0;
  const double thickness = a.thickness;
  const std::size_t nt = a.nt;
  // Node data of the three corners.
  alignas(64) double cx[3][kChunk], cy[3][kChunk], cvx[3][kChunk], cvy[3][kChunk];
  for (int j = 0; j < len; ++j) {  // gather
    const Index e = c0 + j, i0 = n0[e], i1 = n1[e], i2 = n2[e];
    cx[0][j] = x[i0], cx[1][j] = x[i1], cx[2][j] = x[i2];
    cy[0][j] = y[i0], cy[1][j] = y[i1], cy[2][j] = y[i2];
    cvx[0][j] = vx[i0], cvx[1][j] = vx[i1], cvx[2][j] = vx[i2];
    cvy[0][j] = vy[i0], cvy[1][j] = vy[i1], cvy[2][j] = vy[i2];
  }
  double en = 0.0, pw = 0.0, pp = 0.0;
#pragma omp simd reduction(+ : en, pw, pp)
  for (int j = 0; j < len; ++j) {  // compute
    const Index e = c0 + j;
    TriangleState s;
    for (int c = 0; c < 3; ++c) {
      s.x[c] = cx[c][j], s.y[c] = cy[c][j];
      s.vx[c] = cvx[c][j], s.vy[c] = cvy[c][j];
    }
    const EdgeInverse b{b00[e], b01[e], b10[e], b11[e]};
    const CstForce f = cst_force<kDamped>(s, b, area0[e] * thickness, law);
    for (int c = 0; c < 3; ++c) cfx[c * kChunk + j] = f.fx[c], cfy[c * kChunk + j] = f.fy[c];
    en += f.energy;
    if constexpr (kDamped) pw += f.damping_power;
    if constexpr (kViscous) {
      // Power of the previous step's viscous stress at the current velocities; then keep
      // this step's.
      double* __restrict pv = viscous + e;
      pp +=
          pv[0] * f.rate[0] + pv[nt] * f.rate[1] + pv[2 * nt] * f.rate[2] + pv[3 * nt] * f.rate[3];
      pv[0] = f.viscous[0], pv[nt] = f.viscous[1];
      pv[2 * nt] = f.viscous[2], pv[3 * nt] = f.viscous[3];
    }
  }
  return ChunkSums{en, pw, pp};
}

// Calls f(c0, len) for the chunks of the element loop in order: runs of contiguous free
// blocks' triangles (merged across block boundaries, so small blocks still fill whole
// vectors), cut into kChunk triangles.
template <class F>
void for_each_chunk(const Model& model, F&& f) {
  const std::size_t nb = model.blocks.size();
  for (std::size_t b = 0; b < nb;) {
    if (model.blocks[b].fixed) {
      ++b;
      continue;
    }
    const Index begin = model.blocks[b].first_tri;
    Index end = begin + model.blocks[b].tri_count;
    for (++b; b < nb && !model.blocks[b].fixed && model.blocks[b].first_tri == end; ++b)
      end += model.blocks[b].tri_count;
    for (Index c0 = begin; c0 < end; c0 += kChunk) f(c0, int(std::min<Index>(kChunk, end - c0)));
  }
}

ElementStageResult result_of(const ChunkSums& s) {
  ElementStageResult out;
  out.strain_energy = s.energy;
  out.damping_power = s.power;
  out.previous_damping_power = s.previous_power;
  return out;
}

// The one-thread element loop: chunks of the free blocks in order, scatter after each.
template <bool kViscous, bool kDamped>
ElementStageResult element_loop(Model& model, const CstLaw& law, double* viscous) {
  const ElementArrays a = arrays_of(model);
  double* __restrict fx = model.nodes.fx.data();
  double* __restrict fy = model.nodes.fy.data();
  alignas(64) double cfx[3][kChunk], cfy[3][kChunk];
  ChunkSums sum;
  for_each_chunk(model, [&](Index c0, int len) {
    const ChunkSums c = chunk_forces<kViscous, kDamped>(a, law, viscous, c0, len, cfx[0], cfy[0]);
    sum.energy += c.energy, sum.power += c.power, sum.previous_power += c.previous_power;
    for (int j = 0; j < len; ++j) {  // scatter
      const Index e = c0 + j, i0 = a.n0[e], i1 = a.n1[e], i2 = a.n2[e];
      fx[i0] += cfx[0][j], fx[i1] += cfx[1][j], fx[i2] += cfx[2][j];
      fy[i0] += cfy[0][j], fy[i1] += cfy[1][j], fy[i2] += cfy[2][j];
    }
  });
  return result_of(sum);
}

// Chunk list and node -> corner-slot CSR of the threaded path (layout in cst.hpp).
void build_workspace(const Model& model, ElementWorkspace& w) {
  w.chunk_first.clear();
  w.chunk_len.clear();
  for_each_chunk(model, [&w](Index c0, int len) {
    w.chunk_first.push_back(c0);
    w.chunk_len.push_back(len);
  });
  const std::size_t chunks = w.chunk_first.size(), slots = 3 * kChunk * chunks;
  w.corner_fx.assign(slots, 0.0);
  w.corner_fy.assign(slots, 0.0);
  w.chunk_sums.assign(3 * chunks, 0.0);
  const Triangles& t = model.tris;
  build_node_slots(
      model.nodes.size(),
      [&w, &t, chunks](auto&& add) {
        for (std::size_t k = 0; k < chunks; ++k)  // ascending triangle order
          for (int j = 0; j < w.chunk_len[k]; ++j) {
            const Index e = w.chunk_first[k] + j, slot = Index(k * 3 * kChunk) + j;
            add(t.n0[e], slot), add(t.n1[e], slot + kChunk), add(t.n2[e], slot + 2 * kChunk);
          }
      },
      w.slots);
  w.built_tris = t.size();
  w.built_nodes = model.nodes.size();
}

// The threaded element stage: chunks on the threads, then the per-node gather.
template <bool kViscous, bool kDamped>
ElementStageResult element_threads(Model& model, const CstLaw& law, double* viscous,
                                   ElementWorkspace& w) {
  const ElementArrays a = arrays_of(model);
  double* __restrict fx = model.nodes.fx.data();
  double* __restrict fy = model.nodes.fy.data();
  const std::int64_t chunks = std::int64_t(w.chunk_first.size());
  const std::int64_t nodes = gathered_nodes(w.slots);
  double* corner_fx = w.corner_fx.data();
  double* corner_fy = w.corner_fy.data();
  double* sums = w.chunk_sums.data();
#pragma omp parallel
  {
#pragma omp for schedule(static)
    for (std::int64_t k = 0; k < chunks; ++k) {
      const ChunkSums c =
          chunk_forces<kViscous, kDamped>(a, law, viscous, w.chunk_first[k], w.chunk_len[k],
                                          corner_fx + k * 3 * kChunk, corner_fy + k * 3 * kChunk);
      sums[3 * k] = c.energy, sums[3 * k + 1] = c.power, sums[3 * k + 2] = c.previous_power;
    }
#pragma omp for schedule(static)
    for (std::int64_t k = 0; k < nodes; ++k)  // gather, in the scatter's order
      gather_node_slots(w.slots, k, corner_fx, corner_fy, fx, fy);
  }
  ChunkSums sum;
  for (std::int64_t k = 0; k < chunks; ++k)
    sum.energy += sums[3 * k], sum.power += sums[3 * k + 1], sum.previous_power += sums[3 * k + 2];
  return result_of(sum);
}

// Specialised on the features in use: viscous term (eta > 0) and ledger buffer, so an
// undamped run pays for neither (measured with bench/bench_elements).
template <bool kViscous, bool kDamped>
ElementStageResult element_stage(Model& model, const CstLaw& law, double* viscous,
                                 ElementWorkspace* work) {
  if (work != nullptr && model.tris.size() >= kParallelTriangles && threads_available()) {
    if (work->built_tris != model.tris.size() || work->built_nodes != model.nodes.size())
      build_workspace(model, *work);
    if (std::int64_t(work->chunk_first.size()) * kChunk >= kParallelTriangles)
      return element_threads<kViscous, kDamped>(model, law, viscous, *work);
  }
  return element_loop<kViscous, kDamped>(model, law, viscous);
}

}  // namespace

ElementStageResult add_element_forces(Model& model, const CstLaw& law, double* viscous,
                                      ElementWorkspace* work) {
  if (!(law.eta > 0.0)) return element_stage<false, false>(model, law, nullptr, work);
  if (viscous == nullptr) return element_stage<false, true>(model, law, nullptr, work);
  return element_stage<true, true>(model, law, viscous, work);
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

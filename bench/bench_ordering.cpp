// Effect of the METIS locality ordering (core/ordering.hpp) on the element stage and on the
// whole step, one thread, CPU time. Models:
//   rect       one block of 160 x 320 cells (102400 triangles) meshed row by row (the order
//              of a structured mesher: already local);
//   rect-shuf  the same with nodes and triangles randomly renumbered (a mesher with no order);
//   wall       bench/wall.hpp, 102912 triangles in 401 blocks of <= 153 nodes (below the
//              ordering threshold: unchanged by it, listed for the step rate);
//   church     cases/church_a.toml at mesh.size 0.03 (103628 triangles, CGAL mesher order).
// Each model as built and after order_for_locality. Runs alternate the two versions three
// times; the figure is the smallest CPU time per triangle (load noise only adds).
//
// Run: OMP_NUM_THREADS=1 build-*/bench_ordering

#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <numeric>
#include <random>
#include <string>
#include <utility>

#include "bench/wall.hpp"
#include "core/cst.hpp"
#include "core/integrate.hpp"
#include "core/ordering.hpp"
#include "engine/setup.hpp"
#include "io/deck.hpp"

using namespace voussoir;

namespace {

double cpu_seconds() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Random renumbering of nodes and triangles inside each block.
void shuffle_blocks(Model& m) {
  std::mt19937_64 rng(3);
  std::vector<Index> node_new(static_cast<std::size_t>(m.nodes.size())),
      tri_new(static_cast<std::size_t>(m.tris.size()));
  std::iota(node_new.begin(), node_new.end(), 0);
  std::iota(tri_new.begin(), tri_new.end(), 0);
  for (const Block& b : m.blocks) {
    std::shuffle(node_new.begin() + b.first_node, node_new.begin() + b.first_node + b.node_count,
                 rng);
    std::shuffle(tri_new.begin() + b.first_tri, tri_new.begin() + b.first_tri + b.tri_count, rng);
  }
  renumber_model(m, node_new, tri_new);
}

// bench_simulation after 20 steps (contact pairs found, workspaces built).
Simulation simulation_of(Model model) {
  Simulation sim = bench::bench_simulation(std::move(model));
  for (int k = 0; k < 20; ++k) advance(sim);
  return sim;
}

// CPU ns per triangle of the element stage (clear + elements) and of a whole step.
void measure(Simulation& sim, double& element_ns, double& step_ns) {
  const CstLaw law{sim.ctx.lame_lambda, sim.ctx.shear_modulus, sim.ctx.eta};
  const double tris = double(sim.model.tris.size());
  const int reps = 40;
  double t0 = cpu_seconds();
  for (int k = 0; k < reps; ++k) {
    clear_forces(sim.model.nodes);
    add_element_forces(sim.model, law, sim.viscous_piola.data(), &sim.element_work);
  }
  element_ns = std::min(element_ns, 1e9 * (cpu_seconds() - t0) / (reps * tris));
  t0 = cpu_seconds();
  for (int k = 0; k < reps; ++k) advance(sim);
  step_ns = std::min(step_ns, 1e9 * (cpu_seconds() - t0) / (reps * tris));
}

void compare(const std::string& name, const Model& built) {
  Model ordered = built;
  order_for_locality(ordered);
  Simulation a = simulation_of(built), b = simulation_of(ordered);
  double ea = 1e30, sa = 1e30, eb = 1e30, sb = 1e30;
  for (int r = 0; r < 3; ++r) {
    measure(a, ea, sa);
    measure(b, eb, sb);
  }
  std::printf("%-10s %7d tris  elements %6.2f -> %6.2f ns/tri   step %6.2f -> %6.2f ns/tri\n",
              name.c_str(), int(built.tris.size()), ea, eb, sa, sb);
}

}  // namespace

int main() {
  omp_set_num_threads(1);
  std::printf("CPU ns per triangle, as built -> after order_for_locality (one thread)\n");
  Model rect;
  add_grid_rectangle(rect, 0.0, 0.0, 1.6, 3.2, 160, 320, false, "block");
  add_grid_rectangle(rect, -0.1, -0.2, 1.8, 0.2, 4, 1, true, "ground");
  finalize_model(rect);
  compare("rect", rect);
  Model shuffled = rect;
  shuffle_blocks(shuffled);
  compare("rect-shuf", shuffled);
  compare("wall", bench::wall_model(20, 20, 16, 8));
  const Config church =
      load_deck(std::string(VOUSSOIR_SOURCE_DIR) + "/cases/church_a.toml", {"mesh.size=0.03"});
  compare("church", make_simulation(church).model);
  return 0;
}

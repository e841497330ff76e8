#pragma once
// The large benchmark structure of docs/benchmarks.md: a dry-stone wall in running bond on a
// fixed ground slab. Blocks 0.4 m x 0.2 m, each a gridded rectangle (mesh/rectangle.hpp) of
// cells_x x cells_y cells (two triangles each, alternating diagonals); odd courses are
// shifted by half a block and end with half blocks. Material of cases/circular_arch.toml
// (E 40 GPa, nu 0.2, rho 2000), friction 0.6, default penalty (100 x Lame lambda) and
// damping (factor 1), gravity, dt = 0.5 x the stable step.
// 20 courses x 20 blocks of 16 x 8 cells: 102400 + 512 triangles.

#include <array>
#include <utility>
#include <vector>

#include "core/model.hpp"
#include "engine/step.hpp"
#include "mesh/rectangle.hpp"

namespace voussoir::bench {

inline Model wall_model(int courses, int per_course, int cells_x, int cells_y) {
  const double w = 0.4, h = 0.2, length = w * per_course;
  Model m;
  m.kind = "wall";
  add_grid_rectangle(m, -0.2, -0.2, length + 0.4, 0.2, 2 * cells_x, cells_y, true, "ground");
  for (int c = 0; c < courses; ++c) {
    const double y = h * c;
    if (c % 2 == 0) {
      for (int b = 0; b < per_course; ++b)
        add_grid_rectangle(m, w * b, y, w, h, cells_x, cells_y, false, "block");
    } else {  // half block, per_course - 1 whole blocks, half block
      add_grid_rectangle(m, 0.0, y, 0.5 * w, h, cells_x / 2, cells_y, false, "block");
      for (int b = 0; b + 1 < per_course; ++b)
        add_grid_rectangle(m, 0.5 * w + w * b, y, w, h, cells_x, cells_y, false, "block");
      add_grid_rectangle(m, length - 0.5 * w, y, 0.5 * w, h, cells_x / 2, cells_y, false, "block");
    }
  }
  finalize_model(m);
  return m;
}

// Ready-to-step simulation of a model with the settings above (contact, damping, gravity, dt).
inline Simulation bench_simulation(Model model) {
  Simulation sim;
  sim.model = std::move(model);
  ContactParams cp;
  cp.penalty = 100.0 * sim.model.material.lame_lambda();
  cp.friction = 0.6;
  sim.contact.setup(sim.model, cp);
  prepare_context(sim, 1.0);
  sim.ctx.body_ax = 0.0;
  sim.ctx.body_ay = -9.81;
  sim.ctx.dt = 0.5 * stable_time_step(sim);
  return sim;
}

inline Simulation wall_simulation(int courses, int per_course, int cells_x = 16, int cells_y = 8) {
  return bench_simulation(wall_model(courses, per_course, cells_x, cells_y));
}

}  // namespace voussoir::bench

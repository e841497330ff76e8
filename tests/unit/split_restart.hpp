#pragma once
// Test helper: a rocking rigid block run straight for 400 steps, and the same run split at step
// 150 by a checkpoint restored into a fresh simulation that runs 250 more (tests/unit/
// test_rigid.cpp and test_nscd.cpp compare the two bit for bit).

#include <functional>
#include <string>
#include <utility>

#include "core/rigid.hpp"
#include "engine/checkpoint.hpp"
#include "engine/step.hpp"

namespace voussoir::testing {

// `make` builds the simulation from its deck; the free block `block` starts tilted by 0.05 rad
// at (0, 0.51). Returns {straight, restarted}. `checkpoint`: the file's path.
inline std::pair<Simulation, Simulation> split_restart(const std::function<Simulation()>& make,
                                                       Index block, double friction,
                                                       const std::string& checkpoint) {
  auto tilted = [&] {
    Simulation s = make();
    set_rigid_state(s.model, block, 0.0, 0.51, 0.05, 0.0, 0.0, 0.0);
    return s;
  };
  Simulation straight = tilted();
  for (int k = 0; k < 400; ++k) advance(straight);
  Simulation first = tilted();
  for (int k = 0; k < 150; ++k) advance(first);
  write_checkpoint(checkpoint, first, simulation_fingerprint(first, friction), friction, {});
  Simulation second = make();
  read_checkpoint(checkpoint, second, simulation_fingerprint(second, friction));
  for (int k = 0; k < 250; ++k) advance(second);
  return {std::move(straight), std::move(second)};
}

}  // namespace voussoir::testing

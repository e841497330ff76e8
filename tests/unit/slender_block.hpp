#pragma once
// The slender rigid block that tests run through the program (test_pulse_stepping.cpp,
// test_ida.cpp): cases/block.toml at 0.2 x 1 m (b/h = 0.2, its tilting capacity), rigid, stiff
// joints (kn = ks = 1e10 N/m3) and full impact damping (restitution 0).

#include <string>
#include <vector>

namespace voussoir::testing {

// The program, `command` and the deck with the block's settings; the caller appends the rest.
inline std::vector<std::string> slender_block_args(const std::string& command) {
  return {VOUSSOIR_BINARY,
          command,
          std::string(VOUSSOIR_SOURCE_DIR) + "/cases/block.toml",
          "--set",
          "model.width=0.2",
          "--set",
          "material.model=\"rigid\"",
          "--set",
          "contact.normal_stiffness=1e10",
          "--set",
          "contact.shear_stiffness=1e10",
          "--set",
          "contact.restitution=0"};
}

}  // namespace voussoir::testing

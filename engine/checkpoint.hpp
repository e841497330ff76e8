#pragma once
// Checkpoint files of `voussoir run` (--checkpoint-every, --restart): everything that evolves
// during a run, so that a restarted run continues bit for bit as the uninterrupted one would
// have (tests/unit/test_restart.cpp compares every node position and velocity and the ledger).
//
// What is saved, and why it is enough:
//   - node positions and velocities (x, y, vx, vy); forces are cleared at the start of every
//     step, masses and every per-triangle constant come from the mesh;
//   - the step counter, the time, and the body acceleration of the previous step (the
//     trapezoidal external work of engine/step.cpp reads it);
//   - every field of the energy ledger (accumulated terms and the peak energy);
//   - the viscous Piola stress of the last damped step (Simulation::viscous_piola: the exact
//     damping work of the next step reads it);
//   - the contact state (below);
//   - the driver's bookkeeping, opaque here (for `run`: series rows so far, next snapshot time,
//     largest energy error, loop statistics; commands/run.cpp).
// Everything else (mesh, masses, law constants, contact set-up, dt) is rebuilt from the deck by
// make_simulation. A fingerprint of those rebuilt parts is stored and compared on restart, so a
// checkpoint is never restored into another model (an edited deck, another --set); keys that
// do not change the model (solver.end_time, output.*) may differ, which lets a finished run be
// extended.
//
// Contact state. The ContactSystem keeps its candidate pairs, the friction slip of each pair
// and the broad phase's positions of the last detection behind a private Impl; its
// save_state() bytes are stored as they are and restore_state() puts them back (it re-runs the
// last detection from the saved positions, so candidate list, detection steps and slip
// history continue exactly; contact/contact.hpp). With or without friction.
//
// Format (version 1): binary, native byte order and IEEE doubles (restart on the machine type
// that wrote it; the header records the byte order and a mismatch is refused):
//   "VOUSSOIR-CKPT\n" (14 bytes), u32 version, u32 byte-order tag 0x01020304,
//   u64 fingerprint, i64 step, f64 time, dt, prev_body_ax, prev_body_ay,
//   7 x f64 ledger (kinetic, strain, contact, external_work, damping_dissipated,
//   friction_dissipated, max_energy), arrays x, y, vx, vy, viscous_piola, u8 contact kind
//   (1: ContactSystem bytes follow; 0, from builds before save_state, is refused), contact
//   bytes, driver values (each array: u64 count then the items), u64 FNV-1a checksum of
//   everything before it.
// Written to PATH.tmp, flushed and closed, then renamed over PATH (atomic on POSIX file
// systems): a run killed while writing leaves the previous checkpoint intact.

#include <cstdint>
#include <string>
#include <vector>

#include "engine/step.hpp"

namespace voussoir {

// Fingerprint of everything make_simulation rebuilds from the deck: node and triangle counts,
// reference positions, masses, connectivity, material, out-of-plane thickness, dt, law
// constants, damping, body loads, contact switch, penalty and buffer, and `friction` (the
// Coulomb mu of the deck, which the contact interface does not expose). FNV-1a over the bits.
std::uint64_t simulation_fingerprint(const Simulation& sim, double friction);

// Writes the checkpoint atomically (PATH.tmp then rename). Throws OutputError naming the path
// when the file cannot be written. `friction` is not used (the contact state carries what
// friction needs; the fingerprint takes mu).
void write_checkpoint(const std::string& path, const Simulation& sim, std::uint64_t fingerprint,
                      double friction, const std::vector<double>& driver_state);

// Restores the checkpoint into `sim`, freshly built by make_simulation from the same deck, and
// returns the driver values. Throws DeckError (exit status 2: a bad argument) naming the path
// when the file is missing, truncated, corrupt, of another version or byte order, or was
// written for another model (fingerprint or sizes differ).
std::vector<double> read_checkpoint(const std::string& path, Simulation& sim,
                                    std::uint64_t fingerprint);

}  // namespace voussoir

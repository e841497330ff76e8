#pragma once
// Energy ledger (Solfec-style): what went in, what is stored, what was dissipated [J, per the
// model's out-of-plane thickness]. Balance: external_work = kinetic + strain + contact +
// damping_dissipated + friction_dissipated (up to the O(dt^2) error of central differences).

namespace voussoir {

struct EnergyLedger {
  double kinetic = 0.0;              // stored, recomputed each step
  double strain = 0.0;               // stored, recomputed each step
  double contact = 0.0;              // stored penalty energy, recomputed each step
  double external_work = 0.0;        // accumulated: body loads, base motion
  double damping_dissipated = 0.0;   // accumulated: Munjiza viscous term
  double friction_dissipated = 0.0;  // accumulated: Coulomb slip
  double impact_dissipated = 0.0;    // accumulated: contact normal damping (restitution < 1)
  // accumulated: Cundall's local damping of the quasi-static phases (capacity and sweep
  // trials, core/integrate.hpp LocalDamping); 0 in the physical runs (run, pulse, stability),
  // so checkpoints do not carry it
  double local_dissipated = 0.0;
  double max_energy = 0.0;           // largest of the terms seen so far (normalises the error)

  double stored() const { return kinetic + strain + contact; }
  double dissipated() const {
    return damping_dissipated + friction_dissipated + impact_dissipated + local_dissipated;
  }
  // |W - K - U - C - D| / max energy seen (0 before anything happened).
  double balance_error() const;
  void update_max();
};

}  // namespace voussoir

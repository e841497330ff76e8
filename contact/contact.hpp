#pragma once
// Contact between blocks: NBS broad phase (contact/broad_phase), Munjiza potential-based
// penalty force over triangle overlaps (contact/narrow_phase), Coulomb friction on accumulated
// slip (contact/friction); for rigid blocks, the joint law between outlines
// (contact/rigid_contact). This header is the one interface engine/step.cpp calls.

#include <cstdint>
#include <memory>
#include <vector>

#include "contact/nscd.hpp"
#include "contact/rigid_contact.hpp"
#include "core/energy.hpp"
#include "core/model.hpp"

namespace voussoir {

struct ContactParams {
  double penalty = 0.0;   // Ep [Pa] (normal penalty of the potential contact)
  double friction = 0.0;  // Coulomb mu; 0 = no friction work at all
  double buffer = 0.0;    // NBS buffer [m]; 0 = automatic (a fraction of the smallest element)
  // Joint stiffness in engineering units (contact/joint_stiffness.hpp). normal_stiffness kn
  // [N/m3] > 0 replaces the single penalty by one per pair that gives kn on a flat joint;
  // joint_young E [Pa] > 0 (and kn = 0) takes kn = 100 E / L per pair instead (L: the
  // joint's length; the rigid-block default, contact/joint_stiffness.hpp). shear_stiffness ks [N/m3]: tangential spring of the
  // friction law; 0 = 1/4 of the normal stiffness (kTangentialStiffnessRatio).
  double normal_stiffness = 0.0;
  double joint_young = 0.0;
  double shear_stiffness = 0.0;
  // Coefficient of restitution of a normal impact between two bodies, in [0, 1]; 1 = no impact
  // damping (contact/joint_stiffness.hpp). Rigid blocks only: on elastic blocks the dashpot
  // would be tuned to the joint's low frequency and overdamp the element modes that share it.
  double restitution = 1.0;
  // Rigid blocks by non-smooth contact dynamics (solver.scheme = "nscd", contact/nscd.hpp):
  // contact points and impulses instead of the joint law's forces; the stiffness keys above
  // do not apply.
  bool nscd = false;
};

// Highest contact frequency bound and the damping rate (c/m) of that mode [1/s2, 1/s], for the
// stable step of engine/step.cpp.
// The contact force of one touching pair at the current configuration, as the contact stage
// applies it (potential, friction and impact damping parts): on_c[k] on node k (n0, n1, n2) of
// triangle tri_c, on_t[k] on node k of triangle tri_t [N].
struct TouchingPair {
  Index tri_c = 0, tri_t = 0;
  Vec2 on_c[3], on_t[3];
};

struct ContactFrequencyBound {
  double omega_squared = 0.0;
  double damping_rate = 0.0;
};

class ContactSystem {
 public:
  // Value semantics: a copy is a deep copy (capacity trials start from copies of one settled
  // state), including pair lists and friction history.
  ContactSystem();
  ~ContactSystem();
  ContactSystem(const ContactSystem& other);
  ContactSystem& operator=(const ContactSystem& other);
  ContactSystem(ContactSystem&&) noexcept;
  ContactSystem& operator=(ContactSystem&&) noexcept;

  // Chooses the participating triangles (boundary edge, not both fixed), sizes the grid.
  void setup(const Model& model, const ContactParams& params);
  // True when some node has moved more than buffer/2 since the last detection (elastic
  // blocks; always false for rigid ones, which the Model overload serves).
  bool needs_detection(const Nodes& nodes) const;
  // The same for any model: for rigid blocks, when some body has moved a point of its outline
  // by more than buffer/2 (contact/rigid_contact.hpp).
  bool needs_detection(const Model& model) const;
  // Broad phase: rebuilds the candidate pair list (friction history carried over by key).
  void detect(const Model& model);
  // Narrow phase + friction: adds contact forces into nodes.fx/fy (rigid blocks: into the
  // bodies' force and moment), sets ledger.contact and accumulates ledger.friction_dissipated
  // and ledger.impact_dissipated. energy false lets rigid blocks leave ledger.contact as it is
  // (StepContext::contact_energy); elastic blocks always set it.
  void add_forces(Model& model, double dt, EnergyLedger& ledger, bool energy = true);

  // Non-smooth contact dynamics (ContactParams::nscd; contact/nscd.hpp): the contact points at
  // the bodies' current poses (after the broad phase), then the step's impulses from the
  // bodies' free velocities (NscdContact::solve).
  bool nscd_mode() const;
  void build_contact_points(const Model& model);
  NscdStepResult solve_impulses(Model& model, const std::vector<double>& before, double h,
                                Vec2 load, const NscdSettings& settings);

  // The force of every touching pair at the current node positions and velocities, in pair
  // order: what the next add_forces would apply, evaluated on a copy of this system (detection
  // when needed, then the narrow phase and friction), so the run's state and its forces are
  // untouched. For reports (engine/thrust.hpp), never called inside the step.
  std::vector<TouchingPair> pair_forces(const Model& model, double dt) const;
  // Rigid blocks: the force of every touching block pair (contact/rigid_contact.hpp), the same
  // way (by non-smooth contact dynamics: the last step's impulses / dt); empty for elastic
  // blocks (pair_forces serves them).
  std::vector<BlockPairForce> block_pair_forces(const Model& model, double dt) const;
  // True when the blocks are rigid and touch by their outlines.
  bool rigid_outlines() const;

  // Largest effective contact stiffness per unit nodal mass, for the stable time step:
  // omega_max^2 estimate [1/s2].
  double max_omega_squared(const Model& model) const;
  // The same for rigid blocks (Model::rigid), block by block: each body on its joints, from
  // their stiffness and its mass and rotational inertia (contact/joint_stiffness.hpp); zero
  // for a fixed block or one without faces. The model's step is the shortest of theirs.
  std::vector<ContactFrequencyBound> rigid_body_bounds(const Model& model) const;
  // True when the pairs carry their own penalty from a joint stiffness (kn or 100 E / L).
  bool joint_stiffness_mode() const;

  // Candidate pairs from which add_forces runs on threads (default 8192, contact/contact.cpp
  // kParallelPairs): tests lower it to run the threaded path on small scenes.
  void set_parallel_pairs(std::int64_t min_pairs);

  std::int64_t candidate_pairs() const;
  std::int64_t active_pairs() const;  // pairs with nonzero overlap at the last add_forces
  std::int64_t detections() const;

  // Additions (contact helper):
  double penalty() const;  // Ep in use [Pa] (ContactParams::penalty, or 100 x Lame lambda if 0)
  const ContactParams& params() const;  // as given to setup
  double buffer() const;                // NBS buffer in use [m]

  // Checkpoints (engine/checkpoint.hpp). save_state: what evolves here -- the candidate pairs and
  // their friction slip, the positions of the free participant nodes at the last detection
  // (the broad phase's reference for needs_detection), the detection and active-pair counts --
  // as opaque bytes (native byte order, like the checkpoint). restore_state, on a system set up
  // for the same model with the checkpoint's node positions in place: re-runs the last
  // detection from the saved positions (same candidate list, same reference, so the next
  // detections happen at the same steps) and puts the slip back, so the run continues bit for
  // bit. Throws std::runtime_error when the bytes do not fit this model.
  std::vector<char> save_state() const;
  void restore_state(const Model& model, const std::vector<char>& bytes);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace voussoir

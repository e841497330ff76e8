// Contact stage: NBS broad phase (lazy), potential penalty narrow phase, Coulomb friction.
//
// Threads. With OpenMP and at least kParallelPairs candidates, one parallel region per step:
// pairs are evaluated in parallel (each pair owns its friction state) and write their corner
// forces to their own slots; after one barrier each thread walks the touching pairs in pair
// order and adds the corners whose node lies in its own range of node ids (ranges cut at
// equal shares of the candidates' corners, once per detection), which gives every node the
// sequence of additions of the one-thread loop; the first thread also sums the energies in
// pair order. So forces and energies are bit-identical to the one-thread loop for any thread
// count (no atomics, no per-thread force arrays), and only the touching pairs are read. Below
// that size, or inside an enclosing parallel region (parallel sweeps), one thread evaluates
// and adds each pair in turn.
//
// Stable time step contribution (max_omega_squared). Model: a boundary edge k of length L
// pressed flat into a partner face by a depth d. The overlap is a strip of area L d lying in
// the sub-triangles next to the two faces, where |grad phi| = 3/h (h: height of each triangle
// over its face), so the pair force is Ep thick g L d with g = 3/h_c + 3/h_t. With linear
// shape functions along the edge the stiffness of its two nodes is Ep thick g [L/3 L/6; L/6 L/3]
// in the normal direction n, coupled (negated) to the partner's nodes; the Gershgorin row sum
// of a node is Ep thick g L (L/3 + L/6 own, as much on the partner), and the largest
// eigenvalue of M^-1 K, the two faces vibrating against each other, equals it for equal masses.
// Friction adds at most half of that in the tangential direction e (contact/friction.hpp).
// So each free node i gets the 2x2 matrix
//     S_i = sum_{boundary edges k at i} Ep thick g_k L_k (n_k n_k^T + 1/2 e_k e_k^T)
// and omega^2 <= max_i lambda_max(S_i) / m_i. Directions matter: along a flat face the edges
// add up, at a corner the two faces act in perpendicular directions. For g_k the partner's
// height is the smallest face height over the participants of the other blocks (a free block
// can meet any of them). Against a fixed partner the true value is half of this (only one side
// moves); corner contacts (a vertex in a face) are softer (overlap ~ d^2, stiffness ~ d).
// Not covered: penetration deep enough to reach a partner's sub-triangles next to its interior
// edges (slivers); at rest the depth is ~1e-9 of the element size. test_contact_blocks checks
// the bound against the largest eigenvalue of finite-difference stiffness matrices (normal and
// friction parts): it is 2.3 to 3.7 times above it (the conservative part: faces that never
// touch anything and fixed partners count as free ones). The explicit scheme is stable for
// dt <= 2 / omega; engine/step.cpp adds this omega^2 to the element one. With the default
// Ep = 100 x Lame lambda, this contact term is 80 to 130 x the element omega^2 on the shipped
// circular arch (through_thickness 6 to 1), so it sets dt.

#include "contact/contact.hpp"

#include <omp.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "contact/broad_phase.hpp"
#include "contact/friction.hpp"
#include "contact/joint_stiffness.hpp"
#include "contact/narrow_phase.hpp"
#include "contact/rigid_contact.hpp"
#include "contact/state_bytes.hpp"
#include "core/parallel.hpp"

namespace voussoir {

namespace {

// Fewer candidate pairs than this are evaluated on one thread. A parallel region costs a few
// microseconds on an idle machine (about ten pair evaluations), but when the cores are shared
// (capacity and sweep run trials side by side, ctest runs tests side by side) each per-step
// region waits for a descheduled thread: at 128 the 1388-triangle arch ran 30x slower on two
// threads than on one on the loaded 2-core machine. Parallel pairs pay only on large scenes.
constexpr std::size_t kParallelPairs = 8192;

// Separations below this fraction of the broad phase's buffer are not skipped on (a pair
// that close is evaluated every step; resting joints overlap by ~1e-10 m, real clearances
// between non-neighbours are millimetres).
constexpr double kClearanceFloorFraction = 1e-6;
// Candidate pairs from which on the skip is used. Below, its bookkeeping (the blocks' motion
// each step, the separations) costs about what it saves: on the 13-block semicircular arch
// (82 candidates) +1.4% instructions per step, on church B (3300 candidates, 2450 of them
// skipped) -13% (callgrind; docs/performance.md).
constexpr std::size_t kSkinPairs = 512;
// Rejections of a pair without clearance before its separation is measured again.
constexpr std::uint8_t kRemeasureAfter = 15;

// Values of the impact dashpot's state per pair: the x and y of the pair's six potential nodal
// forces of the last step.
constexpr std::size_t kDampedValues = 12;

// Corner slots per pair on the threaded path: [6 p + 2 k + side], side 0 for corner k of the
// pair's first triangle c, 1 for the second t (the order in which the one-thread loop adds them).
constexpr int kPairSlots = 6;

struct XY {
  double x, y;
};

// What one pair adds: nodal forces (potential + friction + impact damping), its penalty energy
// and the energy stored in its slip spring. Pure output of evaluate (every field written when
// the pair touches), so not initialised.
struct PairResult {
  double energy, stored;
  XY on_c[3], on_t[3];
  // Impact damping part of on_c/on_t (written only when restitution < 1), and friction part
  // (written only when mu > 0), for their ledgers.
  XY damp_c[3], damp_t[3], fric_c[3], fric_t[3];
};

// The corners of one pair (c's then t's) to its slots [2 k + side].
inline void write_slots(double* sx, double* sy, const XY* on_c, const XY* on_t) {
  for (int k = 0; k < 3; ++k) {
    sx[2 * k] = on_c[k].x, sy[2 * k] = on_c[k].y;
    sx[2 * k + 1] = on_t[k].x, sy[2 * k + 1] = on_t[k].y;
  }
}

// Adds one pair's slots to the nodes c (its first triangle's) and d that lie in [lo, hi).
inline void add_slots(Index lo, Index hi, const Index* c, const Index* d, const double* sx,
                      const double* sy, double* fx, double* fy) {
  for (int k = 0; k < 3; ++k) {
    if (c[k] >= lo && c[k] < hi) fx[c[k]] += sx[2 * k], fy[c[k]] += sy[2 * k];
    if (d[k] >= lo && d[k] < hi) fx[d[k]] += sx[2 * k + 1], fy[d[k]] += sy[2 * k + 1];
  }
}

// Adds one pair's corners to the nodes c and d (the one-thread path).
inline void add_corners(const Index* c, const Index* d, const XY* on_c, const XY* on_t,
                        double* fx, double* fy) {
  for (int k = 0; k < 3; ++k) {
    fx[c[k]] += on_c[k].x;
    fy[c[k]] += on_c[k].y;
    fx[d[k]] += on_t[k].x;
    fy[d[k]] += on_t[k].y;
  }
}

// A part of the contact forces whose work the ledger books by the trapezoid of its nodal
// values at the two ends of each position increment (x^n - x^(n-1) = dt v^(n-1/2)): the impact
// dashpots and the friction forces. `x`, `y` are filled during the step's contact stage,
// `prev_x`, `prev_y` hold the last step's; the threaded path writes each pair's corners to its
// slots first.
struct TrackedForce {
  std::vector<double> x, y, prev_x, prev_y;  // per node [N]
  std::vector<double> slot_x, slot_y;        // [kPairSlots p + 2 k + side] [N]

  void reset(std::size_t nodes) {
    x.assign(nodes, 0.0);
    y = prev_x = prev_y = x;
  }
  // Work of the forces over the last position increment (trapezoid; node order, so independent
  // of the threads) [J]; then this step's forces become the previous ones.
  double work_and_shift(const Nodes& n, double dt) {
    const double* vx = n.vx.data();
    const double* vy = n.vy.data();
    double work = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      work += (x[i] + prev_x[i]) * vx[i] + (y[i] + prev_y[i]) * vy[i];
      prev_x[i] = x[i];
      prev_y[i] = y[i];
      x[i] = y[i] = 0.0;
    }
    return 0.5 * dt * work;
  }
};

}  // namespace

struct ContactSystem::Impl {
  ContactParams params;
  double penalty = 0.0;    // Ep [Pa]
  double thickness = 1.0;  // out-of-plane [m]
  BroadPhase broad;
  bool ready = false;
  // Rigid blocks (Model::is_rigid at setup): the outline contact of contact/rigid_contact.hpp
  // does all the work; the triangle-pair machinery below stays idle.
  bool rigid_mode = false;
  RigidContact rigid;
  // Rigid blocks by non-smooth contact dynamics (ContactParams::nscd): points and impulses
  // (contact/nscd.hpp) on RigidContact's detection; its joint law stays idle.
  bool nscd_mode = false;
  NscdContact nscd;
  std::int64_t nscd_active = 0;  // points with an impulse at the last solve

  // Candidate pairs (triangle ids, sorted) and their friction state.
  std::vector<IndexPair> pairs, next_pairs;
  std::vector<double> sx, sy, kt, next_sx, next_sy;
  // Joint stiffness (contact/joint_stiffness.hpp): per-pair penalty x thickness [Pa m] when
  // `joints`; impact damping: per-pair beta [s] and the pair's potential nodal forces of the
  // last step [N] (kDampedValues per pair: on_c then on_t, x and y, corner by corner; zero
  // while the pair does not touch) when `damping`, and per node the damping force of this and
  // of the last step (for the ledger's trapezoid).
  bool joints = false, damping = false;
  std::vector<double> ep_thick, beta, prev_f, next_prev_f;
  TrackedForce impact;  // the dashpots' nodal forces (when `damping`)
  // Friction (mu > 0): its nodal forces, and the slip springs' stored energy sum 1/2 k_t s^2
  // of the last step [J]. The ledger books as dissipated the work the friction forces take
  // from the blocks minus what their springs store (accumulate).
  TrackedForce friction;
  double stored_prev = 0.0;
  // Nodes of each pair's two triangles (c = pairs[p].a, t = pairs[p].b), filled at detection
  // so that the per-step loop reads one flat array per corner instead of pairs -> tris -> nodes.
  std::vector<Index> pc0, pc1, pc2, pt0, pt1, pt2;

  // Per triangle id (participants only): longest boundary edge [m] and the height over it [m].
  std::vector<double> edge_len, height;
  // Per block: smallest height of a participant over one of its boundary edges [m].
  std::vector<double> block_min_height;

  // Pairs that cannot touch yet (evaluate). Per free participant node (Participants::
  // free_nodes order), its block; per block, the largest displacement of its free participant
  // nodes from their positions at the last detection, this step's [m] (track_motion; 0 for
  // fixed blocks, which the broad phase already takes as still). Per pair, its two blocks, the
  // value of moved = block_moved[c's] + block_moved[t's] below which the pair is certainly
  // apart [m] (-inf: evaluate it), and how many more rejections pass before a pair found
  // without clearance has its separation measured again.
  std::vector<Index> free_block;
  std::vector<double> block_moved;
  std::vector<Index> pb_c, pb_t;
  std::vector<double> apart_below;
  std::vector<std::uint8_t> remeasure;
  // Per pair, 1 when it touched at the last step: it goes to the kernel without the pre-tests
  // (evaluate). Not state: a pair flagged 0 only takes the longer way to the same result, so a
  // restart, which begins with every flag at 0, continues bit for bit
  // (Restart.*BitForBit, Rigid.RestartContinuesBitForBit).
  std::vector<std::uint8_t> touched;
  double clearance_floor = 0.0;  // smallest separation worth skipping on [m]
  bool skin = false;             // on for kSkinPairs candidate pairs and more

  std::int64_t active = 0;
  std::int64_t detections = 0;
  // Positions of the free participant nodes (Participants::free_nodes) at the last detection:
  // the broad phase's reference, kept here for save_state (its copy is private).
  std::vector<double> detected_x, detected_y;

  // Threaded path (parallel_pairs candidates and up; a test may lower it).
  std::size_t parallel_pairs = kParallelPairs;
  std::vector<double> slot_fx, slot_fy;      // [kPairSlots p + 2 k + side] [N]
  std::vector<double> pair_sums;             // [2 p ..]: energy, stored [J]
  std::vector<unsigned char> pair_touching;  // 1 when pair p touches
  // Node range k is [owner_cut[k], owner_cut[k + 1]), one per thread; empty = not yet cut for
  // the current pairs.
  std::vector<Index> owner_cut;

  void index_pairs(const Model& model);
  void track_motion(const Nodes& nodes);
  void note_apart(std::size_t p, const std::array<Vec2, 3>& cv, const std::array<Vec2, 3>& tv,
                  double moved);
  void record_detection(const Nodes& nodes);
  void cut_owners(Index node_count, int threads);
  void add_owned(Index lo, Index hi, double* fx, double* fy);
  void store(std::size_t p, const PairResult* r);

  template <bool kFriction, bool kSkin>
  bool evaluate(std::size_t p, const Nodes& n, double dt, PairResult& r);
  template <bool kFriction>
  bool evaluate_overlap(std::size_t p, const Nodes& n, double dt, PairResult& r);
  template <bool kFriction, bool kSkin>
  void accumulate(Model& model, double dt, EnergyLedger& ledger);
};

ContactSystem::ContactSystem() : impl_(std::make_unique<Impl>()) {}
ContactSystem::~ContactSystem() = default;
ContactSystem::ContactSystem(const ContactSystem& o) : impl_(std::make_unique<Impl>(*o.impl_)) {}
ContactSystem& ContactSystem::operator=(const ContactSystem& o) {
  if (this != &o) impl_ = std::make_unique<Impl>(*o.impl_);
  return *this;
}
ContactSystem::ContactSystem(ContactSystem&&) noexcept = default;
ContactSystem& ContactSystem::operator=(ContactSystem&&) noexcept = default;

void ContactSystem::setup(const Model& model, const ContactParams& params) {
  Impl& s = *impl_;
  s.params = params;
  s.penalty = params.penalty > 0.0 ? params.penalty : 100.0 * model.material.lame_lambda();
  s.thickness = model.out_of_plane;
  s.joints = params.normal_stiffness > 0.0 || params.joint_young > 0.0;
  s.damping = params.restitution < 1.0;
  s.ep_thick.clear();
  s.beta.clear();
  s.prev_f.clear();
  s.impact.reset(s.damping ? model.nodes.x.size() : 0);
  s.friction.reset(params.friction > 0.0 ? model.nodes.x.size() : 0);
  s.stored_prev = 0.0;
  const Participants parts = select_participants(model);
  const double buffer = params.buffer > 0.0 ? params.buffer : default_buffer(model, parts);
  // Rigid blocks detect on their own broad phase (contact/rigid_contact.hpp).
  if (!model.is_rigid()) s.broad.setup(model, buffer);
  const std::vector<Index>& free_nodes = s.broad.participants().free_nodes;
  s.free_block.resize(free_nodes.size());
  for (std::size_t k = 0; k < free_nodes.size(); ++k)
    s.free_block[k] = model.nodes.block[free_nodes[k]];
  s.block_moved.assign(model.blocks.size(), 0.0);
  s.clearance_floor = kClearanceFloorFraction * buffer;
  s.pairs.clear();
  s.sx.clear();
  s.sy.clear();
  s.kt.clear();
  s.active = 0;
  s.detections = 0;
  s.detected_x.clear();
  s.detected_y.clear();

  // Reference geometry of the participants: longest boundary edge and the height over it
  // (for k_t), smallest face height per block (for the stable step).
  const Nodes& n = model.nodes;
  const Triangles& t = model.tris;
  s.edge_len.assign(t.size(), 0.0);
  s.height.assign(t.size(), 0.0);
  s.block_min_height.assign(model.blocks.size(), std::numeric_limits<double>::infinity());
  for (Index e : parts.tri) {
    const Index v[3] = {t.n0[e], t.n1[e], t.n2[e]};
    for (int k = 0; k < 3; ++k) {
      if (!(t.boundary[e] & (1u << k))) continue;
      const double len =
          std::hypot(n.x0[v[(k + 1) % 3]] - n.x0[v[k]], n.y0[v[(k + 1) % 3]] - n.y0[v[k]]);
      const double h = 2.0 * t.area0[e] / len;
      if (len > s.edge_len[e]) {
        s.edge_len[e] = len;
        s.height[e] = h;
      }
      double& bm = s.block_min_height[t.block[e]];
      bm = std::min(bm, h);
    }
  }
  s.rigid_mode = model.is_rigid();
  if (s.rigid_mode) s.rigid.setup(model, params, s.penalty, buffer, s.block_min_height);
  s.nscd_mode = s.rigid_mode && params.nscd;
  if (s.nscd_mode) s.nscd.setup(model, s.rigid, s.rigid.buffer());
  s.nscd_active = 0;
  s.ready = true;
}

bool ContactSystem::needs_detection(const Nodes& nodes) const {
  return impl_->ready && !impl_->rigid_mode && impl_->broad.needs_detection(nodes);
}

bool ContactSystem::needs_detection(const Model& model) const {
  if (!impl_->ready) return false;
  return impl_->rigid_mode ? impl_->rigid.needs_detection(model)
                           : impl_->broad.needs_detection(model.nodes);
}

void ContactSystem::detect(const Model& model) {
  Impl& s = *impl_;
  if (!s.ready) return;
  if (s.rigid_mode) {
    s.rigid.detect(model);
    return;
  }
  s.broad.detect(model.nodes, s.next_pairs);
  carry_friction_history(s.pairs, s.sx, s.sy, s.next_pairs, s.next_sx, s.next_sy);
  if (s.damping) {
    carry_pair_values(s.pairs, s.prev_f, kDampedValues, s.next_pairs, s.next_prev_f);
    std::swap(s.prev_f, s.next_prev_f);
  }
  std::swap(s.pairs, s.next_pairs);
  std::swap(s.sx, s.next_sx);
  std::swap(s.sy, s.next_sy);
  s.index_pairs(model);
  s.record_detection(model.nodes);
  ++s.detections;
}

// Per-pair node indices and tangential stiffness of the current pair list.
void ContactSystem::Impl::index_pairs(const Model& model) {
  const std::size_t np = pairs.size();
  kt.resize(np);
  for (auto* v : {&pc0, &pc1, &pc2, &pt0, &pt1, &pt2, &pb_c, &pb_t}) v->resize(np);
  skin = np >= kSkinPairs;
  apart_below.assign(np, -std::numeric_limits<double>::infinity());
  remeasure.assign(np, 0);
  touched.assign(np, 0);
  const Triangles& t = model.tris;
  const double scale = kTangentialStiffnessRatio * penalty * thickness;
  const bool mapped = joints || params.shear_stiffness > 0.0 || damping;
  if (joints) ep_thick.resize(np);
  if (damping) beta.resize(np), prev_f.resize(kDampedValues * np, 0.0);
  const double zeta = restitution_damping_ratio(params.restitution);
  for (std::size_t p = 0; p < np; ++p) {
    const Index a = pairs[p].a, b = pairs[p].b;
    pc0[p] = t.n0[a], pc1[p] = t.n1[a], pc2[p] = t.n2[a];
    pt0[p] = t.n0[b], pt1[p] = t.n1[b], pt2[p] = t.n2[b];
    pb_c[p] = t.block[a], pb_t[p] = t.block[b];
    kt[p] = scale * (3.0 / height[a] + 3.0 / height[b]) * std::min(edge_len[a], edge_len[b]);
    if (!mapped) continue;
    const PairJoint j = pair_joint(model, a, b, params.normal_stiffness, params.joint_young,
                                   penalty, params.shear_stiffness, thickness);
    if (joints) ep_thick[p] = j.ep * thickness;
    if (joints || params.shear_stiffness > 0.0) kt[p] = j.kt > 0.0 ? j.kt : kt[p];
    if (damping) beta[p] = j.omega > 0.0 ? 2.0 * zeta / j.omega : 0.0;
  }
  owner_cut.clear();
}

// Node ranges of `threads` threads for the current pairs: cut where the running count of
// candidate corners per node id passes k / threads of the total (a pair's corners are where
// its forces go when it touches).
void ContactSystem::Impl::cut_owners(Index node_count, int threads) {
  const std::size_t np = pairs.size();
  std::vector<std::int64_t> corners(std::size_t(node_count), 0);
  for (const auto* v : {&pc0, &pc1, &pc2, &pt0, &pt1, &pt2})
    for (Index i : *v) ++corners[std::size_t(i)];
  const std::int64_t total = std::int64_t(kPairSlots * np);
  owner_cut.assign(std::size_t(threads) + 1, node_count);
  owner_cut[0] = 0;
  std::int64_t seen = 0;
  int k = 1;
  for (Index i = 0; i < node_count && k < threads; ++i) {
    seen += corners[std::size_t(i)];
    while (k < threads && seen * threads >= total * k) owner_cut[std::size_t(k++)] = i + 1;
  }
}

// Adds the corner forces of the touching pairs, in pair order, to the nodes in [lo, hi).
void ContactSystem::Impl::add_owned(Index lo, Index hi, double* fx, double* fy) {
  const std::size_t np = pairs.size();
  auto add = [lo, hi, fx, fy](Index i, double x, double y) {
    if (i >= lo && i < hi) fx[i] += x, fy[i] += y;
  };
  const bool with_friction = !friction.x.empty();
  for (std::size_t p = 0; p < np; ++p) {
    if (!pair_touching[p]) continue;
    const double* on_x = slot_fx.data() + kPairSlots * p;
    const double* on_y = slot_fy.data() + kPairSlots * p;
    const Index c[3] = {pc0[p], pc1[p], pc2[p]};
    const Index d[3] = {pt0[p], pt1[p], pt2[p]};
    for (int k = 0; k < 3; ++k) {
      add(c[k], on_x[2 * k], on_y[2 * k]);
      add(d[k], on_x[2 * k + 1], on_y[2 * k + 1]);
    }
    const std::size_t at = kPairSlots * p;
    if (damping)
      add_slots(lo, hi, c, d, impact.slot_x.data() + at, impact.slot_y.data() + at,
                impact.x.data(), impact.y.data());
    if (with_friction)
      add_slots(lo, hi, c, d, friction.slot_x.data() + at, friction.slot_y.data() + at,
                friction.x.data(), friction.y.data());
  }
}

// Writes pair p's result to its slots (r == nullptr: the pair does not touch, and its slots are
// not read).
void ContactSystem::Impl::store(std::size_t p, const PairResult* r) {
  pair_touching[p] = r != nullptr;
  if (r == nullptr) return;
  const std::size_t at = kPairSlots * p;
  write_slots(slot_fx.data() + at, slot_fy.data() + at, r->on_c, r->on_t);
  pair_sums[2 * p] = r->energy, pair_sums[2 * p + 1] = r->stored;
  if (damping)
    write_slots(impact.slot_x.data() + at, impact.slot_y.data() + at, r->damp_c, r->damp_t);
  if (!friction.x.empty())
    write_slots(friction.slot_x.data() + at, friction.slot_y.data() + at, r->fric_c, r->fric_t);
}

// block_moved for the current positions (see Impl): a point of a triangle moves by a convex
// combination of its nodes' displacements, so by no more than its block's entry, whether the
// block is rigid or elastic.
void ContactSystem::Impl::track_motion(const Nodes& nodes) {
  std::fill(block_moved.begin(), block_moved.end(), 0.0);
  if (detected_x.size() != free_block.size()) return;  // no detection yet: no pairs
  const std::vector<Index>& free_nodes = broad.participants().free_nodes;
  const double* x = nodes.x.data();
  const double* y = nodes.y.data();
  double* moved = block_moved.data();
  for (std::size_t k = 0; k < free_nodes.size(); ++k) {
    const double dx = x[free_nodes[k]] - detected_x[k], dy = y[free_nodes[k]] - detected_y[k];
    double& m = moved[free_block[k]];
    m = std::max(m, dx * dx + dy * dy);
  }
  for (double& m : block_moved) m = std::sqrt(m);
}

// Pair p was found apart at the current positions, with `moved` its blocks' displacements from
// the last detection. Its two triangles are then at least s = separation_lower_bound apart,
// and any of their points has moved by at most `moved` from the detection; later, with its
// blocks at moved' from the detection, the triangles have come closer by at most
// moved + moved' (each point's path back through its detection position), so they stay apart
// while moved' < s - moved. Half of s is kept as the margin of round-off. A pair without
// clearance (a corner touch, or a pair whose boxes just overlap) is measured again only after
// kRemeasureAfter further rejections: it usually stays one.
void ContactSystem::Impl::note_apart(std::size_t p, const std::array<Vec2, 3>& cv,
                                     const std::array<Vec2, 3>& tv, double moved) {
  const double gap = separation_lower_bound(cv, tv);
  if (gap > clearance_floor)
    apart_below[p] = 0.5 * gap - moved;
  else
    remeasure[p] = kRemeasureAfter;
}

void ContactSystem::Impl::record_detection(const Nodes& nodes) {
  const std::vector<Index>& free_nodes = broad.participants().free_nodes;
  detected_x.resize(free_nodes.size());
  detected_y.resize(free_nodes.size());
  for (std::size_t k = 0; k < free_nodes.size(); ++k) {
    detected_x[k] = nodes.x[free_nodes[k]];
    detected_y[k] = nodes.y[free_nodes[k]];
  }
}

// State bytes: u64 tag, u8 ready, u8 detected, i64 detections, i64 active, then the arrays
// detected_x, detected_y, pairs, sx, sy (each u64 count then the items); from tag 2 on, the
// impact damping's per-pair state and its last nodal forces x and y (per node), empty without
// it; from tag 3 on, friction's last nodal forces x and y (per node, empty without friction)
// and its springs' stored energy of the last step (f64). The per-pair damping state is, from
// tag 4 on, the pair's last potential nodal forces (kDampedValues per pair); tags 2 and 3 held
// |f| of the former dashpot on the force's magnitude, so their states restart only without
// impact damping. A state of tag 1 or 2 with friction restarts with those at zero and the
// stored energy of its slips: its first step books the friction work of half a step less than
// an uninterrupted run (the ledger only).
namespace {

constexpr std::uint64_t kStateTag1 = 0x564f555353434f31ull;  // "VOUSSCO1": no damping arrays
constexpr std::uint64_t kStateTag2 = 0x564f555353434f32ull;  // "VOUSSCO2": no friction arrays
constexpr std::uint64_t kStateTag3 = 0x564f555353434f33ull;  // "VOUSSCO3": |f| dashpot state
constexpr std::uint64_t kStateTag = 0x564f555353434f34ull;   // "VOUSSCO4"
// Rigid blocks by non-smooth contact dynamics: the active count, RigidContact's bytes, then
// NscdContact's.
constexpr std::uint64_t kNscdStateTag = 0x564f5553534e5331ull;  // "VOUSSNS1"

}  // namespace

std::vector<char> ContactSystem::save_state() const {
  const Impl& s = *impl_;
  if (s.nscd_mode) {
    std::vector<char> out;
    put(out, kNscdStateTag);
    put<std::int64_t>(out, s.nscd_active);
    put_array(out, s.rigid.save_state());
    put_array(out, s.nscd.save_state());
    return out;
  }
  if (s.rigid_mode) return s.rigid.save_state();
  std::vector<char> out;
  put(out, kStateTag);
  put<std::uint8_t>(out, s.ready ? 1 : 0);
  put<std::uint8_t>(out, s.detections > 0 ? 1 : 0);
  put<std::int64_t>(out, s.detections);
  put<std::int64_t>(out, s.active);
  put_array(out, s.detected_x);
  put_array(out, s.detected_y);
  put_array(out, s.pairs);
  put_array(out, s.sx);
  put_array(out, s.sy);
  put_array(out, s.prev_f);
  put_array(out, s.impact.prev_x);
  put_array(out, s.impact.prev_y);
  put_array(out, s.friction.prev_x);
  put_array(out, s.friction.prev_y);
  put<double>(out, s.stored_prev);
  return out;
}

void ContactSystem::restore_state(const Model& model, const std::vector<char>& bytes) {
  Impl& s = *impl_;
  if (s.nscd_mode) {
    StateReader in{bytes};
    if (in.get<std::uint64_t>() != kNscdStateTag)
      in.fail("not a non-smooth contact state (written by the explicit scheme?)");
    const auto active = in.get<std::int64_t>();
    const std::vector<char> rigid = in.get_array<char>(), nscd = in.get_array<char>();
    if (in.pos != bytes.size()) in.fail("unexpected data after the non-smooth contact state");
    s.rigid.restore_state(model, rigid);
    s.nscd.restore_state(nscd);
    s.nscd_active = active;
    return;
  }
  if (s.rigid_mode) {
    s.rigid.restore_state(model, bytes);
    return;
  }
  StateReader in{bytes};
  const auto tag = in.get<std::uint64_t>();
  if (tag != kStateTag && tag != kStateTag3 && tag != kStateTag2 && tag != kStateTag1)
    in.fail("not a contact state");
  const bool ready = in.get<std::uint8_t>() != 0, detected = in.get<std::uint8_t>() != 0;
  const auto detections = in.get<std::int64_t>(), active = in.get<std::int64_t>();
  std::vector<double> dx = in.get_array<double>(), dy = in.get_array<double>();
  std::vector<IndexPair> pairs = in.get_array<IndexPair>();
  std::vector<double> sx = in.get_array<double>(), sy = in.get_array<double>();
  std::vector<double> prev_f, fd_prev_x, fd_prev_y, ff_prev_x, ff_prev_y;
  bool has_friction_state = false;
  double stored_prev = 0.0;
  if (tag != kStateTag1) {
    prev_f = in.get_array<double>();
    fd_prev_x = in.get_array<double>();
    fd_prev_y = in.get_array<double>();
  }
  if (tag == kStateTag || tag == kStateTag3) {
    ff_prev_x = in.get_array<double>();
    ff_prev_y = in.get_array<double>();
    stored_prev = in.get<double>();
    has_friction_state = true;
  }
  if (in.pos != bytes.size()) in.fail("unexpected data after the state");
  const std::size_t nodes = model.nodes.x.size();
  if (s.damping && (fd_prev_x.size() != nodes || fd_prev_y.size() != nodes))
    in.fail("written without the impact damping (contact.restitution) of this model");
  if (!s.damping && !fd_prev_x.empty())
    in.fail("written with an impact damping (contact.restitution) this model does not have");
  const bool friction = !s.friction.x.empty();
  if (has_friction_state && friction != !ff_prev_x.empty())
    in.fail(std::string("written ") + (friction ? "without" : "with") + " the friction " +
            (friction ? "of this model" : "this model does not have") + " (contact.friction)");
  if (has_friction_state && friction && (ff_prev_x.size() != nodes || ff_prev_y.size() != nodes))
    in.fail("friction node count differs from the model");
  if (ready != s.ready) in.fail("written with contact " + std::string(ready ? "on" : "off"));
  if (!ready) return;
  const std::vector<Index>& free_nodes = s.broad.participants().free_nodes;
  if (sx.size() != pairs.size() || sy.size() != pairs.size())
    in.fail("slip and pair counts differ");
  if (!detected) {
    if (!pairs.empty()) in.fail("pairs without a detection");
    return;  // the first step detects, as in the uninterrupted run
  }
  if (dx.size() != free_nodes.size() || dy.size() != free_nodes.size())
    in.fail("participant node count differs from the model");
  // The last detection again, from its own positions: the same candidate list (a function of
  // the positions only) and the same reference for needs_detection.
  Nodes at_detection;
  at_detection.x = model.nodes.x;
  at_detection.y = model.nodes.y;
  for (std::size_t k = 0; k < free_nodes.size(); ++k) {
    at_detection.x[free_nodes[k]] = dx[k];
    at_detection.y[free_nodes[k]] = dy[k];
  }
  s.broad.detect(at_detection, s.pairs);
  if (s.pairs != pairs) in.fail("candidate pairs differ from those of the saved detection");
  s.sx = std::move(sx);
  s.sy = std::move(sy);
  if (s.damping) {
    if (tag != kStateTag)
      in.fail("written by an earlier version, whose impact dashpot (contact.restitution < 1) "
              "kept another state: restart from the deck");
    if (prev_f.size() != kDampedValues * s.pairs.size())
      in.fail("impact damping and pair counts differ");
    s.prev_f = std::move(prev_f);
    s.impact.prev_x = std::move(fd_prev_x);
    s.impact.prev_y = std::move(fd_prev_y);
  }
  s.index_pairs(model);
  if (friction) {
    if (has_friction_state) {
      s.friction.prev_x = std::move(ff_prev_x);
      s.friction.prev_y = std::move(ff_prev_y);
    } else {
      stored_prev = 0.0;
      for (std::size_t p = 0; p < s.pairs.size(); ++p)
        stored_prev += 0.5 * s.kt[p] * (s.sx[p] * s.sx[p] + s.sy[p] * s.sy[p]);
    }
    s.stored_prev = stored_prev;
  }
  s.detected_x = std::move(dx);
  s.detected_y = std::move(dy);
  s.detections = detections;
  s.active = active;
}

namespace {

inline double min3(double a, double b, double c) {
  return std::min(a, std::min(b, c));
}
inline double max3(double a, double b, double c) {
  return std::max(a, std::max(b, c));
}

}  // namespace

// One pair: false when it does not touch (friction history cleared), else r filled.
//
// Rejection before the kernel, in two steps. (1) The current, uninflated bounding boxes.
// (2) overlap_negligible (contact/narrow_phase.hpp): the six edge lines of the two triangles,
// in the kernel's local coordinates (origin at c's first vertex). When all vertices of one
// triangle lie outside (or on) one edge line of the other, or only one vertex lies inside it
// and the corner it cuts off is below the kernel's negligible-overlap cut-off, then
// triangle_pair_force would return zero after clipping, so skipping it changes no result.
// On the settled 48-triangle arch 55 of the 82 candidate pairs pass the boxes each step,
// 24 are separated, 19 are corner touches and 12 overlap.
template <bool kFriction, bool kSkin>
inline bool ContactSystem::Impl::evaluate(std::size_t p, const Nodes& n, double dt, PairResult& r) {
  // A pair that touched at the last step most likely still does: straight to the kernel. The
  // pre-tests below only skip pairs whose kernel certainly gives nothing, so this changes no
  // result (the kernel then gives nothing itself, and clears the flag).
  if (touched[p]) return evaluate_overlap<kFriction>(p, n, dt, r);
  // Still certainly apart since it was last found so (note_apart): its friction history and
  // damping state were cleared then and nothing has set them since.
  double moved = 0.0;
  if constexpr (kSkin) {
    moved = block_moved[pb_c[p]] + block_moved[pb_t[p]];
    if (moved < apart_below[p]) return false;
  }
  const double* x = n.x.data();
  const double* y = n.y.data();
  const Index c[3] = {pc0[p], pc1[p], pc2[p]};
  const Index d[3] = {pt0[p], pt1[p], pt2[p]};
  const double cxa[3] = {x[c[0]], x[c[1]], x[c[2]]}, cya[3] = {y[c[0]], y[c[1]], y[c[2]]};
  const double txa[3] = {x[d[0]], x[d[1]], x[d[2]]}, tya[3] = {y[d[0]], y[d[1]], y[d[2]]};
  bool apart = !(min3(cxa[0], cxa[1], cxa[2]) < max3(txa[0], txa[1], txa[2]) &&
                 min3(txa[0], txa[1], txa[2]) < max3(cxa[0], cxa[1], cxa[2]) &&
                 min3(cya[0], cya[1], cya[2]) < max3(tya[0], tya[1], tya[2]) &&
                 min3(tya[0], tya[1], tya[2]) < max3(cya[0], cya[1], cya[2]));
  const std::array<Vec2, 3> cv{Vec2{cxa[0], cya[0]}, Vec2{cxa[1], cya[1]}, Vec2{cxa[2], cya[2]}};
  const std::array<Vec2, 3> tv{Vec2{txa[0], tya[0]}, Vec2{txa[1], tya[1]}, Vec2{txa[2], tya[2]}};
  apart = apart || overlap_negligible(cv, tv);
  if (apart) {
    if constexpr (kFriction) sx[p] = sy[p] = 0.0;  // contact lost: history cleared
    if (damping) std::fill_n(prev_f.data() + kDampedValues * p, kDampedValues, 0.0);
    if constexpr (kSkin) {
      if (remeasure[p] > 0)
        --remeasure[p];
      else
        note_apart(p, cv, tv, moved);
    }
    return false;
  }
  return evaluate_overlap<kFriction>(p, n, dt, r);
}

// The kernel and friction for a pair that passed the pre-tests. Kept out of line so that the
// rejection path above (70 of the 82 pairs per step on the 48-triangle arch) runs without the
// kernel's stack frame and register saves (callgrind: ~20 instructions per rejected pair).
template <bool kFriction>
[[gnu::noinline]] bool ContactSystem::Impl::evaluate_overlap(std::size_t p, const Nodes& n,
                                                             double dt, PairResult& r) {
  // The positions again (12 loads, for the few overlapping pairs): the rejection path keeps
  // them in registers instead of storing them for this call.
  const double* x = n.x.data();
  const double* y = n.y.data();
  const std::array<Vec2, 3> cv{Vec2{x[pc0[p]], y[pc0[p]]}, Vec2{x[pc1[p]], y[pc1[p]]},
                               Vec2{x[pc2[p]], y[pc2[p]]}};
  const std::array<Vec2, 3> tv{Vec2{x[pt0[p]], y[pt0[p]]}, Vec2{x[pt1[p]], y[pt1[p]]},
                               Vec2{x[pt2[p]], y[pt2[p]]}};
  const PairForce f = triangle_pair_force(cv, tv, joints ? ep_thick[p] : penalty * thickness);
  touched[p] = f.area > 0.0;
  if (!(f.area > 0.0)) {
    if constexpr (kFriction) sx[p] = sy[p] = 0.0;
    if (damping) std::fill_n(prev_f.data() + kDampedValues * p, kDampedValues, 0.0);
    return false;
  }
  r.energy = f.energy;
  r.stored = 0.0;
  for (int k = 0; k < 3; ++k) {
    r.on_c[k] = {f.on_c[k].x, f.on_c[k].y};
    r.on_t[k] = {f.on_t[k].x, f.on_t[k].y};
  }
  if (damping) {
    // Impact dashpot on the rate of each nodal force of the potential (contact/
    // joint_stiffness.hpp): beta (f^n - f^(n-1)) / dt, f^(n-1) = 0 at the first touch.
    double* q = prev_f.data() + kDampedValues * p;
    const double rate = beta[p] / dt;
    for (int k = 0; k < 3; ++k) {
      r.damp_c[k] = {rate * (f.on_c[k].x - q[4 * k]), rate * (f.on_c[k].y - q[4 * k + 1])};
      r.damp_t[k] = {rate * (f.on_t[k].x - q[4 * k + 2]), rate * (f.on_t[k].y - q[4 * k + 3])};
      q[4 * k] = f.on_c[k].x, q[4 * k + 1] = f.on_c[k].y;
      q[4 * k + 2] = f.on_t[k].x, q[4 * k + 3] = f.on_t[k].y;
      r.on_c[k].x += r.damp_c[k].x, r.on_c[k].y += r.damp_c[k].y;
      r.on_t[k].x += r.damp_t[k].x, r.on_t[k].y += r.damp_t[k].y;
    }
  }
  if constexpr (kFriction) {
    const double* vx = n.vx.data();
    const double* vy = n.vy.data();
    const Index c[3] = {pc0[p], pc1[p], pc2[p]};
    const Index d[3] = {pt0[p], pt1[p], pt2[p]};
    const auto& wc = f.bary_c;
    const auto& wt = f.bary_t;
    const Vec2 du{dt * (wc[0] * vx[c[0]] + wc[1] * vx[c[1]] + wc[2] * vx[c[2]] - wt[0] * vx[d[0]] -
                        wt[1] * vx[d[1]] - wt[2] * vx[d[2]]),
                  dt * (wc[0] * vy[c[0]] + wc[1] * vy[c[1]] + wc[2] * vy[c[2]] - wt[0] * vy[d[0]] -
                        wt[1] * vy[d[1]] - wt[2] * vy[d[2]])};
    const FrictionResult fr =
        coulomb_friction(f.resultant, du, {sx[p], sy[p]}, kt[p], params.friction);
    sx[p] = fr.slip.x;
    sy[p] = fr.slip.y;
    for (int k = 0; k < 3; ++k) {
      const XY c0 = r.on_c[k], t0 = r.on_t[k];
      r.on_c[k].x += wc[k] * fr.force.x;
      r.on_c[k].y += wc[k] * fr.force.y;
      r.on_t[k].x -= wt[k] * fr.force.x;
      r.on_t[k].y -= wt[k] * fr.force.y;
      // The friction part as it was added (the additions above stay those of the force
      // path: a product kept for the ledger could change how the compiler fuses them).
      r.fric_c[k] = {r.on_c[k].x - c0.x, r.on_c[k].y - c0.y};
      r.fric_t[k] = {r.on_t[k].x - t0.x, r.on_t[k].y - t0.y};
    }
    r.stored = fr.stored;
  }
  return true;
}

// One step's contact forces, with (kSkin) or without the skip of pairs certainly apart. Two
// functions rather than a branch inside one: the two pair loops side by side in one function
// cost the small scenes, which never skip, 5% of their wall time (`run` of the semicircular
// arch, native build) with the same instructions.
template <bool kFriction, bool kSkin>
void ContactSystem::Impl::accumulate(Model& model, double dt, EnergyLedger& ledger) {
  Nodes& n = model.nodes;
  if constexpr (kSkin) track_motion(n);
  double* fx = n.fx.data();
  double* fy = n.fy.data();
  double energy = 0.0, stored = 0.0;
  std::int64_t n_active = 0;
  // Adds one touching pair's result; always called in pair order, so the sums are the same
  // whatever the number of threads that evaluated the pairs.
  auto apply = [&](std::size_t p, const PairResult& r) {
    ++n_active;
    energy += r.energy;
    stored += r.stored;
    const Index c[3] = {pc0[p], pc1[p], pc2[p]};
    const Index d[3] = {pt0[p], pt1[p], pt2[p]};
    for (int k = 0; k < 3; ++k) {
      fx[c[k]] += r.on_c[k].x;
      fy[c[k]] += r.on_c[k].y;
      fx[d[k]] += r.on_t[k].x;
      fy[d[k]] += r.on_t[k].y;
    }
    if (damping) add_corners(c, d, r.damp_c, r.damp_t, impact.x.data(), impact.y.data());
    if constexpr (kFriction)
      add_corners(c, d, r.fric_c, r.fric_t, friction.x.data(), friction.y.data());
  };
  const std::size_t np = pairs.size();
  if (np >= parallel_pairs && threads_available()) {
    // Pairs are independent (each owns its friction state) and write their own slots; then
    // each thread adds the touching pairs' corners on its own nodes in pair order and the
    // first thread the energies in pair order: the additions of the one-thread path, so
    // bit-identical to it.
    const std::int64_t count = static_cast<std::int64_t>(np);
    slot_fx.resize(kPairSlots * np);  // every slot read is written first in this step
    slot_fy.resize(kPairSlots * np);
    pair_sums.resize(2 * np);
    pair_touching.resize(np);
    for (TrackedForce* t : {&impact, &friction}) {
      if (t->x.empty()) continue;
      t->slot_x.resize(kPairSlots * np);
      t->slot_y.resize(kPairSlots * np);
    }
    const int ranges = omp_get_max_threads();
    if (owner_cut.size() != std::size_t(ranges) + 1) cut_owners(n.size(), ranges);
#pragma omp parallel
    {
      // Touching pairs cluster in the pair list (sorted by triangle id): chunks of 256 pairs
      // dealt round-robin balance the threads (one half each gave 62% of the work to one).
#pragma omp for schedule(static, 256)
      for (std::int64_t p = 0; p < count; ++p) {
        PairResult r;
        store(p, evaluate<kFriction, kSkin>(p, n, dt, r) ? &r : nullptr);
      }
      // One range per thread; a smaller team than asked for takes the rest in turn.
      const int me = omp_get_thread_num(), team = omp_get_num_threads();
      for (int k = me; k < ranges; k += team) add_owned(owner_cut[k], owner_cut[k + 1], fx, fy);
      if (me == 0) {
        for (std::size_t p = 0; p < np; ++p) {
          if (!pair_touching[p]) continue;
          ++n_active;
          energy += pair_sums[2 * p];
          stored += pair_sums[2 * p + 1];
        }
      }
    }
  } else {
    PairResult r;
    for (std::size_t p = 0; p < np; ++p)
      if (evaluate<kFriction, kSkin>(p, n, dt, r)) apply(p, r);
  }
  active = n_active;
  ledger.contact = energy + stored;
  // The dashpots' work over the last position increment is what they dissipated. Friction
  // dissipated what its forces took from the blocks less what its slip springs now store
  // more than at the last step. Both works by the trapezoid of the nodal forces at the two
  // ends of the increment: the rule by which the central-difference kinetic energy changes, so
  // the balance closes whatever the contacts do within a step (stick, slip, release of a spring
  // whose pair opens). Friction cannot give energy back: a step whose friction forces added
  // more than their springs released (a spring reversing while its cap falls, at a large
  // step) books nothing, and the excess stays in the balance error, where the scheme's errors
  // belong.
  if (damping) ledger.impact_dissipated -= impact.work_and_shift(n, dt);
  if constexpr (kFriction) {
    const double taken = -friction.work_and_shift(n, dt) - (stored - stored_prev);
    if (taken > 0.0) ledger.friction_dissipated += taken;
    stored_prev = stored;
  }
}

void ContactSystem::add_forces(Model& model, double dt, EnergyLedger& ledger, bool energy) {
  Impl& s = *impl_;
  if (!s.ready) {
    ledger.contact = 0.0;
    return;
  }
  if (s.rigid_mode) {
    s.rigid.add_forces(model, dt, ledger, energy);
    return;
  }
  // Branch once: with mu = 0 no friction code runs at all; below kSkinPairs no skip.
  const bool mu = s.params.friction > 0.0;
  if (s.skin)
    mu ? s.accumulate<true, true>(model, dt, ledger) : s.accumulate<false, true>(model, dt, ledger);
  else
    mu ? s.accumulate<true, false>(model, dt, ledger)
       : s.accumulate<false, false>(model, dt, ledger);
}

bool ContactSystem::nscd_mode() const {
  return impl_->nscd_mode;
}

void ContactSystem::build_contact_points(const Model& model) {
  Impl& s = *impl_;
  if (s.ready && s.nscd_mode) s.nscd.build(model, s.rigid);
}

NscdStepResult ContactSystem::solve_impulses(Model& model, const std::vector<double>& before,
                                             double h, Vec2 load, const NscdSettings& settings) {
  Impl& s = *impl_;
  if (!s.ready || !s.nscd_mode) return {};
  const NscdStepResult r = s.nscd.solve(model, before, h, load, settings);
  s.nscd_active = r.active;
  return r;
}

std::vector<BlockPairForce> ContactSystem::block_pair_forces(const Model& model, double dt) const {
  if (!impl_->ready || !impl_->rigid_mode) return {};
  if (impl_->nscd_mode) return impl_->nscd.pair_forces(model, dt);
  return impl_->rigid.pair_forces(model, dt);
}

bool ContactSystem::rigid_outlines() const {
  return impl_->rigid_mode;
}

std::vector<TouchingPair> ContactSystem::pair_forces(const Model& model, double dt) const {
  std::vector<TouchingPair> out;
  if (!impl_->ready || impl_->rigid_mode) return out;
  ContactSystem copy(*this);  // evaluate moves the slip and impact history: on the copy
  if (copy.needs_detection(model.nodes)) copy.detect(model);
  Impl& s = *copy.impl_;
  PairResult r;
  for (std::size_t p = 0; p < s.pairs.size(); ++p) {
    // Without the skip: the copy's motion record is not kept up to date.
    const bool touching = s.params.friction > 0.0
                              ? s.evaluate<true, false>(p, model.nodes, dt, r)
                              : s.evaluate<false, false>(p, model.nodes, dt, r);
    if (!touching) continue;
    TouchingPair f;
    f.tri_c = s.pairs[p].a;
    f.tri_t = s.pairs[p].b;
    for (int k = 0; k < 3; ++k) {
      f.on_c[k] = {r.on_c[k].x, r.on_c[k].y};
      f.on_t[k] = {r.on_t[k].x, r.on_t[k].y};
    }
    out.push_back(f);
  }
  return out;
}

double ContactSystem::max_omega_squared(const Model& model) const {
  const Impl& s = *impl_;
  if (!s.ready) return 0.0;
  const Participants& parts = s.broad.participants();
  if (parts.size() == 0) return 0.0;
  const Nodes& n = model.nodes;
  const Triangles& t = model.tris;
  const double ep = s.penalty * s.thickness;
  const double tangential = 2.0 * kTangentialStiffnessRatio;  // row share of friction
  // Smallest and second smallest block face heights, to get "smallest over the other blocks".
  double h1 = std::numeric_limits<double>::infinity(), h2 = h1;
  Index b1 = -1;
  for (Index b = 0; b < static_cast<Index>(s.block_min_height.size()); ++b) {
    const double h = s.block_min_height[b];
    if (h < h1) {
      h2 = h1;
      h1 = h;
      b1 = b;
    } else if (h < h2) {
      h2 = h;
    }
  }
  // S_i = [sxx sxy; sxy syy] per node.
  std::vector<double> sxx(n.size(), 0.0), sxy(n.size(), 0.0), syy(n.size(), 0.0);
  // Calls add(i0, i1, len, g, ex, ey) for every boundary edge of a free participant.
  auto each_edge = [&](auto&& add) {
    for (Index i = 0; i < parts.size(); ++i) {
      if (parts.fixed[i]) continue;
      const Index e = parts.tri[i];
      const double h_partner = parts.block[i] == b1 ? h2 : h1;
      if (!std::isfinite(h_partner)) continue;
      const Index v[3] = {t.n0[e], t.n1[e], t.n2[e]};
      for (int k = 0; k < 3; ++k) {
        if (!(t.boundary[e] & (1u << k))) continue;
        const Index i0 = v[k], i1 = v[(k + 1) % 3];
        const double dx = n.x0[i1] - n.x0[i0], dy = n.y0[i1] - n.y0[i0];
        const double len = std::hypot(dx, dy);
        const double g = 3.0 * len / (2.0 * t.area0[e]) + 3.0 / h_partner;
        add(i0, i1, len, g, dx / len, dy / len);  // edge direction = tangent; normal (-ey, ex)
      }
    }
  };
  auto add_to = [&](Index i0, Index i1, double axx, double axy, double ayy) {
    for (Index node : {i0, i1}) {
      sxx[node] += axx;
      sxy[node] += axy;
      syy[node] += ayy;
    }
  };
  if (s.joints || s.params.shear_stiffness > 0.0) {
    // A joint stiffness: normal and tangential row sums kn thick L and 2 ks thick L (the pair
    // penalties give kn on a flat joint whatever the triangles' heights).
    each_edge([&](Index i0, Index i1, double len, double g, double ex, double ey) {
      const double kn_len = s.joints ? s.params.normal_stiffness * s.thickness * len : ep * g * len;
      const double kt_len = s.params.shear_stiffness > 0.0
                                ? 2.0 * s.params.shear_stiffness * s.thickness * len
                                : tangential * kn_len;
      add_to(i0, i1, kn_len * ey * ey + kt_len * ex * ex, -kn_len * ex * ey + kt_len * ex * ey,
             kn_len * ex * ex + kt_len * ey * ey);
    });
  } else {
    each_edge([&](Index i0, Index i1, double len, double g, double ex, double ey) {
      const double k_len = ep * g * len;
      add_to(i0, i1, k_len * (ey * ey + tangential * ex * ex),
             k_len * (-ex * ey + tangential * ex * ey), k_len * (ex * ex + tangential * ey * ey));
    });
  }
  double w2 = 0.0;
  for (Index i = 0; i < n.size(); ++i) {
    if (!(n.inv_mass[i] > 0.0)) continue;
    const double mean = 0.5 * (sxx[i] + syy[i]);
    const double dev = std::hypot(0.5 * (sxx[i] - syy[i]), sxy[i]);
    w2 = std::max(w2, (mean + dev) * n.inv_mass[i]);
  }
  return w2;
}

void ContactSystem::set_parallel_pairs(std::int64_t min_pairs) {
  impl_->parallel_pairs = std::size_t(std::max<std::int64_t>(min_pairs, 0));
}

std::int64_t ContactSystem::candidate_pairs() const {
  if (impl_->rigid_mode) return impl_->rigid.candidate_pairs();
  return static_cast<std::int64_t>(impl_->pairs.size());
}
std::int64_t ContactSystem::active_pairs() const {
  if (impl_->nscd_mode) return impl_->nscd_active;
  if (impl_->rigid_mode) return impl_->rigid.active_pairs();
  return impl_->active;
}
std::int64_t ContactSystem::detections() const {
  if (impl_->rigid_mode) return impl_->rigid.detections();
  return impl_->detections;
}
const ContactParams& ContactSystem::params() const {
  return impl_->params;
}
double ContactSystem::penalty() const {
  return impl_->penalty;
}
double ContactSystem::buffer() const {
  if (impl_->rigid_mode) return impl_->rigid.buffer();
  return impl_->broad.buffer();
}

bool ContactSystem::joint_stiffness_mode() const {
  return impl_->joints;
}

// Stable step of rigid blocks. The contact stiffness couples the bodies' coordinates
// q_b = (c_x, c_y, theta) through each joint. A flat joint of length L between body b and its
// partner, pressed or sheared anywhere along it, is a row of springs kn t_z ds (normal n) and
// ks t_z ds (tangent e) at the points P(s); on b's coordinates each spring acts through
//     g_n = (n_x, n_y, (P - c) x n),    g_t = (e_x, e_y, (P - c) x e),
// so the joint's stiffness block on b is A_b = integral (kn t_z g_n g_n^T + ks t_z g_t g_t^T) ds
// (quadratic in s: Simpson's rule is exact). A joint between two free bodies is a positive
// semi-definite [[A_a, C], [C^T, A_b]] <= 2 diag(A_a, A_b) (the difference is the same matrix
// with C negated); against a fixed block only A_b remains. Hence the whole stiffness is at most
// the block diagonal of K_b = sum over b's joints of (2 or 1) A_b, and
//     omega_max^2 <= max_b lambda_max(M_b^-1/2 K_b M_b^-1/2),    M_b = diag(m, m, I).
// Joints: the model's (scene generators and the polygon joint search), every face pressed
// over its whole length. A free block with no joint (one that falls onto something) gets
// each side of its outline as a face against a fixed support. With impact damping, the
// dashpots (beta K, contact/joint_stiffness.hpp) damp that mode at the rate beta_b omega^2,
// beta_b the largest of b's joints; the body with the shortest damped step sets it
// (engine/step.cpp stable_time_step).
std::vector<ContactFrequencyBound> ContactSystem::rigid_body_bounds(const Model& model) const {
  const Impl& s = *impl_;
  const RigidBodies& r = model.rigid;
  const std::size_t nb = model.blocks.size();
  std::vector<ContactFrequencyBound> bounds(nb);
  if (!s.ready || r.mass.size() != nb) return bounds;
  std::vector<Eigen::Matrix3d> stiffness(nb, Eigen::Matrix3d::Zero());
  std::vector<double> beta_max(nb, 0.0);
  std::vector<char> has_face(nb, 0);
  const double zeta = restitution_damping_ratio(s.params.restitution);
  auto add_face = [&](Index b, Index partner, const Vec2& p0, const Vec2& p1) {
    const Block& blk = model.blocks[std::size_t(b)];
    if (blk.fixed || !(r.mass[b] > 0.0)) return;
    double ex = p1.x - p0.x, ey = p1.y - p0.y;
    const double len = std::hypot(ex, ey);
    if (!(len > 0.0)) return;
    ex /= len, ey /= len;
    const Vec2 normal{ey, -ex}, tangent{ex, ey};
    const Block* other = partner >= 0 ? &model.blocks[std::size_t(partner)] : nullptr;
    const bool partner_free = other != nullptr && !other->fixed;
    double kn = s.params.normal_stiffness;
    if (!(kn > 0.0) && s.params.joint_young > 0.0) {
      kn = default_joint_stiffness(s.params.joint_young, blk, other, normal);
    } else if (!(kn > 0.0)) {
      // Penalty mode: Ep (3/h_b + 3/h_partner) with the smallest face heights.
      const double hb = s.block_min_height[std::size_t(b)];
      double hp = hb;
      if (partner >= 0) hp = s.block_min_height[std::size_t(partner)];
      kn = s.penalty * (3.0 / hb + 3.0 / hp);
    }
    const double ks =
        s.params.shear_stiffness > 0.0 ? s.params.shear_stiffness : kTangentialStiffnessRatio * kn;
    const double kn_t = kn * s.thickness, ks_t = ks * s.thickness;
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
    for (int q = 0; q < 3; ++q) {
      const double w = (q == 1 ? 4.0 : 1.0) * len / 6.0;
      const double px = p0.x + 0.5 * q * (p1.x - p0.x) - r.cx0[b];
      const double py = p0.y + 0.5 * q * (p1.y - p0.y) - r.cy0[b];
      const Eigen::Vector3d gn(normal.x, normal.y, px * normal.y - py * normal.x);
      const Eigen::Vector3d gt(tangent.x, tangent.y, px * tangent.y - py * tangent.x);
      a += w * (kn_t * gn * gn.transpose() + ks_t * gt * gt.transpose());
    }
    stiffness[std::size_t(b)] += (partner_free ? 2.0 : 1.0) * a;
    has_face[std::size_t(b)] = 1;
    if (zeta > 0.0) {
      const double omega = joint_frequency(kn_t, blk, r.mass[b], other,
                                           other != nullptr ? other->mass : 0.0, tangent);
      beta_max[std::size_t(b)] = std::max(beta_max[std::size_t(b)], 2.0 * zeta / omega);
    }
  };
  for (const Joint& j : model.joints) {
    add_face(j.block_a, j.block_b, j.a, j.b);
    add_face(j.block_b, j.block_a, j.a, j.b);
  }
  for (std::size_t b = 0; b < nb; ++b) {
    if (has_face[b]) continue;
    const std::vector<Vec2>& poly = model.blocks[b].polygon;
    for (std::size_t k = 0; k < poly.size(); ++k)
      add_face(Index(b), -1, poly[k], poly[(k + 1) % poly.size()]);
  }
  for (std::size_t b = 0; b < nb; ++b) {
    if (!has_face[b]) continue;
    const Eigen::Vector3d inv_sqrt_m(1.0 / std::sqrt(r.mass[b]), 1.0 / std::sqrt(r.mass[b]),
                                     1.0 / std::sqrt(r.inertia[b]));
    const Eigen::Matrix3d scaled = inv_sqrt_m.asDiagonal() * stiffness[b] * inv_sqrt_m.asDiagonal();
    const double lambda =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scaled).eigenvalues().maxCoeff();
    bounds[b] = {lambda, beta_max[b] * lambda};
  }
  return bounds;
}

}  // namespace voussoir

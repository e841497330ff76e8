#pragma once
// Contact of rigid blocks: one joint law between block outlines, integrated exactly
// (docs/rigid.md).
//
// The law. Two blocks A and B touch where their outlines overlap. On the overlap O the joint
// carries a normal pressure kn x d (no tension), d the penetration measured along the contact
// normal n, and a shear stress capped by Coulomb friction. With s the coordinate along the
// contact and d(s) the width of O along n at s,
//     F_n = kn t_z integral d(s) ds = kn t_z |O|                     (normal force, along n)
// and its line of action passes through the centroid G of O: the moment of the pressure
// about any point, integral kn d(s) (s - s0) ds, is kn |O| (s_G - s0), the first moment of O.
// The elastic energy of the joint's springs is
//     U = kn t_z / 2 integral d(s)^2 ds,
// and F_n = dU/dd for a rigid approach along n, so the ledger books U as contact energy.
// For rigid blocks on a straight face d(s) is linear, so all three are closed forms in the
// vertices of O: a face-to-face joint (O a thin quadrilateral, d linear), a hinge (O a thin
// triangle, the pressure block of the contact strip) and a corner pushed into a face (O a
// triangle, d a tent) are the same computation. This is the Winkler (Cundall's UDEC and
// 3DEC, DIANA's interface) joint law for the joint's stiffness kn in N/m3.
//
// The normal. O is convex when both outlines are (below: non-convex ones are cut into convex
// pieces). Its boundary is made of pieces of A's boundary (inside B) and pieces of B's
// (inside A); with N_A the sum of A's outward normals times lengths over A's pieces, N_A =
// -N_B (a closed polygon), |N_A| is the length of the chord between the two points where the
// outlines cross, and n = N_A / |N_A| points out of A into B. It is the gradient of |O| with
// respect to a translation of B (Feng, Han and Owen, "Energy-conserving contact interaction
// models for arbitrarily shaped discrete elements", CMAME 205 (2012)): normal to the chord.
// On a face-to-face joint the chord runs along the joint to within the penetration over the
// joint's length (1e-9 at rest); for a corner in a face it is the face. F_n acts on B along
// +n, on A along -n.
//
// Exactness. |O|, G and N_A come from the vertices of O by Green's theorem: with O's
// vertices v_k (counter-clockwise) relative to a point of O,
//     |O| = 1/2 sum v_k x v_k+1,   G |O| = 1/6 sum (v_k + v_k+1) (v_k x v_k+1).
// integral d^2 ds: between consecutive abscissae s_j of O's vertices along the chord, d is
// linear, so that interval gives (s_j+1 - s_j)(d_j^2 + d_j d_j+1 + d_j+1^2) / 3, d_j the width
// of O at s_j (its two edges there). For two quadrilaterals (nearly every pair of pieces in
// masonry) |O|, G and N_A come from the pieces of the two outlines' edges that lie inside the
// other, a batch of pairs at a time (contact/quad_overlap.hpp). Otherwise, and for the energy
// integral, which needs O's vertices in order, O comes from clipping A's piece by each side
// line of B's piece (Sutherland and Hodgman, CACM 17 (1974)), each vertex carrying which of the
// two boundaries its outgoing edge lies on, so N_A needs no tolerance even for slivers of
// 1e-10 m. A line of B that has every vertex on its inner side is skipped (a joint's overlap is
// cut by one or two of B's sides). The two ways agree to round-off of the coordinates
// (RigidContact.QuadBatchAgreesWithTheOrderedClipping).
//
// Non-convex outlines (the church's crown blocks) are cut once, in the reference
// configuration, into convex pieces: the block's own triangles merged greedily across shared
// edges while the union stays convex (Hertel and Mehlhorn). A block pair sums its piece
// pairs' overlaps: forces and moments add; where a joint crosses a cut, its overlap is split
// in two at the cut and the two halves carry the same pressure (their normals differ by the
// penetration over the piece's length).
//
// Friction. One state per block pair: the elastic slip s (a 2D vector) of friction.hpp's
// Coulomb law, at the area-weighted centroid G of the pair's overlaps, along the tangent of
// the pair's normal force, with the shear spring k_t = ks t_z L (L: the length of the pair's
// joint, or for blocks that were not joined, the shorter of their longest sides). Kept
// constant per pair so that 1/2 k_t s^2 is an honest energy. (Rejected: k_t following the
// contact length; the stored energy would change without work when a hinge opens.) The slip
// increment is the relative displacement of B's and A's material points at G over the last
// step, dt times the rigid velocity field of the half step.
//
// Impact damping (contact.restitution < 1): the joint's pressure is kn (d + beta d'), d' the
// rate of penetration, beta = 2 zeta / omega as in joint_stiffness.hpp (omega the joint's
// frequency with the blocks' masses): a Winkler joint with a dashpot beta kn per unit area,
// stiffness-proportional, the linear spring-dashpot of a flat drop (restitution e). Along the
// chord (length L, middle x_m, s from -L/2 to L/2) the rigid bodies give a linear rate
//     d'(s) = d'_m + d'_s s,   d'_m = -n . (v_b(x_m) - v_a(x_m)),   d'_s = -(w_b - w_a),
// v_X(x) = v_X + w_X x (x - c_X) the half-step velocity field, so the dashpot's force on b is
//     F_d = beta kn t_z L d'_m n,   moment about c_b: (x_m - c_b) x F_d + beta kn t_z L^3/12 d'_s,
// minus these on a, and it dissipates beta kn t_z (L d'_m^2 + L^3/12 d'_s^2) >= 0: a rigid
// motion of the pair (d' = 0) costs nothing, a bounce and the rocking of a block on its joint
// (the pressure's rate changing along the joint) are damped. The step a pair first touches it
// has touched for the part of the step its mean depth |O| / L took at the rate d'_m, and the
// dashpot acts for that part (without it a drop's rebound missed e^2 by 5 to 7% at half the
// step: the full dashpot from the first step, whatever the depth). (Rejected: beta times the
// rate of the pair's force and moments, by the backward difference. A pair turning with the
// structure turns its force, and that dashpot then pushed along the turn: on the shaking-table
// arch it fed a slow sway that never came to rest. Taking the rate of the force's magnitude
// instead did not end it.) No tension: on a separating overlap (d'_m < 0) the dashpot's normal
// force beta kn t_z L d'_m would pull; when it pulls harder than the spring pushes
// (kn t_z |O|), both dashpot terms are scaled by kn |O| / (beta kn L |d'_m|), so that the
// overlap's total normal force is zero, never tensile, and the dissipation, scaled by the same
// factor, stays >= 0.
//
// Ledger: the dashpots' and friction's generalized forces on each body are booked by the
// trapezoid over the body's position increment (dt v^(n-1/2), dt omega^(n-1/2)), as the
// element damping of core/; friction books its work less the change of its springs' energy.
//
// Lines that cannot cut. Until the next detection every outline point moves by at most
// buffer / 2 from where it was at the detection. A side line of B's piece therefore keeps every
// vertex v of A's piece on its inner side when, at the detection, v lies inside it by more than
// what the two can move towards each other: buffer / 2 for v (if A moves) plus, for the line,
// the move of B's material point at v, |dc_B| + |dtheta_B| |v - c_B| <= buffer / 2 max(1,
// |v - c_B| / R_B) (if B moves). Every vertex of the polygon being clipped lies in A's piece, so
// such a line would leave it whole: the clipping skips it, and the result is the same to the
// bit. On a face-to-face joint this is the far side of B's piece (the other sides pass through
// the joint's corners). A margin of kInnerLineSlack times the coordinates covers round-off.
//
// Detection: the NBS grid of contact/broad_phase.hpp on the blocks' outline triangles, node
// positions taken from the bodies at detection only, candidate triangle pairs folded into
// candidate block pairs, and of those the pairs whose outlines are within the buffer of each
// other kept (the boxes of thin slanted blocks overlap their neighbours' neighbours: on the
// church, 766 block pairs by boxes, 240 of them touching). A new detection is due when some body
// has moved a point of its outline by more than buffer / 2 (bounded by |dc| + R |dtheta|, R the
// farthest outline point).

#include <array>
#include <cstdint>
#include <vector>

#include "contact/broad_phase.hpp"
#include "contact/quad_overlap.hpp"
#include "core/energy.hpp"
#include "core/model.hpp"

namespace voussoir {

struct ContactParams;

// Overlap of two convex polygons P and Q (counter-clockwise), the pure part of the law above.
struct ConvexOverlap {
  double area = 0.0;      // |O| [m2]
  Vec2 centroid;          // G [m]
  Vec2 normal;            // n, unit, out of P into Q
  double chord = 0.0;     // |N_P| [m]: the distance between the points where the outlines cross
  Vec2 chord_mid;         // the middle of those two points [m] (the centroid when not found)
  double depth_sq = 0.0;  // integral of d(s)^2 ds along the chord [m3]
};

// Most vertices a convex piece may have (a piece is cut further when larger).
inline constexpr int kMaxPieceVertices = 16;
// Relative margin for round-off in the certificate of "Lines that cannot cut" (dimensionless:
// times the coordinates and the buffer; round-off is 1e-16 of them).
inline constexpr double kInnerLineSlack = 1e-9;

// The overlap of P (np vertices) and Q (nq vertices); false when they do not overlap (or O has
// no area, or P lies wholly inside Q and O has no chord). depth_sq only `with_energy` (else 0):
// the energy is for the ledger, read at samples.
bool convex_overlap(const Vec2* p, int np, const Vec2* q, int nq, ConvexOverlap& out,
                    bool with_energy = true);
// The same with each vertex given as a reference position plus a displacement (pu, qu; null:
// none), which the kernel keeps apart until the differences are taken. `inner`: side lines of Q
// (bit j: line j, from q[j] to q[j + 1]) known to have P wholly on their inner side, which the
// clipping skips (the result is the same; RigidContact certifies them at detection).
bool convex_overlap(const Vec2* p, const Vec2* pu, int np, const Vec2* q, const Vec2* qu, int nq,
                    ConvexOverlap& out, bool with_energy, std::uint32_t inner = 0);

// A side line of Q (0 <= line < nq) or of P (nq <= line < nq + np) with the other polygon
// wholly outside it: the two are apart. separating_line returns the first such line or -1.
bool separated_by(const Vec2* p, int np, const Vec2* q, int nq, int line);
int separating_line(const Vec2* p, int np, const Vec2* q, int nq);
// The same with each vertex a reference position plus a displacement (pu, qu; null: none).
bool separated_by(const Vec2* p, const Vec2* pu, int np, const Vec2* q, const Vec2* qu, int nq,
                  int line);
int separating_line(const Vec2* p, const Vec2* pu, int np, const Vec2* q, const Vec2* qu, int nq);

// Force of a touching block pair (a, b) as the contact stage applies it: the sum of the normal
// force, friction and dashpot on b, and the moment of all of them about `origin` [N, N m].
struct BlockPairForce {
  Index block_a = 0, block_b = 0;
  Vec2 force;           // on b (minus this on a) [N]
  Vec2 origin;          // point the moment is taken about [m]
  double moment = 0.0;  // of the forces on b about origin [N m]
};

class RigidContact {
 public:
  // Outlines, convex pieces, per-block constants, the broad phase with its `buffer` [m].
  // `penalty` [Pa] and `block_min_height` (per block [m]) serve the penalty mode (no joint
  // stiffness given).
  void setup(const Model& model, const ContactParams& params, double penalty, double buffer,
             const std::vector<double>& block_min_height);
  bool needs_detection(const Model& model) const;
  void detect(const Model& model);
  // Adds the contact forces and moments to model.rigid's fx, fy, torque; sets ledger.contact,
  // books friction and impact dissipation.
  // energy false: ledger.contact is left as it is (the joints' energy is computed for the steps
  // whose ledger is read; friction and dashpots are booked at every step).
  void add_forces(Model& model, double dt, EnergyLedger& ledger, bool energy = true);
  // The force of every touching pair, evaluated on a copy (the run's state untouched).
  std::vector<BlockPairForce> pair_forces(const Model& model, double dt) const;

  std::int64_t candidate_pairs() const { return std::int64_t(pair_a_.size()); }
  std::int64_t active_pairs() const { return active_; }
  std::int64_t detections() const { return detections_; }
  double buffer() const { return broad_.buffer(); }

  std::vector<char> save_state() const;
  void restore_state(const Model& model, const std::vector<char>& bytes);

  // What the non-smooth contact dynamics reads (contact/nscd.hpp): the convex pieces, the
  // live pairs of pieces of the last detection (pair l: a piece of the lower block, one of the
  // higher), and a piece's vertices, counter-clockwise, in the reference configuration or at
  // the bodies' poses in `model` (returns the count, at most kMaxPieceVertices).
  Index piece_count() const { return Index(piece_block_.size()); }
  Index piece_block(Index k) const { return piece_block_[std::size_t(k)]; }
  std::size_t live_pairs() const { return live_i_.size(); }
  Index live_piece_a(std::size_t l) const { return live_i_[l]; }
  Index live_piece_b(std::size_t l) const { return live_j_[l]; }
  int piece_reference(Index k, Vec2* out) const;
  int piece_vertices(const Model& model, Index k, Vec2* out) const;

 private:
  struct PairOut {
    Vec2 fb;                    // all forces on b [N]
    double mb = 0.0, ma = 0.0;  // moments on b about c_b, on a about c_a [N m]
    Vec2 damp_b;                // dashpot part of fb
    double damp_mb = 0.0, damp_ma = 0.0;
    Vec2 fric_b;  // friction part of fb
    double fric_mb = 0.0, fric_ma = 0.0;
    double energy = 0.0, stored = 0.0;
  };
  void detect_at(const Model& model, const std::vector<double>& ux, const std::vector<double>& uy,
                 const std::vector<double>& theta);
  // Each outline vertex's displacement (disp_) with the bodies at the poses (ux, uy, theta).
  void displace_pieces(const Model& model, const std::vector<double>& ux,
                       const std::vector<double>& uy, const std::vector<double>& theta);
  void displace_live_pieces(const Model& model);
  void overlap_pieces(bool energy);
  double piece_gap(Index i, Index j) const;
  std::uint32_t inner_lines(const Model& model, const std::vector<double>& ux,
                            const std::vector<double>& uy, Index i, Index j) const;
  // The bodies' centroids and half-step velocities, as the pair loop reads them.
  struct BodyView {
    const double *cx, *cy, *vx, *vy, *omega;
  };
  bool evaluate(std::size_t p, const BodyView& bodies, double dt, bool energy, PairOut& out);
  void pair_constants(const Model& model);

  // Parameters.
  double mu_ = 0.0, thickness_ = 1.0, zeta_ = 0.0;
  double kn_given_ = 0.0, ks_given_ = 0.0, young_ = 0.0, penalty_ = 0.0;
  bool damping_ = false;
  std::vector<double> min_height_;  // per block [m] (penalty mode)

  // Convex pieces: piece k has vertices [piece_first_[k], piece_first_[k + 1]) of ref_, their
  // reference positions as the model gives them; block b has pieces [block_piece_[b],
  // block_piece_[b + 1]); piece k belongs to block piece_block_[k].
  std::vector<Index> piece_first_, block_piece_, piece_block_;
  std::vector<Vec2> ref_;
  // Current configuration (free blocks rewritten each step): each vertex's displacement from
  // its reference position.
  std::vector<Vec2> disp_;
  // The pieces of the live pairs (below) on bodies with a pose, ascending, which the steps
  // displace; each vertex's offset from its body's reference centroid (set for those pieces).
  std::vector<Index> moving_pieces_;
  std::vector<Vec2> offset_;
  // Per block: farthest outline point from the reference centroid [m], longest side [m].
  std::vector<double> radius_, longest_side_;
  // Per block: 1 when it has a pose of its own (a free body, or a support that moves), as at the
  // last detection.
  std::vector<std::uint8_t> moves_;
  // Joints between block pairs (model.joints), for the pair constants.
  struct JointInfo {
    Index a, b;  // a < b
    double length;
    Vec2 tangent;
  };
  std::vector<JointInfo> joints_;  // sorted by (a, b), lengths summed per pair

  // Broad phase on the outline triangles, with node positions from the bodies.
  BroadPhase broad_;
  Nodes scratch_;
  std::vector<IndexPair> tri_pairs_;
  std::vector<double> ref_ux_, ref_uy_, ref_theta_;  // body poses at the last detection
  bool detected_ = false;

  // Candidate block pairs (a < b), sorted, with their constants and state.
  std::vector<Index> pair_a_, pair_b_;
  std::vector<double> kn_t_, kt_, beta_;  // [N/m2], [N/m], [s]
  std::vector<double> slip_x_, slip_y_;   // friction state [m]
  std::vector<std::uint8_t> touched_;     // 1 when the pair touched at the last step
  std::vector<double> last_w_;            // 4 per pair: F_x, F_y, M_b, M_a of the last step
  // Scratch of add_forces: each pair's joint energy and friction spring energy of the step [J].
  std::vector<double> pair_energy_, pair_stored_;
  // The overlap of each live pair of pieces (below) at the current configuration, by slot: the
  // pairs of quadrilaterals first, a batch of kQuadLanes after another, then the others.
  struct OverlapTable {
    std::vector<double> area, gx, gy, nx, ny, chord, mx, my, depth_sq;
    std::vector<long> on;  // nonzero when the pieces overlap
    void resize(std::size_t slots);
    void set(std::size_t slot, const ConvexOverlap& o);
    ConvexOverlap at(std::size_t slot) const {
      return {area[slot],  {gx[slot], gy[slot]}, {nx[slot], ny[slot]},
              chord[slot], {mx[slot], my[slot]}, depth_sq[slot]};
    }
  };
  OverlapTable overlap_;
  // The pairs of convex pieces of each candidate pair that were within the buffer at the
  // detection (pair p's: [live_first_[p], live_first_[p + 1]) of live_i_, live_j_), and for
  // each a side line that separated them at the last evaluation, or -1 (separated_by's
  // numbering): tried first, it rejects two pieces that are still apart in O(n). The line is
  // not state: it only skips work whose answer is "apart".
  std::vector<Index> live_first_, live_i_, live_j_;
  std::vector<std::int16_t> apart_line_;
  // For each such pair of pieces, the side lines of its second piece that keep the first wholly
  // on their inner side until the next detection (convex_overlap's `inner`; "Lines that cannot
  // cut" above).
  std::vector<std::uint32_t> inner_;
  // The live pairs of pieces that are both quadrilaterals (evaluated in batches) and the
  // others; the slot of each live pair in overlap_.
  std::vector<Index> quad_live_, other_live_, slot_of_live_;
  // Per batch of quadrilateral pairs: the vertices' reference positions relative to P's first
  // vertex (QuadPairs without the displacements; ox, oy: P's first vertex).
  std::vector<QuadPairs> quad_ref_;
  // Per batch, the vertices' offsets from their bodies' reference centroids (offset_; zeros for
  // bodies without a pose), and per lane the body of P and of Q that has a pose (the number of
  // blocks, whose pose is zero: none, or an unused lane). The steps place the batches from the
  // bodies' poses (quad_place), without displacing the vertices one by one.
  std::vector<QuadPairs> quad_offset_;
  std::vector<Index> quad_body_p_, quad_body_q_;
  // Per block with a pose (moves_), this step's: the centroid's displacement, cos(theta) - 1 and
  // sin(theta), as displace_live_pieces computes them; zeros for the others and, after the
  // blocks, for a lane without a body.
  std::vector<double> pose_ux_, pose_uy_, pose_cm1_, pose_s_;
  void pose_bodies(const Model& model);

  // Ledger: per body (3 values: x, y, rotation) the dashpot and friction forces of this and of
  // the last step.
  std::vector<double> damp_now_, damp_prev_, fric_now_, fric_prev_;
  double stored_prev_ = 0.0;

  std::int64_t active_ = 0, detections_ = 0;
};

}  // namespace voussoir

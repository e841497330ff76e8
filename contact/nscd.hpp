#pragma once
// Non-smooth contact dynamics of rigid blocks (`solver.scheme = "nscd"`;
// docs/nscd.md): contact points between block outlines, Signorini's condition with Newton's
// impact law and Coulomb friction at each, solved for the step's impulses by non-linear
// Gauss-Seidel (Moreau, Jean: "Numerical aspects of the sweeping process", CMAME 177 (1999);
// LMGC90's and Solfec's NLGS).
//
// Contact points. The broad phase and the live pairs of convex pieces are RigidContact's
// (contact/rigid_contact.hpp: NBS on the outlines, non-convex outlines cut into convex
// pieces). For two convex pieces P (of block a) and Q (of block b, a < b) the reference face
// is the outline edge of either piece with the largest separation from the other piece (the
// separating-axis distance), the incident edge the other piece's outline edge most opposed to
// it; the incident edge clipped to the reference face's extent gives at most two points, kept
// when their distance to the face (the gap g, negative when they overlap) is below the alert
// distance. A face-to-face joint gives the two ends of the shared segment, a corner on a face
// one point (its other end lies far from the face). Only outline edges serve as faces: the
// cuts between the pieces of a non-convex block lie inside it. Each point carries the unit
// normal n from a into b (the reference face's outward normal, or its opposite), the tangent
// t = (-n_y, n_x), and its middle x between the two outlines. A reference face is switched from
// P to Q only when Q's separation is larger by kFaceSwitch of the alert distance, so that a
// flat joint keeps its points from step to step.
//
// Local velocity. U = (U_n, U_t) = ([v_b + w_b x (x - c_b)] - [v_a + w_a x (x - c_a)]) . (n, t):
// the velocity of b's material point at x relative to a's (a fixed block contributes nothing,
// a moving support its prescribed velocity). The impulse r = (r_n, r_t) acts on b along
// r_n n + r_t t at x, on a opposite. With H the map from the bodies' velocities to U,
//     U = W r + q,  W = H M^-1 H^T  (the 2x2 Delassus block of the point),
// q the velocity the point would have without its own impulse.
//
// The local law at each point, on U = U^+ (the end of the step):
//   Signorini and Newton: 0 <= r_n  _|_  U_n - u_min >= 0, with
//       u_min = -e min(U_n^-, 0)    when g <= 0 (closed: Newton's impact law, restitution e),
//       u_min = -g / (theta h)      when g > 0  (open: the gap may close in the step, not pass),
//   Coulomb: |r_t| <= mu r_n; U_t = 0 when |r_t| < mu r_n, else r_t = -mu r_n sign(U_t).
// Its exact solution for given q (solve_point): none when q_n >= u_min (r = 0); else sticking,
// W r = (u_min - q_n, -q_t), when that r lies in the cone; else sliding, r_t = s mu r_n with the
// sign s for which U_t opposes r_t, r_n = (u_min - q_n) / (W_nn + s mu W_nt).
//
// Non-linear Gauss-Seidel. The points in order, each solved exactly with the others' impulses
// as they stand, the bodies' velocities updated at once (v += M^-1 H^T dr); a sweep over all
// points is an iteration. The first sweep starts from the last step's impulses (warm start,
// matched point by point by the pieces and the faces that made them). Converged when the
// change of the impulses over a sweep is at most `tolerance` of their size (L2 norms over the
// points); stopped at `max_iterations` otherwise (an unconverged step, counted and reported).
// The order is the points' order, fixed by the detection: the result does not depend on the
// thread count (the solve runs on one thread).
//
// Cone solve. Gauss-Seidel carries a change of load along a chain of blocks one block a
// sweep, and settles it in about N^2 sweeps for N blocks: the thrust of an arch of 2-degree
// voussoirs (church_b's) was still wrong after 1000 sweeps. When the sweeps have not converged
// after kSweepsBeforeCone, the step's impulses are found at once as the minimum of a quadratic
// program over all points (cone_solve): Coulomb's law at given normal impulses is Tresca's,
// |r_t| <= mu r_n with r_n fixed, and then the impulses minimise
//     f(r) = r.W r / 2 + r.(q - u),   u = (u_min, 0) point by point,
// over the box r_n >= 0, |r_t| <= mu r_n (f's gradient W r + q - u = U - u: its KKT conditions
// are Signorini's with Newton's u_min and Tresca's law). The box is solved by MPRGP (conjugate
// gradients on the free face with projections: their products grow like N along a chain where
// the sweeps grow like N^2), in variables scaled by the Delassus diagonal, after a few
// active-set steps (an impulse that a step down f's gradient takes past its bound is held at
// it, a Newton step on the rest: a sparse LDL^T of W_FF), which from the sweeps' impulses
// usually solve the box alone, and with a Newton step on the free face every few products,
// kept when it lowers f. Then mu r_n gives the next box, for at most kTrescaPasses boxes. The
// products apply W as H M^-1 H^T; the Newton steps factor the free face of W, assembled once
// per cone solve. Two points on every joint make the contacts redundant (W singular): with
// restitution 0 the gaps' u_min <= 0 keep f bounded below (with a restitution, the cap on the
// products bounds the solve), and the face's matrix takes a small regularisation. The solution
// is where the sweeps go on from; they decide convergence, on the same tolerance, and take the
// cone solve again after every kSweepsBeforeCone sweeps.
//
// Energy (the ledger's terms, booked from the impulses, never as a remainder). Over a step the
// bodies' kinetic energy changes by (h F + P) . (v^- + v^+) / 2 (P: the contact impulses on the
// bodies), so the contact impulses do the work sum over points r . (U^- + U^+) / 2 on the free
// bodies, less the work of the moving supports. Its normal part is booked as impact
// dissipation, its tangential part as friction dissipation (both with the sign that makes them
// losses); the supports' work -sum r . U_support over their points is external work.

#include <cstdint>
#include <vector>

#include "contact/rigid_contact.hpp"
#include "core/energy.hpp"
#include "core/model.hpp"

namespace voussoir {

// Relative margin of the reference face's switch between the two pieces (times the alert
// distance): a flat joint's faces have the same separation to round-off.
inline constexpr double kFaceSwitch = 1e-3;

// The exact solution of one point's law (header): the impulse r = (rn, rt) for the 2x2 Delassus
// block (wnn, wnt, wtt), the velocity without the point's impulse (qn, qt), the least normal
// velocity u_min and the friction coefficient mu. Pure: tests call it.
struct PointImpulse {
  double rn = 0.0, rt = 0.0;
};
PointImpulse solve_point(double wnn, double wnt, double wtt, double qn, double qt, double u_min,
                         double mu);

// One contact point (header), at the start of the step.
struct ContactPoint {
  Index a = 0, b = 0;     // blocks, a < b
  Vec2 x;                 // the point, midway between the outlines [m]
  Vec2 n;                 // unit normal from a into b
  double gap = 0.0;       // g [m], negative when the outlines overlap
  std::uint64_t key = 0;  // pieces and faces that made it (warm start)
};

// The contact points of two convex pieces p (np vertices, of block a) and q (of block b),
// counter-clockwise, whose edges k are outline edges when bit k of p_outline / q_outline is
// set; points within `alert` [m] are appended to `out` with the key `key_base` plus the face
// bits. Pure: tests call it.
void piece_contact_points(const Vec2* p, int np, std::uint32_t p_outline, const Vec2* q, int nq,
                          std::uint32_t q_outline, double alert, Index a, Index b,
                          std::uint64_t key_base, std::vector<ContactPoint>& out);

// The settings of a step (docs/reference/deck.md: solver.theta, solver.tolerance,
// solver.max_iterations, contact.friction, contact.restitution).
struct NscdSettings {
  double theta = 0.5;
  double tolerance = 1e-6;
  int max_iterations = 1000;
  double friction = 0.0;
  double restitution = 0.0;
};

// What one step's solve gives.
struct NscdStepResult {
  int iterations = 0;
  int cone_products = 0;   // products with W of the step's cone solves (0: none)
  int factorisations = 0;  // factorisations of a face's matrix in them
  bool converged = true;
  double residual = 0.0;     // the last sweep's relative change of the impulses
  double penetration = 0.0;  // largest overlap -g of a point at the start of the step [m]
  int points = 0;            // contact points in the solve
  int active = 0;            // points with r_n > 0
  // The impulses' work over the step, split as the ledger books it [J] (header)
  double impact_dissipated = 0.0;
  double friction_dissipated = 0.0;
  double support_work = 0.0;
};

// Every step's solve of a run, summed (the run's JSON; docs/nscd.md "Never silent").
struct NscdStats {
  long long steps = 0;
  long long unconverged_steps = 0;  // steps that stopped at max_iterations
  long long iterations = 0;         // summed over the steps
  long long cone_steps = 0;         // steps that took the cone solve
  long long cone_products = 0;      // products with W in the cone solves, summed
  long long factorisations = 0;     // factorisations of a face's matrix, summed
  int max_iterations = 0;           // largest iteration count of a step
  double max_residual = 0.0;        // largest final residual of a step
  double max_penetration = 0.0;     // largest overlap of a contact point seen [m]
  void add(const NscdStepResult& r);
  // Adds what a run added to a record, from `start` to `end`: the counts' differences, and
  // the largest values of `end` (a run's record includes the state it was copied from).
  void add_run(const NscdStats& end, const NscdStats& start);
  // The record as numbers (checkpoints, the message of an MPI rank): steps, unconverged_steps,
  // iterations, max_iterations, max_residual, max_penetration, cone_steps, cone_products,
  // factorisations. from_numbers also reads the first 6 or 7 of them (older checkpoints; the
  // rest 0) and throws std::invalid_argument on another count.
  std::vector<double> numbers() const;
  static NscdStats from_numbers(const std::vector<double>& v);
};

class NscdContact {
 public:
  // The outline edges of each convex piece of `rigid` (set up on `model` in its reference
  // configuration) and the alert distance [m].
  void setup(const Model& model, const RigidContact& rigid, double alert);
  // The contact points at the bodies' current poses (the live piece pairs of the last
  // detection), their Delassus blocks, and the warm start from the last step's impulses.
  void build(const Model& model, const RigidContact& rigid);
  // Solves the step: on entry model.rigid's vx, vy, omega hold the free velocities (the loads'
  // impulses added) and `before` the velocities at the start of the step (3 per block: vx, vy,
  // omega, prescribed supports' for the step); on return the bodies hold v^+.
  // `load`: the step's body acceleration [m/s2] (the scale of the tolerance).
  NscdStepResult solve(Model& model, const std::vector<double>& before, double h, Vec2 load,
                       const NscdSettings& settings);

  // The force of every touching block pair over the last step (its impulses / h): on b, with
  // the moment about `origin` = b's centroid at the start of the step.
  std::vector<BlockPairForce> pair_forces(const Model& model, double h) const;

  const std::vector<ContactPoint>& points() const { return points_; }
  const std::vector<double>& impulses() const { return rn_; }  // normal, per point [N s]

  // Warm start (checkpoints): the last step's points' keys and impulses.
  std::vector<char> save_state() const;
  void restore_state(const std::vector<char>& bytes);

 private:
  double alert_ = 0.0;
  // The cone solve of the sweeps that converge slowly (header "Cone solve") from the impulses
  // rn_, rt_ as they stand; they take the solution. `inv`: inverse masses, `v_free`: the free
  // velocities, `tol_v`: the largest violation of a point's law left [m/s]. Returns the products
  // with W used (the sweeps after it judge its convergence).
  int cone_solve(const std::vector<double>& inv, const std::vector<double>& v_free,
                 const std::vector<double>& u_min, double mu, double tol_v);
  // The cone solve's matrix A = S W S over all its unknowns (the scaled unknowns' scales s),
  // assembled for face_step.
  void assemble_cone_matrix(const std::vector<double>& inv, const std::vector<double>& s) const;
  // The Newton step d = -A_FF^-1 g_F of the cone solve on its free face (free[i] and s[i] > 0)
  // from the last assembled A; false when the face is empty or its matrix does not factor.
  bool face_step(const std::vector<double>& s, const std::vector<char>& free,
                 const std::vector<double>& g, std::vector<double>& d) const;

  // Adds the impulse (rn, rt) of point k to its bodies' velocities v (inverse masses inv; 3 a
  // block each).
  void apply_impulse(std::size_t k, double rn, double rt, const std::vector<double>& inv,
                     std::vector<double>& v) const;

  std::vector<std::uint32_t> outline_;  // per piece: bit k when edge k is an outline edge
  std::vector<double> radius_;          // per block: farthest outline point from the centroid [m]
  std::vector<ContactPoint> points_;
  // Per point: Delassus block, lever arms (x - c) of a and b, inverse masses (0: fixed)
  std::vector<double> wnn_, wnt_, wtt_;
  std::vector<double> ra_x_, ra_y_, rb_x_, rb_y_;
  std::vector<double> rn_, rt_;  // impulses [N s]
  // The last step's points (sorted by key) and impulses, for the warm start.
  std::vector<std::uint64_t> last_key_;
  std::vector<double> last_rn_, last_rt_;
};

}  // namespace voussoir

// Non-smooth contact dynamics of rigid blocks: contact points, the local law, non-linear
// Gauss-Seidel (the math and the contract are in contact/nscd.hpp).

#include "contact/nscd.hpp"

#include <Eigen/Sparse>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "contact/state_bytes.hpp"

namespace voussoir {

namespace {
// The cone solve (nscd.hpp "Cone solve"): taken after every this many sweeps without
// convergence; at most this many products with the Delassus operator W in one cone solve, and
// this many passes of Tresca's box (a pass stops them when mu r_n moves the box by less than the
// tolerance; with 2 passes the friction was often left unsettled, the sweeps returned to the
// same impulses and 9 steps in 6000 of church_b under a record stopped at the cap, with 4 and
// 16 about one); a Newton step on the free face every this many products; the regularisation of the
// face's matrix (its diagonal is 1), which keeps redundant contacts definite (with 1e-10 the Newton
// steps ran off along the redundancy and the descent test refused 7 to 9 in 10 of them; 1e-3 slowed
// the steps towards the solution: church_b's capacity took 9 times as long).
// Taking the cone solve after 5 or 10 sweeps, or as soon as the sweeps' rate shows they will
// not converge within 20, starts it farther from the answer: church_b under a record then took
// 1.6 to 2.6 cone solves a step, or more boxes and faces in each.
constexpr int kSweepsBeforeCone = 20;
constexpr int kConeProducts = 3000;
// Solving the boxes before the last only loosely (to 10 times the tolerance, then to a tenth of
// how far the last pass moved the box) left the 90-voussoir chain's supports carrying its
// weight to 1.2e-4 only (1e-6 asked); moving each box half way to the new one took 2.3 times
// the factorisations on church_b (bench/bench_nscd.cpp). Starting the passes from the solution
// of the associated cone (in 2D a box in (mu r_n + r_t) / 2 and (mu r_n - r_t) / 2, solved by
// MPRGP alone to 1000 products) halved the passes' factorisations on church_b's heavier second
// (25.3 to 13.9 a step) but cost 960 products a step; solved with its own face's Newton steps
// it took as many factorisations in all (25.1 to 27.3) and 6 to 7% more time.
constexpr int kTrescaPasses = 16;
constexpr int kNewtonEvery = 10;
constexpr double kFaceRegularisation = 1e-6;
// The faces whose factors one cone solve keeps (FaceScratch::kept below).
constexpr std::size_t kKeptFaces = 16;
// Active-set steps at the start of each box (box_qp) before MPRGP takes over: from the sweeps'
// impulses one or two usually solve the box, and a pass of Tresca's box that keeps the face
// reuses its factors. A step is kept even when it raises f (the best iterate is returned to
// MPRGP): refusing such steps, as MPRGP's own Newton steps do, sent a quarter of the boxes to
// MPRGP and took 2.4 times the products on church_b under a record. Bertsekas' projected Newton
// steps (an epsilon-active set, an Armijo search along the projection arc) in their place took
// 4 to 28% more factorisations and 8 to 23% more time there (8, 20 or 40 steps before MPRGP).
constexpr int kActiveSetSteps = 8;
// Power iterations for the largest eigenvalue of W (the projections' step), and its margin
// (power iterations approach it from below).
constexpr int kPowerIterations = 8;
constexpr double kNormMargin = 1.1;
}  // namespace

PointImpulse solve_point(double wnn, double wnt, double wtt, double qn, double qt, double u_min,
                         double mu) {
  const double bn = u_min - qn;
  if (!(bn > 0.0)) return {};  // the free velocity keeps the point open
  if (!(mu > 0.0)) return {bn / wnn, 0.0};
  // Sticking: W r = (bn, -qt).
  const double det = wnn * wtt - wnt * wnt;
  const double rn = (wtt * bn + wnt * qt) / det;
  const double rt = (-wnn * qt - wnt * bn) / det;
  if (rn > 0.0 && std::abs(rt) <= mu * rn) return {rn, rt};
  // Sliding: r_t = s mu r_n, the slip U_t opposite to r_t. Try the sign of the sticking impulse
  // first; in 2D with W positive definite one of the two holds.
  const double first = rt >= 0.0 ? 1.0 : -1.0;
  PointImpulse fallback{};
  for (const double s : {first, -first}) {
    const double denominator = wnn + s * mu * wnt;
    if (!(denominator > 0.0)) continue;
    const double n = bn / denominator;
    const double t = s * mu * n;
    const double ut = wnt * n + wtt * t + qt;
    if (s * ut <= 0.0) return {n, t};
    if (s == first) fallback = {n, t};
  }
  return fallback;
}

namespace {

// Outward unit normal of edge k of a counter-clockwise polygon.
inline Vec2 edge_normal(const Vec2* v, int n, int k) {
  const Vec2 e = v[(k + 1) % n] - v[k];
  const double len = norm(e);
  return {e.y / len, -e.x / len};
}

// Smallest distance of q's vertices from the line of p's edge k along its outward normal
// (positive: every vertex of q lies outside the line).
inline double face_separation(const Vec2* p, int np, int k, const Vec2* q, int nq) {
  const Vec2 n = edge_normal(p, np, k);
  double s = std::numeric_limits<double>::infinity();
  for (int j = 0; j < nq; ++j) s = std::min(s, dot(n, q[j] - p[k]));
  return s;
}

struct Face {
  int edge = -1;
  double separation = -std::numeric_limits<double>::infinity();
};

// The outline face of p with the largest separation from q; also the largest separation over
// every edge of p (outline or not) in `any`.
Face best_face(const Vec2* p, int np, std::uint32_t outline, const Vec2* q, int nq, double& any) {
  Face best;
  for (int k = 0; k < np; ++k) {
    const double s = face_separation(p, np, k, q, nq);
    any = std::max(any, s);
    if ((outline >> k & 1u) && s > best.separation) best = {k, s};
  }
  return best;
}

}  // namespace

void piece_contact_points(const Vec2* p, int np, std::uint32_t p_outline, const Vec2* q, int nq,
                          std::uint32_t q_outline, double alert, Index a, Index b,
                          std::uint64_t key_base, std::vector<ContactPoint>& out) {
  double any = -std::numeric_limits<double>::infinity();
  const Face fp = best_face(p, np, p_outline, q, nq, any);
  const Face fq = best_face(q, nq, q_outline, p, np, any);
  if (any > alert) return;  // a separating line farther than the alert distance
  if (fp.edge < 0 && fq.edge < 0) return;
  const bool ref_q =
      fp.edge < 0 || (fq.edge >= 0 && fq.separation > fp.separation + kFaceSwitch * alert);
  const Vec2* r = ref_q ? q : p;
  const int nr = ref_q ? nq : np;
  const Vec2* in = ref_q ? p : q;
  const int ni = ref_q ? np : nq;
  const std::uint32_t in_outline = ref_q ? p_outline : q_outline;
  const int k = ref_q ? fq.edge : fp.edge;
  const Vec2 n = edge_normal(r, nr, k);
  // Incident edge: the outline edge of the other piece most opposed to n.
  int inc = -1;
  double most = std::numeric_limits<double>::infinity();
  for (int j = 0; j < ni; ++j) {
    if (!(in_outline >> j & 1u)) continue;
    const double d = dot(edge_normal(in, ni, j), n);
    if (d < most) most = d, inc = j;
  }
  if (inc < 0) return;
  const Vec2 r1 = r[k], r2 = r[(k + 1) % nr];
  const Vec2 t = (1.0 / norm(r2 - r1)) * (r2 - r1);
  Vec2 v[2] = {in[inc], in[(inc + 1) % ni]};
  // Clip the incident edge to the reference face's extent: t.(x - r1) >= 0, t.(x - r2) <= 0.
  auto clip = [&](double d0, double d1) {  // keeps the part with d <= 0
    if (d0 > 0.0 && d1 > 0.0) return false;
    if (d0 > 0.0)
      v[0] = v[0] + (d0 / (d0 - d1)) * (v[1] - v[0]);
    else if (d1 > 0.0)
      v[1] = v[1] + (d1 / (d1 - d0)) * (v[0] - v[1]);
    return true;
  };
  if (!clip(-dot(t, v[0] - r1), -dot(t, v[1] - r1))) return;
  if (!clip(dot(t, v[0] - r2), dot(t, v[1] - r2))) return;
  const std::uint64_t face_bits =
      (std::uint64_t(ref_q) << 9) | (std::uint64_t(k) << 5) | (std::uint64_t(inc) << 1);
  for (int c = 0; c < 2; ++c) {
    const double s = dot(n, v[c] - r1);
    if (s > alert) continue;
    ContactPoint pt;
    pt.a = a, pt.b = b;
    pt.x = v[c] - (0.5 * s) * n;
    pt.n = ref_q ? Vec2{-n.x, -n.y} : n;
    pt.gap = s;
    pt.key = key_base | face_bits | std::uint64_t(c);
    out.push_back(pt);
  }
}

std::vector<double> NscdStats::numbers() const {
  return {
      double(steps),         double(unconverged_steps), double(iterations), double(max_iterations),
      max_residual,          max_penetration,           double(cone_steps), double(cone_products),
      double(factorisations)};
}

NscdStats NscdStats::from_numbers(const std::vector<double>& v) {
  if (v.size() != 9 && v.size() != 7 && v.size() != 6)
    throw std::invalid_argument("the non-smooth contact solver's record is not readable");
  NscdStats st;
  st.steps = (long long)v[0], st.unconverged_steps = (long long)v[1];
  st.iterations = (long long)v[2], st.max_iterations = int(v[3]);
  st.max_residual = v[4], st.max_penetration = v[5];
  st.cone_steps = v.size() > 6 ? (long long)v[6] : 0;
  st.cone_products = v.size() > 7 ? (long long)v[7] : 0;
  st.factorisations = v.size() > 8 ? (long long)v[8] : 0;
  return st;
}

void NscdStats::add(const NscdStepResult& r) {
  ++steps;
  iterations += r.iterations;
  if (r.cone_products > 0) ++cone_steps;
  cone_products += r.cone_products;
  factorisations += r.factorisations;
  if (!r.converged) ++unconverged_steps;
  max_iterations = std::max(max_iterations, r.iterations);
  max_residual = std::max(max_residual, r.residual);
  max_penetration = std::max(max_penetration, r.penetration);
}

void NscdStats::add_run(const NscdStats& end, const NscdStats& start) {
  steps += end.steps - start.steps;
  unconverged_steps += end.unconverged_steps - start.unconverged_steps;
  iterations += end.iterations - start.iterations;
  cone_steps += end.cone_steps - start.cone_steps;
  cone_products += end.cone_products - start.cone_products;
  factorisations += end.factorisations - start.factorisations;
  max_iterations = std::max(max_iterations, end.max_iterations);
  max_residual = std::max(max_residual, end.max_residual);
  max_penetration = std::max(max_penetration, end.max_penetration);
}

void NscdContact::setup(const Model& model, const RigidContact& rigid, double alert) {
  alert_ = alert;
  // An edge of a piece is an outline edge when its middle lies on the block's outline.
  const Index pieces = rigid.piece_count();
  outline_.assign(std::size_t(pieces), 0u);
  Vec2 v[kMaxPieceVertices];
  for (Index k = 0; k < pieces; ++k) {
    const int n = rigid.piece_reference(k, v);
    const std::vector<Vec2>& poly = model.blocks[std::size_t(rigid.piece_block(k))].polygon;
    double size = 0.0;
    for (int i = 0; i < n; ++i) size = std::max(size, distance(v[i], v[(i + 1) % n]));
    for (int i = 0; i < n; ++i) {
      const Vec2 mid = 0.5 * (v[i] + v[(i + 1) % n]);
      double d = std::numeric_limits<double>::infinity();
      for (std::size_t j = 0; j < poly.size(); ++j)
        d = std::min(d, distance_to_segment(mid, poly[j], poly[(j + 1) % poly.size()]));
      if (d <= 1e-9 * size) outline_[std::size_t(k)] |= 1u << i;
    }
  }
  points_.clear();
  rn_.clear(), rt_.clear(), last_key_.clear(), last_rn_.clear(), last_rt_.clear();
  // Each block's farthest outline point from its centroid (the tolerance's lever of rotation).
  const RigidBodies& r = model.rigid;
  radius_.assign(model.blocks.size(), 0.0);
  for (std::size_t b = 0; b < model.blocks.size(); ++b)
    for (const Vec2& p : model.blocks[b].polygon)
      radius_[b] = std::max(radius_[b], distance(p, {r.cx0[b], r.cy0[b]}));
}

void NscdContact::build(const Model& model, const RigidContact& rigid) {
  // The last step's impulses by key, for the warm start.
  {
    std::vector<std::size_t> order(points_.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(),
              [&](std::size_t x, std::size_t y) { return points_[x].key < points_[y].key; });
    last_key_.resize(order.size()), last_rn_.resize(order.size()), last_rt_.resize(order.size());
    for (std::size_t i = 0; i < order.size(); ++i)
      last_key_[i] = points_[order[i]].key, last_rn_[i] = rn_[order[i]],
      last_rt_[i] = rt_[order[i]];
  }
  points_.clear();
  Vec2 p[kMaxPieceVertices], q[kMaxPieceVertices];
  for (std::size_t l = 0; l < rigid.live_pairs(); ++l) {
    const Index i = rigid.live_piece_a(l), j = rigid.live_piece_b(l);
    const int np = rigid.piece_vertices(model, i, p);
    const int nq = rigid.piece_vertices(model, j, q);
    const std::uint64_t base = (std::uint64_t(i) << 37) | (std::uint64_t(j) << 10);
    piece_contact_points(p, np, outline_[std::size_t(i)], q, nq, outline_[std::size_t(j)], alert_,
                         rigid.piece_block(i), rigid.piece_block(j), base, points_);
  }
  const std::size_t n = points_.size();
  const RigidBodies& r = model.rigid;
  wnn_.resize(n), wnt_.resize(n), wtt_.resize(n);
  ra_x_.resize(n), ra_y_.resize(n), rb_x_.resize(n), rb_y_.resize(n);
  rn_.assign(n, 0.0), rt_.assign(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    const ContactPoint& c = points_[k];
    const Vec2 t{-c.n.y, c.n.x};
    double wnn = 0.0, wnt = 0.0, wtt = 0.0;
    auto body = [&](Index blk, double& rx, double& ry) {
      const double cx = r.cx0[blk] + r.ux[blk], cy = r.cy0[blk] + r.uy[blk];
      rx = c.x.x - cx, ry = c.x.y - cy;
      if (model.blocks[std::size_t(blk)].fixed) return;
      const double im = 1.0 / r.mass[blk], ii = 1.0 / r.inertia[blk];
      const double an = rx * c.n.y - ry * c.n.x, at = rx * t.y - ry * t.x;
      wnn += im + ii * an * an;
      wnt += ii * an * at;
      wtt += im + ii * at * at;
    };
    body(c.a, ra_x_[k], ra_y_[k]);
    body(c.b, rb_x_[k], rb_y_[k]);
    wnn_[k] = wnn, wnt_[k] = wnt, wtt_[k] = wtt;
    const auto it = std::lower_bound(last_key_.begin(), last_key_.end(), c.key);
    if (it != last_key_.end() && *it == c.key) {
      const std::size_t o = std::size_t(it - last_key_.begin());
      rn_[k] = last_rn_[o], rt_[k] = last_rt_[o];
    }
  }
}

namespace {

// Relative velocity (normal, tangential) of b's material point at the point with respect to
// a's, from per-block velocities v (3 per block).
inline void local_velocity(const ContactPoint& c, const double* v, double rax, double ray,
                           double rbx, double rby, double& un, double& ut) {
  const double* va = v + 3 * c.a;
  const double* vb = v + 3 * c.b;
  // v + w x r = (vx - w ry, vy + w rx)
  const double dx = (vb[0] - vb[2] * rby) - (va[0] - va[2] * ray);
  const double dy = (vb[1] + vb[2] * rbx) - (va[1] + va[2] * rax);
  un = dx * c.n.x + dy * c.n.y;
  ut = -dx * c.n.y + dy * c.n.x;
}

// MPRGP's split of the gradient g at y in the box [lo, hi]: the free gradient phi (zero at a
// bound), the chopped gradient beta (the part of g at a bound that points out of the box) and
// weight |phi + beta| in `weighted`. Here and below the arrays do not overlap, so that the
// compiler does several components at a time (about 7% of a heavy step of church_b).
void split_gradient(std::size_t m, const double* __restrict y, const double* __restrict lo,
                    const double* __restrict hi, const double* __restrict g,
                    const double* __restrict weight, double* __restrict phi,
                    double* __restrict beta, double* __restrict weighted) {
  for (std::size_t i = 0; i < m; ++i) {
    const bool at_lo = y[i] <= lo[i], at_hi = y[i] >= hi[i];
    const double low = std::min(g[i], 0.0), high = std::max(g[i], 0.0);
    const double phi_i = at_lo | at_hi ? 0.0 : g[i];
    const double out_lo = at_hi ? 0.0 : low, out_hi = at_lo ? 0.0 : high;
    const double beta_i = at_lo ? out_lo : at_hi ? out_hi : 0.0;
    phi[i] = phi_i, beta[i] = beta_i;
    weighted[i] = weight[i] * std::abs(phi_i + beta_i);
  }
}

// For each component, how far y can go along -dir before it meets a bound (infinity where dir
// is 0). Every division is taken, so that the compiler does several at a time.
void step_to_bounds(std::size_t m, const double* __restrict y, const double* __restrict lo,
                    const double* __restrict hi, const double* __restrict dir,
                    double* __restrict step) {
  for (std::size_t i = 0; i < m; ++i) {
    const double q = (dir[i] > 0.0 ? y[i] - lo[i] : y[i] - hi[i]) / dir[i];
    step[i] = dir[i] != 0.0 ? q : std::numeric_limits<double>::infinity();
  }
}

// MPRGP's reduced free gradient: phi, cut where a step of alpha_bar along -phi would pass a
// bound (its components where phi is 0 are not used).
void reduced_free_gradient(std::size_t m, const double* __restrict y, const double* __restrict lo,
                           const double* __restrict hi, const double* __restrict phi,
                           double alpha_bar, double* __restrict reduced) {
  for (std::size_t i = 0; i < m; ++i) {
    const double q = (phi[i] > 0.0 ? y[i] - lo[i] : y[i] - hi[i]) / alpha_bar;
    reduced[i] = phi[i] > 0.0 ? std::min(q, phi[i]) : std::max(q, phi[i]);
  }
}

// Modified proportioning with reduced gradient projections (MPRGP: Dostal, "Optimal quadratic
// programming algorithms", Springer 2009, ch. 7 and 8) for min f(y) = y.A y / 2 - b.y over the
// box lo <= y <= hi, A symmetric positive semi-definite with unit diagonal, applied by
// apply_a(x, A x). Conjugate gradients on the free face while they stay in the box, an
// expansion step (to the box, then a projected gradient step of length step_length() <= 1/|A|)
// when they would leave it, a proportioning step that frees the bounds holding the solution
// back when the chopped gradient outweighs the free one. Every kNewtonEvery products,
// face_newton(free, g, d) offers d = -A_FF^-1 g_F on the free face F; its projection on the
// box is taken when it lowers f (else a quarter of it, up to three times).
// Before MPRGP, up to kActiveSetSteps primal-dual active-set steps (Hintermueller, Ito and
// Kunisch, SIAM J. Optim. 13 (2002)): a component that y - g puts past a bound is held at it,
// the others are free, and the Newton step on the free face follows, projected on the box.
// Keeping the status of a component at a bound whose gradient is within the tolerance (so that
// the face and its factors carry over) saved 15% of the factorisations on church_b but left a
// step of the 90-voussoir chain at the cap (test Nscd.AChainOfNinetyVoussoirs...).
// Stops when every component of the projected gradient times `weight` is at most `tol`
// (`converged`), or after `max_products` products with A. Returns the products used.
template <class Apply, class FaceNewton, class StepLength>
int box_qp(const Apply& apply_a, const FaceNewton& face_newton, const std::vector<double>& b,
           const std::vector<double>& lo, const std::vector<double>& hi,
           const std::vector<double>& weight, double tol, const StepLength& step_length,
           int max_products, std::vector<double>& y, bool& converged) {
  const std::size_t m = y.size();
  std::vector<double> g(m), p(m), ap(m), phi(m), beta(m), d(m), y_try(m), g_try(m), scratch(m);
  std::vector<char> free(m);
  int products = 0, last_newton = -kNewtonEvery;
  auto gradient_at = [&](const std::vector<double>& x, std::vector<double>& out) {
    apply_a(x, out);
    ++products;
    for (std::size_t i = 0; i < m; ++i) out[i] -= b[i];
  };
  // f from y and its gradient g = A y - b
  auto objective = [&](const std::vector<double>& x, const std::vector<double>& gx) {
    double f = 0.0;
    for (std::size_t i = 0; i < m; ++i) f += 0.5 * x[i] * (gx[i] - b[i]);
    return f;
  };
  // The free gradient phi and the chopped gradient beta; returns the largest weighted
  // component of the projected gradient phi + beta.
  auto split = [&]() {
    split_gradient(m, y.data(), lo.data(), hi.data(), g.data(), weight.data(), phi.data(),
                   beta.data(), scratch.data());
    double worst = 0.0;
    for (std::size_t i = 0; i < m; ++i) worst = std::max(worst, scratch[i]);
    return worst;
  };
  // The longest step along -dir that stays in the box.
  auto feasible_step = [&](const std::vector<double>& dir) {
    step_to_bounds(m, y.data(), lo.data(), hi.data(), dir.data(), scratch.data());
    double a = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < m; ++i) a = std::min(a, scratch[i]);
    return a;
  };
  for (std::size_t i = 0; i < m; ++i) y[i] = std::clamp(y[i], lo[i], hi[i]);
  gradient_at(y, g);
  double worst = split();
  converged = false;
  std::vector<double> y_best, g_best;  // the lowest f of the active-set steps, when one rose
  double f_best = 0.0;
  for (int step = 0; step < kActiveSetSteps && worst > tol && products < max_products; ++step) {
    bool moved = false;
    for (std::size_t i = 0; i < m; ++i) {
      const double t = y[i] - g[i];
      const bool is_free = lo[i] < t && t < hi[i];
      y_try[i] = is_free ? y[i] : t <= lo[i] ? lo[i] : t >= hi[i] ? hi[i] : y[i];
      free[i] = is_free;
      moved = moved || y_try[i] != y[i];
    }
    if (moved)
      gradient_at(y_try, g_try);
    else
      g_try = g;
    if (!face_newton(free, g_try, d)) break;
    for (std::size_t i = 0; i < m; ++i) y_try[i] = std::clamp(y_try[i] + d[i], lo[i], hi[i]);
    gradient_at(y_try, g_try);
    const double f_try = objective(y_try, g_try), f = objective(y, g);
    if (f_try > f && y_best.empty()) y_best = y, g_best = g, f_best = f;
    y.swap(y_try), g.swap(g_try);
    worst = split();
    if (!y_best.empty() && f_try < f_best) y_best = y, g_best = g, f_best = f_try;
  }
  if (!y_best.empty() && worst > tol && objective(y, g) > f_best) {
    y.swap(y_best), g.swap(g_best);
    worst = split();
  }
  last_newton = products;
  p = phi;
  while (products < max_products) {
    if (worst <= tol) {
      converged = true;
      break;
    }
    if (products - last_newton >= kNewtonEvery) {
      last_newton = products;
      for (std::size_t i = 0; i < m; ++i) free[i] = y[i] > lo[i] && y[i] < hi[i];
      if (face_newton(free, g, d)) {
        const double f0 = objective(y, g);
        double scale = 1.0;
        for (int tries = 0; tries < 4; ++tries, scale *= 0.25) {
          for (std::size_t i = 0; i < m; ++i)
            y_try[i] = std::clamp(y[i] + scale * d[i], lo[i], hi[i]);
          gradient_at(y_try, g_try);
          if (objective(y_try, g_try) <= f0) {
            y.swap(y_try), g.swap(g_try);
            worst = split();
            p = phi;
            break;
          }
        }
        continue;
      }
    }
    const double alpha_bar = step_length();
    reduced_free_gradient(m, y.data(), lo.data(), hi.data(), phi.data(), alpha_bar,
                          scratch.data());
    double beta2 = 0.0, phi_reduced = 0.0;
    for (std::size_t i = 0; i < m; ++i) {
      beta2 += beta[i] * beta[i];
      if (phi[i] != 0.0) phi_reduced += scratch[i] * phi[i];
    }
    if (beta2 <= phi_reduced) {
      apply_a(p, ap);
      ++products;
      double pap = 0.0, gp = 0.0;
      for (std::size_t i = 0; i < m; ++i) pap += p[i] * ap[i], gp += g[i] * p[i];
      if (!(pap > 0.0)) break;
      const double a_cg = gp / pap, a_f = feasible_step(p);
      if (a_cg <= a_f) {  // conjugate gradient step
        for (std::size_t i = 0; i < m; ++i) y[i] -= a_cg * p[i], g[i] -= a_cg * ap[i];
        worst = split();
        double phi_ap = 0.0;
        for (std::size_t i = 0; i < m; ++i) phi_ap += phi[i] * ap[i];
        const double gamma = phi_ap / pap;
        for (std::size_t i = 0; i < m; ++i) p[i] = phi[i] - gamma * p[i];
      } else {  // expansion step
        for (std::size_t i = 0; i < m; ++i) y[i] -= a_f * p[i], g[i] -= a_f * ap[i];
        split();
        for (std::size_t i = 0; i < m; ++i)
          y[i] = std::clamp(y[i] - alpha_bar * phi[i], lo[i], hi[i]);
        gradient_at(y, g);
        worst = split();
        p = phi;
      }
    } else {  // proportioning step
      apply_a(beta, ap);
      ++products;
      double dad = 0.0, gd = 0.0;
      for (std::size_t i = 0; i < m; ++i) dad += beta[i] * ap[i], gd += g[i] * beta[i];
      if (!(dad > 0.0)) break;
      const double a = std::min(gd / dad, feasible_step(beta));
      for (std::size_t i = 0; i < m; ++i) y[i] -= a * beta[i], g[i] -= a * ap[i];
      worst = split();
      p = phi;
    }
  }
  return products;
}

// The factorisations of a face's matrix on this thread so far (FaceScratch below).
long long thread_factorisations();

}  // namespace

NscdStepResult NscdContact::solve(Model& model, const std::vector<double>& before, double h,
                                  Vec2 load, const NscdSettings& settings) {
  NscdStepResult out;
  RigidBodies& r = model.rigid;
  const std::size_t nb = model.blocks.size();
  const std::size_t n = points_.size();
  out.points = int(n);
  // The bodies' velocities as one array (3 per block) and their inverse masses (0: fixed).
  std::vector<double> v(3 * nb), inv(3 * nb, 0.0);
  for (std::size_t b = 0; b < nb; ++b) {
    v[3 * b] = r.vx[b], v[3 * b + 1] = r.vy[b], v[3 * b + 2] = r.omega[b];
    if (model.blocks[b].fixed) continue;
    inv[3 * b] = inv[3 * b + 1] = 1.0 / r.mass[b];
    inv[3 * b + 2] = 1.0 / r.inertia[b];
  }
  // The least normal velocity of each point (nscd.hpp) from its gap and U^-.
  std::vector<double> u_min(n), un0(n), ut0(n);
  for (std::size_t k = 0; k < n; ++k) {
    const ContactPoint& c = points_[k];
    local_velocity(c, before.data(), ra_x_[k], ra_y_[k], rb_x_[k], rb_y_[k], un0[k], ut0[k]);
    u_min[k] =
        c.gap > 0.0 ? -c.gap / (settings.theta * h) : -settings.restitution * std::min(un0[k], 0.0);
    out.penetration = std::max(out.penetration, -c.gap);
  }
  auto apply = [&](std::size_t k, double drn, double drt) { apply_impulse(k, drn, drt, inv, v); };
  const std::vector<double> v_free = v;
  for (std::size_t k = 0; k < n; ++k)
    if (rn_[k] != 0.0 || rt_[k] != 0.0) apply(k, rn_[k], rt_[k]);
  const double mu = settings.friction;
  // The velocity scale of the tolerance: what the loads give in a step, or the fastest
  // approach of a point, whichever is larger.
  double v_scale = h * norm(load);
  for (std::size_t k = 0; k < n; ++k) v_scale = std::max(v_scale, std::abs(un0[k]));
  if (!(v_scale > 0.0)) v_scale = std::numeric_limits<double>::min();
  std::vector<double> v_sweep(v.size());
  out.converged = n == 0;
  while (n > 0 && out.iterations < settings.max_iterations) {
    ++out.iterations;
    std::copy(v.begin(), v.end(), v_sweep.begin());
    for (std::size_t k = 0; k < n; ++k) {
      double un, ut;
      local_velocity(points_[k], v.data(), ra_x_[k], ra_y_[k], rb_x_[k], rb_y_[k], un, ut);
      const double qn = un - (wnn_[k] * rn_[k] + wnt_[k] * rt_[k]);
      const double qt = ut - (wnt_[k] * rn_[k] + wtt_[k] * rt_[k]);
      const PointImpulse p = solve_point(wnn_[k], wnt_[k], wtt_[k], qn, qt, u_min[k], mu);
      const double drn = p.rn - rn_[k], drt = p.rt - rt_[k];
      if (drn == 0.0 && drt == 0.0) continue;
      apply(k, drn, drt);
      rn_[k] = p.rn, rt_[k] = p.rt;
    }
    // How much the sweep changed the bodies' velocities: the largest speed change of a point
    // of a body (its centroid's, plus the angular velocity's change times the body's radius).
    double change = 0.0;
    for (std::size_t b = 0; b < nb; ++b) {
      const double* now = &v[3 * b];
      const double* was = &v_sweep[3 * b];
      const double dx = now[0] - was[0], dy = now[1] - was[1];
      change =
          std::max(change, std::sqrt(dx * dx + dy * dy) + radius_[b] * std::abs(now[2] - was[2]));
    }
    out.residual = change / v_scale;
    if (out.residual <= settings.tolerance) {
      out.converged = true;
      break;
    }
    // Slow sweeps: the impulses settle along the chains of blocks one block a sweep. The cone
    // solve puts them in place (cone_solve); the sweeps go on from there and judge it, and
    // take it again after as many sweeps.
    if (out.iterations % kSweepsBeforeCone == 0) {
      const long long factored = thread_factorisations();
      out.cone_products += cone_solve(inv, v_free, u_min, mu, settings.tolerance * v_scale);
      out.factorisations += int(thread_factorisations() - factored);
      v = v_free;
      for (std::size_t k = 0; k < n; ++k)
        if (rn_[k] != 0.0 || rt_[k] != 0.0) apply(k, rn_[k], rt_[k]);
    }
  }
  // The bodies take v^+; the impulses' work over the step (nscd.hpp "Energy").
  for (std::size_t b = 0; b < nb; ++b) {
    if (model.blocks[b].fixed) continue;
    r.vx[b] = v[3 * b], r.vy[b] = v[3 * b + 1], r.omega[b] = v[3 * b + 2];
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (rn_[k] == 0.0 && rt_[k] == 0.0) continue;
    ++out.active;
    const ContactPoint& c = points_[k];
    double un, ut;
    local_velocity(c, v.data(), ra_x_[k], ra_y_[k], rb_x_[k], rb_y_[k], un, ut);
    out.impact_dissipated -= 0.5 * rn_[k] * (un0[k] + un);
    out.friction_dissipated -= 0.5 * rt_[k] * (ut0[k] + ut);
    // A moving support's velocity (the same over the step): its work on the structure.
    auto support = [&](Index blk, double rx, double ry, double sign) {
      const Block& bk = model.blocks[std::size_t(blk)];
      if (!bk.prescribed) return;
      const double* vs = &v[3 * std::size_t(blk)];
      const double sx = vs[0] - vs[2] * ry, sy = vs[1] + vs[2] * rx;
      const double px = rn_[k] * c.n.x - rt_[k] * c.n.y, py = rn_[k] * c.n.y + rt_[k] * c.n.x;
      out.support_work += sign * (px * sx + py * sy);
    };
    support(c.a, ra_x_[k], ra_y_[k], 1.0);
    support(c.b, rb_x_[k], rb_y_[k], -1.0);
  }
  return out;
}

void NscdContact::apply_impulse(std::size_t k, double rn, double rt, const std::vector<double>& inv,
                                std::vector<double>& v) const {
  const ContactPoint& c = points_[k];
  const double px = rn * c.n.x - rt * c.n.y, py = rn * c.n.y + rt * c.n.x;
  double* va = &v[3 * std::size_t(c.a)];
  double* vb = &v[3 * std::size_t(c.b)];
  const double* ia = &inv[3 * std::size_t(c.a)];
  const double* ib = &inv[3 * std::size_t(c.b)];
  vb[0] += ib[0] * px, vb[1] += ib[1] * py;
  vb[2] += ib[2] * (rb_x_[k] * py - rb_y_[k] * px);
  va[0] -= ia[0] * px, va[1] -= ia[1] * py;
  va[2] -= ia[2] * (ra_x_[k] * py - ra_y_[k] * px);
}

int NscdContact::cone_solve(const std::vector<double>& inv, const std::vector<double>& v_free,
                            const std::vector<double>& u_min, double mu, double tol_v) {
  const std::size_t n = points_.size(), m = 2 * n;
  // Unknowns y = S^-1 (r_n, r_t) point by point, S = diag(W)^-1/2: A = S W S has a unit
  // diagonal. weight = S^-1 turns a component of A y - b back into a velocity.
  std::vector<double> s(m), weight(m), b(m), lo(m, 0.0), hi(m), y(m), vel(v_free.size());
  for (std::size_t k = 0; k < n; ++k) {
    s[2 * k] = wnn_[k] > 0.0 ? 1.0 / std::sqrt(wnn_[k]) : 0.0;
    s[2 * k + 1] = wtt_[k] > 0.0 ? 1.0 / std::sqrt(wtt_[k]) : 0.0;
  }
  for (std::size_t i = 0; i < m; ++i) weight[i] = s[i] > 0.0 ? 1.0 / s[i] : 0.0;
  // A x = S H M^-1 H^T S x: x as impulses on bodies at rest, then the points' velocities.
  auto apply_a = [&](const std::vector<double>& x, std::vector<double>& out) {
    std::fill(vel.begin(), vel.end(), 0.0);
    for (std::size_t k = 0; k < n; ++k) {
      const double pn = s[2 * k] * x[2 * k], pt = s[2 * k + 1] * x[2 * k + 1];
      if (pn != 0.0 || pt != 0.0) apply_impulse(k, pn, pt, inv, vel);
    }
    for (std::size_t k = 0; k < n; ++k) {
      double un, ut;
      local_velocity(points_[k], vel.data(), ra_x_[k], ra_y_[k], rb_x_[k], rb_y_[k], un, ut);
      out[2 * k] = s[2 * k] * un, out[2 * k + 1] = s[2 * k + 1] * ut;
    }
  };
  assemble_cone_matrix(inv, s);
  auto face_newton = [&](const std::vector<char>& free, const std::vector<double>& g,
                         std::vector<double>& d) { return face_step(s, free, g, d); };
  // b = S (u - H v_free), u = (u_min, 0); the start: the sweeps' impulses.
  for (std::size_t k = 0; k < n; ++k) {
    double un, ut;
    local_velocity(points_[k], v_free.data(), ra_x_[k], ra_y_[k], rb_x_[k], rb_y_[k], un, ut);
    b[2 * k] = s[2 * k] * (u_min[k] - un);
    b[2 * k + 1] = -s[2 * k + 1] * ut;
    y[2 * k] = s[2 * k] > 0.0 ? rn_[k] / s[2 * k] : 0.0;
    y[2 * k + 1] = s[2 * k + 1] > 0.0 ? rt_[k] / s[2 * k + 1] : 0.0;
    hi[2 * k] = std::numeric_limits<double>::infinity();
  }
  // The projections' step 1 / |A|, |A| by power iterations, when a step first needs it (a
  // solve that the Newton steps finish never does).
  int products = 0;
  double alpha_bar = 0.0;
  auto step_length = [&]() {
    if (alpha_bar > 0.0) return alpha_bar;
    double norm_a = 1.0;
    std::vector<double> x(m, 1.0), ax(m);
    for (int it = 0; it < kPowerIterations; ++it) {
      apply_a(x, ax);
      double ax2 = 0.0, x2 = 0.0;
      for (std::size_t i = 0; i < m; ++i) ax2 += ax[i] * ax[i], x2 += x[i] * x[i];
      if (!(ax2 > 0.0)) break;
      norm_a = std::sqrt(ax2 / x2);
      const double inv_len = 1.0 / std::sqrt(ax2);
      for (std::size_t i = 0; i < m; ++i) x[i] = ax[i] * inv_len;
    }
    products += kPowerIterations;
    alpha_bar = 1.0 / (kNormMargin * norm_a);
    return alpha_bar;
  };
  for (int pass = 0; pass < kTrescaPasses && products < kConeProducts; ++pass) {
    // Tresca's box |r_t| <= mu r_n of the last r_n
    for (std::size_t k = 0; k < n; ++k) {
      const double c = s[2 * k + 1] > 0.0 ? mu * std::max(rn_[k], 0.0) / s[2 * k + 1] : 0.0;
      lo[2 * k + 1] = -c, hi[2 * k + 1] = c;
    }
    bool box_converged = false;
    products += box_qp(apply_a, face_newton, b, lo, hi, weight, tol_v, step_length,
                       kConeProducts - products, y, box_converged);
    // How far the box would move: mu |dr_n| as a tangential velocity of the point.
    double shift = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      const double rn = s[2 * k] * y[2 * k];
      shift = std::max(shift, mu * std::abs(rn - rn_[k]) * wtt_[k]);
      rn_[k] = rn, rt_[k] = s[2 * k + 1] * y[2 * k + 1];
    }
    if (!box_converged || shift <= tol_v) break;
  }
  return products;
}

namespace {
// The face's matrix: the upper triangle of A over all the cone solve's unknowns, column by
// column, indexed by Eigen::Index: the form the factorisation works on in the natural order
// without copying it.
using FaceMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, Eigen::Index>;

// What the cone solve keeps on a thread between its calls: the structure of A (which unknowns
// share a body), found again only when the points' bodies change, with the symbolic analysis
// of its factorisation; A's values, assembled once per cone solve; scratch arrays. The numbers
// do not depend on what is kept: the same matrix factors to the same values whether its
// structure and analysis are new or kept. Factors kept from step to step (taken while A moved
// by less than 1e-9 on the face) saved no time on church_b under a record. The face's Newton
// step in the bodies' space (Woodbury's identity, K = eps M + H_F^T H_F, 3 unknowns a body)
// cost 8 to 19% less there, but K is ill-conditioned along a long chain: the 90-voussoir
// arch's supports then carried its weight only to 7e-5 (test Nscd.AChainOfNinetyVoussoirs...).
// Factors of one face of the cone solve's A, kept for a face met again.
struct FaceFactors {
  std::vector<char> face;  // the face (empty: none)
  Eigen::SimplicialLDLT<FaceMatrix, Eigen::Upper, Eigen::NaturalOrdering<Eigen::Index>> ldlt;
  long long analysed_for = -1;  // the structure (FaceScratch::structure) ldlt's analysis is of
  long long used = 0;           // when last used (FaceScratch::clock)
};

struct FaceScratch {
  std::vector<long long> key;   // per point: its two bodies (0: fixed), the structure's key
  std::vector<int> body_start;  // per body: its entries (below), grouped by body
  std::vector<Eigen::Index> entry_unknown;       // an entry: an unknown acting on the body...
  std::vector<std::array<double, 3>> entry_row;  // ...and its row of S H on the body
  std::vector<Eigen::Index> pair_position;       // per pair of a body's entries: where it adds in A
  FaceMatrix a;                                  // the face's matrix (A masked to the face)
  std::vector<double> values;                    // A's values, a's positions
  Eigen::VectorXd rhs, x;
  long long structure = 0;       // the structures found (0: none yet), for factors to know theirs
  long long factorisations = 0;  // on this thread, for the solver's record
  // The factors of the last faces met in this cone solve. A face met again reuses its
  // factors: a later pass of Tresca's box keeps the face more often than not, and the
  // active-set steps of a box that does not settle alternate between a few faces. A new face
  // replaces the one used longest ago. A face's factors are the same numbers whether kept or
  // found again, so the results do not depend on kKeptFaces. On church_b under a record
  // (bench/bench_nscd.cpp, the heavier second) 16 faces instead of 1 take 43.3 factorisations
  // a step instead of 48.2 and 8.5% fewer instructions in the solver; 8 faces 44.6 and 5.9%;
  // 32 faces 43.0.
  std::array<FaceFactors, kKeptFaces> kept;
  FaceFactors* current = nullptr;  // the factors face_step solves with
  long long clock = 0;
  std::vector<char> face;  // face_step's face, kept to spare an allocation a step
};
thread_local FaceScratch t_face;

long long thread_factorisations() {
  return t_face.factorisations;
}

// The entries of the bodies (unknowns in order, grouped by body; fixed bodies have none).
template <class Entry>
void for_each_entry(const std::vector<ContactPoint>& points, const std::vector<double>& inv,
                    const Entry& entry) {
  for (std::size_t k = 0; k < points.size(); ++k)
    for (std::size_t t = 0; t < 2; ++t)
      for (const bool on_b : {false, true}) {
        const std::size_t body = std::size_t(on_b ? points[k].b : points[k].a);
        if (inv[3 * body] != 0.0) entry(k, t, on_b, body);
      }
}
}  // namespace

void NscdContact::assemble_cone_matrix(const std::vector<double>& inv,
                                       const std::vector<double>& s) const {
  FaceScratch& w = t_face;
  const std::size_t n = points_.size(), m = 2 * n, nb = inv.size() / 3;
  std::vector<long long> key(n);
  for (std::size_t k = 0; k < n; ++k) {
    const ContactPoint& c = points_[k];
    const long long a = inv[3 * std::size_t(c.a)] == 0.0 ? -1 : c.a;
    const long long b = inv[3 * std::size_t(c.b)] == 0.0 ? -1 : c.b;
    key[k] = ((a + 1) << 32) | (b + 1);
  }
  const bool same = w.structure > 0 && key == w.key && w.body_start.size() == nb + 1;
  if (!same) {
    w.key.swap(key);
    ++w.structure;
    w.body_start.assign(nb + 1, 0);
    for_each_entry(points_, inv, [&](std::size_t, std::size_t, bool, std::size_t body) {
      ++w.body_start[body + 1];
    });
    for (std::size_t b = 0; b < nb; ++b) w.body_start[b + 1] += w.body_start[b];
    w.entry_unknown.resize(std::size_t(w.body_start[nb]));
    w.entry_row.resize(w.entry_unknown.size());
    std::vector<int> fill(w.body_start.begin(), w.body_start.end() - 1);
    for_each_entry(points_, inv, [&](std::size_t k, std::size_t t, bool, std::size_t body) {
      w.entry_unknown[std::size_t(fill[body]++)] = Eigen::Index(2 * k + t);
    });
    // A's structure: the diagonal, and (i, j), i < j, for two unknowns on one body.
    std::vector<Eigen::Triplet<double, Eigen::Index>> entries;
    for (Eigen::Index i = 0; i < Eigen::Index(m); ++i) entries.emplace_back(i, i, 0.0);
    for (std::size_t b = 0; b < nb; ++b)
      for (int e = w.body_start[b]; e < w.body_start[b + 1]; ++e)
        for (int o = w.body_start[b]; o < w.body_start[b + 1]; ++o) {
          const Eigen::Index i = w.entry_unknown[std::size_t(e)];
          const Eigen::Index j = w.entry_unknown[std::size_t(o)];
          if (j < i) entries.emplace_back(j, i, 0.0);
        }
    w.a.resize(Eigen::Index(m), Eigen::Index(m));
    w.a.setFromTriplets(entries.begin(), entries.end());
    w.a.makeCompressed();
    w.pair_position.clear();
    for (std::size_t b = 0; b < nb; ++b)
      for (int e = w.body_start[b]; e < w.body_start[b + 1]; ++e)
        for (int o = w.body_start[b]; o < w.body_start[b + 1]; ++o) {
          const Eigen::Index i = w.entry_unknown[std::size_t(e)];
          const Eigen::Index j = w.entry_unknown[std::size_t(o)];
          if (i < j) continue;
          const Eigen::Index* rows = w.a.innerIndexPtr();
          const Eigen::Index* first = rows + w.a.outerIndexPtr()[i];
          const Eigen::Index* last = rows + w.a.outerIndexPtr()[i + 1];
          w.pair_position.push_back(Eigen::Index(std::lower_bound(first, last, j) - rows));
        }
  }
  // The rows of S H on each movable body (3 entries a body), in the structure's order.
  std::vector<int> fill(w.body_start.begin(), w.body_start.end() - 1);
  for_each_entry(points_, inv, [&](std::size_t k, std::size_t t, bool on_b, std::size_t body) {
    const ContactPoint& c = points_[k];
    const std::size_t i = 2 * k + t;
    const Vec2 dir = t ? Vec2{-c.n.y, c.n.x} : c.n;
    const double rx = on_b ? rb_x_[k] : ra_x_[k], ry = on_b ? rb_y_[k] : ra_y_[k];
    const double sign = (on_b ? 1.0 : -1.0) * s[i];
    w.entry_row[std::size_t(fill[body]++)] = {sign * dir.x, sign * dir.y,
                                              sign * (rx * dir.y - ry * dir.x)};
  });
  for (FaceFactors& f : w.kept) f.face.clear();
  w.current = nullptr;
  // A = sum over the bodies of row_i M^-1 row_j.
  w.values.assign(std::size_t(w.a.nonZeros()), 0.0);
  std::size_t pair = 0;
  for (std::size_t body = 0; body < nb; ++body) {
    const double* ib = &inv[3 * body];
    for (int e = w.body_start[body]; e < w.body_start[body + 1]; ++e)
      for (int o = w.body_start[body]; o < w.body_start[body + 1]; ++o) {
        if (w.entry_unknown[std::size_t(e)] < w.entry_unknown[std::size_t(o)]) continue;
        const auto& ri = w.entry_row[std::size_t(e)];
        const auto& rj = w.entry_row[std::size_t(o)];
        w.values[std::size_t(w.pair_position[pair++])] +=
            ri[0] * ib[0] * rj[0] + ri[1] * ib[1] * rj[1] + ri[2] * ib[2] * rj[2];
      }
  }
}

namespace {
// Factors A_FF for the face `face` into `into`; false when the face is empty or does not
// factor.
bool factor_face(const std::vector<char>& face, FaceFactors& into) {
  FaceScratch& w = t_face;
  const Eigen::Index m = Eigen::Index(face.size());
  auto on_face = [&](Eigen::Index i) { return face[std::size_t(i)] != 0; };
  into.face.clear();
  // A_FF with the regularisation on the free face; an identity row and column elsewhere (they
  // change nothing of the face's factors).
  bool any = false;
  const Eigen::Index* outer = w.a.outerIndexPtr();
  const Eigen::Index* rows = w.a.innerIndexPtr();
  double* values = w.a.valuePtr();
  for (Eigen::Index j = 0; j < m; ++j) {
    const bool fj = on_face(j);
    any = any || fj;
    for (Eigen::Index p = outer[j]; p < outer[j + 1]; ++p) {
      const Eigen::Index i = rows[p];
      const double v = fj && on_face(i) ? w.values[std::size_t(p)] : 0.0;
      values[p] = i != j ? v : fj ? v + kFaceRegularisation : 1.0;
    }
  }
  if (!any) return false;
  // The points come in the order of the detection, which follows the blocks along the
  // structure: the natural order keeps the fill small (an approximate minimum degree ordering
  // cost more than it saved).
  if (into.analysed_for != w.structure) {
    into.ldlt.analyzePattern(w.a);
    into.analysed_for = w.structure;
  }
  into.ldlt.factorize(w.a);
  ++w.factorisations;
  if (into.ldlt.info() != Eigen::Success) return false;
  into.face = face;
  return true;
}
}  // namespace

bool NscdContact::face_step(const std::vector<double>& s, const std::vector<char>& free,
                            const std::vector<double>& g, std::vector<double>& d) const {
  FaceScratch& w = t_face;
  const Eigen::Index m = Eigen::Index(2 * points_.size());
  std::fill(d.begin(), d.end(), 0.0);
  std::vector<char>& face = w.face;
  face.resize(static_cast<std::size_t>(m));
  for (std::size_t i = 0; i < face.size(); ++i) face[i] = char(free[i] && s[i] > 0.0);
  auto on_face = [&](Eigen::Index i) { return face[std::size_t(i)] != 0; };
  if (w.current == nullptr || w.current->face != face) {
    // The kept factors of this face, else the entry used longest ago.
    FaceFactors* found = nullptr;
    FaceFactors* oldest = &w.kept[0];
    for (FaceFactors& f : w.kept) {
      if (f.face == face) found = &f;
      if (f.used < oldest->used) oldest = &f;
    }
    w.current = nullptr;
    if (found == nullptr) {
      if (!factor_face(face, *oldest)) return false;
      found = oldest;
    }
    w.current = found;
  }
  w.current->used = ++w.clock;
  w.rhs.resize(m);
  for (Eigen::Index i = 0; i < m; ++i) w.rhs[i] = on_face(i) ? -g[std::size_t(i)] : 0.0;
  w.x = w.current->ldlt.solve(w.rhs);
  for (Eigen::Index i = 0; i < m; ++i)
    if (on_face(i)) d[std::size_t(i)] = w.x[i];
  return true;
}

std::vector<BlockPairForce> NscdContact::pair_forces(const Model& model, double h) const {
  std::vector<BlockPairForce> out;
  const RigidBodies& r = model.rigid;
  for (std::size_t k = 0; k < points_.size(); ++k) {
    if (rn_[k] == 0.0 && rt_[k] == 0.0) continue;
    const ContactPoint& c = points_[k];
    if (out.empty() || out.back().block_a != c.a || out.back().block_b != c.b) {
      BlockPairForce f;
      f.block_a = c.a, f.block_b = c.b;
      f.origin = {c.x.x - rb_x_[k], c.x.y - rb_y_[k]};  // b's centroid at the step's start
      (void)r;
      out.push_back(f);
    }
    BlockPairForce& f = out.back();
    const double fx = (rn_[k] * c.n.x - rt_[k] * c.n.y) / h;
    const double fy = (rn_[k] * c.n.y + rt_[k] * c.n.x) / h;
    f.force.x += fx, f.force.y += fy;
    f.moment += rb_x_[k] * fy - rb_y_[k] * fx;
  }
  return out;
}

namespace {
constexpr std::uint64_t kNscdTag = 0x564f5553534e5344ull;  // "VOUSSNSD"
}  // namespace

std::vector<char> NscdContact::save_state() const {
  std::vector<char> out;
  put(out, kNscdTag);
  std::vector<std::uint64_t> keys(points_.size());
  for (std::size_t k = 0; k < points_.size(); ++k) keys[k] = points_[k].key;
  put_array(out, keys);
  put_array(out, rn_);
  put_array(out, rt_);
  return out;
}

void NscdContact::restore_state(const std::vector<char>& bytes) {
  StateReader in{bytes};
  if (in.get<std::uint64_t>() != kNscdTag) in.fail("not a non-smooth contact state");
  std::vector<std::uint64_t> keys = in.get_array<std::uint64_t>();
  std::vector<double> rn = in.get_array<double>(), rt = in.get_array<double>();
  if (rn.size() != keys.size() || rt.size() != keys.size())
    in.fail("key and impulse counts differ");
  // The next build matches its points to these by key, as after the step that saved them.
  points_.assign(keys.size(), ContactPoint{});
  for (std::size_t k = 0; k < keys.size(); ++k) points_[k].key = keys[k];
  rn_ = std::move(rn), rt_ = std::move(rt);
}

}  // namespace voussoir

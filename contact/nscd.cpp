// Non-smooth contact dynamics of rigid blocks: contact points, the local law, non-linear
// Gauss-Seidel (the math and the contract are in contact/nscd.hpp).

#include "contact/nscd.hpp"

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "contact/state_bytes.hpp"

namespace voussoir {

namespace {
// The direct solve (nscd.hpp "Direct solve"): after this many sweeps without convergence; at
// most this many passes of status corrections; the compliance that keeps redundant contacts
// definite, as a fraction of each unknown's own Delassus term; a direct solve is taken when it
// changes no body's velocity by more than kDirectReach times the tolerance's velocity scale.
// (church_b's capacity: a compliance of 1e-6 let its trials creep past the time limit, a
// reach of 2 let solves through that made a stable trial creep to a timeout.)
constexpr int kSweepsBeforeDirect = 20;
constexpr int kDirectPasses = 8;
constexpr double kDirectCompliance = 1e-10;
constexpr double kDirectReach = 0.5;
// Unknowns up to which the direct solve's system is dense (an arch's 50; a church's 1000 are
// sparse).
constexpr int kDenseDirect = 200;
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

void NscdStats::add(const NscdStepResult& r) {
  ++steps;
  iterations += r.iterations;
  if (!r.converged) ++unconverged_steps;
  max_iterations = std::max(max_iterations, r.iterations);
  max_residual = std::max(max_residual, r.residual);
  max_penetration = std::max(max_penetration, r.penetration);
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
    // Slow sweeps: the impulses settle along the chains of blocks one block a sweep. The
    // direct solve puts them in place at once (solve_direct); the sweeps go on from there.
    if (out.iterations == kSweepsBeforeDirect) {
      const std::vector<double> rn = rn_, rt = rt_, v_sweeps = v;
      solve_direct(model, v_free, inv, u_min, mu, v);
      ++out.direct_solves;
      // A solve that moves a body by more than a step's worth of the loads is off (statuses
      // that cycle, redundant contacts asked for different velocities): the sweeps go on
      // from where they were instead.
      double moved = 0.0;
      for (std::size_t b = 0; b < nb; ++b)
        moved = std::max(
            moved, std::hypot(v[3 * b] - v_sweeps[3 * b], v[3 * b + 1] - v_sweeps[3 * b + 1]) +
                       radius_[b] * std::abs(v[3 * b + 2] - v_sweeps[3 * b + 2]));
      if (!(moved <= kDirectReach * v_scale)) {
        rn_ = rn, rt_ = rt, v = v_sweeps;
        --out.direct_solves;
      }
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

void NscdContact::solve_direct(const Model& model, const std::vector<double>& v_free,
                               const std::vector<double>& inv, const std::vector<double>& u_min,
                               double mu, std::vector<double>& v) {
  const std::size_t n = points_.size();
  const std::size_t nb = model.blocks.size();
  // Status of each point: 0 open, 1 sticking, 2 sliding (r_t = slide_sign mu r_n).
  std::vector<std::uint8_t> status(n, 0);
  std::vector<double> sign(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    if (!(rn_[k] > 0.0)) continue;
    const bool slides = mu > 0.0 && std::abs(rt_[k]) >= mu * rn_[k] * (1.0 - 1e-9);
    status[k] = slides ? 2 : 1;
    sign[k] = rt_[k] >= 0.0 ? 1.0 : -1.0;
  }
  // The rows of a point on a body: the body's velocity's effect on U_n (or U_t) of the point.
  auto row = [&](std::size_t k, bool tangential, bool on_b, double out[3]) {
    const ContactPoint& c = points_[k];
    const Vec2 d = tangential ? Vec2{-c.n.y, c.n.x} : c.n;
    const double rx = on_b ? rb_x_[k] : ra_x_[k], ry = on_b ? rb_y_[k] : ra_y_[k];
    const double s = on_b ? 1.0 : -1.0;
    out[0] = s * d.x, out[1] = s * d.y, out[2] = s * (rx * d.y - ry * d.x);
  };
  std::vector<double> rn(n), rt(n);
  for (int pass = 0; pass < kDirectPasses; ++pass) {
    // Unknowns: r_n of every closed point, r_t of every sticking one; a sliding point's r_t is
    // its sign times mu times its r_n (a column that is not symmetric: taken from the pass
    // before, as a given impulse).
    std::vector<int> col_n(n, -1), col_t(n, -1);
    int m = 0;
    for (std::size_t k = 0; k < n; ++k) {
      if (status[k] == 0) continue;
      col_n[k] = m++;
      if (status[k] == 1) col_t[k] = m++;
    }
    // The base velocity: free velocities plus the sliding points' friction impulses.
    std::vector<double> base = v_free;
    auto push = [&](std::vector<double>& vel, std::size_t k, double pn, double pt) {
      const ContactPoint& c = points_[k];
      double j[3];
      for (const bool on_b : {false, true}) {
        const std::size_t b = std::size_t(on_b ? c.b : c.a);
        for (const bool tangential : {false, true}) {
          const double p = tangential ? pt : pn;
          if (p == 0.0) continue;
          row(k, tangential, on_b, j);
          for (int i = 0; i < 3; ++i) vel[3 * b + i] += inv[3 * b + i] * j[i] * p;
        }
      }
    };
    for (std::size_t k = 0; k < n; ++k)
      if (status[k] == 2) push(base, k, 0.0, sign[k] * mu * std::max(rn_[k], 0.0));
    if (m == 0) break;
    // A = J M^-1 J^T over the unknowns, by body; b = target - J base.
    std::vector<std::vector<std::pair<int, std::array<double, 3>>>> by_body(nb);
    for (std::size_t k = 0; k < n; ++k) {
      if (status[k] == 0) continue;
      const ContactPoint& c = points_[k];
      for (const bool on_b : {false, true}) {
        const std::size_t b = std::size_t(on_b ? c.b : c.a);
        if (inv[3 * b] == 0.0) continue;
        std::array<double, 3> j;
        row(k, false, on_b, j.data());
        by_body[b].push_back({col_n[k], j});
        if (col_t[k] >= 0) {
          row(k, true, on_b, j.data());
          by_body[b].push_back({col_t[k], j});
        }
      }
    }
    // A small compliance keeps A definite where the contacts are redundant (two points on each
    // joint of a chain of blocks): the impulses of least size among those that give the
    // velocities, to kDirectCompliance of the velocities. Small systems (an arch) are solved
    // dense, large ones (a church) sparse.
    const bool dense = m <= kDenseDirect;
    Eigen::MatrixXd a_dense;
    std::vector<Eigen::Triplet<double>> triplets;
    if (dense) a_dense.setZero(m, m);
    for (std::size_t b = 0; b < nb; ++b)
      for (const auto& [i, ji] : by_body[b])
        for (const auto& [j, jj] : by_body[b]) {
          const double a = ji[0] * inv[3 * b] * jj[0] + ji[1] * inv[3 * b + 1] * jj[1] +
                           ji[2] * inv[3 * b + 2] * jj[2];
          if (dense)
            a_dense(i, j) += a;
          else
            triplets.emplace_back(i, j, a);
        }
    Eigen::SparseMatrix<double> a_sparse;
    if (dense) {
      for (int i = 0; i < m; ++i) a_dense(i, i) *= 1.0 + kDirectCompliance;
    } else {
      a_sparse.resize(m, m);
      a_sparse.setFromTriplets(triplets.begin(), triplets.end());
      for (int i = 0; i < m; ++i) a_sparse.coeffRef(i, i) *= 1.0 + kDirectCompliance;
    }
    Eigen::VectorXd rhs(m);
    for (std::size_t k = 0; k < n; ++k) {
      if (status[k] == 0) continue;
      double un, ut;
      local_velocity(points_[k], base.data(), ra_x_[k], ra_y_[k], rb_x_[k], rb_y_[k], un, ut);
      rhs[col_n[k]] = u_min[k] - un;
      if (col_t[k] >= 0) rhs[col_t[k]] = -ut;
    }
    Eigen::VectorXd x;
    if (dense) {
      const Eigen::LDLT<Eigen::MatrixXd> ldlt(a_dense);
      if (ldlt.info() != Eigen::Success) return;  // the sweeps go on from where they were
      x = ldlt.solve(rhs);
    } else {
      const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(a_sparse);
      if (ldlt.info() != Eigen::Success) return;
      x = ldlt.solve(rhs);
    }
    for (std::size_t k = 0; k < n; ++k) {
      rn[k] = status[k] == 0 ? 0.0 : x[col_n[k]];
      rt[k] = status[k] == 1 ? x[col_t[k]] : (status[k] == 2 ? sign[k] * mu * rn_[k] : 0.0);
    }
    // The velocities of this solution, then each point's status against its law.
    std::vector<double> vel = base;
    for (std::size_t k = 0; k < n; ++k)
      if (status[k] != 0) push(vel, k, rn[k], status[k] == 1 ? rt[k] : 0.0);
    bool changed = false;
    for (std::size_t k = 0; k < n; ++k) {
      double un, ut;
      local_velocity(points_[k], vel.data(), ra_x_[k], ra_y_[k], rb_x_[k], rb_y_[k], un, ut);
      std::uint8_t next = status[k];
      if (status[k] == 0) {
        if (un < u_min[k]) next = 1;
      } else if (!(rn[k] > 0.0)) {
        next = 0;
      } else if (status[k] == 1 && mu > 0.0 && std::abs(rt[k]) > mu * rn[k]) {
        next = 2, sign[k] = rt[k] >= 0.0 ? 1.0 : -1.0;
      } else if (status[k] == 2 && sign[k] * ut > 0.0) {
        next = 1;
      }
      if (mu == 0.0 && next == 1) next = 2, sign[k] = 1.0;  // no friction: r_t = 0
      changed = changed || next != status[k];
      status[k] = next;
    }
    // Keep the solution, projected on the laws (r_n >= 0, |r_t| <= mu r_n).
    for (std::size_t k = 0; k < n; ++k) {
      rn_[k] = std::max(rn[k], 0.0);
      rt_[k] = std::clamp(rt[k], -mu * rn_[k], mu * rn_[k]);
    }
    if (!changed) break;
  }
  // The bodies' velocities from the impulses as they now stand.
  v = v_free;
  for (std::size_t k = 0; k < n; ++k)
    if (rn_[k] != 0.0 || rt_[k] != 0.0) apply_impulse(k, rn_[k], rt_[k], inv, v);
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

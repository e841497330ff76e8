// Contact of rigid blocks between outlines (the law and its integrals in rigid_contact.hpp).

#include "contact/rigid_contact.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "contact/contact.hpp"
#include "contact/friction.hpp"
#include "contact/joint_stiffness.hpp"
#include "contact/quad_overlap.hpp"
#include "contact/state_bytes.hpp"

namespace voussoir {

namespace {

// Largest vertex count of a clipped polygon: P's vertices plus two per line of Q, plus one slot
// for the copy of the first vertex after the last (the loops over edges read vertex k + 1).
constexpr int kMaxClipped = 3 * kMaxPieceVertices + 4;
static_assert(kMaxClipped <= 64, "a polygon's edge labels fit one 64-bit mask");

// A polygon of the clipping, in coordinates relative to P's first vertex [m], with the labels of
// rigid_contact.hpp: bit k of `on` is 1 when vertex k's outgoing edge lies on a line of Q, 0 on
// P's boundary. No initialiser: written before read.
struct Clipped {
  double x[kMaxClipped], y[kMaxClipped];
  std::uint64_t on;
  int n;
};

// Clips the convex polygon `in` by the inner side of a line of Q (d: each vertex's signed
// distance to it times the side's length, >= 0 inside) into `out` (Sutherland and Hodgman with
// the edge labels of rigid_contact.hpp). Rejected: a form without branches (every vertex
// writes its crossing and itself to the next slot, the count advanced by what it keeps); it
// halved the mispredicted jumps that valgrind's model counts on church B but ran its steps 14%
// slower (13% more instructions).
inline void clip_by_line(const Clipped& in, const double* d, Clipped& out) {
  int m = 0;
  std::uint64_t on = 0;
  int prev = in.n - 1;
  bool prev_in = d[prev] >= 0.0;
  for (int k = 0; k < in.n; ++k) {
    const bool cur_in = d[k] >= 0.0;
    if (cur_in != prev_in) {
      const double t = d[prev] / (d[prev] - d[k]);
      out.x[m] = in.x[prev] + t * (in.x[k] - in.x[prev]);
      out.y[m] = in.y[prev] + t * (in.y[k] - in.y[prev]);
      // Entering: the edge from here runs on along P's (or the earlier line's) edge; leaving:
      // along this line of Q.
      on |= (cur_in ? (in.on >> prev) & 1 : std::uint64_t(1)) << m++;
    }
    if (cur_in) {
      out.x[m] = in.x[k];
      out.y[m] = in.y[k];
      on |= ((in.on >> k) & 1) << m++;
    }
    prev = k;
    prev_in = cur_in;
  }
  out.on = on;
  out.n = m;
}

// integral of d(s)^2 ds of the convex polygon (s, h) (n vertices, counter-clockwise in the
// right-handed frame (s, h)): from the leftmost vertex the lower chain runs forward and the
// upper chain backward to the rightmost one, both with growing s; between consecutive
// abscissae of either chain d = upper - lower is linear (rigid_contact.hpp).
double width_squared_integral(const double* s, const double* h, int n) {
  int i0 = 0, i1 = 0;
  for (int k = 1; k < n; ++k) {
    if (s[k] < s[i0] || (s[k] == s[i0] && h[k] < h[i0])) i0 = k;
    if (s[k] > s[i1] || (s[k] == s[i1] && h[k] > h[i1])) i1 = k;
  }
  if (i0 == i1) return 0.0;
  auto next = [n](int k) { return k + 1 < n ? k + 1 : 0; };
  auto prev = [n](int k) { return k > 0 ? k - 1 : n - 1; };
  // Current segments: lower (la -> lb), upper (ua -> ub), each with s[b] > s[a].
  int la = i0, lb = next(i0), ua = i0, ub = prev(i0);
  while (la != i1 && !(s[lb] > s[la])) la = lb, lb = next(lb);
  while (ua != i1 && !(s[ub] > s[ua])) ua = ub, ub = prev(ub);
  double at = s[i0], integral = 0.0;
  while (la != i1 && ua != i1) {
    const double end = std::min(s[lb], s[ub]);
    const double gl = (h[lb] - h[la]) / (s[lb] - s[la]), gu = (h[ub] - h[ua]) / (s[ub] - s[ua]);
    const double w0 = (h[ua] + gu * (at - s[ua])) - (h[la] + gl * (at - s[la]));
    const double w1 = (h[ua] + gu * (end - s[ua])) - (h[la] + gl * (end - s[la]));
    integral += (end - at) * (w0 * w0 + w0 * w1 + w1 * w1);
    at = end;
    while (la != i1 && !(s[lb] > at)) la = lb, lb = next(lb);
    while (ua != i1 && !(s[ub] > at)) ua = ub, ub = prev(ub);
  }
  return integral / 3.0;
}

// sin and cos of theta / 2. Blocks at rest or near it turn by 1e-9 to 1e-3 rad: below 0.02 rad
// the Taylor series to x^9 (x = theta / 2; the next term is below 1e-17 relative) replaces the
// library's calls, a tenth of a joint's cost each.
// The coefficients are constants of the program (the build's -frounding-math, which CGAL asks
// for, would otherwise divide them out at every call).
inline void half_angle(double theta, double& s, double& c) {
  constexpr double kS3 = -1.0 / 6, kS5 = 1.0 / 120, kS7 = -1.0 / 5040, kS9 = 1.0 / 362880;
  constexpr double kC4 = 1.0 / 24, kC6 = -1.0 / 720, kC8 = 1.0 / 40320, kC10 = 1.0 / 3628800;
  const double x = 0.5 * theta;
  if (std::abs(x) < 0.01) {
    const double x2 = x * x;
    s = x * (1.0 + x2 * (kS3 + x2 * (kS5 + x2 * (kS7 + x2 * kS9))));
    c = 1.0 + x2 * (-0.5 + x2 * (kC4 + x2 * (kC6 + x2 * (kC8 - x2 * kC10))));
  } else {
    s = std::sin(x);
    c = std::cos(x);
  }
}

// Does block b have a pose of its own: a free body, or a support whose movement [supports]
// prescribes (core/supports.hpp)? Fixed blocks that stay put keep their reference outline.
inline bool has_pose(const Model& model, std::size_t b) {
  const Block& blk = model.blocks[b];
  return (!blk.fixed || blk.prescribed) && model.rigid.mass[b] > 0.0;
}

// Is the counter-clockwise polygon convex (collinear vertices allowed)?
bool is_convex(const std::vector<Vec2>& v) {
  const std::size_t n = v.size();
  if (n < 3) return false;
  double scale = 0.0;
  for (std::size_t k = 0; k < n; ++k) scale = std::max(scale, distance(v[k], v[(k + 1) % n]));
  const double tol = -1e-12 * scale * scale;
  for (std::size_t k = 0; k < n; ++k) {
    const Vec2 e0 = v[(k + 1) % n] - v[k], e1 = v[(k + 2) % n] - v[(k + 1) % n];
    if (cross(e0, e1) < tol) return false;
  }
  return true;
}

// Convex pieces of block b as lists of node ids: its triangles merged across shared edges while
// the union stays convex and within kMaxPieceVertices.
std::vector<std::vector<Index>> merged_triangles(const Model& model, Index b) {
  const Triangles& t = model.tris;
  const Nodes& n = model.nodes;
  const Block& blk = model.blocks[std::size_t(b)];
  std::vector<std::vector<Index>> pieces;
  for (Index e = blk.first_tri; e < blk.first_tri + blk.tri_count; ++e)
    pieces.push_back({t.n0[e], t.n1[e], t.n2[e]});
  auto points = [&](const std::vector<Index>& ids) {
    std::vector<Vec2> v;
    for (Index i : ids) v.push_back({n.x0[i], n.y0[i]});
    return v;
  };
  for (bool merged = true; merged;) {
    merged = false;
    for (std::size_t i = 0; i < pieces.size() && !merged; ++i)
      for (std::size_t j = i + 1; j < pieces.size() && !merged; ++j) {
        const std::vector<Index>& pi = pieces[i];
        const std::vector<Index>& pj = pieces[j];
        for (std::size_t ki = 0; ki < pi.size() && !merged; ++ki) {
          const Index u = pi[ki], v = pi[(ki + 1) % pi.size()];
          for (std::size_t kj = 0; kj < pj.size(); ++kj) {
            if (pj[kj] != v || pj[(kj + 1) % pj.size()] != u) continue;
            // i from v round to u, then j's vertices strictly between u and v.
            std::vector<Index> joined;
            for (std::size_t s = 0; s < pi.size(); ++s)
              joined.push_back(pi[(ki + 1 + s) % pi.size()]);
            for (std::size_t s = 2; s < pj.size(); ++s) joined.push_back(pj[(kj + s) % pj.size()]);
            if (int(joined.size()) <= kMaxPieceVertices && is_convex(points(joined))) {
              pieces[i] = joined;
              pieces.erase(pieces.begin() + std::ptrdiff_t(j));
              merged = true;
            }
            break;
          }
        }
      }
  }
  return pieces;
}

}  // namespace

namespace {

// The clipping stage of convex_overlap: O = P n Q in coordinates relative to P's first vertex
// (plus its displacement), into one of `buf`; returns it, or null when O has fewer than three
// vertices. kDisp: the vertices carry displacements pu, qu. Lines of Q with a bit in `inner`
// are skipped (P wholly on their inner side).
template <bool kDisp>
[[gnu::always_inline]] inline Clipped* clip_overlap(const Vec2* p, const Vec2* pu, int np,
                                                    const Vec2* q, const Vec2* qu, int nq,
                                                    std::uint32_t inner, Clipped (&buf)[2]) {
  double qx[kMaxPieceVertices + 1], qy[kMaxPieceVertices + 1];
  double d[kMaxClipped];
  // Coordinates relative to P's first vertex, reference and displacement parts apart: a joint's
  // two faces share their reference vertices, so a penetration of 1e-12 m is resolved to
  // round-off of itself, not of the coordinates (rigid_contact.hpp, "Exactness").
  const double ox = p[0].x, oy = p[0].y;
  const double oux = kDisp ? pu[0].x : 0.0, ouy = kDisp ? pu[0].y : 0.0;
  Clipped* v = &buf[0];
  for (int k = 0; k < np; ++k) {
    v->x[k] = (p[k].x - ox) + (kDisp ? pu[k].x - oux : 0.0);
    v->y[k] = (p[k].y - oy) + (kDisp ? pu[k].y - ouy : 0.0);
  }
  v->on = 0;  // every edge on P
  v->n = np;
  for (int j = 0; j < nq; ++j) {
    qx[j] = (q[j].x - ox) + (kDisp ? qu[j].x - oux : 0.0);
    qy[j] = (q[j].y - oy) + (kDisp ? qu[j].y - ouy : 0.0);
  }
  qx[nq] = qx[0], qy[nq] = qy[0];
  for (int j = 0; j < nq; ++j) {
    const double ax = qx[j], ay = qy[j];
    const double ex = qx[j + 1] - ax, ey = qy[j + 1] - ay;
    const int n = v->n;
    if ((inner >> j) & 1) {
      for (int k = 0; k < n; ++k) assert(ex * (v->y[k] - ay) - ey * (v->x[k] - ax) >= 0.0);
      continue;
    }
    long inside = 0, outside = 0;  // counts of d >= 0 and of d < 0
    for (int k = 0; k < n; ++k) {
      // Differences first: a vertex near the line gets its distance to its own round-off.
      d[k] = ex * (v->y[k] - ay) - ey * (v->x[k] - ax);
      inside += d[k] >= 0.0;
      outside += d[k] < 0.0;
    }
    if (inside == 0) return nullptr;  // P wholly outside this side of Q
    if (outside == 0) continue;       // wholly inside: nothing to cut
    Clipped* next = v == &buf[0] ? &buf[1] : &buf[0];
    clip_by_line(*v, d, *next);
    v = next;
    if (v->n < 3) return nullptr;
  }
  return v;
}

// convex_overlap, inlined into the contact stage's pair loop.
[[gnu::always_inline]] inline bool overlap_of(const Vec2* p, const Vec2* pu, int np, const Vec2* q,
                                              const Vec2* qu, int nq, ConvexOverlap& out,
                                              bool with_energy, std::uint32_t inner) {
  Clipped buf[2];
  Clipped* o = pu && qu ? clip_overlap<true>(p, pu, np, q, qu, nq, inner, buf)
                        : clip_overlap<false>(p, pu, np, q, qu, nq, inner, buf);
  if (!o) return false;
  const int n = o->n;
  const double ox = p[0].x + (pu && qu ? pu[0].x : 0.0);
  const double oy = p[0].y + (pu && qu ? pu[0].y : 0.0);
  // O's vertices, the first one copied after the last.
  double* vx = o->x;
  double* vy = o->y;
  vx[n] = vx[0], vy[n] = vy[0];
  const std::uint64_t lab = o->on;
  // Area and first moment about O's first vertex (Green's theorem: a sliver's terms are then
  // each of its own size), and P's outward normals times lengths.
  const double vx0 = vx[0], vy0 = vy[0];
  // n = (N_P - N_Q) / 2: P's edges count +1/2, Q's -1/2.
  double a2 = 0.0, mx = 0.0, my = 0.0, nx = 0.0, ny = 0.0;
  for (int k = 0; k < n; ++k) {
    const double x0 = vx[k] - vx0, y0 = vy[k] - vy0, x1 = vx[k + 1] - vx0, y1 = vy[k + 1] - vy0;
    const double c = x0 * y1 - y0 * x1;
    a2 += c;
    mx += (x0 + x1) * c;
    my += (y0 + y1) * c;
    const double w = (lab >> k) & 1 ? -0.5 : 0.5;
    nx += w * (y1 - y0);
    ny -= w * (x1 - x0);
  }
  if (!(a2 > 0.0)) return false;
  const double chord = std::sqrt(nx * nx + ny * ny);
  if (!(chord > 0.0)) return false;
  out.area = 0.5 * a2;
  const double third = 1.0 / (3.0 * a2), inv_chord = 1.0 / chord;
  out.centroid = {ox + vx0 + mx * third, oy + vy0 + my * third};
  out.normal = {nx * inv_chord, ny * inv_chord};
  out.chord = chord;
  // The points where the outlines cross: where a vertex's edges change from one outline to the
  // other (its label differs from the previous vertex's).
  const std::uint64_t all = n < 64 ? (std::uint64_t(1) << n) - 1 : ~std::uint64_t(0);
  const std::uint64_t crossing = (lab ^ ((lab << 1) | (lab >> (n - 1)))) & all;
  out.chord_mid = out.centroid;
  if (std::popcount(crossing) == 2) {
    const int k0 = std::countr_zero(crossing), k1 = 63 - std::countl_zero(crossing);
    double mx0 = 0.0, my0 = 0.0;
    mx0 += vx[k0], my0 += vy[k0];
    mx0 += vx[k1], my0 += vy[k1];
    out.chord_mid = {ox + 0.5 * mx0, oy + 0.5 * my0};
  }
  out.depth_sq = 0.0;
  if (!with_energy) return true;
  // integral d^2 ds in the frame s along (n_y, -n_x), h along n (right-handed).
  double s[kMaxClipped], h[kMaxClipped];
  const double tx = out.normal.y, ty = -out.normal.x;
  for (int k = 0; k < n; ++k) {
    s[k] = tx * vx[k] + ty * vy[k];
    h[k] = out.normal.x * vx[k] + out.normal.y * vy[k];
  }
  out.depth_sq = width_squared_integral(s, h, n);
  return true;
}

}  // namespace

bool convex_overlap(const Vec2* p, int np, const Vec2* q, int nq, ConvexOverlap& out,
                    bool with_energy) {
  return convex_overlap(p, nullptr, np, q, nullptr, nq, out, with_energy);
}

bool convex_overlap(const Vec2* p, const Vec2* pu, int np, const Vec2* q, const Vec2* qu, int nq,
                    ConvexOverlap& out, bool with_energy, std::uint32_t inner) {
  return overlap_of(p, pu, np, q, qu, nq, out, with_energy, inner);
}

int separating_line(const Vec2* p, int np, const Vec2* q, int nq) {
  return separating_line(p, nullptr, np, q, nullptr, nq);
}

int separating_line(const Vec2* p, const Vec2* pu, int np, const Vec2* q, const Vec2* qu, int nq) {
  for (int j = 0; j < nq + np; ++j)
    if (separated_by(p, pu, np, q, qu, nq, j)) return j;
  return -1;
}

bool separated_by(const Vec2* p, int np, const Vec2* q, int nq, int line) {
  return separated_by(p, nullptr, np, q, nullptr, nq, line);
}

bool separated_by(const Vec2* p, const Vec2* pu, int np, const Vec2* q, const Vec2* qu, int nq,
                  int line) {
  // Line `line` of Q (line < nq) with P's vertices, or of P (line - nq) with Q's.
  const Vec2 *owner = q, *owner_u = qu, *other = p, *other_u = pu;
  int no = nq, nt = np, j = line;
  if (line >= nq) owner = p, owner_u = pu, other = q, other_u = qu, no = np, nt = nq, j = line - nq;
  auto at = [](const Vec2* x, const Vec2* u, int k) {
    return u ? Vec2{x[k].x + u[k].x, x[k].y + u[k].y} : x[k];
  };
  const int j1 = j + 1 < no ? j + 1 : 0;
  const Vec2 a = at(owner, owner_u, j), b = at(owner, owner_u, j1);
  const double ex = b.x - a.x, ey = b.y - a.y;
  for (int k = 0; k < nt; ++k) {
    const Vec2 v = at(other, other_u, k);
    if (ex * (v.y - a.y) - ey * (v.x - a.x) >= 0.0) return false;
  }
  return true;
}

void RigidContact::setup(const Model& model, const ContactParams& params, double penalty,
                         double buffer, const std::vector<double>& block_min_height) {
  const RigidBodies& r = model.rigid;
  mu_ = params.friction;
  thickness_ = model.out_of_plane;
  damping_ = params.restitution < 1.0;
  zeta_ = no_tension_damping_ratio(params.restitution);
  kn_given_ = params.normal_stiffness;
  ks_given_ = params.shear_stiffness;
  young_ = params.joint_young;
  penalty_ = penalty;
  min_height_ = block_min_height;

  // Convex pieces (offsets from the reference centroid for free blocks).
  const std::size_t nb = model.blocks.size();
  piece_first_.assign(1, 0);
  piece_block_.clear();
  block_piece_.assign(1, 0);
  ref_.clear();
  radius_.assign(nb, 0.0);
  longest_side_.assign(nb, 0.0);
  for (std::size_t b = 0; b < nb; ++b) {
    const Block& blk = model.blocks[b];
    const bool moves = (!blk.fixed || blk.prescribed) && r.mass.size() == nb && r.mass[b] > 0.0;
    const Vec2 origin = moves ? Vec2{r.cx0[b], r.cy0[b]} : Vec2{};
    const std::vector<Vec2>& poly = blk.polygon;
    for (std::size_t k = 0; k < poly.size(); ++k)
      longest_side_[b] = std::max(longest_side_[b], distance(poly[k], poly[(k + 1) % poly.size()]));
    std::vector<std::vector<Vec2>> pieces;
    if (is_convex(poly) && int(poly.size()) <= kMaxPieceVertices) {
      pieces.push_back(poly);
    } else {
      for (const std::vector<Index>& ids : merged_triangles(model, Index(b))) {
        std::vector<Vec2> v;
        for (Index i : ids) v.push_back({model.nodes.x0[i], model.nodes.y0[i]});
        pieces.push_back(v);
      }
    }
    for (const std::vector<Vec2>& piece : pieces) {
      ref_.insert(ref_.end(), piece.begin(), piece.end());
      piece_first_.push_back(Index(ref_.size()));
      piece_block_.push_back(Index(b));
    }
    block_piece_.push_back(Index(piece_first_.size() - 1));
    for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i)
      radius_[b] = std::max(radius_[b],
                            std::hypot(model.nodes.x0[i] - origin.x, model.nodes.y0[i] - origin.y));
  }
  disp_.assign(ref_.size(), Vec2{});
  // Joints per block pair: summed length, the direction of the longest.
  joints_.clear();
  for (const Joint& j : model.joints) {
    const double len = distance(j.a, j.b);
    if (!(len > 0.0)) continue;
    JointInfo info{std::min(j.block_a, j.block_b), std::max(j.block_a, j.block_b), len,
                   (1.0 / len) * (j.b - j.a)};
    joints_.push_back(info);
  }
  std::sort(joints_.begin(), joints_.end(), [](const JointInfo& x, const JointInfo& y) {
    return x.a != y.a ? x.a < y.a : (x.b != y.b ? x.b < y.b : x.length > y.length);
  });
  std::vector<JointInfo> summed;
  for (const JointInfo& j : joints_) {
    if (!summed.empty() && summed.back().a == j.a && summed.back().b == j.b)
      summed.back().length += j.length;
    else
      summed.push_back(j);
  }
  joints_ = summed;

  // Broad phase on the outline triangles.
  scratch_ = model.nodes;
  broad_.setup(model, buffer);
  detected_ = false;
  pair_a_.clear(), pair_b_.clear(), kn_t_.clear(), kt_.clear(), beta_.clear();
  slip_x_.clear(), slip_y_.clear(), touched_.clear();
  damp_now_.assign(3 * nb, 0.0), damp_prev_ = damp_now_;
  fric_now_ = damp_now_, fric_prev_ = damp_now_;
  stored_prev_ = 0.0;
  active_ = detections_ = 0;
}

bool RigidContact::needs_detection(const Model& model) const {
  if (!detected_) return true;
  const double* ux = model.rigid.ux.data();
  const double* uy = model.rigid.uy.data();
  const double* theta = model.rigid.theta.data();
  const double* ux0 = ref_ux_.data();
  const double* uy0 = ref_uy_.data();
  const double* theta0 = ref_theta_.data();
  const double* radius = radius_.data();
  const std::uint8_t* moves = moves_.data();
  const double half = 0.5 * broad_.buffer();
  const std::size_t nb = moves_.size();
  for (std::size_t b = 0; b < nb; ++b) {
    if (!moves[b]) continue;
    const double dx = ux[b] - ux0[b], dy = uy[b] - uy0[b];
    const double moved = std::sqrt(dx * dx + dy * dy) + radius[b] * std::abs(theta[b] - theta0[b]);
    if (moved > half) return true;
  }
  return false;
}

void RigidContact::detect(const Model& model) {
  detect_at(model, model.rigid.ux, model.rigid.uy, model.rigid.theta);
}

// The detection with the bodies at the poses (ux, uy, theta): the model's own, or a
// checkpoint's last detection's.
void RigidContact::detect_at(const Model& model, const std::vector<double>& ux,
                             const std::vector<double>& uy, const std::vector<double>& theta) {
  const RigidBodies& r = model.rigid;
  const std::size_t nb = model.blocks.size();
  // Node positions from the bodies (the outline triangles' corners).
  for (std::size_t b = 0; b < nb; ++b) {
    const Block& blk = model.blocks[b];
    if (!has_pose(model, b)) continue;
    const double c = std::cos(theta[b]), s = std::sin(theta[b]);
    const double cx = r.cx0[b] + ux[b], cy = r.cy0[b] + uy[b];
    for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i) {
      scratch_.x[i] = cx + c * r.rx[i] - s * r.ry[i];
      scratch_.y[i] = cy + s * r.rx[i] + c * r.ry[i];
    }
  }
  broad_.detect(scratch_, tri_pairs_);
  std::vector<std::pair<Index, Index>> next;
  next.reserve(tri_pairs_.size());
  const Triangles& t = model.tris;
  for (const IndexPair& tp : tri_pairs_) {
    const Index a = t.block[tp.a], b = t.block[tp.b];
    next.push_back({std::min(a, b), std::max(a, b)});
  }
  std::sort(next.begin(), next.end());
  next.erase(std::unique(next.begin(), next.end()), next.end());
  // Keep the pairs whose outlines are within the buffer of each other, and of each the pairs of
  // convex pieces that are: until the next detection every outline point moves by at most
  // buffer / 2, so the others stay apart.
  displace_pieces(model, ux, uy, theta);
  const double reach = broad_.buffer();
  std::vector<std::pair<Index, Index>> kept;
  std::vector<Index> live_first{0}, live_i, live_j;
  for (const auto& [a, b] : next) {
    for (Index i = block_piece_[a]; i < block_piece_[a + 1]; ++i)
      for (Index j = block_piece_[b]; j < block_piece_[b + 1]; ++j)
        if (piece_gap(i, j) <= reach) live_i.push_back(i), live_j.push_back(j);
    if (Index(live_i.size()) == live_first.back()) continue;
    kept.push_back({a, b});
    live_first.push_back(Index(live_i.size()));
  }
  next.swap(kept);
  live_first_.swap(live_first), live_i_.swap(live_i), live_j_.swap(live_j);
  inner_.resize(live_i_.size());
  for (std::size_t l = 0; l < live_i_.size(); ++l)
    inner_[l] = inner_lines(model, ux, uy, live_i_[l], live_j_[l]);
  // Slots: the pairs of quadrilaterals in batches, the others after them.
  quad_live_.clear(), other_live_.clear();
  auto vertices = [this](Index k) { return piece_first_[k + 1] - piece_first_[k]; };
  for (std::size_t l = 0; l < live_i_.size(); ++l)
    (vertices(live_i_[l]) == 4 && vertices(live_j_[l]) == 4 ? quad_live_ : other_live_)
        .push_back(Index(l));
  const std::size_t batches = (quad_live_.size() + kQuadLanes - 1) / kQuadLanes;
  const std::size_t quad_slots = batches * kQuadLanes;
  slot_of_live_.assign(live_i_.size(), 0);
  quad_ref_.assign(batches, QuadPairs{});
  for (std::size_t slot = 0; slot < quad_live_.size(); ++slot) {
    const std::size_t live = std::size_t(quad_live_[slot]);
    slot_of_live_[live] = Index(slot);
    const Index p0 = piece_first_[live_i_[live]], q0 = piece_first_[live_j_[live]];
    QuadPairs& batch = quad_ref_[slot / kQuadLanes];
    const std::size_t l = slot % kQuadLanes;
    const Vec2 o = ref_[p0];
    for (int k = 0; k < 4; ++k) {
      batch.px[k][l] = ref_[p0 + k].x - o.x, batch.py[k][l] = ref_[p0 + k].y - o.y;
      batch.qx[k][l] = ref_[q0 + k].x - o.x, batch.qy[k][l] = ref_[q0 + k].y - o.y;
    }
    batch.ox[l] = o.x, batch.oy[l] = o.y;
  }
  for (std::size_t k = 0; k < other_live_.size(); ++k)
    slot_of_live_[std::size_t(other_live_[k])] = Index(quad_slots + k);
  overlap_.resize(quad_slots + other_live_.size());
  moves_.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) moves_[b] = has_pose(model, b);
  // The pieces the steps displace: those of the live pairs on bodies with a pose, in order.
  std::vector<char> live_piece(piece_block_.size(), 0);
  for (std::size_t l = 0; l < live_i_.size(); ++l)
    live_piece[live_i_[l]] = live_piece[live_j_[l]] = 1;
  moving_pieces_.clear();
  for (std::size_t k = 0; k < live_piece.size(); ++k)
    if (live_piece[k] && has_pose(model, std::size_t(piece_block_[k])))
      moving_pieces_.push_back(Index(k));
  offset_.resize(ref_.size());
  for (const Index k : moving_pieces_) {
    const std::size_t b = std::size_t(piece_block_[k]);
    for (Index v = piece_first_[k]; v < piece_first_[k + 1]; ++v)
      offset_[v] = {ref_[v].x - r.cx0[b], ref_[v].y - r.cy0[b]};
  }
  // The batches' offsets and bodies (quad_place).
  quad_offset_.assign(batches, QuadPairs{});
  quad_body_p_.assign(quad_slots, Index(nb)), quad_body_q_.assign(quad_slots, Index(nb));
  for (std::size_t slot = 0; slot < quad_live_.size(); ++slot) {
    const std::size_t live = std::size_t(quad_live_[slot]), l = slot % kQuadLanes;
    QuadPairs& batch = quad_offset_[slot / kQuadLanes];
    auto place = [&](Index piece, Index& body, double(&x)[4][kQuadLanes],
                     double(&y)[4][kQuadLanes]) {
      if (!moves_[std::size_t(piece_block_[piece])]) return;
      body = piece_block_[piece];
      for (int k = 0; k < 4; ++k)
        x[k][l] = offset_[piece_first_[piece] + k].x, y[k][l] = offset_[piece_first_[piece] + k].y;
    };
    place(live_i_[live], quad_body_p_[slot], batch.px, batch.py);
    place(live_j_[live], quad_body_q_[slot], batch.qx, batch.qy);
  }
  // Carry the friction slip and whether the pair touched by the block pair.
  const std::size_t np = next.size();
  std::vector<Index> na(np), nbk(np);
  std::vector<double> sx(np, 0.0), sy(np, 0.0);
  std::vector<std::uint8_t> touched(np, 0);
  std::size_t o = 0;
  for (std::size_t p = 0; p < np; ++p) {
    na[p] = next[p].first, nbk[p] = next[p].second;
    while (o < pair_a_.size() &&
           (pair_a_[o] < na[p] || (pair_a_[o] == na[p] && pair_b_[o] < nbk[p])))
      ++o;
    if (o < pair_a_.size() && pair_a_[o] == na[p] && pair_b_[o] == nbk[p]) {
      sx[p] = slip_x_[o], sy[p] = slip_y_[o];
      touched[p] = touched_[o];
    }
  }
  pair_a_.swap(na), pair_b_.swap(nbk);
  apart_line_.assign(live_i_.size(), -1);
  slip_x_.swap(sx), slip_y_.swap(sy), touched_.swap(touched);
  pair_constants(model);
  ref_ux_ = ux, ref_uy_ = uy, ref_theta_ = theta;
  detected_ = true;
  ++detections_;
}

// Smallest distance between convex pieces i and j at the current configuration (0 when they
// overlap) [m].
double RigidContact::piece_gap(Index i, Index j) const {
  auto current = [this](Index k) {
    std::vector<Vec2> v;
    for (Index a = piece_first_[k]; a < piece_first_[k + 1]; ++a)
      v.push_back({ref_[a].x + disp_[a].x, ref_[a].y + disp_[a].y});
    return v;
  };
  const std::vector<Vec2> pp = current(i), qq = current(j);
  const Vec2* p = pp.data();
  const Vec2* q = qq.data();
  const int np = int(pp.size());
  const int nq = int(qq.size());
  if (separating_line(p, np, q, nq) < 0) return 0.0;  // convex pieces not apart: overlap
  double gap = std::numeric_limits<double>::infinity();
  for (int k = 0; k < np; ++k)
    for (int l = 0; l < nq; ++l) {
      gap = std::min(gap, distance_to_segment(p[k], q[l], q[l + 1 < nq ? l + 1 : 0]));
      gap = std::min(gap, distance_to_segment(q[l], p[k], p[k + 1 < np ? k + 1 : 0]));
    }
  return gap;
}

// The side lines of piece j (bit k: from vertex k to k + 1) that keep every vertex of piece i on
// their inner side, by more than the two pieces can move towards the line before the next
// detection (rigid_contact.hpp, "Lines that cannot cut"); at the detection's configuration
// (disp_), the bodies displaced by (ux, uy).
std::uint32_t RigidContact::inner_lines(const Model& model, const std::vector<double>& ux,
                                        const std::vector<double>& uy, Index i, Index j) const {
  const RigidBodies& r = model.rigid;
  const std::size_t bi = std::size_t(piece_block_[i]), bj = std::size_t(piece_block_[j]);
  const double half = 0.5 * broad_.buffer();
  const double move_p = has_pose(model, bi) ? half : 0.0;
  const bool q_moves = has_pose(model, bj);
  if (q_moves && !(radius_[bj] > 0.0)) return 0;  // no bound on the line's turn
  const double cqx = q_moves ? r.cx0[bj] + ux[bj] : 0.0, cqy = q_moves ? r.cy0[bj] + uy[bj] : 0.0;
  auto at = [this](Index v) { return Vec2{ref_[v].x + disp_[v].x, ref_[v].y + disp_[v].y}; };
  const Index q0 = piece_first_[j], nq = piece_first_[j + 1] - q0;
  std::uint32_t inner = 0;
  for (Index k = 0; k < nq; ++k) {
    const Vec2 a = at(q0 + k), e = at(q0 + (k + 1 < nq ? k + 1 : 0)) - a;
    const double len = std::hypot(e.x, e.y);
    if (!(len > 0.0)) continue;
    bool all_inside = true;
    for (Index w = piece_first_[i]; w < piece_first_[i + 1] && all_inside; ++w) {
      const Vec2 v = at(w);
      const double dist = cross(e, v - a) / len;
      // Q's material point at v moves by at most |dc_Q| + |dtheta_Q| |v - c_Q|, which the
      // detection rule bounds by buffer / 2 times max(1, |v - c_Q| / R_Q).
      const double move_q =
          q_moves ? half * std::max(1.0, std::hypot(v.x - cqx, v.y - cqy) / radius_[bj]) : 0.0;
      const double slack = kInnerLineSlack * (broad_.buffer() + std::abs(a.x) + std::abs(a.y) +
                                              std::abs(v.x) + std::abs(v.y));
      all_inside = dist > move_p + move_q + slack;
    }
    if (all_inside) inner |= std::uint32_t(1) << k;
  }
  return inner;
}

// kn t_z, k_t and beta of each candidate pair, from the reference geometry only (so a restart's
// detection gives the same values).
void RigidContact::pair_constants(const Model& model) {
  const std::size_t np = pair_a_.size();
  kn_t_.resize(np), kt_.resize(np), beta_.resize(np);
  pair_energy_.resize(np), pair_stored_.resize(np);
  for (std::size_t p = 0; p < np; ++p) {
    const Index a = pair_a_[p], b = pair_b_[p];
    const Block& ba = model.blocks[std::size_t(a)];
    const Block& bb = model.blocks[std::size_t(b)];
    const JointInfo key{a, b, 0.0, {}};
    const auto it = std::lower_bound(
        joints_.begin(), joints_.end(), key,
        [](const JointInfo& x, const JointInfo& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
    const bool joint = it != joints_.end() && it->a == a && it->b == b;
    const double length =
        joint ? it->length : std::min(longest_side_[std::size_t(a)], longest_side_[std::size_t(b)]);
    // The free block first, as the joint mapping of joint_stiffness.hpp takes it.
    const Block& first = ba.fixed ? bb : ba;
    const Block& second = ba.fixed ? ba : bb;
    double kn = kn_given_;
    if (!(kn > 0.0) && young_ > 0.0) {
      kn = joint ? default_joint_stiffness(young_, first, &second,
                                           Vec2{it->tangent.y, -it->tangent.x})
                 : kRigidJointFactor * young_ / length;
    } else if (!(kn > 0.0)) {
      kn = penalty_ * (3.0 / min_height_[std::size_t(a)] + 3.0 / min_height_[std::size_t(b)]);
    }
    const double ks = ks_given_ > 0.0 ? ks_given_ : kTangentialStiffnessRatio * kn;
    kn_t_[p] = kn * thickness_;
    kt_[p] = ks * thickness_ * length;
    beta_[p] = 0.0;
    if (damping_) {
      double omega = 0.0;
      if (joint) {
        omega = joint_frequency(kn_t_[p], first, first.mass, &second, second.mass, it->tangent);
      } else {
        const double m_eff = ba.fixed   ? bb.mass
                             : bb.fixed ? ba.mass
                                        : ba.mass * bb.mass / (ba.mass + bb.mass);
        omega = m_eff > 0.0 ? std::sqrt(kn_t_[p] * length / m_eff) : 0.0;
      }
      beta_[p] = omega > 0.0 ? 2.0 * zeta_ / omega : 0.0;
    }
  }
}

void RigidContact::displace_pieces(const Model& model, const std::vector<double>& ux_of,
                                   const std::vector<double>& uy_of,
                                   const std::vector<double>& theta) {
  const RigidBodies& r = model.rigid;
  const std::size_t nb = model.blocks.size();
  for (std::size_t b = 0; b < nb; ++b) {
    if (!has_pose(model, b)) continue;
    // Displacement of each vertex, u = (c - c0) + (R - I) r with cos - 1 = -2 sin^2(theta/2):
    // small numbers computed to their own round-off.
    double sh, ch;
    half_angle(theta[b], sh, ch);
    const double cm1 = -2.0 * sh * sh, s = 2.0 * sh * ch;
    const double ux = ux_of[b], uy = uy_of[b];
    for (Index v = piece_first_[block_piece_[b]]; v < piece_first_[block_piece_[b + 1]]; ++v) {
      // r: the vertex's offset from the reference centroid
      const double rx = ref_[v].x - r.cx0[b], ry = ref_[v].y - r.cy0[b];
      const Vec2 u{ux + cm1 * rx - s * ry, uy + s * rx + cm1 * ry};
      disp_[v] = u;
    }
  }
}

// displace_pieces for the pieces of the live pairs, at the bodies' current poses (the same
// numbers, with the offsets r computed at the detection). (Rejected: reading pose_bodies'
// arrays instead of its own half angles. The values are the same, but loaded from memory the
// compiler fuses the products of u differently, and the scaled arch's pulses moved by round-off.)
void RigidContact::displace_live_pieces(const Model& model) {
  const double* ux = model.rigid.ux.data();
  const double* uy = model.rigid.uy.data();
  const double* theta = model.rigid.theta.data();
  const Index* first = piece_first_.data();
  const Vec2* offset = offset_.data();
  Vec2* disp = disp_.data();
  Index block = -1;
  double cm1 = 0.0, s = 0.0, bx = 0.0, by = 0.0;
  for (const Index k : moving_pieces_) {
    if (piece_block_[k] != block) {
      block = piece_block_[k];
      double sh, ch;
      half_angle(theta[block], sh, ch);
      cm1 = -2.0 * sh * sh, s = 2.0 * sh * ch;
      bx = ux[block], by = uy[block];
    }
    for (Index v = first[k]; v < first[k + 1]; ++v) {
      const double rx = offset[v].x, ry = offset[v].y;
      disp[v] = {bx + cm1 * rx - s * ry, by + s * rx + cm1 * ry};
    }
  }
}

void RigidContact::pose_bodies(const Model& model) {
  const std::size_t nb = moves_.size();
  // One more entry, at nb, stays zero: the pose of a lane without a body.
  if (pose_ux_.size() != nb + 1) {
    pose_ux_.assign(nb + 1, 0.0), pose_uy_.assign(nb + 1, 0.0);
    pose_cm1_.assign(nb + 1, 0.0), pose_s_.assign(nb + 1, 0.0);
  }
  for (std::size_t b = 0; b < nb; ++b) {
    if (!moves_[b]) {
      pose_ux_[b] = pose_uy_[b] = pose_cm1_[b] = pose_s_[b] = 0.0;
      continue;
    }
    double sh, ch;
    half_angle(model.rigid.theta[b], sh, ch);
    pose_cm1_[b] = -2.0 * sh * sh, pose_s_[b] = 2.0 * sh * ch;
    pose_ux_[b] = model.rigid.ux[b], pose_uy_[b] = model.rigid.uy[b];
  }
}

// Pair p at the current configuration: false when its blocks do not overlap (its history is
// then dropped). Inlined into the contact stage's pair loop.
[[gnu::always_inline]] inline bool RigidContact::evaluate(std::size_t p, const BodyView& r,
                                                          double dt, bool energy, PairOut& out) {
  const Index a = pair_a_[p], b = pair_b_[p];
  const double kn_t = kn_t_[p];
  const bool touched = touched_[p];
  double area = 0.0, energy2 = 0.0, gx = 0.0, gy = 0.0;
  Vec2 force, unit;  // unit: the one overlap's normal
  int regions = 0;
  double mb = 0.0, ma = 0.0;
  const double ca_x = r.cx[a], ca_y = r.cy[a], cb_x = r.cx[b], cb_y = r.cy[b];
  Vec2 damp;                              // the dashpots' force on b
  double damp_mb = 0.0, damp_ma = 0.0;    // and their moments on b and on a
  const double c_damp = beta_[p] * kn_t;  // beta kn t_z [N s/m2]
  for (Index live = live_first_[p]; live < live_first_[p + 1]; ++live) {
    const std::size_t slot = std::size_t(slot_of_live_[live]);
    if (!overlap_.on[slot]) continue;
    const ConvexOverlap o = overlap_.at(slot);
    const Vec2 f = (kn_t * o.area) * o.normal;  // on b
    force = force + f;
    mb += (o.centroid.x - cb_x) * f.y - (o.centroid.y - cb_y) * f.x;
    ma -= (o.centroid.x - ca_x) * f.y - (o.centroid.y - ca_y) * f.x;
    area += o.area;
    unit = o.normal;
    ++regions;
    gx += o.area * o.centroid.x, gy += o.area * o.centroid.y;
    if (energy) energy2 += o.depth_sq;
    if (damping_) {
      // The viscous Winkler joint along this overlap's chord (rigid_contact.hpp).
      const Vec2 xm = o.chord_mid, n = o.normal;
      const double vb_x = r.vx[b] - r.omega[b] * (xm.y - cb_y);
      const double vb_y = r.vy[b] + r.omega[b] * (xm.x - cb_x);
      const double va_x = r.vx[a] - r.omega[a] * (xm.y - ca_y);
      const double va_y = r.vy[a] + r.omega[a] * (xm.x - ca_x);
      const double rate_m = -(n.x * (vb_x - va_x) + n.y * (vb_y - va_y));
      const double rate_s = -(r.omega[b] - r.omega[a]);
      const double len = o.chord;
      // The step a pair first touches, it has touched for the part of the step its mean depth
      // |O| / L took to reach at the approach rate: the dashpot acts for that part only.
      double part = 1.0;
      if (!touched && rate_m * dt * len > o.area) part = o.area / (rate_m * dt * len);
      // No tension: a separating joint's dashpot pulls no harder than its spring pushes
      // (rigid_contact.hpp), both of its terms scaled alike.
      const double spring = kn_t * o.area, pull = part * c_damp * len * rate_m;
      if (pull < -spring) part *= spring / -pull;
      const Vec2 fd = (part * c_damp * len * rate_m) * n;
      const double twist = part * c_damp * len * len * len / 12.0 * rate_s;
      damp = damp + fd;
      damp_mb += (xm.x - cb_x) * fd.y - (xm.y - cb_y) * fd.x + twist;
      damp_ma -= (xm.x - ca_x) * fd.y - (xm.y - ca_y) * fd.x + twist;
    }
  }
  if (!(area > 0.0)) {
    touched_[p] = 0;
    slip_x_[p] = slip_y_[p] = 0.0;
    return false;
  }
  const Vec2 g{gx / area, gy / area};
  out.energy = 0.5 * kn_t * energy2;
  out.fb = force;
  out.mb = mb, out.ma = ma;
  out.stored = 0.0;
  out.fric_b = {};
  out.fric_mb = out.fric_ma = 0.0;
  if (mu_ > 0.0) {
    // Relative displacement of b's material point at g with respect to a's over the last step.
    const double ub_x = r.vx[b] - r.omega[b] * (g.y - cb_y),
                 ub_y = r.vy[b] + r.omega[b] * (g.x - cb_x);
    const double ua_x = r.vx[a] - r.omega[a] * (g.y - ca_y),
                 ua_y = r.vy[a] + r.omega[a] * (g.x - ca_x);
    const Vec2 du{dt * (ub_x - ua_x), dt * (ub_y - ua_y)};
    // One overlap (a joint): its force kn |O| along its normal, no square root to take again.
    const Vec2 slip{slip_x_[p], slip_y_[p]};
    const FrictionResult fr = regions == 1
                                  ? coulomb_friction(kn_t * area, unit, du, slip, kt_[p], mu_)
                                  : coulomb_friction(force, du, slip, kt_[p], mu_);
    slip_x_[p] = fr.slip.x, slip_y_[p] = fr.slip.y;
    out.stored = fr.stored;
    out.fric_b = fr.force;
    out.fric_mb = (g.x - cb_x) * fr.force.y - (g.y - cb_y) * fr.force.x;
    out.fric_ma = -((g.x - ca_x) * fr.force.y - (g.y - ca_y) * fr.force.x);
    out.fb = out.fb + fr.force;
    out.mb += out.fric_mb, out.ma += out.fric_ma;
  }
  out.damp_b = damp;
  out.damp_mb = damp_mb, out.damp_ma = damp_ma;
  if (damping_) {
    out.fb = out.fb + damp;
    out.mb += damp_mb, out.ma += damp_ma;
  }
  touched_[p] = 1;
  return true;
}

void RigidContact::OverlapTable::resize(std::size_t slots) {
  for (std::vector<double>* v : {&area, &gx, &gy, &nx, &ny, &chord, &mx, &my, &depth_sq})
    v->assign(slots, 0.0);
  on.assign(slots, 0);
}

void RigidContact::OverlapTable::set(std::size_t slot, const ConvexOverlap& o) {
  area[slot] = o.area, gx[slot] = o.centroid.x, gy[slot] = o.centroid.y;
  nx[slot] = o.normal.x, ny[slot] = o.normal.y, chord[slot] = o.chord;
  mx[slot] = o.chord_mid.x, my[slot] = o.chord_mid.y, depth_sq[slot] = o.depth_sq;
}

// The overlap of every live pair of pieces at the current configuration (overlap_): the pairs
// of quadrilaterals a batch at a time (quad_overlap.hpp), the others one by one, with the
// separating lines of those apart. `energy`: the joints' energy too, by the ordered clipping
// (depth_sq).
void RigidContact::overlap_pieces(bool energy) {
  const Index* first = piece_first_.data();
  const Vec2* ref = ref_.data();
  const Vec2* disp = disp_.data();
  auto pieces_of = [&](std::size_t live, const Vec2*& pv, const Vec2*& pu, int& np, const Vec2*& qv,
                       const Vec2*& qu, int& nq) {
    const Index i = live_i_[live], j = live_j_[live];
    pv = &ref[first[i]], pu = &disp[first[i]], qv = &ref[first[j]], qu = &disp[first[j]];
    np = first[i + 1] - first[i], nq = first[j + 1] - first[j];
  };
  const Vec2 *pv, *pu, *qv, *qu;
  int np, nq;
  QuadPairs batch;
  QuadOverlaps result;
  OverlapTable& t = overlap_;
  QuadPoses pose;
  for (std::size_t b = 0; b < quad_ref_.size(); ++b) {
    for (int l = 0; l < kQuadLanes; ++l) {
      const std::size_t lane = b * kQuadLanes + std::size_t(l);
      const std::size_t bp = quad_body_p_[lane], bq = quad_body_q_[lane];
      pose.p_ux[l] = pose_ux_[bp], pose.p_uy[l] = pose_uy_[bp];
      pose.p_cm1[l] = pose_cm1_[bp], pose.p_s[l] = pose_s_[bp];
      pose.q_ux[l] = pose_ux_[bq], pose.q_uy[l] = pose_uy_[bq];
      pose.q_cm1[l] = pose_cm1_[bq], pose.q_s[l] = pose_s_[bq];
    }
    quad_place(quad_ref_[b], quad_offset_[b], pose, batch);
    quad_overlaps(batch, result);
    const std::size_t at = b * kQuadLanes;
    std::copy_n(result.area, kQuadLanes, &t.area[at]);
    std::copy_n(result.gx, kQuadLanes, &t.gx[at]), std::copy_n(result.gy, kQuadLanes, &t.gy[at]);
    std::copy_n(result.nx, kQuadLanes, &t.nx[at]), std::copy_n(result.ny, kQuadLanes, &t.ny[at]);
    std::copy_n(result.chord, kQuadLanes, &t.chord[at]);
    std::copy_n(result.mx, kQuadLanes, &t.mx[at]), std::copy_n(result.my, kQuadLanes, &t.my[at]);
    std::copy_n(result.on, kQuadLanes, &t.on[at]);
  }
  // The joints' energy (read only where `energy`: evaluate's out.energy).
  for (std::size_t slot = 0; energy && slot < quad_live_.size(); ++slot) {
    t.depth_sq[slot] = 0.0;
    ConvexOverlap ordered;
    const std::size_t live = std::size_t(quad_live_[slot]);
    if (!t.on[slot]) continue;
    pieces_of(live, pv, pu, np, qv, qu, nq);
    if (overlap_of(pv, pu, np, qv, qu, nq, ordered, true, inner_[live]))
      t.depth_sq[slot] = ordered.depth_sq;
  }
  for (const Index index : other_live_) {
    const std::size_t live = std::size_t(index), slot = std::size_t(slot_of_live_[live]);
    pieces_of(live, pv, pu, np, qv, qu, nq);
    std::int16_t& apart = apart_line_[live];
    t.on[slot] = 0;
    if (apart >= 0 && separated_by(pv, pu, np, qv, qu, nq, apart)) continue;
    ConvexOverlap o;
    if (!overlap_of(pv, pu, np, qv, qu, nq, o, energy, inner_[live])) {
      apart = std::int16_t(separating_line(pv, pu, np, qv, qu, nq));
      continue;
    }
    t.on[slot] = 1;
    t.set(slot, o);
  }
}

void RigidContact::add_forces(Model& model, double dt, EnergyLedger& ledger, bool with_energy) {
  RigidBodies& r = model.rigid;
  if (!detected_) {
    ledger.contact = 0.0;
    return;
  }
  // The one-by-one displacements serve the ordered clipping only: the other pieces, and the
  // joints' energy.
  if (with_energy || !other_live_.empty()) displace_live_pieces(model);
  if (!quad_ref_.empty()) pose_bodies(model);
  overlap_pieces(with_energy);
  const BodyView bodies{r.cx.data(), r.cy.data(), r.vx.data(), r.vy.data(), r.omega.data()};
  double* fx = r.fx.data();
  double* fy = r.fy.data();
  double* torque = r.torque.data();
  double* damp = damp_now_.data();
  double* fric = fric_now_.data();
  double* pair_energy = pair_energy_.data();
  double* pair_stored = pair_stored_.data();
  std::int64_t active = 0;
  const std::size_t np = pair_a_.size();
  for (std::size_t p = 0; p < np; ++p) {
    PairOut out;
    pair_energy[p] = pair_stored[p] = 0.0;
    if (!evaluate(p, bodies, dt, with_energy, out)) continue;
    ++active;
    pair_energy[p] = out.energy;
    pair_stored[p] = out.stored;
    const Index a = pair_a_[p], b = pair_b_[p];
    fx[b] += out.fb.x, fy[b] += out.fb.y, torque[b] += out.mb;
    fx[a] -= out.fb.x, fy[a] -= out.fb.y, torque[a] += out.ma;
    if (damping_) {
      damp[3 * b] += out.damp_b.x, damp[3 * b + 1] += out.damp_b.y;
      damp[3 * b + 2] += out.damp_mb;
      damp[3 * a] -= out.damp_b.x, damp[3 * a + 1] -= out.damp_b.y;
      damp[3 * a + 2] += out.damp_ma;
    }
    if (mu_ > 0.0) {
      fric[3 * b] += out.fric_b.x, fric[3 * b + 1] += out.fric_b.y;
      fric[3 * b + 2] += out.fric_mb;
      fric[3 * a] -= out.fric_b.x, fric[3 * a + 1] -= out.fric_b.y;
      fric[3 * a + 2] += out.fric_ma;
    }
  }
  active_ = active;
  // The pairs' energies summed apart from the pair loop: each product is rounded before it is
  // added, as the ledger's figures have always been (an add fused with the product would move
  // their last digit).
  double energy = 0.0, stored = 0.0;
  for (std::size_t p = 0; p < np; ++p) energy += pair_energy[p], stored += pair_stored[p];
  if (with_energy) ledger.contact = energy + stored;
  // Work of the tracked forces over the last position increment (trapezoid), bodies in order.
  const std::uint8_t* moves = moves_.data();
  auto work_and_shift = [&](std::vector<double>& now_of, std::vector<double>& prev_of) {
    double work = 0.0;
    double* now = now_of.data();
    double* prev = prev_of.data();
    const std::size_t nb = moves_.size();
    for (std::size_t b = 0; b < nb; ++b) {
      const double* f = &now[3 * b];
      double* g = &prev[3 * b];
      if (moves[b])
        work += (f[0] + g[0]) * bodies.vx[b] + (f[1] + g[1]) * bodies.vy[b] +
                (f[2] + g[2]) * bodies.omega[b];
      g[0] = f[0], g[1] = f[1], g[2] = f[2];
      now[3 * b] = now[3 * b + 1] = now[3 * b + 2] = 0.0;
    }
    return 0.5 * dt * work;
  };
  if (damping_) ledger.impact_dissipated -= work_and_shift(damp_now_, damp_prev_);
  if (mu_ > 0.0) {
    const double taken = -work_and_shift(fric_now_, fric_prev_) - (stored - stored_prev_);
    if (taken > 0.0) ledger.friction_dissipated += taken;
    stored_prev_ = stored;
  }
}

std::vector<BlockPairForce> RigidContact::pair_forces(const Model& model, double dt) const {
  std::vector<BlockPairForce> forces;
  if (!detected_) return forces;
  RigidContact copy(*this);
  if (copy.needs_detection(model)) copy.detect(model);
  const RigidBodies& r = model.rigid;
  copy.displace_live_pieces(model);
  copy.pose_bodies(model);
  copy.overlap_pieces(true);
  const BodyView bodies{r.cx.data(), r.cy.data(), r.vx.data(), r.vy.data(), r.omega.data()};
  PairOut out;
  for (std::size_t p = 0; p < copy.pair_a_.size(); ++p) {
    if (!copy.evaluate(p, bodies, dt, true, out)) continue;
    BlockPairForce f;
    f.block_a = copy.pair_a_[p], f.block_b = copy.pair_b_[p];
    f.force = out.fb;
    f.origin = {r.cx[f.block_b], r.cy[f.block_b]};
    f.moment = out.mb;
    if (model.blocks[std::size_t(f.block_b)].fixed || !(r.mass[f.block_b] > 0.0)) {
      // The moment on b about a fixed point: the forces on a are the negated ones, and their
      // moment about c_a is out.ma; about any origin the moment on b is minus a's.
      f.origin = {r.cx[f.block_a], r.cy[f.block_a]};
      f.moment = -out.ma;
    }
    forces.push_back(f);
  }
  return forces;
}

std::vector<char> RigidContact::save_state() const {
  std::vector<char> out;
  put<std::uint8_t>(out, detected_ ? 1 : 0);
  put<std::int64_t>(out, detections_);
  put<std::int64_t>(out, active_);
  put_array(out, ref_ux_), put_array(out, ref_uy_), put_array(out, ref_theta_);
  put_array(out, pair_a_), put_array(out, pair_b_);
  put_array(out, slip_x_), put_array(out, slip_y_), put_array(out, touched_);
  put_array(out, damp_prev_), put_array(out, fric_prev_);
  put<double>(out, stored_prev_);
  return out;
}

void RigidContact::restore_state(const Model& model, const std::vector<char>& bytes) {
  StateReader in{bytes};
  const bool detected = in.get<std::uint8_t>() != 0;
  const auto detections = in.get<std::int64_t>(), active = in.get<std::int64_t>();
  const auto ux = in.get_array<double>(), uy = in.get_array<double>();
  const auto th = in.get_array<double>();
  auto pa = in.get_array<Index>(), pb = in.get_array<Index>();
  auto sx = in.get_array<double>(), sy = in.get_array<double>();
  auto touched = in.get_array<std::uint8_t>();
  auto dp = in.get_array<double>(), fp = in.get_array<double>();
  const double stored_prev = in.get<double>();
  if (in.pos != bytes.size()) in.fail("unexpected data after the rigid contact state");
  const std::size_t nb = model.blocks.size();
  if (sx.size() != pa.size() || sy.size() != pa.size() || touched.size() != pa.size() ||
      pb.size() != pa.size() || dp.size() != 3 * nb || fp.size() != 3 * nb)
    in.fail("rigid contact state does not fit this model");
  if (detected) {
    if (ux.size() != nb || uy.size() != nb || th.size() != nb)
      in.fail("rigid contact state does not fit this model");
    // The last detection again, from the bodies' poses then: the same candidates and reference.
    pair_a_.clear(), pair_b_.clear(), slip_x_.clear(), slip_y_.clear(), touched_.clear();
    detect_at(model, ux, uy, th);
    if (pair_a_ != pa || pair_b_ != pb) in.fail("the candidate pairs differ from the model's");
  }
  slip_x_ = sx, slip_y_ = sy, touched_ = touched;
  damp_prev_ = dp, fric_prev_ = fp;
  stored_prev_ = stored_prev;
  detections_ = detections;
  active_ = active;
}

int RigidContact::piece_reference(Index k, Vec2* out) const {
  const Index first = piece_first_[std::size_t(k)], last = piece_first_[std::size_t(k) + 1];
  for (Index v = first; v < last; ++v) out[v - first] = ref_[std::size_t(v)];
  return int(last - first);
}

int RigidContact::piece_vertices(const Model& model, Index k, Vec2* out) const {
  const int n = piece_reference(k, out);
  const std::size_t b = std::size_t(piece_block_[std::size_t(k)]);
  if (!has_pose(model, b)) return n;
  const RigidBodies& r = model.rigid;
  const double c = std::cos(r.theta[b]), s = std::sin(r.theta[b]);
  const double cx = r.cx0[b] + r.ux[b], cy = r.cy0[b] + r.uy[b];
  for (int i = 0; i < n; ++i) {
    const double rx = out[i].x - r.cx0[b], ry = out[i].y - r.cy0[b];
    out[i] = {cx + c * rx - s * ry, cy + s * rx + c * ry};
  }
  return n;
}

}  // namespace voussoir

#include "contact/narrow_phase.hpp"

#include <algorithm>
#include <cmath>

namespace voussoir {

namespace {

// A triangle clipped by 3 lines has at most 6 vertices; 8 leaves room.
constexpr int kMaxPoly = 8;

// Convex polygon, counter-clockwise. on_c[k] = 1 when the edge from vertex k to k+1 lies on an
// edge of c (made by clipping), 0 when it lies on an edge of t.
struct Poly {
  int n = 0;
  double x[kMaxPoly], y[kMaxPoly];
  unsigned char on_c[kMaxPoly];
};

// Affine function a + b x + c y.
struct Affine {
  double a = 0.0, b = 0.0, c = 0.0;
  double operator()(double x, double y) const { return a + b * x + c * y; }
};

// Edge functions of a triangle (local coordinates): e[m] = cross(p[m+2] - p[m+1], x - p[m+1]),
// zero on the edge opposite vertex m, positive inside (counter-clockwise); twice the area.
struct Edges {
  Affine e[3];
  double twice_area = 0.0;
};

inline Edges edge_functions(const double* px, const double* py) {
  Edges t;
  t.twice_area = (px[1] - px[0]) * (py[2] - py[0]) - (py[1] - py[0]) * (px[2] - px[0]);
  for (int m = 0; m < 3; ++m) {
    const int i = (m + 1) % 3, j = (m + 2) % 3;
    const double ex = px[j] - px[i], ey = py[j] - py[i];
    // cross(e, x - p_i) = -ey x + ex y + (ey px_i - ex py_i)
    t.e[m] = {ey * px[i] - ex * py[i], -ey, ex};
  }
  return t;
}

// Barycentric coordinates lam[m] = e[m] / (2 A).
struct Bary {
  Affine lam[3];
};

inline Bary barycentric(const Edges& t) {
  const double inv = 1.0 / t.twice_area;
  Bary b;
  for (int m = 0; m < 3; ++m) b.lam[m] = {t.e[m].a * inv, t.e[m].b * inv, t.e[m].c * inv};
  return b;
}

// Keeps the part of convex `in` where f >= 0 (Sutherland-Hodgman, one line of c), keeping
// track of which triangle each edge lies on.
// kN: the vertex count when known at compile time (3: the first clip of t), else 0.
template <int kN = 0>
inline void clip(const Poly& __restrict in, const Affine& f, Poly& __restrict out) {
  const int n = kN > 0 ? kN : in.n;
  int m = 0;  // out.n, counted in a register
  double fv[kMaxPoly];
  for (int k = 0; k < n; ++k) fv[k] = f(in.x[k], in.y[k]);
  for (int q = 0, p = n - 1; q < n; p = q++) {
    const double fp = fv[p], fq = fv[q];
    if ((fp < 0.0 && fq > 0.0) || (fp > 0.0 && fq < 0.0)) {
      const double s = fp / (fp - fq);
      out.x[m] = in.x[p] + s * (in.x[q] - in.x[p]);
      out.y[m] = in.y[p] + s * (in.y[q] - in.y[p]);
      // Leaving: the next edge runs along the clip line; entering: along the edge p -> q.
      out.on_c[m] = fq < 0.0 ? 1 : in.on_c[p];
      ++m;
    }
    if (fq >= 0.0) {
      out.x[m] = in.x[q];
      out.y[m] = in.y[q];
      // Its outgoing edge is part of the input edge q -> r, unless q lies on the line and r
      // is outside: then no intersection follows and the edge runs along the clip line.
      const int r = q + 1 < n ? q + 1 : 0;
      out.on_c[m] = (fq == 0.0 && fv[r] < 0.0) ? 1 : in.on_c[q];
      ++m;
    }
  }
  out.n = m;
}

// Area and first moments (int x dA, int y dA) of a polygon (counter-clockwise).
struct Moments {
  double area = 0.0, sx = 0.0, sy = 0.0;
};

inline Moments moments(const Poly& p) {
  Moments m;
  if (p.n < 3) return m;
  // Fan from the first vertex (no cancellation for thin polygons), shifted back.
  const double x0 = p.x[0], y0 = p.y[0];
  double a2 = 0.0, sx6 = 0.0, sy6 = 0.0;
  for (int k = 2; k < p.n; ++k) {
    const double ux = p.x[k - 1] - x0, uy = p.y[k - 1] - y0;
    const double vx = p.x[k] - x0, vy = p.y[k] - y0;
    const double cr = ux * vy - uy * vx;
    a2 += cr;
    sx6 += (ux + vx) * cr;
    sy6 += (uy + vy) * cr;
  }
  m.area = 0.5 * a2;
  m.sx = m.area * x0 + sx6 * (1.0 / 6.0);
  m.sy = m.area * y0 + sy6 * (1.0 / 6.0);
  return m;
}

// What one triangle's potential field does over the overlap: G = int_P grad phi (x) (1, x, y)
// dA (row 0: x component of grad phi, row 1: y) and Phi = int_P phi dA.
struct Field {
  double g[2][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
  double phi = 0.0;
};

// Along a segment (parameter s in [0, 1]) phi = 3 min_m (alpha_m + beta_m s), the lower
// envelope of three lines (concave, at most three pieces). Returns the exact integrals
// i0 = int_0^1 phi ds and i1 = int_0^1 phi s ds (then int phi x ds = ax i0 + dx i1).
inline void integrate_phi(const double* alpha, const double* beta, double& i0, double& i1) {
  double j0 = 0.0, j1 = 0.0;
  auto piece = [&](int m, double s0, double s1) {
    const double w = s1 - s0;
    const double p0 = alpha[m] + beta[m] * s0, p1 = alpha[m] + beta[m] * s1;
    // int_s0^s1 phi ds and int_s0^s1 phi s ds for linear phi (p0, p1 at the ends), over 3.
    j0 += w * (p0 + p1);
    j1 += w * (p0 * (2.0 * s0 + s1) + p1 * (s0 + 2.0 * s1));
  };
  auto argmin = [](double u, double v, double w) {
    return u <= v ? (u <= w ? 0 : 2) : (v <= w ? 1 : 2);
  };
  const int ma = argmin(alpha[0], alpha[1], alpha[2]);
  const int mb = argmin(alpha[0] + beta[0], alpha[1] + beta[1], alpha[2] + beta[2]);
  if (ma == mb) {
    piece(ma, 0.0, 1.0);
  } else {
    auto cross_at = [&](int i, int j) {  // s where lines i and j meet, clamped to [0, 1]
      const double den = beta[j] - beta[i];
      const double s = den != 0.0 ? (alpha[i] - alpha[j]) / den : 0.0;
      return std::min(1.0, std::max(0.0, s));
    };
    const int mc = 3 - ma - mb;
    const double s = cross_at(ma, mb);
    if (alpha[mc] + beta[mc] * s >= alpha[ma] + beta[ma] * s) {
      piece(ma, 0.0, s);
      piece(mb, s, 1.0);
    } else {
      const double s1 = cross_at(ma, mc), s2 = std::max(s1, cross_at(mc, mb));
      piece(ma, 0.0, s1);
      piece(mc, s1, s2);
      piece(mb, s2, 1.0);
    }
  }
  // phi = 3 lambda: trapezoid 1/2 and Simpson-type 1/6 weights times 3.
  i0 = 1.5 * j0;
  i1 = 0.5 * j1;
}

// Phi_T = int_P phi_T dA by the divergence theorem about a reference point X. On the
// sub-triangle R_k(T) phi = 3 lambda_k is affine, so div(phi (x - X)) = grad phi . (x - X) +
// 2 phi = 3 phi - 3 lambda_k(X), and phi (x - X) is continuous across the sub-triangle lines:
//     Phi = ( oint phi (x - X) . n ds + sum_k 3 lambda_k(X) |P n R_k| ) / 3.
// R_m is the sub-triangle holding P's centroid. When P stays in R_m, X is the centroid
// projected onto the line of edge m (lambda_m(X) = 0): no area term at all. When P reaches
// into R_k too (a strip running into a corner of T), X is the vertex where edges m and k meet
// (lambda_m = lambda_k = 0 there); only a third sub-triangle, if P reaches it as well, needs
// its piece (P clipped to R_k, an area ~d^2 for a strip of depth d). Near edge m, phi and
// (x - X) . n on P's boundary are both ~d and of one sign, so a thin overlap gets Phi to the
// relative error of its vertices' distances to the edge, ~eps L / d
// (tests/unit/test_narrow_phase.cpp, ThinStripEnergy*).
// Replaced: X = G, the centroid of T, where every 3 lambda_k(G) = 1 and the terms sum to the
// overlap area: Phi = (oint phi (x - G) . n ds + A_P) / 3 needs no clipping but subtracts two
// quantities of the size of A_P; a strip 1e-12 m deep lost every digit of its energy and came
// out negative (docs/robustness.md section 2). Tried: each piece P n R_m integrated as a fan
// of 3 lambda_m (exact and stable, but six clips whenever P reaches a corner of T): 134 k
// instructions per step of the resting 188-triangle arch against 114 k here and 101 k with
// the unstable form (callgrind, steps 1000 to 2000).
struct PhiReference {
  double x = 0.0, y = 0.0;  // X (local coordinates)
  double corners = 0.0;     // sum over k of 3 lambda_k(X) |P n R_k|
};

// (px, py): T's vertices; (cx, cy): P's centroid.
inline PhiReference phi_reference(const Bary& T, const double* px, const double* py, const Poly& P,
                                  double cx, double cy) {
  const double l0 = T.lam[0](cx, cy), l1 = T.lam[1](cx, cy), l2 = T.lam[2](cx, cy);
  const int m = l0 <= l1 ? (l0 <= l2 ? 0 : 2) : (l1 <= l2 ? 1 : 2);
  const Affine& lm = T.lam[m];
  // Which other sub-triangles P reaches into (P convex: none of R_k when lambda_k is not below
  // lambda_m, or not below lambda_j, at any vertex of P).
  const int k1 = m == 2 ? 0 : m + 1, k2 = m == 0 ? 2 : m - 1;
  bool k1_above_m = true, k1_above_k2 = true, k2_above_m = true, k2_above_k1 = true;
  for (int v = 0; v < P.n; ++v) {
    const double am = lm(P.x[v], P.y[v]), a1 = T.lam[k1](P.x[v], P.y[v]),
                 a2 = T.lam[k2](P.x[v], P.y[v]);
    k1_above_m = k1_above_m && a1 >= am;
    k1_above_k2 = k1_above_k2 && a1 >= a2;
    k2_above_m = k2_above_m && a2 >= am;
    k2_above_k1 = k2_above_k1 && a2 >= a1;
  }
  bool reaches[3] = {false, false, false};
  reaches[k1] = !(k1_above_m || k1_above_k2);
  reaches[k2] = !(k2_above_m || k2_above_k1);
  PhiReference r;
  if (!(reaches[k1] || reaches[k2])) {
    // Within R_m: X = the centroid projected onto edge line m (lambda_m(X) = 0).
    const double s = (m == 0 ? l0 : (m == 1 ? l1 : l2)) / (lm.b * lm.b + lm.c * lm.c);
    r.x = cx - s * lm.b;
    r.y = cy - s * lm.c;
    return r;
  }
  // P reaches a corner of T: X = the vertex where edge m meets the edge of a sub-triangle P
  // reaches (lambda_m = lambda_k = 0 there), so only the third sub-triangle, if P reaches it
  // as well, needs its piece.
  const int k = reaches[k1] ? k1 : k2;
  const int third = 3 - m - k;  // also the vertex opposite it: on edges m and k
  r.x = px[third];
  r.y = py[third];
  if (reaches[third]) {
    const Affine& lk = T.lam[third];
    const Affine& lj = T.lam[k];
    Poly half, piece;
    clip(P, {lm.a - lk.a, lm.b - lk.b, lm.c - lk.c}, half);  // lambda_m >= lambda_k
    clip(half, {lj.a - lk.a, lj.b - lk.b, lj.c - lk.c}, piece);
    r.corners = 3.0 * lk(r.x, r.y) * moments(piece).area;
  }
  return r;
}

// Field of triangle T (barycentric lam, vertices px, py) over P, by boundary integrals;
// (cx, cy) P's centroid.
// phi_T vanishes on T's edges, so only the edges of P lying on the other triangle count
// (on_c == other_is_c). With n ds = (dy, -dx) ds_param on a counter-clockwise polygon:
//     int_P grad phi dA     = sum (dy, -dx) I0,
//     int_P x grad phi dA   = sum (dy, -dx) Ix - (Phi, 0),   (integration by parts)
//     int_P y grad phi dA   = sum (dy, -dx) Iy - (0, Phi),
//     Phi = int_P phi dA    = (sum (dy, -dx) . (Ix - X_x I0, Iy - X_y I0) + corners) / 3
// (phi_reference above).
inline Field field_over(const Bary& T, const double* px, const double* py, const Poly& P, double cx,
                        double cy, unsigned char other_is_c) {
  Field f;
  const PhiReference ref = phi_reference(T, px, py, P, cx, cy);
  double j0x = 0.0, j0y = 0.0, jxx = 0.0, jxy = 0.0, jyx = 0.0, jyy = 0.0, k = 0.0;
  for (int q = 0, r = 1; q < P.n; ++q, r = (r + 1 == P.n ? 0 : r + 1)) {
    if (P.on_c[q] != other_is_c) continue;
    const double ax = P.x[q], ay = P.y[q], dx = P.x[r] - ax, dy = P.y[r] - ay;
    double alpha[3], beta[3];
    for (int m = 0; m < 3; ++m) {
      alpha[m] = T.lam[m](ax, ay);
      beta[m] = T.lam[m].b * dx + T.lam[m].c * dy;
    }
    double i0, i1;
    integrate_phi(alpha, beta, i0, i1);
    const double ix = ax * i0 + dx * i1, iy = ay * i0 + dy * i1;
    // Outward normal times length: (dy, -dx).
    j0x += dy * i0;
    j0y -= dx * i0;
    jxx += dy * ix;
    jxy -= dx * ix;
    jyx += dy * iy;
    jyy -= dx * iy;
    k += dy * ((ax - ref.x) * i0 + dx * i1) - dx * ((ay - ref.y) * i0 + dy * i1);
  }
  f.phi = (k + ref.corners) * (1.0 / 3.0);
  f.g[0][0] = j0x;
  f.g[1][0] = j0y;
  f.g[0][1] = jxx - f.phi;
  f.g[1][1] = jxy;
  f.g[0][2] = jyx;
  f.g[1][2] = jyy - f.phi;
  return f;
}

}  // namespace

PairForce triangle_pair_force(const std::array<Vec2, 3>& c, const std::array<Vec2, 3>& t,
                              double penalty) {
  // Local coordinates about c's first vertex.
  const double ox = c[0].x, oy = c[0].y;
  double cx[3], cy[3], tx[3], ty[3];
  for (int k = 0; k < 3; ++k) {
    cx[k] = c[k].x - ox;
    cy[k] = c[k].y - oy;
    tx[k] = t[k].x - ox;
    ty[k] = t[k].y - oy;
  }
  const Edges ec = edge_functions(cx, cy);
  const double t_twice_area = (tx[1] - tx[0]) * (ty[2] - ty[0]) - (ty[1] - ty[0]) * (tx[2] - tx[0]);
  PairForce out;  // zero until the overlap is known (one returned object: no copy)
  if (!(ec.twice_area > 0.0) || !(t_twice_area > 0.0)) return out;

  // Overlap P = t clipped by the three edges of c (no division before we know it is there).
  Poly p0, p1;
  p0.n = 3;
  for (int k = 0; k < 3; ++k) {
    p0.x[k] = tx[k];
    p0.y[k] = ty[k];
    p0.on_c[k] = 0;
  }
  clip<3>(p0, ec.e[0], p1);
  if (p1.n < 3) return out;
  clip(p1, ec.e[1], p0);
  if (p0.n < 3) return out;
  clip(p0, ec.e[2], p1);
  const Poly& P = p1;
  if (P.n < 3) return out;
  const Moments mp = moments(P);
  if (!(mp.area > kMinOverlapFraction * 0.5 * std::min(ec.twice_area, t_twice_area))) return out;

  const Edges et = edge_functions(tx, ty);
  const Bary bc = barycentric(ec), bt = barycentric(et);
  const double c0x = mp.sx / mp.area, c0y = mp.sy / mp.area;  // overlap centroid
  const Field fc = field_over(bc, cx, cy, P, c0x, c0y, 0);
  const Field ft = field_over(bt, tx, ty, P, c0x, c0y, 1);

  // Nodal forces: f_i(c) = Ep [(G_c - G_t) l_i^c - Phi_t grad N_i^c], and symmetrically.
  double d[2][3];
  for (int r = 0; r < 2; ++r)
    for (int k = 0; k < 3; ++k) d[r][k] = penalty * (fc.g[r][k] - ft.g[r][k]);
  const double phi_c = penalty * fc.phi, phi_t = penalty * ft.phi;
  for (int i = 0; i < 3; ++i) {
    const Affine& l = bc.lam[i];
    out.on_c[i].x = d[0][0] * l.a + d[0][1] * l.b + d[0][2] * l.c - phi_t * l.b;
    out.on_c[i].y = d[1][0] * l.a + d[1][1] * l.b + d[1][2] * l.c - phi_t * l.c;
    const Affine& m = bt.lam[i];
    out.on_t[i].x = -(d[0][0] * m.a + d[0][1] * m.b + d[0][2] * m.c) - phi_c * m.b;
    out.on_t[i].y = -(d[1][0] * m.a + d[1][1] * m.b + d[1][2] * m.c) - phi_c * m.c;
  }
  out.resultant = {d[0][0], d[1][0]};
  out.area = mp.area;
  out.energy = phi_c + phi_t;

  // Point of action: on the line of action, nearest the overlap centroid (local coordinates).
  out.centroid = {c0x + ox, c0y + oy};
  const double fx = d[0][0], fy = d[1][0];
  const double moment = d[1][1] - d[0][2];  // Ep int (x d_y phi - y d_x phi), c minus t
  const double f2 = fx * fx + fy * fy;
  for (int i = 0; i < 3; ++i) {
    out.bary_c[i] = bc.lam[i](c0x, c0y);
    out.bary_t[i] = bt.lam[i](c0x, c0y);
  }
  out.point = out.centroid;
  if (f2 > 0.0) {
    const double s = (moment - (c0x * fy - c0y * fx)) / f2;
    out.point = {c0x + s * fy + ox, c0y - s * fx + oy};
  }
  return out;
}

}  // namespace voussoir

#include "contact/narrow_phase.hpp"

#include <algorithm>
#include <cmath>

namespace voussoir {

namespace {

// A triangle clipped by 3 lines has at most 6 vertices; 8 leaves room.
constexpr int kMaxPoly = 8;

// Convex polygon, counter-clockwise.
struct Poly {
  int n = 0;
  double x[kMaxPoly], y[kMaxPoly];
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

// Keeps the part of convex `in` where f >= 0 (Sutherland-Hodgman, one line).
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
      ++m;
    }
    if (fq >= 0.0) {
      out.x[m] = in.x[q];
      out.y[m] = in.y[q];
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

// Moments of the part of convex P where fv >= 0 (fv: a function's values at P's vertices,
// affine along the edges), as clip then moments would give them, without forming the
// polygon: its vertices are summed into the fan as the clip emits them.
inline Moments clipped_moments(const Poly& P, const double* fv) {
  Moments m;
  double x0 = 0.0, y0 = 0.0, px = 0.0, py = 0.0, a2 = 0.0, sx6 = 0.0, sy6 = 0.0;
  int count = 0;
  auto emit = [&](double x, double y) {
    if (count == 0) {
      x0 = x, y0 = y;
    } else if (count >= 2) {
      const double ux = px - x0, uy = py - y0, vx = x - x0, vy = y - y0;
      const double cr = ux * vy - uy * vx;
      a2 += cr;
      sx6 += (ux + vx) * cr;
      sy6 += (uy + vy) * cr;
    }
    px = x, py = y;
    ++count;
  };
  const int n = P.n;
  for (int q = 0, p = n - 1; q < n; p = q++) {
    const double fp = fv[p], fq = fv[q];
    if ((fp < 0.0 && fq > 0.0) || (fp > 0.0 && fq < 0.0)) {
      const double s = fp / (fp - fq);
      emit(P.x[p] + s * (P.x[q] - P.x[p]), P.y[p] + s * (P.y[q] - P.y[p]));
    }
    if (fq >= 0.0) emit(P.x[q], P.y[q]);
  }
  if (count < 3) return m;
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
  std::array<double, 3> at_centroid{};  // the barycentric coordinates at P's centroid
};

// Field of triangle T (barycentric lam, vertices px, py) over the overlap P, whose area and
// first moments are mp and centroid (cx, cy), by sub-triangle pieces.
// On the sub-triangle R_k(T) (lambda_k the smallest coordinate) phi = 3 lambda_k with the
// constant gradient g_k = 3 grad lambda_k, so with M(Q) = int_Q (1, x, y) dA
//     G = sum_k g_k (x) M(P n R_k),     Phi = 3 sum_k int_{P n R_k} lambda_k dA.
// R_m is the sub-triangle holding P's centroid; P n R_m is not formed: it is P less the
// pieces Q_k = P n R_k of the other sub-triangles P reaches into, so
//     G   = g_m (x) M(P) + sum_k (g_k - g_m) (x) M(Q_k),
//     Phi = 3 [ int_P lambda_m dA + sum_k int_{Q_k} (lambda_k - lambda_m) dA ].
// Q_k is P clipped by lambda_k <= lambda_m, and by lambda_k <= lambda_j as well when P also
// reaches the third sub-triangle R_j (otherwise the first cut already leaves R_k only). A
// joint's strip along edge m reaches R_k only in a sliver ~d x d at a corner of T (d: its
// depth), so the pieces are small and the clips short.
// int_P lambda_m dA by the fan from a vertex V of edge m (lambda_m(V) = 0): each edge p -> q
// of P spans the signed triangle (V, p, q), over which the affine lambda_m averages
// (lambda_m(p) + lambda_m(q)) / 3. Near edge m both the fan triangle's height over the edge
// line and lambda_m are ~d, so a thin overlap gets Phi to the relative error of its vertices'
// distances to the edge, ~eps L / d (tests/unit/test_narrow_phase.cpp, ThinStripEnergy*),
// with no quantity of the overlap's size subtracted (docs/robustness.md section 2).
inline Field field_over(const Bary& T, const double* px, const double* py, const Poly& P,
                        const Moments& mp, double cx, double cy) {
  const double l0 = T.lam[0](cx, cy), l1 = T.lam[1](cx, cy), l2 = T.lam[2](cx, cy);
  const int m = l0 <= l1 ? (l0 <= l2 ? 0 : 2) : (l1 <= l2 ? 1 : 2);
  const int k1 = m == 2 ? 0 : m + 1, k2 = m == 0 ? 2 : m - 1;
  const Affine& lm = T.lam[m];
  // lambda_m at P's vertices, and which other sub-triangles P reaches into (P convex: none of
  // R_k when lambda_k is not below lambda_m, or not below lambda_j, at any vertex of P).
  double am[kMaxPoly], a1v[kMaxPoly], a2v[kMaxPoly];
  double depth = 0.0;  // largest lambda_m over P
  bool k1_above_m = true, k1_above_k2 = true, k2_above_m = true, k2_above_k1 = true;
  for (int v = 0; v < P.n; ++v) {
    const double a = lm(P.x[v], P.y[v]), a1 = T.lam[k1](P.x[v], P.y[v]),
                 a2 = T.lam[k2](P.x[v], P.y[v]);
    am[v] = a, a1v[v] = a1, a2v[v] = a2;
    depth = std::max(depth, a);
    k1_above_m = k1_above_m && a1 >= a;
    k1_above_k2 = k1_above_k2 && a1 >= a2;
    k2_above_m = k2_above_m && a2 >= a;
    k2_above_k1 = k2_above_k1 && a2 >= a1;
  }
  const bool reach1 = !(k1_above_m || k1_above_k2), reach2 = !(k2_above_m || k2_above_k1);
  // int_P lambda_m dA, fan from V = vertex k1 (on edge m: the edge opposite vertex m).
  const double vx = px[k1], vy = py[k1];
  double fan = 0.0;
  for (int q = 0, r = 1; q < P.n; ++q, r = (r + 1 == P.n ? 0 : r + 1)) {
    const double ux = P.x[q] - vx, uy = P.y[q] - vy, wx = P.x[r] - vx, wy = P.y[r] - vy;
    fan += (ux * wy - uy * wx) * (am[q] + am[r]);
  }
  double lam_integral = fan * (1.0 / 6.0);  // (1/2 cross) x (sum / 3)
  // G row 0: x component of grad phi, row 1: y; columns (1, x, y).
  const double gmx = 3.0 * lm.b, gmy = 3.0 * lm.c;
  double gx[3] = {gmx * mp.area, gmx * mp.sx, gmx * mp.sy};
  double gy[3] = {gmy * mp.area, gmy * mp.sx, gmy * mp.sy};
  // Where lambda_m <= 1/3 on all of P, lambda_k <= lambda_m implies lambda_j = 1 - lambda_m -
  // lambda_k >= 1/3 >= lambda_k: the first cut alone leaves R_k (a joint's strip, lambda_m ~
  // d / h), cut with the vertex values already taken.
  const bool one_cut = depth <= 1.0 / 3.0;
  auto add_piece = [&](int k, int j, bool reach_j, const double* ak) {
    const Affine& lk = T.lam[k];
    Moments mq;
    if (!reach_j || one_cut) {
      double fv[kMaxPoly];
      for (int v = 0; v < P.n; ++v) fv[v] = am[v] - ak[v];  // lambda_k <= lambda_m
      mq = clipped_moments(P, fv);
    } else {
      const Affine& lj = T.lam[j];
      Poly half, piece;
      clip(P, {lm.a - lk.a, lm.b - lk.b, lm.c - lk.c}, half);      // lambda_k <= lambda_m
      clip(half, {lj.a - lk.a, lj.b - lk.b, lj.c - lk.c}, piece);  // lambda_k <= lambda_j
      mq = moments(piece);
    }
    if (!(mq.area > 0.0)) return;
    const double da = lk.a - lm.a, db = lk.b - lm.b, dc = lk.c - lm.c;
    lam_integral += da * mq.area + db * mq.sx + dc * mq.sy;
    const double dgx = 3.0 * db, dgy = 3.0 * dc;
    gx[0] += dgx * mq.area, gx[1] += dgx * mq.sx, gx[2] += dgx * mq.sy;
    gy[0] += dgy * mq.area, gy[1] += dgy * mq.sx, gy[2] += dgy * mq.sy;
  };
  if (reach1) add_piece(k1, k2, reach2, a1v);
  if (reach2) add_piece(k2, k1, reach1, a2v);
  Field f;
  f.at_centroid = {l0, l1, l2};
  f.phi = 3.0 * lam_integral;
  for (int c = 0; c < 3; ++c) {
    f.g[0][c] = gx[c];
    f.g[1][c] = gy[c];
  }
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
  const Field fc = field_over(bc, cx, cy, P, mp, c0x, c0y);
  const Field ft = field_over(bt, tx, ty, P, mp, c0x, c0y);

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
  out.bary_c = fc.at_centroid;
  out.bary_t = ft.at_centroid;
  out.point = out.centroid;
  if (f2 > 0.0) {
    const double s = (moment - (c0x * fy - c0y * fx)) / f2;
    out.point = {c0x + s * fy + ox, c0y - s * fx + oy};
  }
  return out;
}

}  // namespace voussoir

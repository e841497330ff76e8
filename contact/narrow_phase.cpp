#include "contact/narrow_phase.hpp"

#include <cmath>

namespace voussoir {

namespace {

// A triangle clipped by up to 5 lines has at most 8 vertices; 12 leaves room.
constexpr int kMaxPoly = 12;

struct Poly {
  int n = 0;
  double x[kMaxPoly], y[kMaxPoly];
};

// Affine function a + b x + c y.
struct Affine {
  double a = 0.0, b = 0.0, c = 0.0;
  double operator()(double x, double y) const { return a + b * x + c * y; }
};

inline Affine operator-(const Affine& p, const Affine& q) {
  return {p.a - q.a, p.b - q.b, p.c - q.c};
}

// Barycentric coordinates of a triangle as affine functions (local coordinates):
// lam[m] = cross(p[m+2] - p[m+1], x - p[m+1]) / (2 A), zero on the edge opposite vertex m.
struct Bary {
  Affine lam[3];
  double twice_area = 0.0;
};

inline Bary barycentric(const double* px, const double* py) {
  Bary t;
  t.twice_area = (px[1] - px[0]) * (py[2] - py[0]) - (py[1] - py[0]) * (px[2] - px[0]);
  if (!(t.twice_area > 0.0)) return t;
  const double inv = 1.0 / t.twice_area;
  for (int m = 0; m < 3; ++m) {
    const int i = (m + 1) % 3, j = (m + 2) % 3;
    const double ex = px[j] - px[i], ey = py[j] - py[i];
    // cross(e, x - p_i) = -ey x + ex y + (ey px_i - ex py_i)
    t.lam[m] = {(ey * px[i] - ex * py[i]) * inv, -ey * inv, ex * inv};
  }
  return t;
}

// Keeps the part of convex `in` where f >= 0 (Sutherland-Hodgman, one line).
inline void clip(const Poly& in, const Affine& f, Poly& out) {
  out.n = 0;
  if (in.n == 0) return;
  double fp = f(in.x[in.n - 1], in.y[in.n - 1]);
  double px = in.x[in.n - 1], py = in.y[in.n - 1];
  for (int k = 0; k < in.n; ++k) {
    const double qx = in.x[k], qy = in.y[k], fq = f(qx, qy);
    if ((fp < 0.0 && fq > 0.0) || (fp > 0.0 && fq < 0.0)) {
      const double s = fp / (fp - fq);
      out.x[out.n] = px + s * (qx - px);
      out.y[out.n] = py + s * (qy - py);
      ++out.n;
    }
    if (fq >= 0.0) {
      out.x[out.n] = qx;
      out.y[out.n] = qy;
      ++out.n;
    }
    px = qx;
    py = qy;
    fp = fq;
  }
}

// Splits convex `in` by the line f = 0 into the parts f <= 0 (neg) and f >= 0 (pos).
inline void split(const Poly& in, const Affine& f, Poly& neg, Poly& pos) {
  neg.n = pos.n = 0;
  if (in.n == 0) return;
  double px = in.x[in.n - 1], py = in.y[in.n - 1];
  double fp = f(px, py);
  for (int k = 0; k < in.n; ++k) {
    const double qx = in.x[k], qy = in.y[k], fq = f(qx, qy);
    if ((fp < 0.0 && fq > 0.0) || (fp > 0.0 && fq < 0.0)) {
      const double s = fp / (fp - fq);
      const double ix = px + s * (qx - px), iy = py + s * (qy - py);
      neg.x[neg.n] = pos.x[pos.n] = ix;
      neg.y[neg.n] = pos.y[pos.n] = iy;
      ++neg.n;
      ++pos.n;
    }
    if (fq <= 0.0) {
      neg.x[neg.n] = qx;
      neg.y[neg.n] = qy;
      ++neg.n;
    }
    if (fq >= 0.0) {
      pos.x[pos.n] = qx;
      pos.y[pos.n] = qy;
      ++pos.n;
    }
    px = qx;
    py = qy;
    fp = fq;
  }
}

// Area and first moments (int x dA, int y dA) of a polygon (counter-clockwise).
struct Moments {
  double area = 0.0, sx = 0.0, sy = 0.0;
};

inline Moments moments(const Poly& p) {
  Moments m;
  if (p.n < 3) return m;
  double a2 = 0.0, sx6 = 0.0, sy6 = 0.0;
  for (int k = 0, j = p.n - 1; k < p.n; j = k++) {
    const double cr = p.x[j] * p.y[k] - p.x[k] * p.y[j];
    a2 += cr;
    sx6 += (p.x[j] + p.x[k]) * cr;
    sy6 += (p.y[j] + p.y[k]) * cr;
  }
  m.area = 0.5 * a2;
  m.sx = sx6 / 6.0;
  m.sy = sy6 / 6.0;
  return m;
}

// What one triangle's potential field does over the overlap: G = sum_m g_m (A, Sx, Sy)_m
// (row 0: x component of g, row 1: y) and Phi = int phi dA.
struct Field {
  double g[2][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
  double phi = 0.0;
};

inline void add_region(const Bary& T, int m, const Poly& region, Field& f) {
  const Moments mo = moments(region);
  if (!(mo.area > 0.0)) return;
  const Affine& l = T.lam[m];
  const double gx = 3.0 * l.b, gy = 3.0 * l.c;
  f.g[0][0] += gx * mo.area;
  f.g[0][1] += gx * mo.sx;
  f.g[0][2] += gx * mo.sy;
  f.g[1][0] += gy * mo.area;
  f.g[1][1] += gy * mo.sx;
  f.g[1][2] += gy * mo.sy;
  f.phi += 3.0 * (l.a * mo.area + l.b * mo.sx + l.c * mo.sy);
}

inline int argmin3(double a, double b, double c) {
  return a <= b ? (a <= c ? 0 : 2) : (b <= c ? 1 : 2);
}

inline Field field_over(const Bary& T, const Poly& P) {
  Field f;
  // Fast path: every vertex of P in the same sub-triangle (a convex region), so all of P is.
  int m0 = -1;
  bool same = true;
  for (int k = 0; k < P.n && same; ++k) {
    const double x = P.x[k], y = P.y[k];
    const int m = argmin3(T.lam[0](x, y), T.lam[1](x, y), T.lam[2](x, y));
    if (m0 < 0) m0 = m;
    same = (m == m0);
  }
  if (same) {
    add_region(T, m0, P, f);
    return f;
  }
  // lambda_0 >= lambda_1: min is lambda_1 or lambda_2; else lambda_0 or lambda_2.
  Poly a, b, r1, r2;
  split(P, T.lam[0] - T.lam[1], b, a);
  split(a, T.lam[1] - T.lam[2], r1, r2);  // r1: lambda_1 <= lambda_2, r2: lambda_2 < lambda_1
  add_region(T, 1, r1, f);
  add_region(T, 2, r2, f);
  split(b, T.lam[0] - T.lam[2], r1, r2);  // r1: lambda_0 <= lambda_2
  add_region(T, 0, r1, f);
  add_region(T, 2, r2, f);
  return f;
}

}  // namespace

PairForce triangle_pair_force(const std::array<Vec2, 3>& c, const std::array<Vec2, 3>& t,
                              double penalty) {
  PairForce out;
  // Local coordinates about c's first vertex.
  const double ox = c[0].x, oy = c[0].y;
  double cx[3], cy[3], tx[3], ty[3];
  for (int k = 0; k < 3; ++k) {
    cx[k] = c[k].x - ox;
    cy[k] = c[k].y - oy;
    tx[k] = t[k].x - ox;
    ty[k] = t[k].y - oy;
  }
  const Bary bc = barycentric(cx, cy), bt = barycentric(tx, ty);
  if (!(bc.twice_area > 0.0) || !(bt.twice_area > 0.0)) return out;

  // Overlap P = t clipped by the three edges of c (lambda_m^c >= 0).
  Poly p0, p1;
  p0.n = 3;
  for (int k = 0; k < 3; ++k) {
    p0.x[k] = tx[k];
    p0.y[k] = ty[k];
  }
  clip(p0, bc.lam[0], p1);
  clip(p1, bc.lam[1], p0);
  clip(p0, bc.lam[2], p1);
  const Poly& P = p1;
  const Moments mp = moments(P);
  if (P.n < 3 || !(mp.area > 0.0)) return out;

  const Field fc = field_over(bc, P), ft = field_over(bt, P);

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
  const double c0x = mp.sx / mp.area, c0y = mp.sy / mp.area;
  out.centroid = {c0x + ox, c0y + oy};
  const double fx = d[0][0], fy = d[1][0];
  const double moment = d[1][1] - d[0][2];  // sum over regions of Sx g_y - Sy g_x, times Ep
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

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

// A polygon whose vertices carry the barycentric coordinates l[m] of one triangle (affine
// functions, so intersection points interpolate them exactly up to round-off).
struct BaryPoly {
  int n = 0;
  double x[kMaxPoly], y[kMaxPoly], l[3][kMaxPoly];
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
inline void clip(const Poly& in, const Affine& f, Poly& out) {
  out.n = 0;
  if (in.n == 0) return;
  double px = in.x[in.n - 1], py = in.y[in.n - 1];
  double fp = f(px, py);
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

// Keeps the part of convex `in` where l[b] - l[a] >= 0, i.e. lambda_a <= lambda_b.
inline void clip_le(const BaryPoly& in, int a, int b, BaryPoly& out) {
  out.n = 0;
  if (in.n == 0) return;
  int p = in.n - 1;
  double fp = in.l[b][p] - in.l[a][p];
  for (int q = 0; q < in.n; ++q) {
    const double fq = in.l[b][q] - in.l[a][q];
    if ((fp < 0.0 && fq > 0.0) || (fp > 0.0 && fq < 0.0)) {
      const double s = fp / (fp - fq);
      out.x[out.n] = in.x[p] + s * (in.x[q] - in.x[p]);
      out.y[out.n] = in.y[p] + s * (in.y[q] - in.y[p]);
      for (int m = 0; m < 3; ++m) out.l[m][out.n] = in.l[m][p] + s * (in.l[m][q] - in.l[m][p]);
      ++out.n;
    }
    if (fq >= 0.0) {
      out.x[out.n] = in.x[q];
      out.y[out.n] = in.y[q];
      for (int m = 0; m < 3; ++m) out.l[m][out.n] = in.l[m][q];
      ++out.n;
    }
    p = q;
    fp = fq;
  }
}

// Area and first moments (int x dA, int y dA) of a polygon (counter-clockwise).
struct Moments {
  double area = 0.0, sx = 0.0, sy = 0.0;
};

template <class P>
inline Moments moments(const P& p) {
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
  m.sx = sx6 * (1.0 / 6.0);
  m.sy = sy6 * (1.0 / 6.0);
  return m;
}

// What one triangle's potential field does over the overlap: G = sum_m g_m (A, Sx, Sy)_m
// (row 0: x component of g, row 1: y) and Phi = int phi dA.
struct Field {
  double g[2][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
  double phi = 0.0;
};

inline void add_region(const Bary& T, int m, const Moments& mo, Field& f) {
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

// Region m of P (where lambda_m is the smallest coordinate) for m = 0, 1, 2. The region that
// holds P's centroid (usually the large one) is P minus the other two, so only two regions are
// clipped (two lines each).
inline Field field_over(const Bary& T, const Poly& P, const Moments& mp) {
  Field f;
  BaryPoly a;
  a.n = P.n;
  int m0 = -1;
  bool same = true;
  for (int k = 0; k < P.n; ++k) {
    const double x = P.x[k], y = P.y[k];
    a.x[k] = x;
    a.y[k] = y;
    for (int m = 0; m < 3; ++m) a.l[m][k] = T.lam[m](x, y);
    const int m = argmin3(a.l[0][k], a.l[1][k], a.l[2][k]);
    if (m0 < 0) m0 = m;
    same = same && m == m0;
  }
  // Fast path: every vertex in the same sub-triangle (a convex region), so all of P is.
  if (same) {
    add_region(T, m0, mp, f);
    return f;
  }
  const double cx = mp.sx / mp.area, cy = mp.sy / mp.area;
  const int big = argmin3(T.lam[0](cx, cy), T.lam[1](cx, cy), T.lam[2](cx, cy));
  Moments rest = mp;
  BaryPoly tmp, region;
  for (int m = 0; m < 3; ++m) {
    if (m == big) continue;
    clip_le(a, m, (m + 1) % 3, tmp);
    clip_le(tmp, m, (m + 2) % 3, region);
    const Moments mo = moments(region);
    if (!(mo.area > 0.0)) continue;
    add_region(T, m, mo, f);
    rest.area -= mo.area;
    rest.sx -= mo.sx;
    rest.sy -= mo.sy;
  }
  if (rest.area > 0.0) add_region(T, big, rest, f);
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
  const Edges ec = edge_functions(cx, cy), et = edge_functions(tx, ty);
  if (!(ec.twice_area > 0.0) || !(et.twice_area > 0.0)) return out;

  // Overlap P = t clipped by the three edges of c (no division before we know it is there).
  Poly p0, p1;
  p0.n = 3;
  for (int k = 0; k < 3; ++k) {
    p0.x[k] = tx[k];
    p0.y[k] = ty[k];
  }
  clip(p0, ec.e[0], p1);
  if (p1.n < 3) return out;
  clip(p1, ec.e[1], p0);
  if (p0.n < 3) return out;
  clip(p0, ec.e[2], p1);
  const Poly& P = p1;
  if (P.n < 3) return out;
  const Moments mp = moments(P);
  if (!(mp.area > 0.0)) return out;

  const Bary bc = barycentric(ec), bt = barycentric(et);
  const Field fc = field_over(bc, P, mp), ft = field_over(bt, P, mp);

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

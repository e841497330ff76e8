// Narrow phase (contact/narrow_phase.hpp) and the friction kernel (contact/friction.hpp):
// one triangle pair against hand-derived closed forms, equilibrium, symmetry, energy/force
// consistency, and the stick/slip return mapping.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "contact/friction.hpp"
#include "contact/narrow_phase.hpp"

using namespace voussoir;

namespace {

using Tri = std::array<Vec2, 3>;

// Area and centroid of a triangle (vertex average): the only geometry the closed forms use.
struct Piece {
  double area, cx, cy;
};
Piece triangle_piece(Vec2 a, Vec2 b, Vec2 c) {
  const double area = 0.5 * std::abs((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
  return {area, (a.x + b.x + c.x) / 3.0, (a.y + b.y + c.y) / 3.0};
}
Piece merge(Piece p, Piece q) {
  const double a = p.area + q.area;
  return {a, (p.area * p.cx + q.area * q.cx) / a, (p.area * p.cy + q.area * q.cy) / a};
}

double sum_x(const PairForce& f) {
  double s = 0.0;
  for (int k = 0; k < 3; ++k) s += f.on_c[k].x + f.on_t[k].x;
  return s;
}
double sum_y(const PairForce& f) {
  double s = 0.0;
  for (int k = 0; k < 3; ++k) s += f.on_c[k].y + f.on_t[k].y;
  return s;
}
// Total moment about the origin of all six nodal forces.
double total_moment(const Tri& c, const Tri& t, const PairForce& f) {
  double m = 0.0;
  for (int k = 0; k < 3; ++k) {
    m += c[k].x * f.on_c[k].y - c[k].y * f.on_c[k].x;
    m += t[k].x * f.on_t[k].y - t[k].y * f.on_t[k].x;
  }
  return m;
}
double force_scale(const PairForce& f) {
  double s = 0.0;
  for (int k = 0; k < 3; ++k)
    s += std::hypot(f.on_c[k].x, f.on_c[k].y) + std::hypot(f.on_t[k].x, f.on_t[k].y);
  return s;
}

// Swapping the triangles swaps the forces (g: the pair evaluated as (t, c)).
void expect_swapped(const PairForce& f, const PairForce& g, double tol) {
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(g.on_t[k].x, f.on_c[k].x, tol);
    EXPECT_NEAR(g.on_t[k].y, f.on_c[k].y, tol);
    EXPECT_NEAR(g.on_c[k].x, f.on_t[k].x, tol);
    EXPECT_NEAR(g.on_c[k].y, f.on_t[k].y, tol);
  }
}

// f = -dE/dx for every one of the 12 coordinates (central differences of `step`).
void expect_conservative(const Tri& c, const Tri& t, double Ep, const PairForce& f, double step,
                         double tol, const std::string& what) {
  for (int which = 0; which < 2; ++which)
    for (int k = 0; k < 3; ++k)
      for (int axis = 0; axis < 2; ++axis) {
        Tri cp = c, cm = c, tp = t, tm = t;
        Tri& P = which == 0 ? cp : tp;
        Tri& Mi = which == 0 ? cm : tm;
        (axis == 0 ? P[k].x : P[k].y) += step;
        (axis == 0 ? Mi[k].x : Mi[k].y) -= step;
        const double dE =
            (triangle_pair_force(cp, tp, Ep).energy - triangle_pair_force(cm, tm, Ep).energy) /
            (2 * step);
        const Vec2 fk = which == 0 ? f.on_c[k] : f.on_t[k];
        EXPECT_NEAR(-dE, axis == 0 ? fk.x : fk.y, tol)
            << what << " tri " << which << " node " << k << " axis " << axis;
      }
}

}  // namespace

// Contactor c = (0,0), (L,0), (p,h) (an asymmetric triangle standing on its base), target t a
// wide, deep triangle whose top edge lies at y = d, so the overlap is the trapezoid of c below
// y = d and, for t, lies wholly in the sub-triangle of its top edge: grad phi_t = (0, -3/D).
// For c the strip splits (lines from the base corners to the centroid G = ((L+p)/3, h/3)):
//   middle   (sub-triangle of the base)        grad phi_c = (0, 3/h),
//   left     corner triangle (0,0), ((L+p)d/h, d), (pd/h, d),   grad phi_c = 3 (h, -p)/(L h),
//   right    corner triangle (L,0), (L+(p-L)d/h, d), (L+(p-2L)d/h, d),
//                                                 grad phi_c = 3 (-h, p-L)/(L h).
// Areas: corners L d^2/(2h) each, middle L (d - 3 d^2/(2h)), overlap L (d - d^2/(2h)); so
//   F_c = Ep [ (0, 3 L d/h - 6 L d^2/h^2) + (0, 3/D) L (d - d^2/(2h)) ]     (F_x = 0: the
// corner x components cancel). Each piece's force acts at its centroid; the line of action is
// x = M / F_y with M the sum of the piece moments; energy E = Ep sum_pieces 3 lambda(centroid) A.
TEST(NarrowPhase, FlatStripMatchesClosedForm) {
  const double L = 1.0, h = 0.8, p = 0.3, d = 0.01, D = 10.0, B = 10.0, Ep = 2.0e9;
  const Tri c = {Vec2{0.0, 0.0}, Vec2{L, 0.0}, Vec2{p, h}};
  const Tri t = {Vec2{L / 2 - B, d}, Vec2{L / 2, d - D}, Vec2{L / 2 + B, d}};
  const PairForce f = triangle_pair_force(c, t, Ep);

  // Pieces of the overlap (hand geometry).
  const Vec2 a0{0.0, 0.0}, a1{L, 0.0};
  const Vec2 left_top{p * d / h, d}, right_top{L + (p - L) * d / h, d};
  const Vec2 gl_top{(L + p) * d / h, d}, gr_top{L + (p - 2 * L) * d / h, d};
  const Piece left = triangle_piece(a0, gl_top, left_top);
  const Piece right = triangle_piece(a1, right_top, gr_top);
  const Piece middle = merge(triangle_piece(a0, a1, gr_top), triangle_piece(a0, gr_top, gl_top));
  const Piece overlap = merge(merge(left, right), middle);
  EXPECT_NEAR(left.area, L * d * d / (2 * h), 1e-15);
  EXPECT_NEAR(middle.area, L * (d - 1.5 * d * d / h), 1e-15);
  EXPECT_NEAR(f.area, L * (d - d * d / (2 * h)), 1e-14);

  const double gtx = 0.0, gty = -3.0 / D;
  const double glx = 3.0 * h / (L * h), gly = -3.0 * p / (L * h);
  const double grx = -3.0 * h / (L * h), gry = 3.0 * (p - L) / (L * h);
  const double gmx = 0.0, gmy = 3.0 / h;
  const double Fy = Ep * (3 * L * d / h - 6 * L * d * d / (h * h) + 3.0 / D * overlap.area);
  EXPECT_NEAR(f.resultant.x, 0.0, 1e-12 * Fy);
  EXPECT_NEAR(f.resultant.y, Fy, 1e-12 * Fy);
  // Sum of the nodal forces on c equals the resultant.
  EXPECT_NEAR(f.on_c[0].y + f.on_c[1].y + f.on_c[2].y, Fy, 1e-12 * Fy);

  // Line of action.
  auto moment = [](const Piece& q, double gx, double gy) {
    return q.area * (q.cx * gy - q.cy * gx);
  };
  const double M = Ep * (moment(left, glx, gly) + moment(right, grx, gry) +
                         moment(middle, gmx, gmy) - moment(overlap, gtx, gty));
  EXPECT_NEAR(f.point.x, M / Fy, 1e-12 * L);
  // Nearest point of the (vertical) line to the overlap centroid: same height.
  EXPECT_NEAR(f.point.y, overlap.cy, 1e-12 * L);
  EXPECT_NEAR(f.centroid.x, overlap.cx, 1e-12 * L);
  EXPECT_GT(std::abs(M / Fy - overlap.cx), 1e-6);  // the asymmetry is actually tested

  // Energy: phi = 3 lambda on each piece, lambda affine so its integral is A lambda(centroid).
  //   middle: lambda = y/h; left: lambda_1 = (h x - p y)/(L h); right: lambda_0 =
  //   (-h (x - L) + (p - L) y)/(L h); t: phi_t = 3 (d - y)/D.
  const double Ec =
      3.0 * (middle.area * middle.cy / h + left.area * (h * left.cx - p * left.cy) / (L * h) +
             right.area * (-h * (right.cx - L) + (p - L) * right.cy) / (L * h));
  const double Et = 3.0 * overlap.area * (d - overlap.cy) / D;
  EXPECT_NEAR(f.energy, Ep * (Ec + Et), 1e-12 * Ep * (Ec + Et));
}

// A vertex of c poking down into the flat top of a wide target: the overlap is the triangle
// (0,-d), (+-a d/H, 0), split by the vertical line through the apex (which passes through c's
// centroid) into two halves with grad phi_c = (-+3/(2a), 3/(2H)); for t, grad phi_t = (0,-3/D).
// F_c = Ep (a d^2 / H) (0, 3/(2H) + 3/D), acting on the line x = x0 (mirror symmetry).
TEST(NarrowPhase, CornerIntoFaceMatchesClosedForm) {
  const double a = 0.4, H = 1.2, d = 0.02, D = 5.0, x0 = 0.37, Ep = 1.0e10;
  const Tri c = {Vec2{x0, -d}, Vec2{x0 + a, H - d}, Vec2{x0 - a, H - d}};
  const Tri t = {Vec2{x0 - 8.0, 0.0}, Vec2{x0 + 1.0, -D}, Vec2{x0 + 8.0, 0.0}};
  const PairForce f = triangle_pair_force(c, t, Ep);
  const double area = a * d * d / H;
  const double Fy = Ep * area * (3.0 / (2 * H) + 3.0 / D);
  EXPECT_NEAR(f.area, area, 1e-12 * area);
  EXPECT_NEAR(f.resultant.x, 0.0, 1e-12 * Fy);
  EXPECT_NEAR(f.resultant.y, Fy, 1e-12 * Fy);
  EXPECT_NEAR(f.point.x, x0, 1e-12);
  EXPECT_NEAR(f.point.y, -d / 3.0, 1e-12);  // overlap centroid height
  // Each half pushes its side of c inward: the x forces on c's two upper nodes have opposite
  // signs (right half pulls left, left half pushes right).
  EXPECT_NEAR(f.on_c[1].x + f.on_c[2].x + f.on_c[0].x, 0.0, 1e-12 * Fy);
}

TEST(NarrowPhase, SeparatedOrTouchingGivesNothing) {
  const Tri c = {Vec2{0, 0}, Vec2{1, 0}, Vec2{0, 1}};
  const Tri far = {Vec2{2, 2}, Vec2{3, 2}, Vec2{2, 3}};
  const Tri touching = {Vec2{0, 0}, Vec2{1, -1}, Vec2{1, 0}};  // shares the edge (0,0)-(1,0)
  for (const Tri& t : {far, touching}) {
    const PairForce f = triangle_pair_force(c, t, 1e10);
    EXPECT_EQ(f.area, 0.0);
    EXPECT_EQ(f.energy, 0.0);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(f.on_c[k].x, 0.0);
      EXPECT_EQ(f.on_t[k].y, 0.0);
    }
  }
}

// Random overlapping pairs: forces and moments sum to zero, swapping the triangles swaps the
// forces, and the nodal forces are minus the gradient of the energy (central differences).
TEST(NarrowPhase, RandomPairsBalanceSwapAndAreConservative) {
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double Ep = 3.0e9;
  int tested = 0;
  for (int trial = 0; trial < 400 && tested < 150; ++trial) {
    Tri c, t;
    for (int k = 0; k < 3; ++k) {
      c[k] = {u(rng) + 10.0, u(rng) - 7.0};
      t[k] = {0.8 * u(rng) + 10.3, 0.8 * u(rng) - 7.2};
    }
    auto ccw = [](Tri& q) {
      const double cr =
          (q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[1].y - q[0].y) * (q[2].x - q[0].x);
      if (cr < 0) std::swap(q[1], q[2]);
      return std::abs(cr);
    };
    if (ccw(c) < 0.05 || ccw(t) < 0.05) continue;
    const PairForce f = triangle_pair_force(c, t, Ep);
    if (!(f.area > 1e-3)) continue;
    ++tested;
    const double scale = force_scale(f);
    EXPECT_NEAR(sum_x(f), 0.0, 1e-12 * scale);
    EXPECT_NEAR(sum_y(f), 0.0, 1e-12 * scale);
    EXPECT_NEAR(total_moment(c, t, f), 0.0, 1e-12 * scale * 12.0);  // lever arm ~ |x| ~ 12

    const PairForce g = triangle_pair_force(t, c, Ep);
    EXPECT_NEAR(g.area, f.area, 1e-10 * f.area);
    EXPECT_NEAR(g.energy, f.energy, 1e-10 * f.energy);
    expect_swapped(f, g, 1e-10 * scale);
    expect_conservative(c, t, Ep, f, 1e-6, 1e-5 * scale, "trial " + std::to_string(trial));
  }
  EXPECT_GE(tested, 100);
}

// The resultant equals Munjiza's Ep int (grad phi_c - grad phi_t) dA for a deep overlap of two
// identical triangles shifted sideways; with no shift the integrals cancel exactly (phi_c and
// phi_t are the same field) and so does the force.
TEST(NarrowPhase, IdenticalTrianglesCancel) {
  const Tri c = {Vec2{0, 0}, Vec2{2, 0}, Vec2{0.5, 1.5}};
  const PairForce f = triangle_pair_force(c, c, 1e9);
  EXPECT_NEAR(f.area, 1.5, 1e-12);
  EXPECT_NEAR(f.resultant.x, 0.0, 1e-3);
  EXPECT_NEAR(f.resultant.y, 0.0, 1e-3);
  // Energy 2 Ep int phi dA = 2 Ep A / 3 (phi is a pyramid of height 1 over the triangle).
  EXPECT_NEAR(f.energy, 2.0 * 1e9 * 1.5 / 3.0, 1e-3);
}

namespace {

// Long-double reference of the energy Ep int_P (phi_c + phi_t) dA (x86-64: 64-bit mantissa,
// 2048 times finer than double), written independently of the kernel: P = t clipped by c's
// edges, then each piece P n R_m(T) (the sub-triangle of T where lambda_m is the smallest
// coordinate, phi_T = 3 lambda_m) contributes 3 A lambda_m(centroid), exact for affine lambda.
using LD = long double;
struct PointLD {
  LD x, y;
};
using PolyLD = std::vector<PointLD>;

// Keeps {p : a + b x + c y >= 0} of a convex polygon.
PolyLD clip_ld(const PolyLD& in, LD a, LD b, LD c) {
  PolyLD out;
  for (std::size_t q = 0; q < in.size(); ++q) {
    const PointLD& P = in[(q + in.size() - 1) % in.size()];
    const PointLD& Q = in[q];
    const LD fp = a + b * P.x + c * P.y, fq = a + b * Q.x + c * Q.y;
    if ((fp < 0) != (fq < 0) && fp != 0 && fq != 0) {
      const LD s = fp / (fp - fq);
      out.push_back({P.x + s * (Q.x - P.x), P.y + s * (Q.y - P.y)});
    }
    if (fq >= 0) out.push_back(Q);
  }
  return out;
}

// Barycentric coordinate m of triangle T as (a, b, c): lambda = a + b x + c y.
std::array<LD, 3> lambda_ld(const std::array<PointLD, 3>& T, int m) {
  const PointLD& i = T[(m + 1) % 3];
  const PointLD& j = T[(m + 2) % 3];
  const LD area2 = (T[1].x - T[0].x) * (T[2].y - T[0].y) - (T[1].y - T[0].y) * (T[2].x - T[0].x);
  const LD ex = j.x - i.x, ey = j.y - i.y;
  return {(ey * i.x - ex * i.y) / area2, -ey / area2, ex / area2};
}

LD potential_ld(const std::array<PointLD, 3>& T, const PolyLD& P) {
  LD sum = 0;
  for (int m = 0; m < 3; ++m) {
    const auto lm = lambda_ld(T, m), li = lambda_ld(T, (m + 1) % 3), lj = lambda_ld(T, (m + 2) % 3);
    PolyLD piece = clip_ld(P, li[0] - lm[0], li[1] - lm[1], li[2] - lm[2]);
    piece = clip_ld(piece, lj[0] - lm[0], lj[1] - lm[1], lj[2] - lm[2]);
    if (piece.size() < 3) continue;
    LD a2 = 0, sx = 0, sy = 0;  // twice the area, 6 x first moments (about piece[0])
    for (std::size_t k = 2; k < piece.size(); ++k) {
      const LD ux = piece[k - 1].x - piece[0].x, uy = piece[k - 1].y - piece[0].y;
      const LD vx = piece[k].x - piece[0].x, vy = piece[k].y - piece[0].y;
      const LD cr = ux * vy - uy * vx;
      a2 += cr;
      sx += (ux + vx) * cr;
      sy += (uy + vy) * cr;
    }
    if (!(a2 > 0)) continue;
    const LD gx = piece[0].x + sx / (3 * a2), gy = piece[0].y + sy / (3 * a2);
    sum += 3 * (a2 / 2) * (lm[0] + lm[1] * gx + lm[2] * gy);
  }
  return sum;
}

LD energy_ld(const Tri& c, const Tri& t, double Ep) {
  // Local coordinates about c's first vertex, as exact as the inputs (Sterbenz does not hold
  // in general, but long double keeps 11 more bits of every difference).
  std::array<PointLD, 3> cl, tl;
  for (int k = 0; k < 3; ++k) {
    cl[k] = {LD(c[k].x) - LD(c[0].x), LD(c[k].y) - LD(c[0].y)};
    tl[k] = {LD(t[k].x) - LD(c[0].x), LD(t[k].y) - LD(c[0].y)};
  }
  PolyLD P(tl.begin(), tl.end());
  for (int m = 0; m < 3; ++m) {
    const auto l = lambda_ld(cl, m);
    P = clip_ld(P, l[0], l[1], l[2]);
  }
  if (P.size() < 3) return 0;
  return Ep * (potential_ld(cl, P) + potential_ld(tl, P));
}

// Relative error of the energy allowed for a strip of depth d and length L: the clipped
// vertices carry an error of a few eps L across the strip, i.e. a relative error ~eps L / d
// of the distances phi is made of (the bound of the rounding, not a fitted figure); the
// factor 8 covers the handful of roundings per vertex (measured: up to 0.3 eps L / d).
// 1e-12 for the deep end.
double strip_tolerance(double depth, double length) {
  return 1e-12 + 8.0 * std::numeric_limits<double>::epsilon() * length / depth;
}

}  // namespace

// The example of docs/robustness.md section 2: the arch with E = 200 GPa at step 2, a strip
// ~2.9e-12 m deep under a 0.2 m face. The energy was -2.2e-6 J (the former Phi subtracted two
// quantities of the size of the overlap area); the exact one is ~1.7e-10 J.
TEST(NarrowPhase, ThinStripEnergyOfTheStiffArch) {
  const Tri c = {Vec2{-1.1000000000000001, -2.911501233756747e-12},
                 Vec2{-0.90000000000000002, -2.9004055445454038e-12},
                 Vec2{-0.97974648680724874, 0.14086627841769794}};
  const Tri t = {Vec2{-1.1000000000000001, 0.0}, Vec2{-1.1000000000000001, -0.20000000000000001},
                 Vec2{-0.90000000000000002, 0.0}};
  const double Ep = 5.556e12;
  const PairForce f = triangle_pair_force(c, t, Ep);
  const double ref = static_cast<double>(energy_ld(c, t, Ep));
  EXPECT_GT(ref, 1.5e-10);
  EXPECT_LT(ref, 2.0e-10);
  EXPECT_GT(f.energy, 0.0);
  EXPECT_NEAR(f.energy, ref, strip_tolerance(2.9e-12, 0.2) * ref);
  // And the same with the roles swapped (the kernel is symmetric).
  const PairForce g = triangle_pair_force(t, c, Ep);
  EXPECT_NEAR(g.energy, ref, strip_tolerance(2.9e-12, 0.2) * ref);
  std::printf("[thin strip] stiff arch pair: energy %.6e J (swapped %.6e J), reference %.6e J, "
              "area %.4e m2, resultant (%.6e, %.6e) N\n",
              f.energy, g.energy, ref, f.area, f.resultant.x, f.resultant.y);
}

// Strips of depth 1e-3 to 1e-13 of the element size L between a contactor face and a target
// face that are nearly parallel (slope 1e-3 of the depth), rotated and moved away from the
// origin, the contactor face shorter than the target's (P inside one sub-triangle of t) or
// overhanging one end (P reaching t's corner, cut by its sub-triangle line). The energy
// matches the long-double reference to the rounding bound and is never negative.
TEST(NarrowPhase, ThinStripEnergyMatchesLongDoubleReference) {
  const double L = 0.2, Ep = 5.556e12, angle = 0.37, ox = 12.3, oy = -4.56;
  auto place = [&](double x, double y) {
    return Vec2{ox + std::cos(angle) * x - std::sin(angle) * y,
                oy + std::sin(angle) * x + std::cos(angle) * y};
  };
  int checked = 0;
  for (const double overhang : {-0.1, 0.15}) {  // contactor's left end inside / outside t
    for (int e = 3; e <= 13; ++e) {
      const double d = L * std::pow(10.0, -e);
      const Tri t = {place(0.0, 0.0), place(0.3 * L, -0.9 * L), place(L, 0.0)};
      const Tri c = {place(-overhang * L, -d), place(0.8 * L, -d * (1.0 - 1e-3)),
                     place(0.35 * L, 0.7 * L)};
      const PairForce f = triangle_pair_force(c, t, Ep);
      const double ref = static_cast<double>(energy_ld(c, t, Ep));
      ASSERT_GT(ref, 0.0) << "d/L = 1e-" << e;
      EXPECT_GE(f.energy, 0.0) << "d/L = 1e-" << e;
      const double rel = std::abs(f.energy - ref) / ref;
      EXPECT_LE(rel, strip_tolerance(d, L)) << "d/L = 1e-" << e << " overhang " << overhang
                                            << ": energy " << f.energy << " J, reference " << ref;
      std::printf(
          "[thin strip] overhang %5.2f d/L 1e-%02d energy %.6e J reference %.6e J "
          "relative error %.1e (allowed %.1e)\n",
          overhang, e, f.energy, ref, rel, strip_tolerance(d, L));
      ++checked;
    }
  }
  EXPECT_EQ(checked, 22);
}

// Joint strips, the overlaps of a dry joint: two faces nearly parallel, pressed by 1e-2 to
// 1e-5 of their length, each end of the strip at a corner of c, of t or of both (slivers of
// the sub-triangles next to the face), tilted and moved away from the origin. The forces sum to zero with zero moment, swapping the
// triangles swaps them, they are minus the gradient of the energy (central differences, steps
// of 1e-3 of the depth), and the energy matches the long-double reference to the rounding
// bound.
TEST(NarrowPhase, JointStripsBalanceAndAreConservative) {
  const double L = 0.2, Ep = 5.556e12, angle = -1.1, ox = -3.7, oy = 8.9;
  auto place = [&](double x, double y) {
    return Vec2{ox + std::cos(angle) * x - std::sin(angle) * y,
                oy + std::sin(angle) * x + std::cos(angle) * y};
  };
  int checked = 0;
  for (const double left : {-0.1, 0.0, 0.12})      // c's left end beyond, at, inside t's
    for (const double right : {-0.07, 0.0, 0.09})  // same at the right end
      for (const int e : {2, 3, 5}) {
        const double d = L * std::pow(10.0, -e);
        const Tri t = {place(0.0, 0.0), place(0.45 * L, -0.8 * L), place(L, 0.0)};
        const Tri c = {place(left * L, -d), place((1.0 - right) * L, -d * (1.0 + 2e-2)),
                       place(0.6 * L, 0.75 * L)};
        const PairForce f = triangle_pair_force(c, t, Ep);
        ASSERT_GT(f.area, 0.0);
        const double ref = static_cast<double>(energy_ld(c, t, Ep));
        EXPECT_NEAR(f.energy, ref, strip_tolerance(d, L) * ref) << left << " " << right << " " << e;
        const double scale = force_scale(f);
        EXPECT_NEAR(sum_x(f), 0.0, 1e-12 * scale);
        EXPECT_NEAR(sum_y(f), 0.0, 1e-12 * scale);
        EXPECT_NEAR(total_moment(c, t, f), 0.0, 1e-11 * scale * 10.0);  // lever arm ~ 10
        expect_swapped(f, triangle_pair_force(t, c, Ep), 1e-10 * scale);
        expect_conservative(c, t, Ep, f, 1e-3 * d, 1e-6 * scale,
                            std::to_string(left) + " " + std::to_string(right) + " d/L 1e-" +
                                std::to_string(e));
        ++checked;
      }
  EXPECT_EQ(checked, 27);
}

// Energy is never negative, whatever the overlap: random thin and deep overlaps.
TEST(NarrowPhase, EnergyNeverNegative) {
  std::mt19937_64 rng(777);
  std::uniform_real_distribution<double> u(-1.0, 1.0), lg(-14.0, -1.0);
  const double Ep = 1e12;
  int touching = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    // c's base on y = -depth (slightly tilted), t's top edge on y = 0, random lengths.
    const double d = std::pow(10.0, lg(rng));
    const Tri t = {Vec2{u(rng) - 1.0, 0.0}, Vec2{u(rng), -0.5 - 0.4 * u(rng)},
                   Vec2{u(rng) + 1.0, 0.0}};
    const Tri c = {Vec2{u(rng) - 0.5, -d * (1.0 + 0.01 * u(rng))},
                   Vec2{u(rng) + 0.5, -d * (1.0 + 0.01 * u(rng))}, Vec2{u(rng), 0.6}};
    const PairForce f = triangle_pair_force(c, t, Ep);
    ASSERT_GE(f.energy, 0.0) << "trial " << trial << " depth " << d;
    if (f.area > 0.0) ++touching;
  }
  EXPECT_GT(touching, 3000);
}

TEST(Friction, SticksBelowTheCone) {
  // Normal force up (on c): tangent e = (-1, 0). A small slip du along +x is s = -du.
  const double kt = 2e9, mu = 0.5;
  const FrictionResult r = coulomb_friction({0.0, 1000.0}, {1e-8, 0.0}, {0.0, 0.0}, kt, mu);
  EXPECT_FALSE(r.sliding);
  EXPECT_NEAR(r.force.x, -kt * 1e-8, 1e-9);  // opposes the slip of c
  EXPECT_NEAR(r.force.y, 0.0, 1e-12);
  EXPECT_EQ(r.dissipated, 0.0);
  EXPECT_NEAR(r.stored, 0.5 * kt * 1e-16, 1e-12);
  // History: a further slip adds to the stored one.
  const FrictionResult r2 = coulomb_friction({0.0, 1000.0}, {1e-8, 0.0}, r.slip, kt, mu);
  EXPECT_NEAR(r2.force.x, -kt * 2e-8, 1e-9);
}

TEST(Friction, SlipsAtTheCapAndDissipates) {
  const double kt = 2e9, mu = 0.5, fn = 1000.0, du = 1e-6;
  const FrictionResult r = coulomb_friction({0.0, fn}, {du, 0.0}, {0.0, 0.0}, kt, mu);
  EXPECT_TRUE(r.sliding);
  EXPECT_NEAR(std::hypot(r.force.x, r.force.y), mu * fn, 1e-9);
  EXPECT_LT(r.force.x, 0.0);
  const double s_el = mu * fn / kt;
  EXPECT_NEAR(std::abs(r.slip.x), s_el, 1e-18);
  EXPECT_NEAR(r.dissipated, mu * fn * (du - s_el), 1e-12);
  // Reversing the slip first unloads elastically (no dissipation while |f| < cap).
  const FrictionResult back = coulomb_friction({0.0, fn}, {-0.5 * s_el, 0.0}, r.slip, kt, mu);
  EXPECT_FALSE(back.sliding);
  EXPECT_NEAR(back.force.x, -0.5 * mu * fn, 1e-9);
  // No normal force: no friction at all.
  const FrictionResult none = coulomb_friction({0.0, 0.0}, {du, 0.0}, {1e-9, 0.0}, kt, mu);
  EXPECT_EQ(none.force.x, 0.0);
  EXPECT_EQ(none.stored, 0.0);
}

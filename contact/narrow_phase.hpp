#pragma once
// Narrow phase: Munjiza's potential-based penalty contact between two triangles.
//
// Potential. Every triangle T carries phi_T(x) = 3 min_k lambda_k(x), lambda_k its barycentric
// coordinates (linear shape functions N_k). phi_T = 1 at the centroid, 0 on the edges, and on
// the sub-triangle R_k(T) = (centroid, edge opposite vertex m) -- where lambda_m is the
// smallest coordinate -- it is linear, phi_T = 3 lambda_m, with the constant gradient
//     g_m(T) = 3 grad lambda_m = 3 n_m / h_m          (n_m inward unit normal, h_m height).
//
// Energy. For the pair (c, t) with overlap P = c n t, per unit thickness,
//     E = Ep  integral_P (phi_c + phi_t) dA                                         [J/m]
// (Munjiza 2004, ch. 2: each triangle's material sits in the other's potential field; the
// pair is always evaluated both ways, so there is no contactor/target asymmetry.)
//
// Force (exact gradient of E). Take the half E_t = Ep int_P phi_t dA: the material of c moving
// in the field of t. phi_t vanishes on t's edges, so only c's motion and t's field matter:
//  - node j of t moves the field: d lambda_m / d X_j = -lambda_j grad lambda_m, hence
//        f_j(t) = -dE_t/dX_j = +Ep int_P N_j^t grad phi_t dA;
//  - node i of c moves the material of c (Reynolds transport with the affine velocity N_i^c):
//        f_i(c) = -dE_t/dx_i = -Ep int_P (N_i^c grad phi_t + phi_t grad N_i^c) dA.
// Summing both halves, the resultant on c is Munjiza's
//     F_c = Ep int_P (grad phi_c - grad phi_t) dA = -F_t,
// the force on c pushes it out of t (grad phi_t points into t). The forces -g dA on c and
// +g dA on t act at the same point x, so with linear N the pair's forces sum to zero and their
// moments cancel exactly. The "area change" term phi_t grad N_i^c (absent from the classical
// distribution) has zero resultant (sum_i grad N_i = 0) and zero moment
// (sum_i x_i (x) grad N_i = I is symmetric); it only makes the nodal forces the exact gradient
// of E when c deforms, which closes the energy balance.
//
// What is needed. With G_T = int_P grad phi_T (x) (1, x, y) dA (a 2x3 matrix) and
// Phi_T = int_P phi_T dA, every integral above is a combination of them
// (int N dA-type weights: N = alpha + beta x + gamma y, l = (alpha, beta, gamma)):
//     f_i(c) = Ep [ (G_c - G_t) l_i^c - Phi_t grad N_i^c ],
//     f_j(t) = Ep [ (G_t - G_c) l_j^t - Phi_c grad N_j^t ],   E = Ep (Phi_c + Phi_t).
//
// Evaluation (exact, edge-wise, by sub-triangle pieces). P is obtained by clipping t against
// c's three edges (Sutherland-Hodgman, convex, at most 6 vertices); its area and first
// moments are summed as a fan from its own first vertex. Every integral below is such a sum
// over the edges of the clipped overlap or of a piece clipped from it (Green's theorem: the
// edge-wise integration of docs/design.md "Contact"). On the sub-triangle R_k(T) phi_T = 3 lambda_k has the
// constant gradient g_k, so G_T = sum_k g_k (x) int_{P n R_k} (1, x, y) dA. With R_m the
// sub-triangle holding P's centroid, P n R_m is P less the pieces P n R_k of the other
// sub-triangles that P reaches into (found from the barycentric coordinates at P's vertices):
//     G_T   = g_m (x) M(P) + sum_k (g_k - g_m) (x) M(P n R_k),   M(Q) = int_Q (1, x, y) dA,
//     Phi_T = 3 int_P lambda_m dA + 3 sum_k int_{P n R_k} (lambda_k - lambda_m) dA,
// each piece P clipped by lambda_k <= lambda_m (and by lambda_k <= lambda_j too, unless
// lambda_m <= 1/3 on P makes that cut empty). A joint's strip of depth d lies in R_m but for
// slivers ~d x d at T's corners, so the pieces are small and cut in one pass. int_P lambda_m
// dA is the fan of P from a vertex of edge m (where lambda_m = 0): near the edge the fan
// triangles' heights and lambda_m are both ~d, so a thin overlap gets Phi to the relative
// error of its vertices' distances to the edge, ~eps L / d (narrow_phase.cpp field_over;
// tests/unit/test_narrow_phase.cpp, ThinStripEnergy*). Coordinates are shifted to a local
// origin (c's first vertex): overlaps at rest are ~1e-10 m deep and absolute coordinates
// would cancel catastrophically.
//
// Point of action. The forces on c have resultant F and moment M = sum (x F_y - y F_x) about
// the origin (the area-change term contributes neither); their line of action is
// {x : x F_y - y F_x = M}. We report the point of that line nearest the overlap centroid C0:
//     x_F = C0 + (M - C0 x F) / |F|^2 (F_y, -F_x)         (C0 if F = 0).
//
// Tried and replaced (same forces to round-off, measured with callgrind on one strip-shaped
// overlap): splitting P into the three sub-triangle regions by clipping for every integral
// (~3000 instructions per pair) and a fan of signed triangles from G cut at the sub-triangle
// lines (~3150), against ~2060 for an envelope form: by
// the divergence theorem int_P grad phi (x) (1, x, y) dA became integrals of phi along the
// edges of P lying on the other triangle, where phi = 3 min lambda is the lower envelope of
// three lines, integrated piece by piece, and Phi came from the divergence theorem about a
// point on an edge line of T. On church B the pieces above take 1962
// instructions per touching pair against 2313 for the envelope form: the envelope
// integrals cost more than the one clip of each small corner sliver (callgrind). The first
// Phi, (oint phi (x - G) . n ds + A_P) / 3 with G the centroid of
// the triangle, subtracted two quantities of the size of the overlap area: for a resting
// strip ~1e-12 m deep it lost every digit of the energy (negative values;
// docs/robustness.md section 2).
//
// Negligible overlaps. An overlap smaller than kMinOverlapFraction of the smaller triangle's
// area counts as no contact (no force, no energy, friction history reset). Such overlaps are
// the corner touches of neighbouring triangles along a joint (in the settled 1388-triangle
// arch: areas 1e-27 to 1e-20 m2, forces ~1e-6 N against ~1e3 N through the joint; 86 of
// the 158 overlapping pairs); skipping them right after the clip cuts the instructions of the
// contact stage there by 27% (callgrind). A resting face-to-face strip of depth d has
// p = Ep (3/h_c + 3/h_t) d ~ 6 Ep d / h (p: contact pressure) and a relative area
// L d / (L h / 2) = p / (3 Ep), so the cut-off reaches real contacts only below
// p = 3e-13 Ep, 0.3 Pa at the default Ep of a 40 GPa stone (a sheet of paper weighs ~1 Pa).
//
// Units: Ep in Pa, multiplied by the out-of-plane thickness [m] before calling (the kernel
// takes `penalty` = Ep x thickness [N/m2]); forces N, energy J, area m2.

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "contact/broad_phase.hpp"
#include "core/model.hpp"

namespace voussoir {

// Overlaps below this fraction of the smaller triangle's area are ignored (dimensionless).
inline constexpr double kMinOverlapFraction = 1e-13;

struct PairForce {
  std::array<Vec2, 3> on_c{}, on_t{};        // nodal forces on c and on t [N]
  Vec2 resultant;                            // total force on c (= minus total on t) [N]
  double area = 0.0;                         // overlap area [m2]
  double energy = 0.0;                       // penalty energy Ep thick int (phi_c + phi_t) dA [J]
  Vec2 point;                                // point of action of the resultant [m]
  Vec2 centroid;                             // overlap centroid [m]
  std::array<double, 3> bary_c{}, bary_t{};  // shape functions of c and t at the centroid
};

// Pre-test before the kernel: true only when triangle_pair_force(c, t, .) certainly returns
// zero, so a caller may skip it (tests/unit/test_speed.cpp checks the implication on random
// and on corner-touch pairs). Evaluated like the kernel in coordinates relative to c's first
// vertex. For each of the six edge lines of one triangle, with e_v = cross(A_j - A_i, B_v - A_i)
// at the vertices of the other triangle B (positive on A's side):
//  - separated: every e_v <= 0, the overlap has no area (2D separating-axis theorem);
//  - corner touch: exactly one e_v > 0. The part of B on A's side of the line is then the
//    corner triangle at v, of area A_B e_v^2 / ((e_v - e_a)(e_v - e_b)), and it holds the
//    overlap. When that is below kNegligibleMargin x the kernel's cut-off (kMinOverlapFraction
//    of the smaller area) the kernel discards the overlap after clipping: rejecting it here
//    changes no result. The margin leaves room for the round-off of the kernel's own area,
//    ~eps L^2, ~1e-3 of the cut-off.
// Such corner touches are the neighbours across a joint (a vertex of one block's triangle
// pressed ~1e-10 m past the other block's face line: area ~1e-20 m2 against a cut-off
// ~1e-15 m2); on the settled 48-triangle arch 19 of the 31 pairs that pass the
// separating-axis test. Callgrind on that arch: this test ~110 instructions per pair on average
// over the 55 pairs that pass the boxes, against ~575 for clipping a corner touch in the
// kernel; 62.6e3 -> 55.5e3 instructions per step with the same final state.
// Tried and rejected (callgrind, same arch): all 18 edge values first, then the corner pass
// (+7e3 per step); the separation pass first with the values kept for the corner pass (+4e3);
// trying first the line that rejected the pair at the previous step (a per-pair hint): +2.5e3
// (the first lines tried usually reject already, and the generic line code costs more).
inline constexpr double kNegligibleMargin = 0.25;

inline bool overlap_negligible(const std::array<Vec2, 3>& c, const std::array<Vec2, 3>& t) {
  const double ox = c[0].x, oy = c[0].y;
  const double cx[3] = {0.0, c[1].x - ox, c[2].x - ox}, cy[3] = {0.0, c[1].y - oy, c[2].y - oy};
  const double tx[3] = {t[0].x - ox, t[1].x - ox, t[2].x - ox};
  const double ty[3] = {t[0].y - oy, t[1].y - oy, t[2].y - oy};
  const double c2 = cx[1] * cy[2] - cy[1] * cx[2];  // twice the areas
  const double t2 = (tx[1] - tx[0]) * (ty[2] - ty[0]) - (ty[1] - ty[0]) * (tx[2] - tx[0]);
  // Twice the area below which an overlap is certainly discarded; NaN for an inverted or
  // degenerate triangle (every comparison with it is false: only separation rejects).
  double cut = kNegligibleMargin * kMinOverlapFraction * std::min(c2, t2);
  if (!(cut > 0.0)) cut = std::numeric_limits<double>::quiet_NaN();
  // Some edge line of A leaves on its side nothing of B, or a corner of B below the cut-off.
  auto beyond_an_edge = [cut](const double* ax, const double* ay, const double* bx,
                              const double* by, double b2) {
    for (int i = 0; i < 3; ++i) {
      const int j = i == 2 ? 0 : i + 1;
      const double ex = ax[j] - ax[i], ey = ay[j] - ay[i];
      const double e0 = ex * (by[0] - ay[i]) - ey * (bx[0] - ax[i]);
      const double e1 = ex * (by[1] - ay[i]) - ey * (bx[1] - ax[i]);
      const double e2 = ex * (by[2] - ay[i]) - ey * (bx[2] - ax[i]);
      if (e0 <= 0.0 && e1 <= 0.0 && e2 <= 0.0) return true;
      double ev, ea, eb;  // exactly one vertex inside, or next line
      if (e0 > 0.0) {
        if (e1 > 0.0 || e2 > 0.0) continue;
        ev = e0, ea = e1, eb = e2;
      } else if (e1 > 0.0) {
        if (e2 > 0.0) continue;
        ev = e1, ea = e0, eb = e2;
      } else {
        ev = e2, ea = e0, eb = e1;
      }
      if (b2 * ev * ev <= cut * (ev - ea) * (ev - eb)) return true;
    }
    return false;
  };
  return beyond_an_edge(cx, cy, tx, ty, t2) || beyond_an_edge(tx, ty, cx, cy, c2);
}

// A lower bound of the distance between triangles c and t [m] (counter-clockwise vertices):
// the largest clearance of one triangle's three vertices beyond an edge line of the other (the
// separating-axis theorem: a line with one triangle on its inner side and the other at least s
// beyond it keeps them at least s apart). 0 when no edge line separates them (touching or
// overlapping), or when either triangle is inverted or degenerate. Not on the hot path (the
// contact stage calls it once for a pair found apart, contact/contact.cpp note_apart), so in
// plain vector form.
inline double separation_lower_bound(const std::array<Vec2, 3>& c, const std::array<Vec2, 3>& t) {
  auto cross = [](Vec2 o, Vec2 a, Vec2 b) {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
  };
  if (!(cross(c[0], c[1], c[2]) > 0.0) || !(cross(t[0], t[1], t[2]) > 0.0)) return 0.0;
  double best = 0.0;
  for (const auto* pair : {&c, &t}) {
    const std::array<Vec2, 3>& a = *pair;
    const std::array<Vec2, 3>& b = pair == &c ? t : c;
    for (int i = 0; i < 3; ++i) {
      const Vec2 p = a[i], q = a[(i + 1) % 3];
      // |pq| x the signed distance of b's nearest vertex from the line, positive inside a.
      double nearest = -std::numeric_limits<double>::infinity();
      for (const Vec2& v : b) nearest = std::max(nearest, cross(p, q, v));
      if (nearest < 0.0) best = std::max(best, -nearest / std::hypot(q.x - p.x, q.y - p.y));
    }
  }
  return best;
}

// Contact between triangles c and t (vertices counter-clockwise, current positions).
// `penalty` = Ep x out-of-plane thickness [N/m2]. Zero everything (area included) when they
// do not overlap, when the overlap is negligible (above), or when either triangle is inverted
// or degenerate.
PairForce triangle_pair_force(const std::array<Vec2, 3>& c, const std::array<Vec2, 3>& t,
                              double penalty);

}  // namespace voussoir

#pragma once
// Finite-strain constant-strain triangle (CST) with a St Venant-Kirchhoff law and Munjiza's
// viscous damping. Pure kernels (`cst_force`, `cst_cauchy_stress`, `cst_frequency_bound`) that
// tests call directly, and the element stage (`add_element_forces`) that advance() calls.
//
// Kinematics. Reference nodes X0, X1, X2 (counter-clockwise), current nodes x0, x1, x2,
// velocities v0, v1, v2. With the reference edge matrix M = [X1-X0, X2-X0] and its inverse
// B = M^-1 (Triangles::b00..b11, row-major), the map X -> x is affine on the triangle and
//     F    = [x1-x0, x2-x0] B          (deformation gradient, 2x2)
//     Fdot = [v1-v0, v2-v0] B          (its rate)
// The reference shape-function gradients are the rows of B and minus their sum:
//     g1 = (b00, b01),  g2 = (b10, b11),  g0 = -(g1 + g2),   F = sum_a x_a (x) g_a.
//
// Elastic law (St Venant-Kirchhoff, 2D). Green-Lagrange strain E = (F^T F - I) / 2,
//     second Piola-Kirchhoff  S = lambda tr(E) I + 2 mu E,
//     energy density          W = lambda/2 tr(E)^2 + mu E:E        [J/m3]
//     first Piola-Kirchhoff   P = F S,      Cauchy  sigma = F S F^T / J,   J = det F.
// lambda is the 2D first Lame constant (Material::lame_lambda_2d: the 3D value in plane
// strain, the condensed 2 lambda mu / (lambda + 2 mu) in plane stress), mu the shear modulus.
// E depends on F only through F^T F, so any rigid rotation R (F = R) gives E = 0, S = 0 and
// zero force: objectivity holds for every angle, up to round-off in F^T F.
//
// Damping (Munjiza). Cauchy viscous stress  sigma_v = eta D,  D = sym(L),  L = Fdot F^-1.
// A rigid velocity field (v = w + W x with W skew) gives L = W, D = 0: no rigid-body damping.
// In Piola form, with cof(F) = J F^-T = [[F11, -F10], [-F01, F00]]:
//     P_v = J sigma_v F^-T = eta D cof(F),    L = Fdot cof(F)^T / J.
// Dissipated power of the triangle  V0 P_v : Fdot = V0 J eta D:D >= 0  (V0 = A0 x thickness).
// In advance() the velocity is the half-step velocity v^(n-1/2) (Munjiza's choice: explicit,
// no iteration); the stable time step accounts for that lag (see cst_frequency_bound).
//
// Nodal forces. With the element energy V0 W(F), the internal force on node a is
//     f_a = -d(V0 W)/dx_a (+ viscous) = -V0 (P + P_v) g_a,     f0 = -(f1 + f2)
// so the three forces sum to zero (momentum) and their moment about any point vanishes
// ((P + P_v) F^T = J (sigma + sigma_v) is symmetric).
//
// Why SVK: the simplest objective hyperelastic law, exact rotations, and at masonry strains
// (1e-4) indistinguishable from linear elasticity. Known limit, accepted: SVK softens under
// compressive stretch below ~0.58 and has no barrier against inversion; a triangle that
// crushed that far means the run is already wrong (too soft blocks or a far too large dt).
//
// Units: lengths m, velocities m/s, stresses Pa, eta Pa s, V0 m3 (area x out-of-plane
// thickness), forces N, energy J, power W.

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/model.hpp"
#include "core/node_slots.hpp"

namespace voussoir {

// Law constants of the 2D material [Pa] and the viscosity [Pa s].
struct CstLaw {
  double lambda = 0.0;  // first Lame constant of the 2D law
  double mu = 0.0;      // shear modulus
  double eta = 0.0;     // Munjiza viscosity; 0 = undamped
};

// Inverse reference edge matrix B = [X1-X0, X2-X0]^-1, row-major.
struct EdgeInverse {
  double b00 = 0.0, b01 = 0.0, b10 = 0.0, b11 = 0.0;
};

// Current positions and velocities of the three nodes of one triangle.
struct TriangleState {
  double x[3] = {0.0, 0.0, 0.0}, y[3] = {0.0, 0.0, 0.0};
  double vx[3] = {0.0, 0.0, 0.0}, vy[3] = {0.0, 0.0, 0.0};
};

// Result of one triangle: internal nodal forces [N], strain energy V0 W [J], the damping
// power V0 J eta D:D [W] (what the viscous term dissipates at this instant), and for the
// energy ledger the viscous Piola stress times the volume, V0 P_v [N m], and Fdot [1/s]
// (row-major), so that V0 P_v : Fdot' is the power of these viscous forces at other velocities.
// No default initialisers: cst_force sets every field, and zero initialisers would become
// block stores that stop the element loop from vectorizing (g++ 12, undamped variant).
struct CstForce {
  double fx[3], fy[3];
  double energy;
  double damping_power;
  double viscous[4];
  double rate[4];
};

// Symmetric 2D stress [Pa].
struct Stress2 {
  double xx = 0.0, yy = 0.0, xy = 0.0;
};

// Deformation gradient F and its rate Fdot of one triangle (row-major 2x2).
struct CstKinematics {
  double f00, f01, f10, f11;
  double d00, d01, d10, d11;  // Fdot
};

inline CstKinematics cst_kinematics(const TriangleState& s, const EdgeInverse& b) {
  const double e1x = s.x[1] - s.x[0], e1y = s.y[1] - s.y[0];
  const double e2x = s.x[2] - s.x[0], e2y = s.y[2] - s.y[0];
  const double w1x = s.vx[1] - s.vx[0], w1y = s.vy[1] - s.vy[0];
  const double w2x = s.vx[2] - s.vx[0], w2y = s.vy[2] - s.vy[0];
  CstKinematics k;
  k.f00 = e1x * b.b00 + e2x * b.b10;
  k.f01 = e1x * b.b01 + e2x * b.b11;
  k.f10 = e1y * b.b00 + e2y * b.b10;
  k.f11 = e1y * b.b01 + e2y * b.b11;
  k.d00 = w1x * b.b00 + w2x * b.b10;
  k.d01 = w1x * b.b01 + w2x * b.b11;
  k.d10 = w1y * b.b00 + w2y * b.b10;
  k.d11 = w1y * b.b01 + w2y * b.b11;
  return k;
}

// Internal forces, strain energy and damping power of one triangle of reference volume
// `volume0` (area0 x out-of-plane thickness) [m3]. Pure; see the derivation at the top.
// kDamped = false leaves out the viscous term (for law.eta = 0 it only adds zeros: the result
// is the same up to the sign of zero forces); the element stage uses it for undamped runs.
template <bool kDamped = true>
inline CstForce cst_force(const TriangleState& s, const EdgeInverse& b, double volume0,
                          const CstLaw& law) {
  const CstKinematics k = cst_kinematics(s, b);
  // Green-Lagrange strain E = (F^T F - I) / 2 (symmetric: e01 = e10).
  const double e00 = 0.5 * (k.f00 * k.f00 + k.f10 * k.f10 - 1.0);
  const double e11 = 0.5 * (k.f01 * k.f01 + k.f11 * k.f11 - 1.0);
  const double e01 = 0.5 * (k.f00 * k.f01 + k.f10 * k.f11);
  const double tr = e00 + e11;
  // S = lambda tr(E) I + 2 mu E.
  const double s00 = law.lambda * tr + 2.0 * law.mu * e00;
  const double s11 = law.lambda * tr + 2.0 * law.mu * e11;
  const double s01 = 2.0 * law.mu * e01;
  // P = F S.
  double p00 = k.f00 * s00 + k.f01 * s01;
  double p01 = k.f00 * s01 + k.f01 * s11;
  double p10 = k.f10 * s00 + k.f11 * s01;
  double p11 = k.f10 * s01 + k.f11 * s11;

  CstForce out;
  out.energy =
      volume0 * (0.5 * law.lambda * tr * tr + law.mu * (e00 * e00 + e11 * e11 + 2.0 * e01 * e01));

  // Viscous term. With M = sym(Fdot cof(F)^T) = J D (no division) and s = eta / J:
  //   P_v = eta D cof(F) = s M cof(F),   power = V0 J eta D:D = V0 s M:M.
  // The division runs beside the products instead of ahead of them (shorter dependency chain),
  // and the term has no branch (eta = 0 just gives zeros) so the element stage vectorizes
  // across triangles. A degenerate or inverted triangle (J <= 0) gets no damping rather than
  // a division by 0.
  if constexpr (kDamped) {
    const double J = k.f00 * k.f11 - k.f01 * k.f10;
    const double j_pos = J > 0.0 ? J : std::numeric_limits<double>::infinity();
    const double sc = law.eta / j_pos;  // 0 when J <= 0 (branch-free)
    // cof(F) = [[f11, -f10], [-f01, f00]].
    const double m00 = k.d00 * k.f11 - k.d01 * k.f10;
    const double m11 = -k.d10 * k.f01 + k.d11 * k.f00;
    const double m01 = 0.5 * ((-k.d00 * k.f01 + k.d01 * k.f00) + (k.d10 * k.f11 - k.d11 * k.f10));
    // M cof(F), then scaled by s.
    const double v00 = sc * (m00 * k.f11 - m01 * k.f01);
    const double v01 = sc * (-m00 * k.f10 + m01 * k.f00);
    const double v10 = sc * (m01 * k.f11 - m11 * k.f01);
    const double v11 = sc * (-m01 * k.f10 + m11 * k.f00);
    p00 += v00, p01 += v01, p10 += v10, p11 += v11;
    out.damping_power = volume0 * sc * (m00 * m00 + m11 * m11 + 2.0 * m01 * m01);
    out.viscous[0] = volume0 * v00, out.viscous[1] = volume0 * v01;
    out.viscous[2] = volume0 * v10, out.viscous[3] = volume0 * v11;
  } else {
    out.damping_power = 0.0;
    out.viscous[0] = out.viscous[1] = out.viscous[2] = out.viscous[3] = 0.0;
  }
  out.rate[0] = k.d00, out.rate[1] = k.d01, out.rate[2] = k.d10, out.rate[3] = k.d11;

  // f_a = -V0 P g_a for a = 1, 2;  f0 = -(f1 + f2).
  out.fx[1] = -volume0 * (p00 * b.b00 + p01 * b.b01);
  out.fy[1] = -volume0 * (p10 * b.b00 + p11 * b.b01);
  out.fx[2] = -volume0 * (p00 * b.b10 + p01 * b.b11);
  out.fy[2] = -volume0 * (p10 * b.b10 + p11 * b.b11);
  out.fx[0] = -(out.fx[1] + out.fx[2]);
  out.fy[0] = -(out.fy[1] + out.fy[2]);
  return out;
}

// Cauchy stress of one triangle [Pa]: elastic F S F^T / J plus, when law.eta > 0, the viscous
// eta D of the given velocities. A degenerate triangle (J <= 0) returns zero stress.
inline Stress2 cst_cauchy_stress(const TriangleState& s, const EdgeInverse& b, const CstLaw& law) {
  const CstKinematics k = cst_kinematics(s, b);
  const double J = k.f00 * k.f11 - k.f01 * k.f10;
  Stress2 out;
  if (!(J > 0.0)) return out;
  const double e00 = 0.5 * (k.f00 * k.f00 + k.f10 * k.f10 - 1.0);
  const double e11 = 0.5 * (k.f01 * k.f01 + k.f11 * k.f11 - 1.0);
  const double e01 = 0.5 * (k.f00 * k.f01 + k.f10 * k.f11);
  const double tr = e00 + e11;
  const double s00 = law.lambda * tr + 2.0 * law.mu * e00;
  const double s11 = law.lambda * tr + 2.0 * law.mu * e11;
  const double s01 = 2.0 * law.mu * e01;
  // P = F S, sigma = P F^T / J.
  const double p00 = k.f00 * s00 + k.f01 * s01, p01 = k.f00 * s01 + k.f01 * s11;
  const double p10 = k.f10 * s00 + k.f11 * s01, p11 = k.f10 * s01 + k.f11 * s11;
  const double inv_j = 1.0 / J;
  out.xx = (p00 * k.f00 + p01 * k.f01) * inv_j;
  out.yy = (p10 * k.f10 + p11 * k.f11) * inv_j;
  out.xy = (p00 * k.f10 + p01 * k.f11) * inv_j;
  if (law.eta > 0.0) {
    const double l00 = (k.d00 * k.f11 - k.d01 * k.f10) * inv_j;
    const double l01 = (-k.d00 * k.f01 + k.d01 * k.f00) * inv_j;
    const double l10 = (k.d10 * k.f11 - k.d11 * k.f10) * inv_j;
    const double l11 = (-k.d10 * k.f01 + k.d11 * k.f00) * inv_j;
    out.xx += law.eta * l00;
    out.yy += law.eta * l11;
    out.xy += law.eta * 0.5 * (l01 + l10);
  }
  return out;
}

// Bounds for the stable time step of one triangle with lumped mass (rho A0 t / 3 per node),
// linearised about the reference configuration.
//
// Let G = [g0 g1 g2] (2x3) and H = G G^T = sum_a g_a g_a^T (2x2). For nodal displacements
// u_a, grad u = sum_a u_a (x) g_a and the element energy is V0 (lambda (div u)^2/2 + mu |eps|^2).
//   (div u)^2 = (sum_a u_a . g_a)^2 <= tr(H) sum_a |u_a|^2            (Cauchy-Schwarz)
//   |eps|^2 <= |grad u|^2 <= lambda_max(H) sum_a |u_a|^2
// so the element stiffness/mass Rayleigh quotient is bounded by
//   omega_e^2 <= (3 / rho) (lambda tr(H) + 2 mu lambda_max(H))                     [1/s2]
// with equality for the breathing mode u_a = g_a of an equilateral triangle (where H is
// isotropic). Likewise the viscous form V0 eta |D|^2 gives a damping rate per unit mass
//   c_e / m <= (3 / rho) eta lambda_max(H)                                          [1/s]
// By the element eigenvalue theorem (u^T K u = sum_e u_e^T K_e u_e <= max_e omega_e^2 u^T M u,
// lumped M = sum_e M_e) these bound the whole mesh. Note that the textbook h_min / c_p
// (c_p^2 = (lambda + 2 mu) / rho) is NOT a safe CST bound: for an equilateral triangle of
// height h, omega^2 = 9 (lambda + mu) / (rho h^2) exceeds (2 c_p / h)^2 = 4 (lambda + 2 mu) /
// (rho h^2) for every nu >= 0 (5 lambda + mu > 0; 1.41x in omega^2 at nu = 0.2, plane
// strain), so h / c_p exceeds that triangle's limit 2 / omega by 19%. How loose the bound is:
// on structured right-triangle meshes the measured blow-up step is 1.23-1.33x the step it
// gives (undamped to damping factor 2; tests/unit/test_dynamics.cpp).
struct CstFrequencyBound {
  double omega_squared = 0.0;  // upper bound of the largest elastic omega^2 [1/s2]
  double damping_rate = 0.0;   // upper bound of c / m of the viscous term [1/s]
};

inline CstFrequencyBound cst_frequency_bound(const EdgeInverse& b, double density,
                                             const CstLaw& law) {
  const double g1x = b.b00, g1y = b.b01, g2x = b.b10, g2y = b.b11;
  const double g0x = -(g1x + g2x), g0y = -(g1y + g2y);
  const double hxx = g0x * g0x + g1x * g1x + g2x * g2x;
  const double hyy = g0y * g0y + g1y * g1y + g2y * g2y;
  const double hxy = g0x * g0y + g1x * g1y + g2x * g2y;
  const double tr = hxx + hyy;
  const double half_diff = 0.5 * (hxx - hyy);
  const double lmax = 0.5 * tr + std::sqrt(half_diff * half_diff + hxy * hxy);
  CstFrequencyBound out;
  out.omega_squared = 3.0 / density * (law.lambda * tr + 2.0 * law.mu * lmax);
  out.damping_rate = 3.0 / density * law.eta * lmax;
  return out;
}

// Largest stable central-difference step for a mode of angular frequency omega [1/s] and
// damping rate c/m [1/s] when the damping force uses the lagged half-step velocity:
// with g = (c/m)/2, x'' + 2 g x' + omega^2 x = 0 integrated by
//   v+ = v- + dt (-omega^2 x - 2 g v-),  x' = x + dt v+
// has the amplification matrix of trace 2 - 2 g dt - (omega dt)^2 and determinant 1 - 2 g dt;
// Jury's conditions give  dt < 2 / (g + sqrt(omega^2 + g^2))  (2/omega when undamped; the
// determinant condition dt < 1/g is then implied). Munjiza's default eta = 2 h sqrt(E rho)
// over-damps the highest element modes (g ~ 2 omega), which cuts the step by about 4x.
inline double damped_stable_step(double omega_squared, double damping_rate) {
  const double g = 0.5 * damping_rate;
  return 2.0 / (g + std::sqrt(omega_squared + g * g));
}

// Gathers the state of triangle e from the model arrays.
inline TriangleState triangle_state(const Model& model, Index e) {
  const Nodes& n = model.nodes;
  const Index v[3] = {model.tris.n0[e], model.tris.n1[e], model.tris.n2[e]};
  TriangleState s;
  for (int a = 0; a < 3; ++a) {
    s.x[a] = n.x[v[a]];
    s.y[a] = n.y[v[a]];
    s.vx[a] = n.vx[v[a]];
    s.vy[a] = n.vy[v[a]];
  }
  return s;
}

inline EdgeInverse edge_inverse(const Triangles& t, Index e) {
  return EdgeInverse{t.b00[e], t.b01[e], t.b10[e], t.b11[e]};
}

// Cauchy stress of triangle e of the model in its current state [Pa] (for output): elastic
// part plus the viscous part of the current (half-step) velocities when law.eta > 0.
Stress2 triangle_cauchy_stress(const Model& model, Index e, const CstLaw& law);

// Result of the element stage.
struct ElementStageResult {
  double strain_energy = 0.0;  // sum of V0 W over free triangles [J]
  double damping_power = 0.0;  // sum of V0 J eta D:D at the current velocities [W]
  // sum of V0 P_v(previous step) : Fdot(current velocities) [W]: the power of the previous
  // step's viscous forces at the current half-step velocity (energy ledger, engine/step.cpp).
  double previous_damping_power = 0.0;
};

// Triangles per chunk of the element loop (core/cst.cpp): the unit of vectorization and of the
// work handed to threads.
constexpr int kElementChunk = 32;

// Scratch of the threaded element stage, built at its first use for a model and kept by the
// Simulation (the triangle and node sets and the blocks' fixed flags must not change after).
//   chunk_first[k], chunk_len[k]: triangles [first, first + len) of chunk k, in the order of
//     the one-thread loop (runs of contiguous free blocks, kElementChunk triangles at a time);
//   corner_fx/fy[k * 3 kElementChunk + a kElementChunk + j]: force on corner a of triangle
//     chunk_first[k] + j (the chunk buffer layout of the kernel);
//   slots (core/node_slots.hpp): per node of a free triangle its corner slots, in ascending
//     triangle order, i.e. the order in which the one-thread loop adds them into fx[i];
//   chunk_sums[3 k ..]: energy, damping power, previous damping power of chunk k.
struct ElementWorkspace {
  std::vector<Index> chunk_first;
  std::vector<int> chunk_len;
  std::vector<double> corner_fx, corner_fy;
  NodeSlots slots;
  std::vector<double> chunk_sums;
  Index built_tris = -1, built_nodes = -1;
};

// Element stage: adds the CST forces of every triangle of a free block into nodes.fx/fy
// (triangles of fixed blocks are skipped: their nodes never move).
// `viscous` (4 x triangle count, component-major: viscous[k * ntri + e] is component k of
// V0 P_v of triangle e, row-major k = 00, 01, 10, 11; or nullptr) holds the previous step's
// viscous stress on entry and this step's on return; it feeds the exact damping work of the
// ledger (ElementStageResult::previous_damping_power).
// With a workspace, at least kParallelTriangles free triangles, more than one OpenMP thread and
// no enclosing parallel region, the stage runs on threads; the result is bit-identical to the
// one-thread loop (core/cst.cpp explains why).
ElementStageResult add_element_forces(Model& model, const CstLaw& law, double* viscous = nullptr,
                                      ElementWorkspace* work = nullptr);

// Largest element bounds over the triangles of free blocks (all blocks if none is free).
CstFrequencyBound max_frequency_bound(const Model& model, const CstLaw& law);

}  // namespace voussoir

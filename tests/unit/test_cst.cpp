// Unit tests of the finite-strain CST kernel (core/cst.hpp): objectivity under rigid rotation,
// the patch test against an independent St Venant-Kirchhoff evaluation, forces as the exact
// energy gradient, Munjiza damping (zero for rigid motion, power consistent with the forces)
// and the per-element frequency bound used by the stable time step.

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/cst.hpp"
#include "core/model.hpp"
#include "mesh/rectangle.hpp"

namespace voussoir {
namespace {

// A width x height rectangle with its lower-left corner at (x0, y0), nx x ny cells, each cell
// split into two triangles with the diagonal direction alternating (a criss-cross of
// different triangle shapes: mesh/rectangle.hpp), finalized as a one-block model.
Model make_rectangle(double width, double height, int nx, int ny, const Material& mat,
                     double x0 = 0.0, double y0 = 0.0) {
  Model model;
  model.material = mat;
  add_grid_rectangle(model, x0, y0, width, height, nx, ny, false, "test");
  finalize_model(model);
  return model;
}

Material stone(bool plane_stress = false) {
  Material m;
  m.density = 2000.0;
  m.young = 40e9;
  m.poisson = 0.2;
  m.plane_stress = plane_stress;
  return m;
}

CstLaw law_of(const Material& m, double eta = 0.0) {
  return CstLaw{m.lame_lambda_2d(), m.shear_modulus(), eta};
}

// Maps every node by x = A X + t (and sets the velocity v = Adot X + w).
void map_affine(Model& model, const Eigen::Matrix2d& a, const Eigen::Vector2d& t,
                const Eigen::Matrix2d& adot = Eigen::Matrix2d::Zero(),
                const Eigen::Vector2d& w = Eigen::Vector2d::Zero()) {
  Nodes& n = model.nodes;
  for (Index i = 0; i < n.size(); ++i) {
    const Eigen::Vector2d X(n.x0[i], n.y0[i]);
    const Eigen::Vector2d x = a * X + t, v = adot * X + w;
    n.x[i] = x.x();
    n.y[i] = x.y();
    n.vx[i] = v.x();
    n.vy[i] = v.y();
  }
}

Eigen::Matrix2d rotation(double deg) {
  const double r = deg * std::numbers::pi / 180.0;
  Eigen::Matrix2d q;
  q << std::cos(r), -std::sin(r), std::sin(r), std::cos(r);
  return q;
}

// Independent reference of the law: Cauchy stress of SVK for a deformation gradient F.
Eigen::Matrix2d svk_cauchy(const Eigen::Matrix2d& f, const CstLaw& law) {
  const Eigen::Matrix2d e = 0.5 * (f.transpose() * f - Eigen::Matrix2d::Identity());
  const Eigen::Matrix2d s = law.lambda * e.trace() * Eigen::Matrix2d::Identity() + 2.0 * law.mu * e;
  return f * s * f.transpose() / f.determinant();
}

// Assembled internal forces of the whole model (fx, fy cleared first).
ElementStageResult assemble(Model& model, const CstLaw& law) {
  std::fill(model.nodes.fx.begin(), model.nodes.fx.end(), 0.0);
  std::fill(model.nodes.fy.begin(), model.nodes.fy.end(), 0.0);
  return add_element_forces(model, law);
}

double max_abs_force(const Nodes& n) {
  double m = 0.0;
  for (Index i = 0; i < n.size(); ++i) m = std::max({m, std::abs(n.fx[i]), std::abs(n.fy[i])});
  return m;
}

TEST(Cst, RigidRotationOfAnyAngleGivesZeroStressAndForce) {
  const Material mat = stone();
  for (double deg : {30.0, 90.0, 180.0, 217.3}) {
    Model model = make_rectangle(0.4, 0.2, 8, 4, mat, -0.1, 0.3);
    const CstLaw law = law_of(mat);
    map_affine(model, rotation(deg), Eigen::Vector2d(2.5, -1.25));
    const ElementStageResult r = assemble(model, law);
    // Scales: stress E; nodal force E x cell size x thickness; energy E x area x thickness.
    const double cell = 0.05;
    EXPECT_LE(max_abs_force(model.nodes), 1e-12 * mat.young * cell * model.out_of_plane)
        << deg << " deg";
    EXPECT_LE(std::abs(r.strain_energy), 1e-12 * mat.young * 0.4 * 0.2) << deg << " deg";
    for (Index e = 0; e < model.tris.size(); ++e) {
      const Stress2 s = triangle_cauchy_stress(model, e, law);
      ASSERT_LE(std::max({std::abs(s.xx), std::abs(s.yy), std::abs(s.xy)}), 1e-12 * mat.young)
          << deg << " deg, triangle " << e;
    }
  }
}

TEST(Cst, RotationOfAStretchedBlockRotatesItsStress) {
  // Objectivity beyond zero stress: rotating a strained state by Q rotates sigma to Q sigma Q^T.
  const Material mat = stone();
  const CstLaw law = law_of(mat);
  Eigen::Matrix2d a;
  a << 1.004, 0.0015, -0.001, 0.997;
  Model model = make_rectangle(0.3, 0.3, 3, 3, mat);
  map_affine(model, a, Eigen::Vector2d::Zero());
  const Stress2 s0 = triangle_cauchy_stress(model, 4, law);
  Eigen::Matrix2d sig0;
  sig0 << s0.xx, s0.xy, s0.xy, s0.yy;
  for (double deg : {30.0, 90.0, 180.0}) {
    const Eigen::Matrix2d q = rotation(deg);
    map_affine(model, q * a, Eigen::Vector2d(1.0, 2.0));
    const Stress2 s = triangle_cauchy_stress(model, 4, law);
    const Eigen::Matrix2d expect = q * sig0 * q.transpose();
    const double tol = 1e-10 * sig0.norm();
    EXPECT_NEAR(s.xx, expect(0, 0), tol);
    EXPECT_NEAR(s.yy, expect(1, 1), tol);
    EXPECT_NEAR(s.xy, expect(0, 1), tol);
  }
}

// Patch test: under x = A X + t every triangle has F = A and the exact SVK Cauchy stress, the
// interior nodal forces cancel, and the boundary forces on an edge add up to the traction
// -P N L0 t of the first Piola stress P = F S on that edge.
void check_patch(const Material& mat, const Eigen::Matrix2d& a) {
  const double width = 0.6, height = 0.4;
  const int nx = 6, ny = 4;
  Model model = make_rectangle(width, height, nx, ny, mat);
  model.out_of_plane = 0.7;
  finalize_model(model);
  const CstLaw law = law_of(mat);
  map_affine(model, a, Eigen::Vector2d(0.3, -0.2));
  assemble(model, law);

  const Eigen::Matrix2d sigma = svk_cauchy(a, law);
  ASSERT_GT(sigma.norm(), 1e6);  // the map really strains the block
  for (Index e = 0; e < model.tris.size(); ++e) {
    const Stress2 s = triangle_cauchy_stress(model, e, law);
    const double tol = 1e-10 * sigma.norm();
    ASSERT_NEAR(s.xx, sigma(0, 0), tol) << "triangle " << e;
    ASSERT_NEAR(s.yy, sigma(1, 1), tol) << "triangle " << e;
    ASSERT_NEAR(s.xy, sigma(0, 1), tol) << "triangle " << e;
  }

  // First Piola stress P = J sigma F^-T, and the force scale |P| x cell x thickness.
  const Eigen::Matrix2d p = a.determinant() * sigma * a.inverse().transpose();
  const double force_scale = p.norm() * (width / nx) * model.out_of_plane;
  const Nodes& n = model.nodes;
  Eigen::Vector2d right_sum = Eigen::Vector2d::Zero(), total = Eigen::Vector2d::Zero();
  for (Index i = 0; i < n.size(); ++i) {
    const bool on_boundary =
        n.x0[i] < 1e-12 || n.x0[i] > width - 1e-12 || n.y0[i] < 1e-12 || n.y0[i] > height - 1e-12;
    if (!on_boundary) {
      EXPECT_LE(std::hypot(n.fx[i], n.fy[i]), 1e-10 * force_scale) << "interior node " << i;
    }
    if (n.x0[i] > width - 1e-12 && n.y0[i] > 1e-12 && n.y0[i] < height - 1e-12)
      right_sum += Eigen::Vector2d(n.fx[i], n.fy[i]);
    total += Eigen::Vector2d(n.fx[i], n.fy[i]);
  }
  // Right edge without its corners: interior right-edge nodes carry the traction of the edge
  // length (ny - 1) dy (each corner takes half a cell of its two edges).
  const Eigen::Vector2d traction =
      -p * Eigen::Vector2d(1.0, 0.0) * (height * (ny - 1) / ny) * model.out_of_plane;
  EXPECT_NEAR(right_sum.x(), traction.x(), 1e-10 * force_scale * ny);
  EXPECT_NEAR(right_sum.y(), traction.y(), 1e-10 * force_scale * ny);
  EXPECT_LE(total.norm(), 1e-10 * force_scale);  // internal forces are self-equilibrated
}

TEST(Cst, PatchTestUniformStretch) {
  Eigen::Matrix2d a;
  a << 1.01, 0.0, 0.0, 1.0;
  check_patch(stone(), a);
  check_patch(stone(true), a);
  // The uniaxial stretch value by hand (plane strain): E11 = (1.01^2 - 1)/2 = 0.01005,
  // S11 = (lambda + 2 mu) E11, sigma11 = 1.01^2 S11 / 1.01, sigma22 = lambda E11.
  const Material mat = stone();
  const CstLaw law = law_of(mat);
  Model model = make_rectangle(0.2, 0.1, 2, 1, mat);
  map_affine(model, a, Eigen::Vector2d::Zero());
  const Stress2 s = triangle_cauchy_stress(model, 1, law);
  const double e11 = 0.5 * (1.01 * 1.01 - 1.0);
  const double sxx = 1.01 * (law.lambda + 2.0 * law.mu) * e11;  // 4.51e8 Pa
  EXPECT_NEAR(s.xx, sxx, 1e-12 * sxx);
  EXPECT_NEAR(s.yy, law.lambda * e11 / 1.01, 1e-12 * sxx);
  EXPECT_NEAR(s.xy, 0.0, 1e-12 * sxx);
}

TEST(Cst, PatchTestGeneralAffineMap) {
  Eigen::Matrix2d a;
  a << 1.02, 0.013, -0.007, 0.985;
  check_patch(stone(), rotation(37.0) * a);
  check_patch(stone(true), rotation(-120.0) * a);
}

TEST(Cst, ForcesAreMinusTheEnergyGradient) {
  const Material mat = stone();
  const CstLaw law = law_of(mat);
  TriangleState s;
  const double X[3] = {0.0, 0.12, 0.03}, Y[3] = {0.0, 0.01, 0.09};
  const double mxx = X[1] - X[0], mxy = X[2] - X[0], myx = Y[1] - Y[0], myy = Y[2] - Y[0];
  const double det = mxx * myy - mxy * myx;
  const EdgeInverse b{myy / det, -mxy / det, -myx / det, mxx / det};
  // A finitely strained, rotated state (strains of a few percent).
  const double x[3] = {0.01, 0.128, 0.031}, y[3] = {-0.002, 0.02, 0.087};
  for (int a = 0; a < 3; ++a) s.x[a] = x[a], s.y[a] = y[a];
  const double v0 = 0.5 * det * 0.8;
  const CstForce f = cst_force(s, b, v0, law);
  const double delta = 1e-7;
  for (int a = 0; a < 3; ++a) {
    for (int comp = 0; comp < 2; ++comp) {
      TriangleState plus = s, minus = s;
      (comp == 0 ? plus.x : plus.y)[a] += delta;
      (comp == 0 ? minus.x : minus.y)[a] -= delta;
      const double grad =
          (cst_force(plus, b, v0, law).energy - cst_force(minus, b, v0, law).energy) / (2 * delta);
      const double force = comp == 0 ? f.fx[a] : f.fy[a];
      EXPECT_NEAR(force, -grad, 1e-6 * std::abs(force)) << "node " << a << " comp " << comp;
    }
  }
  // Momentum and angular momentum balance of the elastic forces.
  double sum_x = 0.0, sum_y = 0.0, moment = 0.0;
  for (int a = 0; a < 3; ++a) {
    sum_x += f.fx[a];
    sum_y += f.fy[a];
    moment += s.x[a] * f.fy[a] - s.y[a] * f.fx[a];
  }
  const double scale = std::abs(f.fx[1]) + std::abs(f.fy[1]);
  EXPECT_LE(std::abs(sum_x) + std::abs(sum_y), 1e-12 * scale);
  EXPECT_LE(std::abs(moment), 1e-12 * scale * 0.13);
}

TEST(Cst, DampingIgnoresRigidMotionAtAnyRotation) {
  const Material mat = stone();
  const double eta = 2.0 * 0.05 * std::sqrt(mat.young * mat.density);
  const CstLaw damped = law_of(mat, eta);
  for (double deg : {0.0, 30.0, 90.0, 180.0}) {
    Model model = make_rectangle(0.4, 0.2, 4, 2, mat);
    // Rigid motion: x = Q X + t, v = omega k x (x - c) + w  =>  Adot = omega J Q.
    const double omega = 3.0;
    Eigen::Matrix2d spin;
    spin << 0.0, -omega, omega, 0.0;
    const Eigen::Matrix2d q = rotation(deg);
    map_affine(model, q, Eigen::Vector2d(0.1, 0.2), spin * q, Eigen::Vector2d(-1.5, 4.0));
    const ElementStageResult r = assemble(model, damped);
    // Velocity scale 4 m/s: a viscous stress of eta x 1 /s would be ~1e5 Pa; demand round-off.
    EXPECT_LE(max_abs_force(model.nodes), 1e-12 * mat.young * 0.1) << deg;
    EXPECT_LE(r.damping_power, 1e-20 * eta * 0.08) << deg;
    const Stress2 s = triangle_cauchy_stress(model, 3, damped);
    EXPECT_LE(std::max({std::abs(s.xx), std::abs(s.yy), std::abs(s.xy)}), 1e-12 * mat.young);
  }
}

TEST(Cst, DampingStressAndPowerMatchTheRateOfDeformation) {
  // Stretched, rotated triangle with a general velocity field v = Adot X: the viscous Cauchy
  // stress must be eta sym(Adot A^-1), and the power of the viscous forces eta J V0 D:D.
  const Material mat = stone();
  const double eta = 1.0e6;
  Eigen::Matrix2d a, adot;
  a << 1.01, 0.02, -0.015, 0.99;
  a = rotation(50.0) * a;
  adot << 0.3, -0.7, 1.1, -0.2;
  Model model = make_rectangle(0.2, 0.2, 2, 2, mat);
  map_affine(model, a, Eigen::Vector2d(0.0, 0.0), adot);
  const Eigen::Matrix2d l = adot * a.inverse();
  const Eigen::Matrix2d d = 0.5 * (l + l.transpose());

  const Stress2 elastic = triangle_cauchy_stress(model, 2, law_of(mat));
  const Stress2 total = triangle_cauchy_stress(model, 2, law_of(mat, eta));
  EXPECT_NEAR(total.xx - elastic.xx, eta * d(0, 0), 1e-6 * eta);
  EXPECT_NEAR(total.yy - elastic.yy, eta * d(1, 1), 1e-6 * eta);
  EXPECT_NEAR(total.xy - elastic.xy, eta * d(0, 1), 1e-6 * eta);

  const ElementStageResult r_el = assemble(model, law_of(mat));
  std::vector<double> fx = model.nodes.fx, fy = model.nodes.fy;
  const ElementStageResult r = assemble(model, law_of(mat, eta));
  double viscous_power = 0.0;  // -(f_damped - f_elastic) . v
  for (Index i = 0; i < model.nodes.size(); ++i)
    viscous_power -= (model.nodes.fx[i] - fx[i]) * model.nodes.vx[i] +
                     (model.nodes.fy[i] - fy[i]) * model.nodes.vy[i];
  const double expect =
      eta * a.determinant() * 0.04 * model.out_of_plane * (d.array().square().sum());
  EXPECT_NEAR(r.damping_power, expect, 1e-9 * expect);
  EXPECT_NEAR(viscous_power, expect, 1e-9 * expect);
  EXPECT_EQ(r_el.damping_power, 0.0);
  EXPECT_DOUBLE_EQ(r.strain_energy, r_el.strain_energy);
}

// The element stiffness at the reference state by central differences of cst_force.
Eigen::Matrix<double, 6, 6> element_stiffness(const TriangleState& ref, const EdgeInverse& b,
                                              double v0, const CstLaw& law) {
  Eigen::Matrix<double, 6, 6> k;
  const double delta = 1e-7;
  for (int j = 0; j < 6; ++j) {
    TriangleState plus = ref, minus = ref;
    (j % 2 == 0 ? plus.x : plus.y)[j / 2] += delta;
    (j % 2 == 0 ? minus.x : minus.y)[j / 2] -= delta;
    const CstForce fp = cst_force(plus, b, v0, law), fm = cst_force(minus, b, v0, law);
    for (int i = 0; i < 6; ++i) {
      const double p = i % 2 == 0 ? fp.fx[i / 2] : fp.fy[i / 2];
      const double m = i % 2 == 0 ? fm.fx[i / 2] : fm.fy[i / 2];
      k(i, j) = -(p - m) / (2 * delta);
    }
  }
  return 0.5 * (k + k.transpose());
}

TEST(Cst, FrequencyBoundIsAnUpperBoundAndTightForEquilateral) {
  const Material mat = stone();
  const CstLaw law = law_of(mat);
  struct Shape {
    double x[3], y[3];
    bool equilateral;
  };
  const double s3 = std::sqrt(3.0) / 2.0;
  const Shape shapes[] = {{{0, 0.1, 0.05}, {0, 0, 0.1 * s3}, true},
                          {{0, 0.1, 0.0}, {0, 0, 0.1}, false},
                          {{0, 0.3, 0.02}, {0, 0.01, 0.04}, false},
                          {{0, 0.1, 0.05}, {0, 0, 0.01}, false}};
  for (const Shape& sh : shapes) {
    const double mxx = sh.x[1] - sh.x[0], mxy = sh.x[2] - sh.x[0];
    const double myx = sh.y[1] - sh.y[0], myy = sh.y[2] - sh.y[0];
    const double det = mxx * myy - mxy * myx;
    const EdgeInverse b{myy / det, -mxy / det, -myx / det, mxx / det};
    TriangleState ref;
    for (int a = 0; a < 3; ++a) ref.x[a] = sh.x[a], ref.y[a] = sh.y[a];
    const double area = 0.5 * det;
    const Eigen::Matrix<double, 6, 6> k = element_stiffness(ref, b, area, law);
    const double lumped = mat.density * area / 3.0;
    const double omega2 =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>>(k).eigenvalues().maxCoeff() /
        lumped;
    const CstFrequencyBound bound = cst_frequency_bound(b, mat.density, law);
    EXPECT_GE(bound.omega_squared, omega2 * (1.0 - 1e-6));
    if (sh.equilateral) {
      EXPECT_NEAR(bound.omega_squared, omega2, 1e-6 * omega2);
      // The closed form 9 (lambda + mu) / (rho h^2), h the height, and the fact that the
      // textbook h / c_p is not a safe step here: 2 / omega < h / c_p.
      const double h = 0.1 * s3;
      EXPECT_NEAR(omega2, 9.0 * (law.lambda + law.mu) / (mat.density * h * h), 1e-6 * omega2);
      EXPECT_LT(2.0 / std::sqrt(omega2), h / std::sqrt(mat.p_modulus_2d() / mat.density));
    } else {
      EXPECT_LE(bound.omega_squared, 3.0 * omega2);  // and not absurdly loose
    }
  }
}

}  // namespace
}  // namespace voussoir

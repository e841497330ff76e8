// Rigid-block limit analysis (limit/): interfaces found from block outlines, the LP against
// analytic answers (single block, stack, incline) and published arch values (Dimitri and
// Tornabene 2015, docs/regression.md), gravity-only admissibility against the minimum
// thickness of a semicircular arch (Heyman / Milankovitch: t/R ~ 0.1075 for a continuous
// arch), and two-ways checks: the primal forces satisfy every block's equilibrium and the
// friction cones, and the dual mechanism's virtual work gives back the same lambda.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/model.hpp"
#include "io/deck.hpp"
#include "limit/interfaces.hpp"
#include "limit/limit_analysis.hpp"
#include "mesh/geometry.hpp"
#include "mesh/rectangle.hpp"
#include "mesh/scene.hpp"

namespace voussoir {
namespace {

std::string case_path(const std::string& name) {
  return std::string(VOUSSOIR_SOURCE_DIR) + "/cases/" + name + ".toml";
}

Model case_model(const std::string& name, const std::vector<std::string>& sets = {}) {
  return build_model(scene_params(load_deck(case_path(name), sets)));
}

// A width x height rectangle at (x0, y0) as one block, its sides cut into nx and ny pieces
// (so its outline has collinear vertices, like a meshed block): mesh/rectangle.hpp.
Index add_cut_rectangle(Model& model, double x0, double y0, double width, double height, int nx,
                        int ny, bool fixed) {
  return add_grid_rectangle(model, x0, y0, width, height, nx, ny, fixed, fixed ? "ground" : "block",
                            GridDiagonals::Uniform, GridOutline::Nodes);
}

// Residual of every free block's equilibrium (force x, force y, moment about its centroid)
// under the primal forces of `res`, relative to the block weight (and weight x model size for
// moments); and the worst violation of N >= 0 and |S| <= mu N relative to the largest N.
struct PrimalCheck {
  double equilibrium = 0.0;
  double cone = 0.0;
};

PrimalCheck check_primal(const Model& model, const LimitResult& res, double mu, double g) {
  const std::size_t nb = model.blocks.size();
  std::vector<std::array<double, 3>> sum(nb, {0.0, 0.0, 0.0});
  std::vector<Vec2> c(nb);
  std::vector<double> w(nb);
  double size = 0.0, nmax = 0.0;
  for (std::size_t i = 0; i < nb; ++i) {
    const double a = polygon_centroid(model.blocks[i].polygon, &c[i]);
    w[i] = model.material.density * model.out_of_plane * g * a;
    for (const Vec2& p : model.blocks[i].polygon) size = std::max(size, std::hypot(p.x, p.y));
  }
  PrimalCheck out;
  for (std::size_t k = 0; k < res.interfaces.size(); ++k) {
    const Interface& f = res.interfaces[k];
    const InterfaceForces& F = res.forces[k];
    const double len = f.length();
    const Vec2 t{(f.b.x - f.a.x) / len, (f.b.y - f.a.y) / len};
    const std::array<std::pair<Vec2, std::pair<double, double>>, 2> ends = {
        {{f.a, {F.normal_a, F.shear_a}}, {f.b, {F.normal_b, F.shear_b}}}};
    for (const auto& [p, ns] : ends) {
      const auto [N, S] = ns;
      nmax = std::max(nmax, N);
      out.cone = std::max({out.cone, -N, std::abs(S) - mu * N});
      const double fx = N * f.normal.x + S * t.x, fy = N * f.normal.y + S * t.y;
      for (const auto& [blk, sgn] : {std::pair{f.block_b, 1.0}, std::pair{f.block_a, -1.0}}) {
        sum[blk][0] += sgn * fx;
        sum[blk][1] += sgn * fy;
        sum[blk][2] += sgn * ((p.x - c[blk].x) * fy - (p.y - c[blk].y) * fx);
      }
    }
  }
  out.cone /= nmax;
  const double lambda = res.gravity_only ? 0.0 : res.lambda_la;
  for (std::size_t i = 0; i < nb; ++i) {
    if (model.blocks[i].fixed) continue;
    // Loads at the centroid: (lambda W, -W), no moment about it.
    out.equilibrium =
        std::max({out.equilibrium, std::abs(sum[i][0] + lambda * w[i]) / w[i],
                  std::abs(sum[i][1] - w[i]) / w[i], std::abs(sum[i][2]) / (w[i] * size)});
  }
  return out;
}

// lambda from the dual mechanism by virtual work: the contact forces do no work on an
// associative mechanism, so lambda sum W v_x + (-sum W v_y) = 0 at the block centroids.
double lambda_from_mechanism(const Model& model, const LimitResult& res) {
  double px = 0.0, py = 0.0;
  for (std::size_t i = 0; i < model.blocks.size(); ++i) {
    Vec2 c;
    const double a = polygon_centroid(model.blocks[i].polygon, &c);
    px += a * res.velocities[i].ux;
    py += a * res.velocities[i].uy;
  }
  return py / px;
}

// ---------------------------------------------------------------- interfaces and centroids

TEST(LimitInterfaces, PolygonCentroidOfAnLShape) {
  // L: unit square [0,2]x[0,1] plus [0,1]x[1,2]: area 3, centroid (5/6, 5/6).
  const std::vector<Vec2> poly = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  Vec2 c;
  EXPECT_DOUBLE_EQ(polygon_centroid(poly, &c), 3.0);
  EXPECT_NEAR(c.x, 5.0 / 6.0, 1e-15);
  EXPECT_NEAR(c.y, 5.0 / 6.0, 1e-15);
  // Clockwise gives the same area and centroid.
  const std::vector<Vec2> cw(poly.rbegin(), poly.rend());
  EXPECT_DOUBLE_EQ(polygon_centroid(cw, &c), 3.0);
  EXPECT_NEAR(c.x, 5.0 / 6.0, 1e-15);
}

TEST(LimitInterfaces, MergesCollinearEdgesIntoOneInterfacePerFace) {
  Model m;
  add_cut_rectangle(m, 0.0, 0.0, 1.0, 1.0, 3, 2, false);  // block 0, edges cut in pieces
  add_cut_rectangle(m, 1.0, 0.25, 1.0, 0.5, 1, 5,
                    false);  // block 1: touches 0 on x = 1, y 0.25..0.75
  add_cut_rectangle(m, 2.0, 0.75, 1.0, 1.0, 2, 2, false);  // block 2: touches 1 at one corner only
  add_cut_rectangle(m, -1.0, -0.5, 4.0, 0.5, 7, 1, true);  // block 3: ground under block 0
  finalize_model(m);
  const auto faces = find_interfaces(m);
  ASSERT_EQ(faces.size(), 2u);
  // Block pair order, ends left to right / bottom to top, normal from a into b.
  EXPECT_EQ(faces[0].block_a, 0);
  EXPECT_EQ(faces[0].block_b, 1);
  EXPECT_NEAR(faces[0].a.x, 1.0, 1e-15);
  EXPECT_NEAR(faces[0].a.y, 0.25, 1e-15);
  EXPECT_NEAR(faces[0].b.y, 0.75, 1e-15);
  EXPECT_NEAR(faces[0].normal.x, 1.0, 1e-15);
  EXPECT_EQ(faces[0].joint, -1);
  EXPECT_EQ(faces[1].block_a, 0);
  EXPECT_EQ(faces[1].block_b, 3);
  EXPECT_NEAR(faces[1].a.x, 0.0, 1e-15);
  EXPECT_NEAR(faces[1].b.x, 1.0, 1e-15);
  EXPECT_NEAR(faces[1].length(), 1.0, 1e-15);
  EXPECT_NEAR(faces[1].normal.y, -1.0, 1e-15);
}

TEST(LimitInterfaces, ArchInterfacesAreTheSceneJoints) {
  const Model m = case_model("circular_arch", {"model.embrace=150"});
  const auto faces = find_interfaces(m);
  // 11 voussoirs: 10 joints between them and 2 springing joints on the abutments.
  ASSERT_EQ(faces.size(), 12u);
  for (const Interface& f : faces) {
    ASSERT_GE(f.joint, 0);
    const Joint& j = m.joints[f.joint];
    EXPECT_EQ(f.block_a, j.block_a);
    EXPECT_EQ(f.block_b, j.block_b);
    EXPECT_NEAR(distance(f.a, j.a), 0.0, 1e-12);  // a: intrados end, as the scene says
    EXPECT_NEAR(distance(f.b, j.b), 0.0, 1e-12);
    EXPECT_NEAR(f.length(), 0.2, 1e-12);  // radial joints span the thickness
  }
}

// ---------------------------------------------------------------- analytic block cases

TEST(LimitBlock, OverturnsAtWidthOverHeightOrSlidesAtMu) {
  // b/h = 0.5: lambda = min(0.5, mu).
  for (const double mu : {0.8, 0.3}) {
    const Model m = case_model("block");
    const LimitResult r = limit_analysis(m, mu, 9.81, false);
    ASSERT_EQ(r.status, "optimal");
    EXPECT_NEAR(r.lambda_la, std::min(0.5, mu), 1e-9) << "mu = " << mu;
    ASSERT_EQ(r.mechanism.size(), 1u);
    const MechanismJoint& mj = r.mechanism[0];
    if (mu > 0.5) {
      // Overturning to +x about the right toe (0.25, 0).
      EXPECT_EQ(mj.kind, "hinge");
      EXPECT_NEAR(mj.x, 0.25, 1e-12);
      EXPECT_NEAR(mj.y, 0.0, 1e-12);
    } else {
      EXPECT_EQ(mj.kind, "sliding");
      EXPECT_GT(mj.slip, 0.5);
    }
    const PrimalCheck pc = check_primal(m, r, mu, 9.81);
    EXPECT_LT(pc.equilibrium, 1e-12);
    EXPECT_LT(pc.cone, 1e-12);
    EXPECT_NEAR(lambda_from_mechanism(m, r), r.lambda_la, 1e-9);
  }
}

// An interface end marked open carries no force (the open joints of a moved structure as point
// contacts, commands/capacity.hpp OpenJoints::Points). The block (b/h = 0.5, mu = 0.8) on its
// right toe alone stands only where the load's moment about the toe balances the weight's:
// lambda = +b/h, the one admissible value; on its left toe alone, lambda = -b/h. Neither stands
// under gravity alone.
TEST(LimitBlock, AnOpenEndCarriesNoForce) {
  const Model m = case_model("block");
  std::vector<Interface> faces = find_interfaces(m);
  ASSERT_EQ(faces.size(), 1u);
  ASSERT_LT(faces[0].a.x, faces[0].b.x);  // a: the left toe, b: the right toe
  for (const bool right_toe : {true, false}) {
    std::vector<Interface> point = faces;
    (right_toe ? point[0].open_a : point[0].open_b) = true;
    LimitOptions options;
    options.interfaces = &point;
    const LimitResult r = limit_analysis(m, 0.8, 9.81, false, options);
    ASSERT_EQ(r.status, "optimal") << right_toe;
    EXPECT_NEAR(r.lambda_la, right_toe ? 0.5 : -0.5, 1e-9);
    ASSERT_EQ(r.forces.size(), 1u);
    EXPECT_EQ(right_toe ? r.forces[0].normal_a : r.forces[0].normal_b, 0.0);
    ASSERT_EQ(r.mechanism.size(), 1u);
    EXPECT_EQ(r.mechanism[0].kind, "hinge");
    EXPECT_NEAR(r.mechanism[0].x, right_toe ? 0.25 : -0.25, 1e-12);
    EXPECT_EQ(limit_analysis(m, 0.8, 9.81, true, options).status, "infeasible") << right_toe;
  }
}

TEST(LimitBlock, IndependentOfGravityDensityAndThickness) {
  Model m = case_model("block");
  const double ref = limit_analysis(m, 0.8, 9.81, false).lambda_la;
  m.material.density = 450.0;
  m.out_of_plane = 0.092;
  EXPECT_NEAR(limit_analysis(m, 0.8, 3.7, false).lambda_la, ref, 1e-12);
}

TEST(LimitBlock, StackOverturnsAsOneColumn) {
  // Three 0.5 x 1 blocks: the whole column tips about its base toe, lambda = 0.25 / 1.5.
  const Model m = case_model("block", {"model.stack=3"});
  const LimitResult r = limit_analysis(m, 0.8, 9.81, false);
  ASSERT_EQ(r.status, "optimal");
  EXPECT_NEAR(r.lambda_la, 0.5 / 3.0, 1e-9);
}

TEST(LimitBlock, GravityOnlyOnAnInclineSticksIffTanBelowMu) {
  // tan 15 deg = 0.268 < 0.3 < tan 20 deg = 0.364; b/h = 0.5 keeps it from tipping.
  for (const auto& [incline, sticks] : {std::pair{15.0, true}, std::pair{20.0, false}}) {
    const Model m = case_model("block", {"model.incline=" + std::to_string(incline)});
    const LimitResult r = limit_analysis(m, 0.3, 9.81, true);
    EXPECT_EQ(r.admissible, sticks) << "incline " << incline;
    EXPECT_EQ(r.status, sticks ? "optimal" : "infeasible");
  }
}

TEST(LimitBlock, FloatingBlockHasNoEquilibrium) {
  Model m;
  add_cut_rectangle(m, 0.0, 0.0, 1.0, 1.0, 1, 1, true);
  add_cut_rectangle(m, 0.0, 1.5, 1.0, 1.0, 1, 1, false);  // not touching the ground
  finalize_model(m);
  EXPECT_EQ(limit_analysis(m, 0.6, 9.81, false).status, "infeasible");
  EXPECT_FALSE(limit_analysis(m, 0.6, 9.81, true).admissible);
}

TEST(LimitBlock, WedgedBlockNeverCollapses) {
  // A block between two fixed walls on a fixed ground: every horizontal load is carried.
  Model m;
  add_cut_rectangle(m, -1.0, -0.5, 3.0, 0.5, 3, 1, true);  // ground
  add_cut_rectangle(m, -1.0, 0.0, 1.0, 1.0, 1, 1, true);   // left wall
  add_cut_rectangle(m, 1.0, 0.0, 1.0, 1.0, 1, 1, true);    // right wall
  add_cut_rectangle(m, 0.0, 0.0, 1.0, 1.0, 2, 2, false);   // the block, touching all three
  finalize_model(m);
  EXPECT_EQ(find_interfaces(m).size(), 5u);  // 2 ground-wall, 3 around the block
  const LimitResult r = limit_analysis(m, 0.6, 9.81, false);
  EXPECT_EQ(r.status, "unbounded");
  EXPECT_TRUE(std::isnan(r.lambda_la));
  EXPECT_TRUE(r.admissible);
  EXPECT_EQ(r.interfaces.size(), 3u);  // fixed-fixed interfaces are left out of the LP
}

// ---------------------------------------------------------------- published arch values

TEST(LimitArch, CircularArchesMatchPublishedLimitAnalysis) {
  // Dimitri & Tornabene (2015), Rc = 1, t/Rc = 0.2, 11 voussoirs, no sliding (mu = 10).
  const std::array<std::pair<double, double>, 3> published = {
      {{120.0, 1.27}, {150.0, 0.62}, {180.0, 0.29}}};
  for (const auto& [beta, lambda_pub] : published) {
    const Model m = case_model("circular_arch",
                               {"model.embrace=" + std::to_string(beta), "contact.friction=10"});
    const LimitResult r = limit_analysis(m, 10.0, 9.81, false);
    ASSERT_EQ(r.status, "optimal");
    std::printf("beta %.0f: lambda_la = %.5f (published %.2f, %+.2f%%), LP %.4f s\n", beta,
                r.lambda_la, lambda_pub, 100.0 * (r.lambda_la / lambda_pub - 1.0), r.wall_s);
    EXPECT_NEAR(r.lambda_la, lambda_pub, 0.02 * lambda_pub) << "beta " << beta;
    // Four hinges, alternating intrados / extrados, none sliding.
    ASSERT_EQ(r.mechanism.size(), 4u) << "beta " << beta;
    for (std::size_t k = 0; k < 4; ++k) {
      EXPECT_EQ(r.mechanism[k].kind, "hinge");
      EXPECT_EQ(r.mechanism[k].side, k % 2 == 0 ? "intrados" : "extrados");
    }
    const PrimalCheck pc = check_primal(m, r, 10.0, 9.81);
    EXPECT_LT(pc.equilibrium, 1e-9);
    EXPECT_LT(pc.cone, 1e-9);
    EXPECT_NEAR(lambda_from_mechanism(m, r), r.lambda_la, 1e-9 * r.lambda_la);
  }
}

TEST(LimitArch, LowFrictionOnlyLowersLambda) {
  // beta = 120 needs lambda > mu = 0.6: sliding at the inclined springings governs and the
  // (associative) limit load drops below the no-sliding value.
  const Model m = case_model("circular_arch", {"model.embrace=120"});
  const LimitResult hi = limit_analysis(m, 10.0, 9.81, false);
  const LimitResult lo = limit_analysis(m, 0.6, 9.81, false);
  ASSERT_EQ(lo.status, "optimal");
  std::printf("beta 120: lambda_la = %.5f at mu = 0.6, %.5f at mu = 10\n", lo.lambda_la,
              hi.lambda_la);
  EXPECT_LT(lo.lambda_la, hi.lambda_la - 0.05);
  bool sliding = false;
  for (const MechanismJoint& mj : lo.mechanism) sliding |= mj.kind == "sliding";
  EXPECT_TRUE(sliding);
  EXPECT_NEAR(lambda_from_mechanism(m, lo), lo.lambda_la, 1e-9 * lo.lambda_la);
}

TEST(LimitArch, SemicircularGravityAdmissibilityBracketsMinimumThickness) {
  // Continuous semicircular arch: t/R = 0.1075 (Heyman; Milankovitch); discrete joints only
  // lower it a little. 0.15 must stand, 0.09 must not.
  for (const auto& [t, stands] : {std::pair{0.15, true}, std::pair{0.09, false}}) {
    const Model m = case_model("circular_arch",
                               {"model.thickness=" + std::to_string(t), "contact.friction=10"});
    const LimitResult r = limit_analysis(m, 10.0, 9.81, true);
    EXPECT_EQ(r.admissible, stands) << "t/R = " << t;
    EXPECT_TRUE(r.exact);
    if (stands) {
      const PrimalCheck pc = check_primal(m, r, 10.0, 9.81);
      EXPECT_LT(pc.equilibrium, 1e-9);
      EXPECT_LT(pc.cone, 1e-9);
    }
    // The full problem agrees: lambda_la >= 0 exactly when gravity alone is admissible.
    const LimitResult full = limit_analysis(m, 10.0, 9.81, false);
    if (full.status == "optimal") {
      EXPECT_EQ(full.lambda_la >= 0.0, stands) << "t/R = " << t;
    }
  }
}

TEST(LimitArch, ThreadsGiveTheSameAnswers) {
  // GLPK 5 keeps its environment in thread-local storage: one problem per thread is safe
  // (`voussoir stability` checks its cells in parallel).
  std::vector<Model> models;
  for (const double beta : {120.0, 135.0, 150.0, 165.0, 180.0})
    models.push_back(case_model("circular_arch", {"model.embrace=" + std::to_string(beta)}));
  const int n = static_cast<int>(models.size());
  std::vector<double> serial(n), parallel(n);
  for (int k = 0; k < n; ++k) serial[k] = limit_analysis(models[k], 0.6, 9.81, false).lambda_la;
#pragma omp parallel for schedule(dynamic, 1) num_threads(2)
  for (int k = 0; k < n; ++k) parallel[k] = limit_analysis(models[k], 0.6, 9.81, false).lambda_la;
  for (int k = 0; k < n; ++k) EXPECT_EQ(serial[k], parallel[k]) << "case " << k;
}

// ---------------------------------------------------------------- church

TEST(LimitChurch, SchemeBSolvesAndSchemeAIsNoStronger) {
  const Model b = case_model("church_b");
  const LimitResult rb = limit_analysis(b, 0.6, 9.81, false);
  ASSERT_EQ(rb.status, "optimal");
  EXPECT_GT(rb.lambda_la, 0.0);
  EXPECT_FALSE(rb.mechanism.empty());
  const PrimalCheck pc = check_primal(b, rb, 0.6, 9.81);
  EXPECT_LT(pc.equilibrium, 1e-8);
  EXPECT_LT(pc.cone, 1e-8);
  EXPECT_NEAR(lambda_from_mechanism(b, rb), rb.lambda_la, 1e-8 * rb.lambda_la);
  // Scheme A cuts the supports into courses: more joints can only lower the limit load.
  const Model a = case_model("church_a");
  const LimitResult ra = limit_analysis(a, 0.6, 9.81, false);
  ASSERT_EQ(ra.status, "optimal");
  EXPECT_LE(ra.lambda_la, rb.lambda_la + 1e-9);
  std::printf("church: lambda_la B = %.6f (%d blocks, LP %.3f s), A = %.6f (LP %.3f s)\n",
              rb.lambda_la, rb.free_blocks, rb.wall_s, ra.lambda_la, ra.wall_s);
}

// ---------------------------------------------------------------- least and greatest thrust

TEST(LimitThrust, TwoCantileversMeetingAtMidspan) {
  // Two blocks w x h (w = 1, h = 0.5) meet on a vertical joint at x = 0; each rests on a fixed
  // support only over its outer s = 0.2 (the support's top y = 0 ends at x = -/+(w - s)).
  // By symmetry and convexity of the LP the extremes are symmetric, so the mid joint carries
  // a horizontal force H at height y2 in (0, h] and no shear. The left block on its support:
  // vertical reaction W, horizontal H (outward on the support), at x1 in [-w, -(w - s)].
  // Moments about (x1, 0):  H y2 - W (-w/2 - x1) = 0,  H = W (-w/2 - x1) / y2.
  // Least: x1 = -(w - s), y2 = h:  H_min = W (w/2 - s) / h = 0.6 W.
  // Greatest: y2 -> 0 is geometrically free, so friction at the support binds: H_max = mu W.
  for (const double mu : {0.8, 1.5}) {
    Model m;
    add_cut_rectangle(m, -1.5, -0.5, 0.7, 0.5, 1, 1, true);  // left support, top to x = -0.8
    add_cut_rectangle(m, 0.8, -0.5, 0.7, 0.5, 1, 1, true);   // right support
    add_cut_rectangle(m, -1.0, 0.0, 1.0, 0.5, 1, 1, false);  // left block
    add_cut_rectangle(m, 0.0, 0.0, 1.0, 0.5, 1, 1, false);   // right block
    finalize_model(m);
    const double g = 9.81;
    const double W = m.material.density * m.out_of_plane * g * 0.5;
    const LimitResult lo = limit_thrust(m, mu, g, ThrustBound::Min);
    ASSERT_EQ(lo.status, "optimal");
    EXPECT_NEAR(lo.thrust, 0.6 * W, 1e-9 * W) << "mu " << mu;
    EXPECT_TRUE(std::isnan(lo.lambda_la));
    const PrimalCheck c = check_primal(m, lo, mu, g);
    EXPECT_LT(c.equilibrium, 1e-9);
    EXPECT_LT(c.cone, 1e-9);
    const LimitResult hi = limit_thrust(m, mu, g, ThrustBound::Max);
    ASSERT_EQ(hi.status, "optimal");
    EXPECT_NEAR(hi.thrust, mu * W, 1e-9 * W) << "mu " << mu;
  }
}

TEST(LimitThrust, LintelBetweenWallsHasNoGreatestThrust) {
  // The same two blocks wedged between two fixed walls (a flat arch): the least thrust is
  // W (w/2) / h (walls bear the whole height), the greatest unbounded.
  Model m;
  add_cut_rectangle(m, -1.5, 0.0, 0.5, 0.5, 1, 1, true);
  add_cut_rectangle(m, 1.0, 0.0, 0.5, 0.5, 1, 1, true);
  add_cut_rectangle(m, -1.0, 0.0, 1.0, 0.5, 1, 1, false);
  add_cut_rectangle(m, 0.0, 0.0, 1.0, 0.5, 1, 1, false);
  finalize_model(m);
  const double W = m.material.density * 9.81 * 0.5;
  const LimitResult lo = limit_thrust(m, 2.0, 9.81, ThrustBound::Min);
  ASSERT_EQ(lo.status, "optimal");
  EXPECT_NEAR(lo.thrust, W * 0.5 / 0.5, 1e-9 * W);
  EXPECT_EQ(limit_thrust(m, 2.0, 9.81, ThrustBound::Max).status, "unbounded");
}

TEST(LimitThrust, SemicircularArchBetweenItsBounds) {
  // The shipped arch (t/R = 0.2, 11 voussoirs, no sliding): min < max, both positive, the
  // least thrust close to Heyman's continuous-arch value (docs/supports.md quotes both).
  const Model m = case_model("circular_arch");
  const LimitResult lo = limit_thrust(m, 10.0, 9.81, ThrustBound::Min);
  const LimitResult hi = limit_thrust(m, 10.0, 9.81, ThrustBound::Max);
  ASSERT_EQ(lo.status, "optimal");
  ASSERT_EQ(hi.status, "optimal");
  double weight = 0.0;
  for (const Block& b : m.blocks)
    if (!b.fixed) weight += b.mass * 9.81;
  std::printf("semicircular arch: H_min / W = %.5f, H_max / W = %.5f\n", lo.thrust / weight,
              hi.thrust / weight);
  EXPECT_GT(lo.thrust, 0.0);
  EXPECT_GT(hi.thrust, 1.2 * lo.thrust);
}

// ---------------------------------------------------------------- the command

TEST(LimitCommand, WritesLambdaAndMechanismJson) {
  const std::string out = ::testing::TempDir() + "limit_block.json";
  const std::string cmd = std::string(VOUSSOIR_BINARY) + " limit " + case_path("block") +
                          " --quiet --json " + out + " > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::ifstream in(out);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_NEAR(j.at("lambda_la").get<double>(), 0.5, 1e-9);  // the deck's mu = 0.8
  ASSERT_EQ(j.at("mechanism").size(), 1u);
  EXPECT_EQ(j.at("mechanism")[0].at("kind"), "hinge");
  EXPECT_GE(j.at("wall_s").get<double>(), 0.0);

  const std::string cmd2 = std::string(VOUSSOIR_BINARY) + " limit " + case_path("circular_arch") +
                           " --gravity-only --set model.thickness=0.09 --quiet --json " + out +
                           " > /dev/null";
  ASSERT_EQ(std::system(cmd2.c_str()), 0);
  std::ifstream in2(out);
  const nlohmann::json j2 = nlohmann::json::parse(in2);
  EXPECT_FALSE(j2.at("admissible").get<bool>());
  std::remove(out.c_str());
}

// `limit --thrust min|max` through the program: its JSON holds "thrust_min" / "thrust_max" in N
// per out_of_plane, the LP's thrust of the same blocks and friction (limit_thrust), no
// "lambda_la"; min below max.
TEST(LimitCommand, ThrustBoundsInTheJson) {
  const std::string out = ::testing::TempDir() + "limit_thrust.json";
  const Config config = load_deck(case_path("circular_arch"), {});
  const Model m = build_model(scene_params(config));
  double thrust[2];
  const char* bound[2] = {"min", "max"};
  for (int k = 0; k < 2; ++k) {
    const std::string cmd = std::string(VOUSSOIR_BINARY) + " limit " + case_path("circular_arch") +
                            " --thrust " + bound[k] + " --quiet --json " + out + " > /dev/null";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    std::ifstream in(out);
    const nlohmann::json j = nlohmann::json::parse(in);
    const std::string key = std::string("thrust_") + bound[k];
    ASSERT_TRUE(j.contains(key)) << j.dump();
    EXPECT_FALSE(j.contains("lambda_la"));
    EXPECT_FALSE(j.at("gravity_only").get<bool>());
    thrust[k] = j.at(key).get<double>();
    const LimitResult lp = limit_thrust(m, config.contact.friction, config.load.gravity,
                                        k == 0 ? ThrustBound::Min : ThrustBound::Max);
    EXPECT_NEAR(thrust[k], lp.thrust, 1e-9 * std::abs(lp.thrust)) << key;
  }
  EXPECT_GT(thrust[0], 0.0);
  EXPECT_GT(thrust[1], thrust[0]);
  std::remove(out.c_str());
}

}  // namespace
}  // namespace voussoir

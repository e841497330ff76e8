// Contact of rigid blocks between outlines (contact/rigid_contact.hpp): the overlap integrals
// against hand-computed values (a face pressed flat, a tilted face, a corner in a face, two
// corners), the symmetry of the law, a non-convex block resting on two legs, and the
// quasi-static capacity of a rigid block on a Winkler joint against the closed form of its
// contact strip at three joint stiffnesses.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "commands/capacity.hpp"
#include "contact/quad_overlap.hpp"
#include "contact/rigid_contact.hpp"
#include "core/rigid.hpp"
#include "engine/run_loop.hpp"
#include "engine/setup.hpp"
#include "engine/step.hpp"
#include "engine/thrust.hpp"
#include "io/deck.hpp"

namespace voussoir {
namespace {

namespace fs = std::filesystem;

std::vector<Vec2> box(double x0, double y0, double x1, double y1) {
  return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
}

// The overlap of two quadrilaterals by the batch kernel (contact/quad_overlap.hpp), in lane
// `lane` of a batch whose other lanes hold other pairs; false when it finds none.
bool quad_overlap(const std::vector<Vec2>& p, const std::vector<Vec2>& q, ConvexOverlap& o,
                  int lane = 0) {
  QuadPairs batch;
  for (int l = 0; l < kQuadLanes; ++l) {
    // Other lanes: the pair turned by l + 1 quarter turns about P's first vertex.
    const int turns = l == lane ? 0 : l + 1;
    const double c = std::cos(turns * 1.5707963267948966),
                 s = std::sin(turns * 1.5707963267948966);
    for (int k = 0; k < 4; ++k) {
      const Vec2 a = p[std::size_t(k)] - p[0], b = q[std::size_t(k)] - p[0];
      batch.px[k][l] = c * a.x - s * a.y, batch.py[k][l] = s * a.x + c * a.y;
      batch.qx[k][l] = c * b.x - s * b.y, batch.qy[k][l] = s * b.x + c * b.y;
    }
    batch.ox[l] = p[0].x, batch.oy[l] = p[0].y;
  }
  QuadOverlaps out;
  quad_overlaps(batch, out);
  if (!out.on[lane]) return false;
  o.area = out.area[lane];
  o.centroid = {out.gx[lane], out.gy[lane]};
  o.normal = {out.nx[lane], out.ny[lane]};
  o.chord = out.chord[lane];
  o.chord_mid = {out.mx[lane], out.my[lane]};
  return true;
}

// The overlap by the ordered clipping; for two quadrilaterals, the batch kernel's force terms
// checked against it.
ConvexOverlap overlap(const std::vector<Vec2>& p, const std::vector<Vec2>& q) {
  ConvexOverlap o;
  EXPECT_TRUE(convex_overlap(p.data(), int(p.size()), q.data(), int(q.size()), o));
  if (p.size() == 4 && q.size() == 4) {
    ConvexOverlap b;
    EXPECT_TRUE(quad_overlap(p, q, b, 3));
    const double scale = std::sqrt(o.area) + o.chord;
    EXPECT_NEAR(b.area, o.area, 1e-14 * scale * scale);
    EXPECT_NEAR(b.centroid.x, o.centroid.x, 1e-12 * scale);
    EXPECT_NEAR(b.centroid.y, o.centroid.y, 1e-12 * scale);
    EXPECT_NEAR(b.normal.x, o.normal.x, 1e-12);
    EXPECT_NEAR(b.normal.y, o.normal.y, 1e-12);
    EXPECT_NEAR(b.chord, o.chord, 1e-12 * scale);
    EXPECT_NEAR(b.chord_mid.x, o.chord_mid.x, 1e-12 * scale);
    EXPECT_NEAR(b.chord_mid.y, o.chord_mid.y, 1e-12 * scale);
  }
  return o;
}

// A block pressed flat into a face: O = [0.2, 0.8] x [0.99, 1], the pressure uniform.
TEST(RigidContact, FacePressedFlatIsAUniformStrip) {
  const ConvexOverlap o = overlap(box(0, 0, 1, 1), box(0.2, 0.99, 0.8, 2.0));
  EXPECT_NEAR(o.area, 0.6 * 0.01, 1e-15);
  EXPECT_NEAR(o.centroid.x, 0.5, 1e-12);
  EXPECT_NEAR(o.centroid.y, 0.995, 1e-12);
  EXPECT_NEAR(o.normal.x, 0.0, 1e-15);
  EXPECT_NEAR(o.normal.y, 1.0, 1e-15);  // out of P (below) into Q
  EXPECT_NEAR(o.chord, 0.6, 1e-12);
  EXPECT_NEAR(o.depth_sq, 0.6 * 0.01 * 0.01, 1e-17);  // integral of d^2 over the contact
}

// A block whose base is tilted: d falls linearly from 0.002 to 0 over the unit contact, the
// pressure block of a hinge. |O| = 0.001, G a third of the way from the deep end, integral of
// d^2 = 0.002^2 / 3.
TEST(RigidContact, TiltedFaceIsATriangularPressureBlock) {
  const std::vector<Vec2> ground = box(-1, -1, 1, 0);
  const std::vector<Vec2> block = {{-0.5, -0.002}, {0.5, 0.0}, {0.5, 1.0}, {-0.5, 1.0}};
  const ConvexOverlap o = overlap(ground, block);
  EXPECT_NEAR(o.area, 0.001, 1e-15);
  EXPECT_NEAR(o.centroid.x, -0.5 + 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(o.centroid.y, -0.002 / 3.0, 1e-14);
  EXPECT_NEAR(o.normal.y, 1.0, 1e-15);
  EXPECT_NEAR(o.depth_sq, 0.002 * 0.002 / 3.0, 1e-18);
}

// A square turned by 45 degrees pushed corner first into a face by delta: O is the triangle of
// base 2 delta and height delta, the force along the face's normal, integral of d^2 = 2 delta^3
// / 3 (the tent d = delta - |s|).
TEST(RigidContact, CornerInAFaceActsAlongTheFaceNormal) {
  const double delta = 1e-3, r = 0.5 * std::sqrt(2.0);
  const Vec2 c{0.5, 1.0 - delta + r};
  const std::vector<Vec2> diamond = {
      {c.x, c.y - r}, {c.x + r, c.y}, {c.x, c.y + r}, {c.x - r, c.y}};
  const ConvexOverlap o = overlap(box(0, 0, 1, 1), diamond);
  EXPECT_NEAR(o.area, delta * delta, 1e-15);
  EXPECT_NEAR(o.centroid.x, 0.5, 1e-12);
  EXPECT_NEAR(o.centroid.y, 1.0 - delta / 3.0, 1e-12);
  EXPECT_NEAR(o.normal.x, 0.0, 1e-12);
  EXPECT_NEAR(o.normal.y, 1.0, 1e-12);
  EXPECT_NEAR(o.depth_sq, 2.0 * delta * delta * delta / 3.0, 1e-15 * delta);
}

// Two corners overlapping: O = [0.5, 1] x [0.9, 1]; the normal is that of the chord between
// the points where the outlines cross, (1, 0.9) and (0.5, 1). Swapping the blocks negates the
// normal and keeps everything else.
TEST(RigidContact, TwoCornersTakeTheChordsNormalAndSwappingNegatesIt) {
  const std::vector<Vec2> p = box(0, 0, 1, 1), q = box(0.5, 0.9, 1.5, 2.0);
  const ConvexOverlap o = overlap(p, q), r = overlap(q, p);
  EXPECT_NEAR(o.area, 0.05, 1e-14);
  const double len = std::hypot(0.1, 0.5);
  EXPECT_NEAR(o.normal.x, 0.1 / len, 1e-12);
  EXPECT_NEAR(o.normal.y, 0.5 / len, 1e-12);
  EXPECT_NEAR(o.chord, len, 1e-12);
  EXPECT_NEAR(r.area, o.area, 1e-15);
  EXPECT_NEAR(r.normal.x, -o.normal.x, 1e-12);
  EXPECT_NEAR(r.normal.y, -o.normal.y, 1e-12);
  EXPECT_NEAR(r.centroid.x, o.centroid.x, 1e-12);
  EXPECT_NEAR(r.centroid.y, o.centroid.y, 1e-12);
  EXPECT_NEAR(r.depth_sq, o.depth_sq, 1e-15);
  // Width along the normal integrated numerically (midpoint rule on 20000 strips).
  const Vec2 n = o.normal, t{n.y, -n.x};
  const std::vector<Vec2> v = {{0.5, 0.9}, {1.0, 0.9}, {1.0, 1.0}, {0.5, 1.0}};
  double lo = 1e9, hi = -1e9;
  for (const Vec2& a : v) lo = std::min(lo, dot(a, t)), hi = std::max(hi, dot(a, t));
  const int strips = 20000;
  double sum = 0.0;
  for (int k = 0; k < strips; ++k) {
    const double s = lo + (k + 0.5) * (hi - lo) / strips;
    double h0 = 1e9, h1 = -1e9;
    for (int e = 0; e < 4; ++e) {
      const Vec2 a = v[e], b = v[(e + 1) % 4];
      const double sa = dot(a, t), sb = dot(b, t);
      if ((s - sa) * (s - sb) > 0.0 || sa == sb) continue;
      const double h = dot(a, n) + (dot(b, n) - dot(a, n)) * (s - sa) / (sb - sa);
      h0 = std::min(h0, h), h1 = std::max(h1, h);
    }
    sum += (h1 - h0) * (h1 - h0) * (hi - lo) / strips;
  }
  EXPECT_NEAR(o.depth_sq, sum, 1e-6 * sum);
}

TEST(RigidContact, ApartPolygonsHaveASeparatingLine) {
  const std::vector<Vec2> p = box(0, 0, 1, 1), q = box(1.5, 0.2, 2.0, 0.8);
  ConvexOverlap o;
  EXPECT_FALSE(convex_overlap(p.data(), 4, q.data(), 4, o));
  const int line = separating_line(p.data(), 4, q.data(), 4);
  ASSERT_GE(line, 0);
  EXPECT_TRUE(separated_by(p.data(), 4, q.data(), 4, line));
  const std::vector<Vec2> touching = box(0.9, 0.2, 2.0, 0.8);
  EXPECT_EQ(separating_line(p.data(), 4, touching.data(), 4), -1);
}

// The batch kernel against the ordered clipping on random pairs of quadrilaterals of the kinds
// a masonry structure has: joints (Q built on a side of P, its two corners on P's, then moved
// by a penetration of 1e-10 to 1e-3 of the side, turned by as little and slid), corners pushed
// into faces, and pairs overlapping anyhow. Both find an overlap or neither; the force terms
// agree to round-off of the pair's size.
TEST(RigidContact, QuadBatchAgreesWithTheOrderedClipping) {
  std::mt19937_64 rng(20261127);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto quad = [&](double size) {
    // A convex quadrilateral: four points on an ellipse at jittered angles.
    const double a = size * (0.5 + unit(rng)), b = size * (0.5 + unit(rng)), turn = 6.3 * unit(rng);
    std::vector<Vec2> v;
    for (int k = 0; k < 4; ++k) {
      const double t = turn + 1.5707963267948966 * (k + 0.6 * (unit(rng) - 0.5));
      v.push_back({a * std::cos(t), b * std::sin(t)});
    }
    return v;
  };
  int overlaps = 0, agreed = 0, joints = 0;
  double tilt = 0.0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::vector<Vec2> p = quad(1.0), q;
    const int kind = trial % 3;
    if (kind == 0) {  // a joint on P's side k
      const int k = int(4 * unit(rng)) % 4;
      const Vec2 a = p[std::size_t(k)], b = p[std::size_t((k + 1) % 4)];
      const Vec2 e = b - a;
      const double len = std::hypot(e.x, e.y);
      const Vec2 n{e.y / len, -e.x / len};  // out of P
      const double h = 0.3 + unit(rng);
      q = {b, a, a + h * n + (0.3 * (unit(rng) - 0.5)) * e,
           b + h * n + (0.3 * (unit(rng) - 0.5)) * e};
      const double depth = len * std::pow(10.0, -10.0 + 7.0 * unit(rng));
      tilt = (unit(rng) - 0.5) * std::pow(10.0, -10.0 + 7.0 * unit(rng));
      const Vec2 slide = (len * (unit(rng) - 0.5) * std::pow(10.0, -6.0 * unit(rng))) * e;
      const Vec2 mid = 0.5 * (a + b);
      for (Vec2& v : q) {
        const Vec2 r = v - mid;
        v = mid + Vec2{r.x - tilt * r.y, r.y + tilt * r.x} - depth * n + (1.0 / len) * slide;
      }
      ++joints;
    } else {
      q = quad(kind == 1 ? 0.5 : 1.5);
      const Vec2 shift{2.0 * (unit(rng) - 0.5), 2.0 * (unit(rng) - 0.5)};
      for (Vec2& v : q) v = v + shift;
    }
    ConvexOverlap o, b;
    // Round-off of the coordinates (1e-16 of the size, 1 here) moves the area by as much times
    // the size, the centroid of a sliver by the area's relative error times the size, and a
    // point where two outlines cross at an angle alpha by as much over alpha (the faces of a
    // joint turned by `tilt` cross at that angle).
    const double crossing = kind == 0 ? 1e-15 / std::abs(tilt) : 0.0;
    const bool ordered = convex_overlap(p.data(), 4, q.data(), 4, o, false);
    const bool batch = quad_overlap(p, q, b, trial % kQuadLanes);
    const double scale = ordered ? std::sqrt(o.area) + o.chord : 1.0;
    // One piece wholly inside the other has no chord: the ordered clipping's sum of the edges
    // then leaves round-off, 1e-16, where the batch finds no crossing and no overlap.
    if (ordered && o.chord < 1e-12) {
      EXPECT_FALSE(batch) << "trial " << trial;
      continue;
    }
    // A touch of no area may be found by one and not the other.
    if (ordered != batch) {
      EXPECT_LT(ordered ? o.area : b.area, 1e-14) << "trial " << trial;
      continue;
    }
    if (!ordered) continue;
    ++overlaps;
    const double sliver = 1e-15 / o.area;
    const bool same = std::abs(b.area - o.area) <= 1e-13 * o.area + 1e-15 &&
                      std::abs(b.centroid.x - o.centroid.x) <= 1e-12 * scale + sliver &&
                      std::abs(b.centroid.y - o.centroid.y) <= 1e-12 * scale + sliver &&
                      std::abs(b.normal.x - o.normal.x) <= 1e-9 &&
                      std::abs(b.normal.y - o.normal.y) <= 1e-9 &&
                      std::abs(b.chord - o.chord) <= 1e-12 * scale + crossing &&
                      std::abs(b.chord_mid.x - o.chord_mid.x) <= 1e-12 * scale + crossing &&
                      std::abs(b.chord_mid.y - o.chord_mid.y) <= 1e-12 * scale + crossing;
    EXPECT_TRUE(same) << "trial " << trial << ": area " << b.area << " against " << o.area
                      << ", normal (" << b.normal.x << ", " << b.normal.y << ") against ("
                      << o.normal.x << ", " << o.normal.y << "), chord " << b.chord << " against "
                      << o.chord << ", centroid (" << b.centroid.x - o.centroid.x << ", "
                      << b.centroid.y - o.centroid.y << "), middle ("
                      << b.chord_mid.x - o.chord_mid.x << ", " << b.chord_mid.y - o.chord_mid.y
                      << ")";
    agreed += same;
  }
  EXPECT_GT(overlaps, 1500);
  EXPECT_EQ(agreed, overlaps);
  EXPECT_EQ(joints, 1000);
}

// Skipping a side line of Q that leaves P whole (convex_overlap's `inner`, certified by the
// contact stage at detection) gives the same overlap to the bit: a block pressed into a tilted
// joint, with displacements, Q's far side (line 2, from q[2] to q[3]) skipped.
TEST(RigidContact, SkippedInnerLineChangesNothing) {
  const std::vector<Vec2> p = box(0, 0, 1, 1);
  const std::vector<Vec2> q = {{0.1, 0.99}, {0.9, 0.995}, {0.9, 2.0}, {0.1, 2.0}};
  const std::vector<Vec2> pu = {{1e-7, -2e-8}, {1e-7, -2e-8}, {1e-7, -2e-8}, {1e-7, -2e-8}};
  const std::vector<Vec2> qu = {{-3e-8, 5e-8}, {-3e-8, 5e-8}, {-3e-8, 5e-8}, {-3e-8, 5e-8}};
  ConvexOverlap all, skipped;
  ASSERT_TRUE(convex_overlap(p.data(), pu.data(), 4, q.data(), qu.data(), 4, all, true));
  ASSERT_TRUE(
      convex_overlap(p.data(), pu.data(), 4, q.data(), qu.data(), 4, skipped, true, 1u << 2));
  EXPECT_EQ(all.area, skipped.area);
  EXPECT_EQ(all.centroid.x, skipped.centroid.x);
  EXPECT_EQ(all.centroid.y, skipped.centroid.y);
  EXPECT_EQ(all.normal.x, skipped.normal.x);
  EXPECT_EQ(all.normal.y, skipped.normal.y);
  EXPECT_EQ(all.chord, skipped.chord);
  EXPECT_EQ(all.chord_mid.x, skipped.chord_mid.x);
  EXPECT_EQ(all.chord_mid.y, skipped.chord_mid.y);
  EXPECT_EQ(all.depth_sq, skipped.depth_sq);
}

// A non-convex block (a portal: two legs 0.3 m wide under a 0.5 m lintel) settles on its legs
// by weight / (kn x 0.6 m2) and stays level, the ledger closed.
TEST(RigidContact, NonConvexBlockRestsOnBothLegs) {
  const fs::path dir = fs::temp_directory_path() / "voussoir_rigid_portal";
  fs::create_directories(dir);
  const fs::path file = dir / "portal.txt";
  std::ofstream(file) << "block\n0 0\n0.3 0\n0.3 0.5\n0.7 0.5\n0.7 0\n1 0\n1 1\n0 1\n\n"
                         "block\n-1 -0.5\n2 -0.5\n2 0\n-1 0\n";
  const double kn = 1e9;
  const std::string deck = "[model]\nkind = \"polygons\"\nfile = \"" + file.string() +
                           "\"\nfixed = [1]\n[material]\nmodel = \"rigid\"\n[contact]\n"
                           "friction = 0.8\nnormal_stiffness = 1e9\nrestitution = 0\n";
  Simulation sim = make_simulation(parse_deck(deck, (dir / "portal.toml").string()));
  double worst = 0.0;
  while (sim.ctx.time < 0.5) {
    advance(sim);
    worst = std::max(worst, sim.ledger.balance_error());
  }
  const RigidBodies& r = sim.model.rigid;
  const double area = 1.0 - 0.4 * 0.5, weight = 2000.0 * area * 9.81;
  EXPECT_NEAR(r.cy0[0] - r.cy[0], weight / (kn * 0.6), 0.01 * weight / (kn * 0.6));
  EXPECT_LT(std::abs(r.theta[0]), 1e-9);
  EXPECT_LT(worst, 0.01);
  fs::remove_all(dir);
}

// Quasi-static capacity of a b x h rigid block on a Winkler joint of stiffness kn (no
// tension), loaded by its weight W and lambda W at its centroid, sticking (mu > lambda).
// Tilted by phi about its right-hand corner, which sits delta below the ground, the block's
// overlap with the ground is the triangle between the ground line, its base and its right
// side: base from x_C - delta cot(phi) to x_C + delta tan(phi), depth delta at the corner
// x_C. The joint's pressure kn d over it gives the vertical force
//     N = kn delta^2 / (2 sin phi cos phi)
// through its centroid G (x_C + delta (tan phi - cot phi) / 3, -delta / 3); the friction
// force, also at G, takes the horizontal load. Equilibrium: N = W fixes delta, and the moment
// of the loads about G vanishes, with the centroid at
//     X_c = x_C - b/2 cos phi + h/2 sin phi,  Y_c = -delta + b/2 sin phi + h/2 cos phi:
//     lambda(phi) = (x_G - X_c) / (Y_c - y_G)
//                 = (delta (tan phi - cot phi) / 3 + b/2 cos phi - h/2 sin phi)
//                   / (b/2 sin phi + h/2 cos phi - 2 delta / 3).
// The capacity is the peak of lambda(phi) (the rigid block's b/h at kn -> infinity).
double winkler_capacity(double b, double h, double weight, double kn) {
  double best = 0.0;
  for (double phi = 1e-7; phi < std::atan(b / h); phi *= 1.0005) {
    const double delta = std::sqrt(2.0 * weight * std::sin(phi) * std::cos(phi) / kn);
    if (delta / std::sin(phi) > b) continue;  // the whole base still presses
    const double lam = (delta * (std::tan(phi) - 1.0 / std::tan(phi)) / 3.0 +
                        0.5 * b * std::cos(phi) - 0.5 * h * std::sin(phi)) /
                       (0.5 * b * std::sin(phi) + 0.5 * h * std::cos(phi) - 2.0 * delta / 3.0);
    best = std::max(best, lam);
  }
  return best;
}

TEST(RigidContact, WinklerBlockReachesTheClosedFormCapacityOfItsContactStrip) {
  const double b = 0.25, h = 1.0, weight = 2000.0 * b * h * 9.81;
  TrialCriteria crit;
  crit.quasi_static = true;
  for (const char* kn : {"1e8", "1e10", "1e12"}) {
    const std::string deck =
        "[model]\nkind = \"block\"\nwidth = 0.25\nheight = 1.0\n[material]\nmodel = \"rigid\"\n"
        "[contact]\nfriction = 0.8\nnormal_stiffness = " +
        std::string(kn) + "\n[capacity]\ntolerance = 0.002\n";
    const CapacityResult r = find_capacity(parse_deck(deck, "test"), crit, 2, true);
    ASSERT_TRUE(r.bracketed) << kn;
    const double expected = winkler_capacity(b, h, weight, std::stod(kn));
    std::printf("[winkler] kn %s: lambda* %.5f, closed form %.5f (rigid block %.5f)\n", kn,
                r.lambda_star, expected, b / h);
    EXPECT_NEAR(r.lambda_star, expected, 0.01 * expected) << kn;
  }
}

// The shipped semicircular arch run for 0.3 s with the rigid blocks' default joint damping: the
// springings carry the arch's weight, and the mirror joints carry mirror thrusts (the deck is
// symmetric). Undamped joints ring on and miss both (docs/rigid.md, "Joint damping by default").
TEST(RigidContact, ShippedArchRunEndsInStaticEquilibrium) {
  const Config config = load_deck(std::string(VOUSSOIR_SOURCE_DIR) + "/cases/circular_arch.toml",
                                  {"solver.end_time=0.3"});
  Simulation sim = make_simulation(config);
  run_loop(
      sim, 0.3, 1e-3, [](const Simulation&) { return true; }, true, "arch");
  const std::vector<JointResultant> joints = joint_resultants(sim.model, sim.contact, sim.ctx.dt);
  const std::size_t nj = joints.size();
  ASSERT_EQ(nj, 12u);
  double weight = 0.0;
  for (const Block& b : sim.model.blocks)
    if (!b.fixed) weight += b.mass * config.load.gravity;
  // Joints 0 and nj - 1 are the springings (on the abutments); their vertical forces carry it.
  const double carried = std::abs(joints.front().force.y) + std::abs(joints.back().force.y);
  EXPECT_NEAR(carried, weight, 0.01 * weight);
  for (std::size_t j = 0; j < nj / 2; ++j) {
    const JointResultant &left = joints[j], &right = joints[nj - 1 - j];
    ASSERT_TRUE(left.closed && right.closed) << "joint " << j;
    EXPECT_NEAR(left.eccentricity, right.eccentricity, 0.01)
        << "joints " << j << ", " << nj - 1 - j;
    EXPECT_NEAR(left.normal_force, right.normal_force, 1e-3 * weight) << "joint " << j;
  }
}

}  // namespace
}  // namespace voussoir

// Capacity curves (drivers/pushover.hpp): a rigid block on a Winkler joint against the closed
// form of its contact strip, and on a stiff joint against the rigid block's rocking curve; the
// equivalent SDOF curve of a single block and of a hand-made two-block mechanism; the default
// control block; bad options refused with the option and value.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "drivers/pushover.hpp"
#include "drivers/setup.hpp"
#include "io/deck.hpp"
#include "subprocess.hpp"

namespace voussoir {
namespace {

struct Pt {
  double x, y;
};

// Area and centroid of the part of the polygon `p` (counter-clockwise) below y = 0.
void clip_below_ground(const std::vector<Pt>& p, double& area, Pt& centroid) {
  std::vector<Pt> q;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Pt a = p[i], b = p[(i + 1) % p.size()];
    if (a.y <= 0.0) q.push_back(a);
    if ((a.y < 0.0) != (b.y < 0.0) && a.y != b.y) {
      const double t = a.y / (a.y - b.y);
      q.push_back({a.x + t * (b.x - a.x), 0.0});
    }
  }
  double a2 = 0.0, cx = 0.0, cy = 0.0;
  for (std::size_t i = 0; i < q.size(); ++i) {
    const Pt a = q[i], b = q[(i + 1) % q.size()];
    const double c = a.x * b.y - b.x * a.y;
    a2 += c;
    cx += (a.x + b.x) * c;
    cy += (a.y + b.y) * c;
  }
  area = 0.5 * a2;
  centroid = area != 0.0 ? Pt{cx / (3.0 * a2), cy / (3.0 * a2)} : Pt{0.0, 0.0};
}

// The quasi-static curve of a b x h rigid block (weight W) on a Winkler joint of stiffness kn
// and shear stiffness kt (per unit slip, the joint's ks x its length), loaded by lambda W at its
// centroid, sticking, control at its centroid.
//
// Tilted clockwise by phi (towards +x), its right-hand base corner delta below the ground
// line y = 0, the block overlaps the ground in the polygon O (a trapezoid while the whole base
// presses, a triangle after); the joint's pressure kn d integrates to kn |O| upwards through
// O's centroid G (contact/rigid_contact.hpp), and the shear force -lambda W acts there too.
// Vertical equilibrium kn |O(delta, phi)| = W fixes delta; the moments about G give
//     lambda(phi) = (x_G - X_c) / (Y_c - y_G).
// The centroid's horizontal displacement: the block's material point at G moves with the
// joint's elastic slip s = lambda W / kt (the friction law's tangential spring, sticking), and
// the block turns about it at the rate phi', so dX_c = ds + (Y_c - y_G) dphi:
//     u(phi) = lambda(phi) W / kt + integral_0^phi (Y_c - y_G) dphi'.
struct StripCurve {
  std::vector<double> u, lambda;
};

StripCurve strip_curve(double b, double h, double weight, double kn, double kt, double phi_end) {
  StripCurve c;
  double integral = 0.0, prev_arm = 0.0, prev_phi = 0.0;
  const int n = 20000;
  for (int i = 0; i <= n; ++i) {
    const double phi = phi_end * std::pow(static_cast<double>(i) / n, 2.0);
    const double cs = std::cos(phi), sn = std::sin(phi);
    auto shape = [&](double delta) {
      const Pt r0{0.0, -delta}, l0{-b * cs, -delta + b * sn};
      const Pt r1{r0.x + h * sn, r0.y + h * cs}, l1{l0.x + h * sn, l0.y + h * cs};
      return std::vector<Pt>{r0, r1, l1, l0};
    };
    // kn |O| = W: |O| grows with delta.
    double lo = 0.0, hi = 1.0;
    for (int it = 0; it < 200; ++it) {
      const double mid = 0.5 * (lo + hi);
      double area;
      Pt g;
      clip_below_ground(shape(mid), area, g);
      (kn * area < weight ? lo : hi) = mid;
    }
    const double delta = 0.5 * (lo + hi);
    double area;
    Pt g;
    clip_below_ground(shape(delta), area, g);
    const double xc = -0.5 * b * cs + 0.5 * h * sn, yc = -delta + 0.5 * b * sn + 0.5 * h * cs;
    const double arm = yc - g.y;
    const double lam = (g.x - xc) / arm;
    if (i > 0) integral += 0.5 * (arm + prev_arm) * (phi - prev_phi);
    prev_arm = arm, prev_phi = phi;
    c.u.push_back(lam * weight / kt + integral);
    c.lambda.push_back(lam);
  }
  return c;
}

// lambda of a curve at displacement d (linear between its points; the first crossing).
double lambda_at(const std::vector<double>& u, const std::vector<double>& lam, double d) {
  for (std::size_t i = 1; i < u.size(); ++i)
    if ((u[i - 1] - d) * (u[i] - d) <= 0.0 && u[i] != u[i - 1])
      return lam[i - 1] + (lam[i] - lam[i - 1]) * (d - u[i - 1]) / (u[i] - u[i - 1]);
  return NAN;
}

Config block_deck(const std::string& kn, const std::string& ks) {
  return parse_deck(
      "[model]\nkind = \"block\"\nwidth = 0.25\nheight = 1.0\n[material]\n"
      "model = \"rigid\"\n[contact]\nfriction = 0.8\nnormal_stiffness = " +
          kn + "\nshear_stiffness = " + ks + "\n",
      "test");
}

void curve_of(const PushoverResult& r, std::vector<double>& u, std::vector<double>& lam) {
  for (const PushoverPoint& p : r.curve) u.push_back(p.displacement), lam.push_back(p.lambda);
}

TEST(Pushover, WinklerBlockFollowsTheClosedFormCurveOfItsContactStrip) {
  const double b = 0.25, h = 1.0, weight = 2000.0 * b * h * 9.81;
  for (const double kn : {1e8, 1e10}) {
    const double kt = kn * b;  // shear_stiffness = kn, over the joint's length b
    const StripCurve exact = strip_curve(b, h, weight, kn, kt, 0.2);
    const std::size_t ip = static_cast<std::size_t>(
        std::max_element(exact.lambda.begin(), exact.lambda.end()) - exact.lambda.begin());
    const double d_peak = exact.u[ip];
    PushoverSettings set;
    set.criteria.quasi_static = true;
    set.max_displacement = 6.0 * d_peak;
    const PushoverResult r =
        run_pushover(block_deck(std::to_string(kn), std::to_string(kn)), set, true);
    std::vector<double> u, lam;
    curve_of(r, u, lam);
    std::printf(
        "[pushover winkler] kn %.0e: peak %.5f at %.3g m (closed form %.5f at %.3g m), "
        "energy balance %.2g\n",
        kn, r.peak.lambda, r.peak.displacement, exact.lambda[ip], d_peak, r.energy_balance_error);
    for (const double f : {0.5, 1.0, 2.0, 5.0}) {
      const double d = f * d_peak;
      const double got = lambda_at(u, lam, d), want = lambda_at(exact.u, exact.lambda, d);
      std::printf("  d = %.1f x peak: lambda %.5f, closed form %.5f\n", f, got, want);
      EXPECT_NEAR(got, want, 0.02 * b / h) << "kn " << kn << " at " << f << " x peak";
    }
    EXPECT_LT(r.energy_balance_error, 0.01);
  }
}

TEST(Pushover, StiffJointFollowsTheRigidBlockRockingCurveToItsEnd) {
  const double b = 0.25, h = 1.0;
  PushoverSettings set;
  set.criteria.quasi_static = true;
  const PushoverResult r = run_pushover(block_deck("1e14", "1e14"), set, true);
  ASSERT_TRUE(r.reached_zero);
  std::vector<double> u, lam;
  curve_of(r, u, lam);
  // Rocking about the corner: u(theta) = b/2 (1 - cos theta) + h/2 sin theta.
  const double alpha = std::atan(b / h);
  auto u_of = [&](double t) { return 0.5 * b * (1.0 - std::cos(t)) + 0.5 * h * std::sin(t); };
  for (const double f : {0.1, 0.3, 0.5, 0.7, 0.9}) {
    const double t = f * alpha;
    const double want = (b * std::cos(t) - h * std::sin(t)) / (h * std::cos(t) + b * std::sin(t));
    const double got = lambda_at(u, lam, u_of(t));
    std::printf("[pushover rigid] theta %.3f: lambda %.5f, rigid block %.5f\n", t, got, want);
    EXPECT_NEAR(got, want, 0.02 * b / h) << "theta " << t;
  }
  EXPECT_NEAR(r.ultimate_displacement, u_of(alpha), 0.02 * u_of(alpha));
  EXPECT_LT(r.energy_balance_error, 0.01);
  // One block: the SDOF curve is the block's own (M* = M, e* = 1, d* = d, a* = lambda g).
  ASSERT_TRUE(r.sdof.valid);
  EXPECT_NEAR(r.sdof.participating_mass_ratio, 1.0, 1e-12);
  EXPECT_NEAR(r.sdof.factor, 1.0, 1e-12);
  EXPECT_NEAR(r.sdof.d_star_u, 0.4 * r.ultimate_displacement, 1e-12);
}

// Two blocks of weights 1 and 3 moving 1 and 0.5 with the control at the first:
// sum P dx = 2.5, sum P dx^2 = 1.75, M* = 2.5^2 / (1.75 g), e* = 6.25 / (1.75 x 4),
// d* / d = 1.75 / 2.5.
TEST(Pushover, EquivalentSdofOfATwoBlockMechanism) {
  const double g = 9.81;
  const std::vector<PushoverPoint> curve = {
      {0.0, 0.0, 0.0, 0.0}, {0.1, 0.4, 1.0, 0.4}, {0.3, 0.0, 2.0, 0.0}};
  const Sdof s = equivalent_sdof({1.0, 3.0, 0.0}, {1.0, 0.5, 0.0}, 0, curve, g, true, 0.3);
  ASSERT_TRUE(s.valid);
  EXPECT_NEAR(s.participating_mass, 6.25 / (1.75 * g), 1e-12);
  EXPECT_NEAR(s.participating_mass_ratio, 6.25 / 7.0, 1e-12);
  EXPECT_NEAR(s.factor, 0.7, 1e-12);
  EXPECT_NEAR(s.a_star[1], 0.4 * g * 7.0 / 6.25, 1e-12);
  EXPECT_NEAR(s.d_star[2], 0.21, 1e-12);
  EXPECT_NEAR(s.d_star_u, 0.4 * 0.21, 1e-12);
}

TEST(Pushover, DefaultControlIsTheCrownOfAnArch) {
  const Config config =
      load_deck(std::string(VOUSSOIR_SOURCE_DIR) + "/cases/circular_arch.toml", {});
  const Simulation sim = make_simulation(config);
  const int k = default_control_block(sim.model);
  ASSERT_GE(k, 0);
  const Block& crown = sim.model.blocks[static_cast<std::size_t>(k)];
  EXPECT_EQ(crown.role, "voussoir");
  // The crown of the symmetric arch of 11 voussoirs straddles x = 0.
  double xlo = 1e9, xhi = -1e9;
  for (const Vec2& p : crown.polygon) xlo = std::min(xlo, p.x), xhi = std::max(xhi, p.x);
  EXPECT_LT(xlo, 0.0);
  EXPECT_GT(xhi, 0.0);
}

TEST(Pushover, BadOptionsNameTheOptionAndValue) {
  const Config config =
      load_deck(std::string(VOUSSOIR_SOURCE_DIR) + "/cases/circular_arch.toml", {});
  const Simulation sim = make_simulation(config);
  auto message = [&](const PushoverSettings& s) {
    try {
      validate_pushover(sim.model, s);
    } catch (const DeckError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  PushoverSettings s;
  s.control = 99;
  EXPECT_NE(message(s).find("--control 99"), std::string::npos) << message(s);
  int fixed = -1;
  for (std::size_t b = 0; b < sim.model.blocks.size(); ++b)
    if (sim.model.blocks[b].fixed) fixed = static_cast<int>(b);
  ASSERT_GE(fixed, 0);
  s.control = fixed;
  EXPECT_NE(message(s).find("is fixed"), std::string::npos) << message(s);
  s = PushoverSettings{};
  s.rate = -1.0;
  EXPECT_NE(message(s).find("--rate -1"), std::string::npos) << message(s);
  s = PushoverSettings{};
  s.max_displacement = -0.5;
  EXPECT_NE(message(s).find("--max-displacement -0.5"), std::string::npos) << message(s);
  s = PushoverSettings{};
  s.servo = -3.0;
  EXPECT_NE(message(s).find("--servo -3"), std::string::npos) << message(s);
  s = PushoverSettings{};
  EXPECT_EQ(message(s), "accepted");
}

// The program: exit status 2 and the option and value named, before any settle.
TEST(Pushover, CommandRefusesBadOptionsWithStatusTwo) {
  const std::string deck = std::string(VOUSSOIR_SOURCE_DIR) + "/cases/circular_arch.toml";
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "voussoir_pushover_cli";
  std::filesystem::create_directories(dir);
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--direction", "y"}, "--direction y"},
      {{"--rate", "0"}, "--rate 0"},
      {{"--control", "99"}, "--control 99"},
      {{"--stop-at", "1"}, "--stop-at 1"}};
  for (const auto& [args, named] : cases) {
    std::vector<std::string> all = {VOUSSOIR_BINARY, "pushover", deck, "--quiet"};
    all.insert(all.end(), args.begin(), args.end());
    const testing::ProcessResult r = testing::run_process(all, {}, (dir / "child").string());
    ASSERT_TRUE(r.exited) << r.describe();
    EXPECT_EQ(r.status, 2) << named << ": " << r.err;
    EXPECT_NE(r.err.find(named), std::string::npos) << r.err;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace voussoir

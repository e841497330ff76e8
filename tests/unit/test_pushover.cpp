// Capacity curves (commands/pushover.hpp): a rigid block on a Winkler joint against the closed
// form of its contact strip, and on a stiff joint against the rigid block's rocking curve; the
// equivalent SDOF curve of a single block and of a hand-made two-block mechanism; the default
// control block; bad options refused with the option and value.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "commands/pushover.hpp"
#include "engine/setup.hpp"
#include "io/deck.hpp"
#include "limit/limit_analysis.hpp"
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

// The semicircular arch's four-hinge mechanism, its SDOF quantities by hand. The hinges are the
// limit analysis' (pivots A, B, C, D from the left), and the pushover opens the same four first;
// the voussoirs between them form three rigid links: A-B turning about A at the rate 1, B-C
// about the intersection I of the lines AB and DC (its rate w2 from B's velocity,
// w1 (B - A) = w2 (B - I)), C-D about D (w3 from C's, w2 (C - I) = w3 (C - D)); the blocks
// between a springing and its hinge stay. A centroid P of a link turning at w about O moves by
// dx = -w (P_y - O_y); normalised at the crown block, with the blocks' weights P_i:
//     M* = (sum P dx)^2 / (g sum P dx^2),  e* = g M* / sum P,  d* / d = sum P dx^2 / sum P dx,
// which equivalent_sdof must give for these dx (e* = 0.76: not the single block's 1).
TEST(Pushover, EquivalentSdofOfTheSemicircularArchsFourHingeMechanism) {
  const Config config =
      load_deck(std::string(VOUSSOIR_SOURCE_DIR) + "/cases/circular_arch.toml", {});
  const Model model = make_simulation(config).model;
  const double g = config.load.gravity;
  const LimitResult la = limit_analysis(model, config.contact.friction, g, false);
  std::vector<Pt> pivot;
  std::vector<int> joints;
  for (const MechanismJoint& j : la.mechanism) {
    ASSERT_EQ(j.kind, "hinge");
    pivot.push_back({j.x, j.y});
    joints.push_back(j.joint);
  }
  ASSERT_EQ(pivot.size(), 4u);
  // From the left springing (angle 180 deg) to the right (0 deg).
  auto angle = [](double x, double y) { return std::atan2(y, x); };
  std::sort(pivot.begin(), pivot.end(),
            [&](const Pt& a, const Pt& b) { return angle(a.x, a.y) > angle(b.x, b.y); });
  const Pt A = pivot[0], B = pivot[1], C = pivot[2], D = pivot[3];
  // I = A + s (B - A) on the line DC: cross(I - D, C - D) = 0.
  const Pt ab{B.x - A.x, B.y - A.y}, dc{C.x - D.x, C.y - D.y};
  const double s_i = ((D.x - A.x) * dc.y - (D.y - A.y) * dc.x) / (ab.x * dc.y - ab.y * dc.x);
  const Pt I{A.x + s_i * ab.x, A.y + s_i * ab.y};
  auto dot = [](Pt u, Pt v) { return u.x * v.x + u.y * v.y; };
  const Pt bi{B.x - I.x, B.y - I.y}, ci{C.x - I.x, C.y - I.y}, cd{C.x - D.x, C.y - D.y};
  const double w1 = 1.0, w2 = w1 * dot(ab, bi) / dot(bi, bi), w3 = w2 * dot(ci, cd) / dot(cd, cd);
  const int crown = default_control_block(model);
  std::vector<double> weight(model.blocks.size(), 0.0), dx(model.blocks.size(), 0.0);
  for (std::size_t b = 0; b < model.blocks.size(); ++b) {
    const Block& blk = model.blocks[b];
    if (blk.fixed) continue;
    const double px = model.rigid.cx0[Index(b)], py = model.rigid.cy0[Index(b)];
    const double t = angle(px, py);
    weight[b] = blk.mass * g;
    if (t > angle(A.x, A.y) || t < angle(D.x, D.y))
      dx[b] = 0.0;  // between a springing and its hinge: at rest
    else if (t > angle(B.x, B.y))
      dx[b] = -w1 * (py - A.y);
    else if (t > angle(C.x, C.y))
      dx[b] = -w2 * (py - I.y);
    else
      dx[b] = -w3 * (py - D.y);
  }
  const double dk = dx[std::size_t(crown)];
  double sum_p = 0.0, sum_pd = 0.0, sum_pd2 = 0.0;
  for (std::size_t b = 0; b < dx.size(); ++b) {
    dx[b] /= dk;
    sum_p += weight[b], sum_pd += weight[b] * dx[b], sum_pd2 += weight[b] * dx[b] * dx[b];
  }
  const double m_star = sum_pd * sum_pd / (g * sum_pd2);
  const double e_star = g * m_star / sum_p, factor = sum_pd2 / sum_pd;
  ASSERT_LT(e_star, 0.9);  // a mechanism, not one block: e* = 1 would test nothing
  const std::vector<PushoverPoint> curve = {
      {0.0, 0.0, 0.0, 0.0}, {0.01, 0.29, 1.0, 0.29}, {0.05, 0.0, 2.0, 0.0}};
  const Sdof s = equivalent_sdof(weight, dx, crown, curve, g, true, 0.05);
  ASSERT_TRUE(s.valid);
  std::printf("[pushover arch] four-hinge mechanism: e* %.4f, M* %.2f kg, d*/d %.4f\n", e_star,
              m_star, factor);
  EXPECT_NEAR(s.participating_mass_ratio, e_star, 1e-12);
  EXPECT_NEAR(s.participating_mass, m_star, 1e-9 * m_star);
  EXPECT_NEAR(s.factor, factor, 1e-12);
  EXPECT_NEAR(s.a_star[1], 0.29 * g / e_star, 1e-12);
  EXPECT_NEAR(s.d_star[2], 0.05 * factor, 1e-12);
  EXPECT_NEAR(s.d_star_u, 0.4 * 0.05 * factor, 1e-12);

  // The pushover opens these four joints first (the order aside).
  PushoverSettings set;
  set.stop_fraction = 0.8;
  const PushoverResult r = run_pushover(config, set, true);
  ASSERT_GE(r.hinges.size(), 4u);
  std::vector<int> first;
  for (std::size_t i = 0; i < 4; ++i) first.push_back(r.hinges[i].hinge.joint);
  std::sort(first.begin(), first.end());
  std::sort(joints.begin(), joints.end());
  EXPECT_EQ(first, joints);
}

// [supports]: the servo's lambda_la and the technique come from the limit analysis of the moved
// blocks, as capacity's seed does (limit_of_settled of the same settle), not of the blocks as
// built (spread by 5 mm, lambda_la falls).
TEST(Pushover, WithSupportsTheLimitAnalysisIsOfTheMovedBlocks) {
  const std::string deck = std::string(VOUSSOIR_SOURCE_DIR) + "/cases/circular_arch.toml";
  const Config config = load_deck(deck, {"supports.moves=[{block = 11, dx = -0.005}, "
                                         "{block = 12, dx = 0.005}]",
                                         "supports.ramp=0.1"});
  PushoverSettings set;
  set.max_displacement = 1e-4;  // the reference is set before the run: a short one
  const PushoverResult r = run_pushover(config, set, true);
  TrialCriteria crit;
  crit.quasi_static = true;
  const SettledState settled = settle(config, crit, true);
  ASSERT_TRUE(settled.settled);
  const double moved = limit_of_settled(settled, config.contact.friction, 1.0).lambda_la;
  const double built =
      limit_analysis(make_simulation(config).model, config.contact.friction, 9.81, false).lambda_la;
  ASSERT_LT(moved, 0.99 * built);
  EXPECT_EQ(r.lambda_ref_from, "limit analysis");
  EXPECT_DOUBLE_EQ(r.lambda_ref, moved);
  EXPECT_TRUE(r.quasi_static);
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

// The program's JSON against docs/reference/output.md's names, towards -x and +x, with its CSV: a 0.25 x 1 m rigid
// block on stiff joints (its rocking curve: peak b/h at d ~ 0, lambda 0 at the corner's
// tipping point). -x is the mirror of +x: the same curve within 1e-3 b/h. The CSV holds the
// JSON's curve and its SDOF curve (one block: d* = d, a* = lambda g). --dynamic runs the
// physical technique and finds the same peak within 2% of b/h; a block sliding at mu = 0.15
// < b/h runs it unasked, its peak mu within 2% of it.
nlohmann::json pushover_cli(const std::filesystem::path& dir, const std::string& name,
                            const std::vector<std::string>& extra,
                            std::string* csv_text = nullptr) {
  std::vector<std::string> args = {VOUSSOIR_BINARY,
                                   "pushover",
                                   std::string(VOUSSOIR_SOURCE_DIR) + "/cases/block.toml",
                                   "-q",
                                   "--set",
                                   "model.width=0.25",
                                   "--set",
                                   "material.model=\"rigid\"",
                                   "--set",
                                   "contact.normal_stiffness=1e14",
                                   "--set",
                                   "contact.shear_stiffness=1e14",
                                   "--json",
                                   (dir / (name + ".json")).string(),
                                   "--csv",
                                   (dir / (name + ".csv")).string()};
  args.insert(args.end(), extra.begin(), extra.end());
  const testing::ProcessResult r =
      testing::run_process(args, {.wall_s = 300, .cpu_s = 600}, (dir / name).string());
  EXPECT_TRUE(r.exited && r.status == 0) << name << ": " << r.describe() << r.err;
  if (csv_text) *csv_text = testing::read_text_file((dir / (name + ".csv")).string());
  return nlohmann::json::parse(testing::read_text_file((dir / (name + ".json")).string()));
}

TEST(Pushover, CommandJsonCsvAndDirections) {
  const double b_over_h = 0.25;
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "voussoir_pushover_json";
  std::filesystem::create_directories(dir);
  std::string csv;
  const nlohmann::json minus = pushover_cli(dir, "minus", {"--direction", "-x"}, &csv);
  // docs/reference/output.md's fields.
  for (const char* key :
       {"curve", "peak", "ultimate_displacement", "control", "sdof", "hinges", "wall_s"})
    EXPECT_TRUE(minus.contains(key)) << key;
  for (const char* key : {"displacement", "lambda"})
    EXPECT_TRUE(minus.at("curve").at(0).contains(key)) << key;
  EXPECT_TRUE(minus.at("peak").contains("lambda") && minus.at("peak").contains("displacement"));
  EXPECT_TRUE(minus.at("control").contains("block") && minus.at("control").contains("point"));
  for (const char* key : {"participating_mass_ratio", "e_star", "curve", "d_star_u"})
    EXPECT_TRUE(minus.at("sdof").contains(key)) << key;
  EXPECT_TRUE(minus.at("sdof").at("curve").at(0).contains("d_star"));
  EXPECT_TRUE(minus.at("sdof").at("curve").at(0).contains("a_star"));
  EXPECT_EQ(minus.at("direction"), "-x");
  EXPECT_EQ(minus.at("technique"), "quasi-static: the limit-analysis mechanism does not slide");

  const nlohmann::json plus = pushover_cli(dir, "plus", {});
  const double peak = plus.at("peak").at("lambda").get<double>();
  EXPECT_NEAR(peak, b_over_h, 0.02 * b_over_h);
  EXPECT_NEAR(minus.at("peak").at("lambda").get<double>(), peak, 1e-3 * b_over_h);
  EXPECT_NEAR(minus.at("ultimate_displacement").get<double>(),
              plus.at("ultimate_displacement").get<double>(),
              1e-3 * plus.at("ultimate_displacement").get<double>());
  // Towards -x the displacement along the load is positive, as towards +x.
  EXPECT_GT(minus.at("curve").back().at("displacement").get<double>(), 0.0);

  // The CSV: the JSON's curve, row by row, and its SDOF curve (one block: d* = d, a* = lambda g).
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "displacement,lambda,time,d_star,a_star");
  const nlohmann::json& curve = minus.at("curve");
  std::size_t row = 0;
  while (std::getline(in, line)) {
    double v[5];
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2], &v[3], &v[4]),
              5)
        << line;
    ASSERT_LT(row, curve.size());
    EXPECT_NEAR(v[0], curve[row].at("displacement").get<double>(), 1e-8);
    EXPECT_NEAR(v[1], curve[row].at("lambda").get<double>(), 1e-8);
    EXPECT_NEAR(v[3], v[0], 1e-8);
    EXPECT_NEAR(v[4], v[1] * 9.81, 1e-7);
    ++row;
  }
  EXPECT_EQ(row, curve.size());

  const nlohmann::json dynamic = pushover_cli(dir, "dynamic", {"--dynamic"});
  EXPECT_EQ(dynamic.at("technique"), "dynamic (asked)");
  EXPECT_FALSE(dynamic.at("quasi_static").get<bool>());
  EXPECT_NEAR(dynamic.at("peak").at("lambda").get<double>(), b_over_h, 0.02 * b_over_h);

  const double mu = 0.15;
  const nlohmann::json slides =
      pushover_cli(dir, "slides", {"--set", "contact.friction=0.15", "--max-displacement", "0.05"});
  EXPECT_EQ(slides.at("technique"), "physical: the limit-analysis mechanism slides");
  EXPECT_FALSE(slides.at("quasi_static").get<bool>());
  EXPECT_NEAR(slides.at("peak").at("lambda").get<double>(), mu, 0.02 * mu);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace voussoir

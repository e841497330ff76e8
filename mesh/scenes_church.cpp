// The church scene (docs/reference/deck.md, [model]): a hall church of pointed (two-centred) arches
// on supports (outer buttress, piers, outer buttress) standing on a fixed ground.
//
// Layout, x = 0 at the middle of the whole width W = 2 outer_width + sum(spans) + (K-1) pier:
//   support 0 = [-W/2, -W/2 + outer_width], then span 0, pier 1, span 1, ..., support K (outer);
//   supports are rectangles from y = 0 to y = height (flat tops); the ground is a fixed
//   rectangle under them, outer_width/2 deep, reaching outer_width beyond the outer faces.
// Arch over a clear span S between faces a (left) and b (right), springing line y = H:
//   c = eccentricity S / 2, Ri = S/2 + c, Re = Ri + t, midspan xm = (a + b)/2;
//   right half: centre C_R = (xm - c, H), point at angle theta from the springing and radius rho
//     (xm - c + rho cos theta, H + rho sin theta);
//   left half: centre C_L = (xm + c, H), point (xm + c - rho cos theta, H + rho sin theta)
//     (written with the same theta so that mirrored spans are exact mirror images);
//   intrados apex angle theta_i = acos(c / Ri), extrados apex angle theta_e = acos(c / Re);
//   the springing joint is horizontal: intrados point exactly on the support face (x = b on the
//   right, a on the left), extrados point t further out.
// Voussoirs: each half is cut into polar voussoirs of `voussoir_angle` (D) about its own centre
// from the springing. The crown block takes the rest, which spans the apex (its intrados has
// the pointed notch, so it is not convex). Decision: K = floor(theta_i / D) voussoirs per half,
// one fewer when the intrados remainder theta_i - K D would be under D/2, so the crown block's
// intrados reaches between D/2 and 3D/2 past the last joint on each side and the crown is never
// a sliver (a sliver would set the stable time step of the whole church). With the default
// eccentricity 0.25, theta_i = acos(0.2) = 78.46 deg and D = 2 deg give K = 38 per half.
// Supports with `courses` > 0 (scheme A) are cut by horizontal joints every `courses` metres
// from the ground; the top course takes what is left (shorter if needed).

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "mesh/scene_spec.hpp"

namespace voussoir {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kFixedCoarsening = 3.0;
// Largest support width, pier width, height and arch thickness accepted, as a multiple of the
// largest span (dimensionless; real churches stay below ~3).
constexpr double kMaxSizeToSpan = 100.0;
// Smallest support height accepted, as a multiple of the largest span. Lower supports are
// outlined into ever thinner course slivers (4450 triangles at 0.05 m, 49418 at 1e-4 m, and
// no end at 1e-6 m: a fuzzing finding); no church stands on supports that low.
constexpr double kMinHeightToSpan = 0.01;

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

// Points of the horizontal segment from x0 to x1 at height y (both ends included), parts no
// longer than h. A segment symmetric about x = 0 (x0 == -x1) is built from its right half and
// mirrored, with a point at x = 0 exactly.
std::vector<Vec2> row_points(double x0, double x1, double y, double h) {
  std::vector<Vec2> out;
  if (x0 == -x1 && x0 != 0.0) {
    const double xr = std::abs(x0);
    std::vector<Vec2> half;
    append_segment(half, {0.0, y}, {xr, y}, h);
    half.push_back({xr, y});  // 0 .. xr
    if (x0 > 0.0) {           // right to left
      for (auto it = half.rbegin(); it != half.rend(); ++it) out.push_back(*it);
      for (std::size_t k = 1; k < half.size(); ++k) out.push_back(mirror_x(half[k]));
    } else {
      for (auto it = half.rbegin(); it != half.rend(); ++it) out.push_back(mirror_x(*it));
      for (std::size_t k = 1; k < half.size(); ++k) out.push_back(half[k]);
    }
    return out;
  }
  append_segment(out, {x0, y}, {x1, y}, h);
  out.push_back({x1, y});
  return out;
}

// The right chain (from the lower point on x = 0, counter-clockwise, to the upper one) of a
// closed boundary symmetric about x = 0 that has exactly two points on the axis.
std::vector<Vec2> right_chain_of(const std::vector<Vec2>& boundary) {
  std::vector<std::size_t> on_axis;
  for (std::size_t i = 0; i < boundary.size(); ++i)
    if (boundary[i].x == 0.0) on_axis.push_back(i);
  if (on_axis.size() != 2) throw std::logic_error("right_chain_of: need two points on x = 0");
  std::size_t lo = on_axis[0], hi = on_axis[1];
  if (boundary[lo].y > boundary[hi].y) std::swap(lo, hi);
  std::vector<Vec2> chain;
  for (std::size_t i = lo;; i = (i + 1) % boundary.size()) {
    chain.push_back(boundary[i]);
    if (i == hi) break;
  }
  return chain;
}

struct Support {
  double xl = 0.0, xr = 0.0;
  std::string role;
  std::vector<Index> blocks;  // bottom course first
  std::vector<Vec2> base;     // base row, left to right
};

struct SpanFaces {
  std::vector<Vec2> left, right;  // springing faces, intrados point first
};

// Relative slack of a support's least width, 2t for a pier and t for an outer buttress
// (check_church; church_arch makes the extrados springing points meet on a support that wide).
constexpr double kTight = 1e-9;

// The blocks of one arch, stored aside and added after the supports.
struct ArchBlocks {
  std::vector<BlockSpec> blocks;
  std::vector<Joint> joints;  // block indices local to the arch, patched when added
};

// The church's keys checked (geometry_error naming the key); `t` is the thickness it is built
// with.
void check_church(const SceneParams& params, double t) {
  const ModelConfig& mc = params.model;
  const std::vector<double>& spans = mc.spans;
  const int ns = static_cast<int>(spans.size());
  const double pier = mc.pier_width, outer = mc.outer_width, height = mc.height;
  const double ecc = mc.eccentricity, dtheta = mc.voussoir_angle * kDeg;
  const double hc = mc.courses;
  if (ns < 1) geometry_error(params, VOUSSOIR_KEY(model.spans), "[]", "expected at least one span");
  for (double s : spans)
    if (!(s > 0.0))
      geometry_error(params, VOUSSOIR_KEY(model.spans), s, "every span must be > 0 m");
  if (!(t > 0.0))
    geometry_error(params, VOUSSOIR_KEY(model.thickness), t, "expected a thickness > 0 m");
  // A support exactly as wide as its springings (pier = 2t, outer = t, the default church)
  // is allowed: the extrados springing points then meet at the pier's middle (or the outer
  // face) and are made the same point.
  if (!(outer >= t * (1.0 - kTight)))
    geometry_error(params, VOUSSOIR_KEY(model.outer_width), outer,
                   "an outer buttress must carry its arch's springing joint: it must be at least " +
                       std::string(VOUSSOIR_KEY(model.thickness)) + " = " + fmt(t) + " m wide");
  if (ns > 1 && !(pier >= 2.0 * t * (1.0 - kTight)))
    geometry_error(params, VOUSSOIR_KEY(model.pier_width), pier,
                   "too narrow for its two springings: a pier carries two springing joints of " +
                       std::string(VOUSSOIR_KEY(model.thickness)) + " = " + fmt(t) +
                       " m each, so it must be at least " + fmt(2.0 * t) + " m wide");
  if (!(height > 0.0))
    geometry_error(params, VOUSSOIR_KEY(model.height), height, "expected a height > 0 m");
  if (!(ecc >= 0.0))
    geometry_error(params, VOUSSOIR_KEY(model.eccentricity), ecc, "expected a value >= 0");
  if (!(dtheta > 0.0 && dtheta < 0.5 * kPi))
    geometry_error(params, VOUSSOIR_KEY(model.voussoir_angle), mc.voussoir_angle,
                   "expected (0, 90) degrees");
  // Absurd sizes. Supports are outlined at the arches' element size before any triangle
  // budget can be estimated (mesh/scene.cpp), so a 4.3e9 m outer buttress (a fuzzing finding)
  // exhausted memory in the generator. No church has a support or a height of more than
  // kMaxSizeToSpan times its largest span; a thickness that large is no arch either.
  const double span_max = *std::max_element(spans.begin(), spans.end());
  const double size_limit = kMaxSizeToSpan * span_max;
  auto refuse_above_limit = [&](const char* key, double value) {
    if (!(value <= size_limit))
      geometry_error(params, key, value,
                     "expected at most " + fmt(kMaxSizeToSpan) + " x the largest span (" +
                         fmt(span_max) + " m), i.e. " + fmt(size_limit) + " m");
  };
  refuse_above_limit(VOUSSOIR_KEY(model.outer_width), outer);
  if (ns > 1) refuse_above_limit(VOUSSOIR_KEY(model.pier_width), pier);
  refuse_above_limit(VOUSSOIR_KEY(model.height), height);
  if (!(height >= kMinHeightToSpan * span_max))
    geometry_error(params, VOUSSOIR_KEY(model.height), height,
                   "expected at least " + fmt(kMinHeightToSpan) + " x the largest span (" +
                       fmt(span_max) + " m), i.e. " + fmt(kMinHeightToSpan * span_max) + " m");
  refuse_above_limit(VOUSSOIR_KEY(model.thickness), t);
  if (hc > 0.0 && height / hc > 10000.0)
    geometry_error(params, VOUSSOIR_KEY(model.courses), hc,
                   "makes more than 10000 courses per support");
}

// Support faces, left to right; mirrored exactly when the church is symmetric.
std::vector<Support> support_faces(const ModelConfig& mc, bool symmetric) {
  const std::vector<double>& spans = mc.spans;
  const int ns = static_cast<int>(spans.size());
  const double pier = mc.pier_width, outer = mc.outer_width;
  double width = 2.0 * outer + (ns - 1) * pier;
  for (double s : spans) width += s;
  std::vector<Support> sup(ns + 1);
  double x = -0.5 * width;
  for (int i = 0; i <= ns; ++i) {
    const double w = (i == 0 || i == ns) ? outer : pier;
    sup[i].xl = x;
    sup[i].xr = x + w;
    sup[i].role = (i == 0 || i == ns) ? "buttress" : "pier";
    x += w + (i < ns ? spans[i] : 0.0);
  }
  if (symmetric) {
    for (int i = 0; i <= ns; ++i) {
      const int j = ns - i;
      if (i < j) {
        sup[i].xl = -sup[j].xr;
        sup[i].xr = -sup[j].xl;
      } else if (i == j) {
        sup[i].xr = -sup[i].xl;
      }
    }
  }
  return sup;
}

// The blocks and inner joints of span `s` between the supports sup[s] and sup[s + 1], and its
// springing faces.
ArchBlocks church_arch(const SceneParams& params, double t, double h,
                       const std::vector<Support>& sup, int s, SpanFaces& face) {
  const ModelConfig& mc = params.model;
  const double height = mc.height;
  const double ecc = mc.eccentricity, dtheta = mc.voussoir_angle * kDeg;
  ArchBlocks ab;
  const double a = sup[s].xr, b = sup[s + 1].xl;
  const double span = b - a, xm = 0.5 * (a + b);
  const double c = 0.5 * ecc * span, ri = 0.5 * span + c, re = ri + t;
  const double th_i = std::acos(c / ri), th_e = std::acos(c / re);
  int kh = static_cast<int>(std::floor(th_i / dtheta));
  if (th_i - kh * dtheta < 0.5 * dtheta) --kh;
  kh = std::max(kh, 0);
  if (kh > 100000)
    geometry_error(params, VOUSSOIR_KEY(model.voussoir_angle), mc.voussoir_angle,
                   "makes more than 100000 voussoirs per half arch");
  int n = 1, m = 1;
  choose_band_cells(t, (ri + 0.5 * t) * dtheta, 0.5 * t / (ri + 0.5 * t), h, &n, &m);
  check_triangle_budget(params, 4.0 * kh * (static_cast<double>(n) * m + n));
  const double ya_i = height + std::sqrt(ri * ri - c * c);
  const double ya_e = height + std::sqrt(re * re - c * c);
  const Vec2 apex_i{xm, ya_i}, apex_e{xm, ya_e};
  const double crl = xm - c, cll = xm + c;  // x of C_R and C_L
  auto rho = [&](int i) { return i == n ? re : ri + (i * t) / n; };
  // side +1: right half, -1: left half; column j at theta = j D / m, row i at radius rho(i).
  // Point at angle th and radius r on one half. Explicit fma: GCC contracts a + r cos into
  // an fma at some call sites and not at others (-ffp-contract=fast is its default), which
  // would break the bit-exact mirror pairs; with fma(-r, c, cll) = -fma(r, c, -cll) the
  // left half is the exact mirror image of the right half of the mirrored span.
  auto polar = [&](int side, double r, double th) -> Vec2 {
    const double y = std::fma(r, std::sin(th), height);
    return side > 0 ? Vec2{std::fma(r, std::cos(th), crl), y}
                    : Vec2{std::fma(-r, std::cos(th), cll), y};
  };
  // Extrados springing points: t beyond the faces, or exactly the meeting point when the
  // support is just wide enough (see the validation above).
  auto tight = [&](const Support& sp) {
    return sp.xr - sp.xl <=
           (&sp == &sup.front() || &sp == &sup.back() ? 1.0 : 2.0) * t * (1.0 + kTight);
  };
  const Support &sl = sup[s], &sr = sup[s + 1];
  const double xe_left = !tight(sl) ? a - t : (&sl == &sup.front() ? sl.xl : 0.5 * (sl.xl + sl.xr));
  const double xe_right = !tight(sr) ? b + t : (&sr == &sup.back() ? sr.xr : 0.5 * (sr.xl + sr.xr));
  auto point = [&](int side, long long j, int i) -> Vec2 {
    if (j == 0 && i == n) return {side > 0 ? xe_right : xe_left, height};
    if (j == 0) return side > 0 ? Vec2{b + (i * t) / n, height} : Vec2{a - (i * t) / n, height};
    return polar(side, rho(i), static_cast<double>(j) * dtheta / m);
  };
  auto column = [&](int side, long long j) {
    std::vector<Vec2> col(n + 1);
    for (int i = 0; i <= n; ++i) col[i] = point(side, j, i);
    return col;
  };
  face.left = column(-1, 0);
  face.right = column(+1, 0);

  const Vec2 cr{crl, height}, cl{cll, height};
  // Left half: voussoirs 0..kh-1 from the springing; crown; right half from the crown down.
  for (int k = 0; k < kh; ++k) {
    BlockSpec v;
    v.role = "voussoir";
    v.mesher = BlockSpec::Mesher::Band;
    for (long long j = static_cast<long long>(k) * m; j <= static_cast<long long>(k + 1) * m; ++j)
      v.columns.push_back(column(-1, j));
    const Vec2 ia = v.columns.front()[0], ib = v.columns.back()[0];
    const Vec2 ea = v.columns.front()[n], eb = v.columns.back()[n];
    v.outline = {OutlineEdge{ia, ri, cl, -dtheta}, OutlineEdge{ib, 0.0, {}, 0.0},
                 OutlineEdge{eb, re, cl, dtheta}, OutlineEdge{ea, 0.0, {}, 0.0}};
    ab.blocks.push_back(std::move(v));
  }
  const long long jk = static_cast<long long>(kh) * m;
  const double th_k = static_cast<double>(jk) * dtheta / m;
  const std::vector<Vec2> fl = column(-1, jk), fr = column(+1, jk);
  {
    BlockSpec crown;
    crown.role = "crown";
    crown.mesher = BlockSpec::Mesher::Polygon;
    crown.size = std::sqrt(2.0) * h;
    // Counter-clockwise: right joint face up, right extrados up to the apex, left extrados
    // down, left joint face down, left intrados up to the apex notch, right intrados down.
    // (With kh = 0 the crown is the whole arch and its joint faces are the springings.)
    auto arc = [&](int side, double r, double th0, double th1, std::vector<Vec2>& out) {
      // Points strictly between th0 and th1 on the arc of radius r (parts no longer than h).
      const int parts = std::max(1, static_cast<int>(std::ceil(r * std::abs(th1 - th0) / h)));
      for (int q = 1; q < parts; ++q) out.push_back(polar(side, r, th0 + (th1 - th0) * q / parts));
    };
    std::vector<Vec2> bnd;
    bnd.push_back(fr[0]);
    for (int i = 1; i <= n; ++i) bnd.push_back(fr[i]);
    arc(+1, re, th_k, th_e, bnd);
    bnd.push_back(apex_e);
    arc(-1, re, th_e, th_k, bnd);
    for (int i = n; i >= 0; --i) bnd.push_back(fl[i]);
    arc(-1, ri, th_k, th_i, bnd);
    bnd.push_back(apex_i);
    arc(+1, ri, th_i, th_k, bnd);
    crown.boundary = bnd;
    crown.outline = {
        OutlineEdge{fr[0], 0.0, {}, 0.0},         OutlineEdge{fr[n], re, cr, th_e - th_k},
        OutlineEdge{apex_e, re, cl, th_e - th_k}, OutlineEdge{fl[n], 0.0, {}, 0.0},
        OutlineEdge{fl[0], ri, cl, th_k - th_i},  OutlineEdge{apex_i, ri, cr, th_k - th_i}};
    ab.blocks.push_back(std::move(crown));
  }
  for (int k = kh - 1; k >= 0; --k) {
    BlockSpec v;
    v.role = "voussoir";
    v.mesher = BlockSpec::Mesher::Band;
    for (long long j = static_cast<long long>(k) * m; j <= static_cast<long long>(k + 1) * m; ++j)
      v.columns.push_back(column(+1, j));
    const Vec2 ia = v.columns.front()[0], ib = v.columns.back()[0];
    const Vec2 ea = v.columns.front()[n], eb = v.columns.back()[n];
    v.outline = {OutlineEdge{ib, ri, cr, -dtheta}, OutlineEdge{ia, 0.0, {}, 0.0},
                 OutlineEdge{ea, re, cr, dtheta}, OutlineEdge{eb, 0.0, {}, 0.0}};
    ab.blocks.push_back(std::move(v));
  }
  // Joints inside the arch, left to right (local indices: 0..kh-1 left, kh crown, ...).
  for (int k = 1; k <= kh; ++k) {
    const std::vector<Vec2> f = column(-1, static_cast<long long>(k) * m);
    ab.joints.push_back(Joint{k - 1, k, f[0], f[n], k * m * (dtheta / m) / kDeg});
  }
  for (int k = kh; k >= 1; --k) {
    const std::vector<Vec2> f = column(+1, static_cast<long long>(k) * m);
    const Index left_block = kh + (kh - k);  // crown is kh, then right voussoirs
    ab.joints.push_back(
        Joint{left_block, left_block + 1, f[0], f[n], 180.0 - k * m * (dtheta / m) / kDeg});
  }
  return ab;
}

// Supports (course blocks bottom to top), left to right, with their course joints; the top
// course takes the springing faces of its spans.
void add_church_supports(Scene& scene, std::vector<Support>& sup,
                         const std::vector<SpanFaces>& faces, const std::vector<double>& cuts,
                         double h, double y_top) {
  const int ns = static_cast<int>(faces.size());
  for (int i = 0; i <= ns; ++i) {
    Support& sp = sup[i];
    std::vector<std::vector<Vec2>> rows;
    for (double y : cuts) rows.push_back(row_points(sp.xl, sp.xr, y, h));
    sp.base = rows[0];
    for (std::size_t k = 0; k < cuts.size(); ++k) {
      BlockSpec b;
      b.role = sp.role;
      b.mesher = BlockSpec::Mesher::Polygon;
      b.size = std::sqrt(2.0) * h;
      PointChain ch;
      ch.add(rows[k]);
      const bool top = k + 1 == cuts.size();
      const double y1 = top ? y_top : cuts[k + 1];
      ch.segment({sp.xr, cuts[k]}, {sp.xr, y1}, h);
      if (!top) {
        ch.add_reversed(rows[k + 1]);
      } else {
        // Top face right to left: springing of the span on the right (its left face), gap,
        // springing of the span on the left (its right face, extrados first).
        double x_now = sp.xr;
        if (i < ns) {
          ch.add(faces[i].left);
          x_now = faces[i].left.back().x;
        }
        const double x_end = i > 0 ? faces[i - 1].right.back().x : sp.xl;
        ch.add(row_points(x_now, x_end, y_top, h));
        if (i > 0) ch.add_reversed(faces[i - 1].right);
      }
      ch.segment({sp.xl, y1}, {sp.xl, cuts[k]}, h);
      b.boundary = ch.loop();
      b.outline = polygon_outline({{sp.xl, cuts[k]}, {sp.xr, cuts[k]}, {sp.xr, y1}, {sp.xl, y1}});
      sp.blocks.push_back(static_cast<Index>(scene.blocks.size()));
      scene.blocks.push_back(std::move(b));
    }
    for (std::size_t k = 1; k < cuts.size(); ++k) {
      // Course joint: a = end on the arch side (inner face); for the outer buttresses the
      // inner face is the one facing the church, for piers the left end.
      const bool right_outer = i == ns && ns > 0;
      const Vec2 pa{right_outer ? sp.xl : (i == 0 ? sp.xr : sp.xl), cuts[k]};
      const Vec2 pb{right_outer ? sp.xr : (i == 0 ? sp.xl : sp.xr), cuts[k]};
      scene.joints.push_back(Joint{sp.blocks[k - 1], sp.blocks[k], pa, pb, kNaN});
    }
  }
}

// The fixed ground under the supports, with a joint to each support's bottom course.
void add_church_ground(Scene& scene, const std::vector<Support>& sup, const ModelConfig& mc,
                       bool symmetric, double h) {
  const int ns = static_cast<int>(sup.size()) - 1;
  const double outer = mc.outer_width;
  double width = 2.0 * outer + (ns - 1) * mc.pier_width;
  for (double s : mc.spans) width += s;
  const double margin = outer, depth = 0.5 * outer;
  const double xg = 0.5 * width + margin;
  const double xl = symmetric ? -xg : sup[0].xl - margin, xr = xg;
  BlockSpec g;
  g.role = "ground";
  g.fixed = true;
  g.mesher = BlockSpec::Mesher::Polygon;
  g.size = kFixedCoarsening * std::sqrt(2.0) * h;
  PointChain ch;
  ch.add(row_points(xl, xr, -depth, kFixedCoarsening * h));
  ch.segment({xr, -depth}, {xr, 0.0}, kFixedCoarsening * h);
  double x_now = xr;
  for (int i = ns; i >= 0; --i) {
    ch.add(row_points(x_now, sup[i].xr, 0.0, i == ns ? kFixedCoarsening * h : h));
    ch.add_reversed(sup[i].base);
    x_now = sup[i].xl;
  }
  ch.add(row_points(x_now, xl, 0.0, kFixedCoarsening * h));
  ch.segment({xl, 0.0}, {xl, -depth}, kFixedCoarsening * h);
  g.boundary = ch.loop();
  g.outline = polygon_outline({{xl, -depth}, {xr, -depth}, {xr, 0.0}, {xl, 0.0}});
  const Index gi = static_cast<Index>(scene.blocks.size());
  scene.blocks.push_back(std::move(g));
  for (int i = 0; i <= ns; ++i)
    scene.joints.push_back(
        Joint{gi, sup[i].blocks.front(), {sup[i].xl, 0.0}, {sup[i].xr, 0.0}, kNaN});
}

// Symmetric church: blocks left of the axis become mirror images of their right partners,
// blocks across the axis are meshed half and mirrored.
void mirror_church_halves(Scene& scene) {
  for (std::size_t i = 0; i < scene.blocks.size(); ++i) {
    BlockSpec& b = scene.blocks[i];
    if (b.mesher != BlockSpec::Mesher::Polygon) continue;
    double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin;
    for (const Vec2& p : b.boundary) {
      xmin = std::min(xmin, p.x);
      xmax = std::max(xmax, p.x);
    }
    if (xmin < 0.0 && xmax > 0.0) {
      b.boundary = right_chain_of(b.boundary);
      b.mesher = BlockSpec::Mesher::SymmetricPolygon;
    } else if (xmax <= 0.0) {
      // Partner: the polygon block whose exact outline is this one's mirror image.
      const Outline mirrored = mirror_outline(b.outline);
      Index partner = -1;
      for (std::size_t j = 0; j < scene.blocks.size() && partner < 0; ++j) {
        const BlockSpec& c = scene.blocks[j];
        if (j == i || c.mesher != BlockSpec::Mesher::Polygon || c.outline.size() != mirrored.size())
          continue;
        bool same = true;
        for (const OutlineEdge& e : mirrored) {
          bool found = false;
          for (const OutlineEdge& f : c.outline)
            found = found || (f.start.x == e.start.x && f.start.y == e.start.y);
          same = same && found;
        }
        if (same) partner = static_cast<Index>(j);
      }
      if (partner < 0)
        throw std::logic_error("church: no mirror partner for block " + std::to_string(i));
      b.mesher = BlockSpec::Mesher::Mirror;
      b.mirror_of = partner;
      b.outline = mirror_outline(scene.blocks[partner].outline);
    }
  }
}

}  // namespace

Scene build_church_scene(const SceneParams& params) {
  const ModelConfig& mc = params.model;
  const std::vector<double>& spans = mc.spans;
  const int ns = static_cast<int>(spans.size());
  const double height = mc.height;
  // The church's published thickness (0.5 m) differs from the arches' (core/schema.hpp: 0.2 m).
  const double t = mc.has("thickness") ? mc.thickness : 0.5;
  const double hc = mc.courses;
  check_church(params, t);
  const double h = element_size(params, t);
  bool symmetric = true;
  for (int i = 0; i < ns; ++i) symmetric = symmetric && spans[i] == spans[ns - 1 - i];
  std::vector<Support> sup = support_faces(mc, symmetric);

  Scene scene;
  scene.symmetric = symmetric;
  scene.element_size = h;
  const double y_top = height;
  std::vector<double> cuts{0.0};
  if (hc > 0.0)
    for (int k = 1;; ++k) {
      const double y = k * hc;
      if (!(y < height * (1.0 - 1e-9))) break;
      cuts.push_back(y);
    }

  // Arches first (their springing faces go into the supports' tops), stored aside and added
  // after the supports so that block order is: supports, arches (left to right), ground.
  std::vector<ArchBlocks> arches(ns);
  std::vector<SpanFaces> faces(ns);
  for (int s = 0; s < ns; ++s) arches[s] = church_arch(params, t, h, sup, s, faces[s]);

  add_church_supports(scene, sup, faces, cuts, h, y_top);
  // Arches, left to right, with the springing joints.
  for (int s = 0; s < ns; ++s) {
    const Index first = static_cast<Index>(scene.blocks.size());
    const Index count = static_cast<Index>(arches[s].blocks.size());
    for (BlockSpec& b : arches[s].blocks) scene.blocks.push_back(std::move(b));
    scene.joints.push_back(
        Joint{sup[s].blocks.back(), first, faces[s].left.front(), faces[s].left.back(), 0.0});
    for (Joint j : arches[s].joints) {
      j.block_a += first;
      j.block_b += first;
      scene.joints.push_back(j);
    }
    scene.joints.push_back(Joint{first + count - 1, sup[s + 1].blocks.back(),
                                 faces[s].right.front(), faces[s].right.back(), 180.0});
  }

  add_church_ground(scene, sup, mc, symmetric, h);
  if (symmetric) mirror_church_halves(scene);
  return scene;
}

}  // namespace voussoir

// Arch scenes (docs/reference/deck.md, [model]): circular_arch, basket_arch and buttressed_arch.
//
// Geometry. Every arch here is symmetric about x = 0 and its centreline is a chain of circular
// arcs. Only the right half is computed: pieces from the crown (u = 0) to the right springing
// (u = L/2), u the arc length from the crown; a point of the left half is the mirror image of
// the right-half point at -u. A point at arc length u offset by w along the outward normal is
//   P(u, w) = C_k + (R_k + w) (cos theta, sin theta),  theta = theta0_k - (u - u_k) / R_k
// on piece k (centre C_k, radius R_k, crown-side angle theta0_k, starting at u_k).
//   circular: one piece, C = O = (0, 0), R = Rc, theta0 = 90 deg, length Rc beta / 2.
//   basket:   g = (180 - beta) / 2, O3 = (Rc - r)(cos g, sin g), O1 = (0, -d),
//             R1 = |O1 O3| + r, psi = direction of O1 -> O3 (the tangent point of the two arcs
//             is O3 + r (cos psi, sin psi) = O1 + R1 (cos psi, sin psi));
//             pieces: large arc (O1, R1) from 90 deg down to psi, small arc (O3, r) from psi down
//             to g, which ends at S_R = Rc (cos g, sin g).
// Intrados and extrados are the offsets w = -t/2 and +t/2: arcs with the same centres, so a
// band between two normals is bounded by arcs and its exact area is (length) x t.
//
// Voussoirs: N blocks of equal centreline length L/N, joints normal to the centreline. The
// mesh columns (m per voussoir, n + 1 nodes across) sit at u_J = (2J - N m) L / (2 N m): the
// integer factor makes u_{Nm-J} = -u_J exactly, so left and right columns are exact mirrors
// and each joint face is one column shared by the two voussoirs that meet there.
//
// Supports:
//   circular_arch / basket_arch: a fixed abutment under each springing joint: the t-deep
//     rectangle I, I + t D, E + t D, E (I, E: intrados and extrados springing points, D the
//     centreline direction beyond the springing, normal to the joint), so its top face is
//     exactly the springing joint and every corner is square (vertical sides would leave a
//     90 - g degree corner at E, too sharp to mesh well for small embraces).
//   buttressed_arch: a free buttress on each side (the published geometry: inner face vertical
//   through I, top
//     along the joint to E, then horizontal out to x_I + B, outer face down to the ground line
//     y = -H1), monolithic or in horizontal courses of height `courses` from the ground up (the
//     top course, which carries the springing, takes what is left, so it may be shorter or,
//     by the sloping joint, taller); one fixed ground block under both, B/2 deep, reaching B/2
//     beyond the outer faces.

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include "mesh/scene_spec.hpp"

namespace voussoir {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Fixed blocks (abutments, ground) are meshed this many times coarser inside than the element
// size; their faces that touch free blocks keep the free blocks' nodes.
constexpr double kFixedCoarsening = 3.0;

struct Piece {
  Vec2 centre;
  double radius = 0.0;
  double theta0 = 0.0;  // angle at the crown-side end [rad]
  double length = 0.0;  // centreline length of the piece [m]
};

// Right half of a symmetric centreline, crown first.
struct HalfCentreline {
  std::vector<Piece> pieces;
  double half_length = 0.0;
  double min_radius = 0.0;

  std::size_t piece_at(double u) const {
    double start = 0.0;
    for (std::size_t k = 0; k + 1 < pieces.size(); ++k) {
      if (u <= start + pieces[k].length) return k;
      start += pieces[k].length;
    }
    return pieces.size() - 1;
  }
  double piece_start(std::size_t k) const {
    double start = 0.0;
    for (std::size_t i = 0; i < k; ++i) start += pieces[i].length;
    return start;
  }
  Vec2 right_point(double u, double w) const {
    const std::size_t k = piece_at(u);
    const Piece& p = pieces[k];
    return on_circle(p.centre, p.radius + w, p.theta0 - (u - piece_start(k)) / p.radius);
  }
  // P(u, w) for any u in [-L/2, L/2]; the crown point has x = 0 exactly.
  Vec2 point(double u, double w) const {
    if (u > 0.0) return right_point(u, w);
    if (u < 0.0) return mirror_x(right_point(-u, w));
    Vec2 p = right_point(0.0, w);
    p.x = 0.0;
    return p;
  }
  // Turning angle of the normal from the crown to arc length u >= 0 [rad].
  double turn(double u) const {
    double angle = 0.0, start = 0.0;
    for (const Piece& p : pieces) {
      const double part = std::clamp(u - start, 0.0, p.length);
      angle += part / p.radius;
      start += p.length;
    }
    return angle;
  }
  // Piece (centre, radius) carrying the centreline around u (mirrored on the left half).
  void piece_around(double u, Vec2* centre, double* radius) const {
    const Piece& p = pieces[piece_at(std::abs(u))];
    *centre = u < 0.0 ? mirror_x(p.centre) : p.centre;
    *radius = p.radius;
  }
  // Arc lengths of the joints between pieces, both halves, ascending.
  std::vector<double> breaks() const {
    std::vector<double> out;
    double start = 0.0;
    for (std::size_t k = 0; k + 1 < pieces.size(); ++k) {
      start += pieces[k].length;
      out.push_back(start);
    }
    std::vector<double> all;
    for (auto it = out.rbegin(); it != out.rend(); ++it) all.push_back(-*it);
    all.insert(all.end(), out.begin(), out.end());
    return all;
  }
};

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

HalfCentreline circular_centreline(const SceneParams& params) {
  const ModelConfig& mc = params.model;
  const double rc = mc.radius, t = mc.thickness, beta = mc.embrace * kDeg;
  if (!(rc > 0.0))
    geometry_error(params, VOUSSOIR_KEY(model.radius), rc, "expected a radius > 0 [m]");
  if (!(t > 0.0 && t < 2.0 * rc))
    geometry_error(params, VOUSSOIR_KEY(model.thickness), t,
                   "must be below twice the centreline radius (2 x " +
                       std::string(VOUSSOIR_KEY(model.radius)) + " = " + fmt(2.0 * rc) +
                       " m): the intrados radius Rc - t/2 must stay positive");
  HalfCentreline c;
  c.pieces.push_back(Piece{{0.0, 0.0}, rc, 0.5 * kPi, 0.5 * rc * beta});
  c.half_length = 0.5 * rc * beta;
  c.min_radius = rc;
  return c;
}

HalfCentreline basket_centreline(const SceneParams& params) {
  const ModelConfig& mc = params.model;
  const double rc = mc.radius, d = mc.offset, r = mc.small_radius, t = mc.thickness;
  const double g = 0.5 * (180.0 - mc.embrace) * kDeg;
  if (!(rc > 0.0))
    geometry_error(params, VOUSSOIR_KEY(model.radius), rc, "expected a radius > 0 [m]");
  if (!(r > 0.0 && r < rc))
    geometry_error(params, VOUSSOIR_KEY(model.small_radius), r,
                   "the small arcs must lie inside the reference circle: need 0 < r < " +
                       std::string(VOUSSOIR_KEY(model.radius)) + " = " + fmt(rc) +
                       " m (their centres O3 = (Rc - r)(cos g, sin g) "
                       "must differ from O)");
  if (!(d > 0.0))
    geometry_error(params, VOUSSOIR_KEY(model.offset), d,
                   "the large arc's centre O1 = (0, -d) must lie below O (d > 0); with d <= 0 "
                   "the large arc cannot be tangent to both small arcs from above");
  if (!(t > 0.0 && t < 2.0 * r))
    geometry_error(params, VOUSSOIR_KEY(model.thickness), t,
                   "must be below twice " + std::string(VOUSSOIR_KEY(model.small_radius)) +
                       " (2 r = " + fmt(2.0 * r) +
                       " m): the intrados of the small arcs, radius r - t/2, must stay positive");
  const Vec2 o3{(rc - r) * std::cos(g), (rc - r) * std::sin(g)};
  const Vec2 o1{0.0, -d};
  const double r1 = distance(o1, o3) + r;
  const double psi = std::atan2(o3.y - o1.y, o3.x - o1.x);
  // psi > g holds for d > 0 and psi < 90 deg for r < Rc; checked all the same.
  if (!(psi > g && psi < 0.5 * kPi))
    geometry_error(params, VOUSSOIR_KEY(model.offset), d,
                   "the small and large arcs cannot be made tangent");
  if (!(t < 2.0 * r1))
    geometry_error(params, VOUSSOIR_KEY(model.thickness), t, "thicker than the large arc allows");
  HalfCentreline c;
  c.pieces.push_back(Piece{o1, r1, 0.5 * kPi, r1 * (0.5 * kPi - psi)});
  c.pieces.push_back(Piece{o3, r, psi, r * (psi - g)});
  c.half_length = c.pieces[0].length + c.pieces[1].length;
  c.min_radius = std::min(r, r1);
  return c;
}

// Voussoirs of a symmetric arch: adds N band blocks (indices 0..N-1 if the scene is empty) and
// their mutual joints; returns the springing faces (intrados to extrados) through `left` and
// `right`.
void add_voussoirs(const SceneParams& params, const HalfCentreline& cl, Scene& scene,
                   std::vector<Vec2>* left, std::vector<Vec2>* right) {
  const ModelConfig& mc = params.model;
  const int nv = mc.voussoirs;
  if (nv < 1)
    geometry_error(params, VOUSSOIR_KEY(model.voussoirs), nv, "an arch needs at least 1 voussoir");
  const double t = mc.thickness, beta_deg = mc.embrace;
  // A voussoir much thinner along the arch than across it is a slice, not a block: its
  // meshing needs slivers or tens of thousands of cells and a time step of ~1e-10 s (found by
  // tests/unit/test_fuzz.cpp: embrace 0.092 deg with 13 voussoirs). Refuse beyond 1:50.
  constexpr double kMaxSlenderness = 50.0;
  const double voussoir_length = 2.0 * cl.half_length / nv;
  if (t > kMaxSlenderness * voussoir_length) {
    std::ostringstream why;
    why << "gives voussoirs " << voussoir_length << " m long for a thickness of " << t
        << " m (more than " << kMaxSlenderness << " times thinner than thick): use fewer "
        << "voussoirs or a larger embrace or radius";
    geometry_error(params, VOUSSOIR_KEY(model.embrace), beta_deg, why.str());
  }
  const double h = element_size(params, t);
  int n = 1, m = 1;
  choose_band_cells(t, 2.0 * cl.half_length / nv, 0.5 * t / cl.min_radius, h, &n, &m);

  check_triangle_budget(params, 2.0 * nv * (static_cast<double>(n) * m + n));
  const long long nm = static_cast<long long>(nv) * m;
  const double du = cl.half_length / static_cast<double>(nm);
  const double dw = t / (2.0 * n);
  auto u_of = [&](long long j) { return static_cast<double>(2 * j - nm) * du; };
  auto w_of = [&](int i) { return static_cast<double>(2 * i - n) * dw; };
  std::vector<std::vector<Vec2>> cols(nm + 1, std::vector<Vec2>(n + 1));
  for (long long j = 0; j <= nm; ++j)
    for (int i = 0; i <= n; ++i) cols[j][i] = cl.point(u_of(j), w_of(i));

  const Index first = static_cast<Index>(scene.blocks.size());
  const std::vector<double> breaks = cl.breaks();
  for (int k = 0; k < nv; ++k) {
    BlockSpec b;
    b.role = "voussoir";
    b.mesher = BlockSpec::Mesher::Band;
    b.columns.assign(cols.begin() + static_cast<long long>(k) * m,
                     cols.begin() + static_cast<long long>(k + 1) * m + 1);
    // Exact outline: intrados left to right (clockwise arcs), joint, extrados right to left
    // (counter-clockwise arcs), joint. Arc edges split where the centreline changes piece.
    const double ua = u_of(static_cast<long long>(k) * m),
                 ub = u_of(static_cast<long long>(k + 1) * m);
    std::vector<double> us{ua};
    for (double br : breaks)
      if (br > ua && br < ub) us.push_back(br);
    us.push_back(ub);
    const double wi = w_of(0), we = w_of(n);
    for (std::size_t s = 0; s + 1 < us.size(); ++s) {
      Vec2 c;
      double r;
      cl.piece_around(0.5 * (us[s] + us[s + 1]), &c, &r);
      const Vec2 start = s == 0 ? b.columns.front()[0] : cl.point(us[s], wi);
      b.outline.push_back(OutlineEdge{start, r + wi, c, -(us[s + 1] - us[s]) / r});
    }
    b.outline.push_back(OutlineEdge{b.columns.back()[0], 0.0, {}, 0.0});
    for (std::size_t s = us.size() - 1; s > 0; --s) {
      Vec2 c;
      double r;
      cl.piece_around(0.5 * (us[s] + us[s - 1]), &c, &r);
      const Vec2 start = s == us.size() - 1 ? b.columns.back()[n] : cl.point(us[s], we);
      b.outline.push_back(OutlineEdge{start, r + we, c, (us[s] - us[s - 1]) / r});
    }
    b.outline.push_back(OutlineEdge{b.columns.front()[n], 0.0, {}, 0.0});
    scene.blocks.push_back(std::move(b));
  }
  for (int k = 1; k < nv; ++k) {
    const auto& f = cols[static_cast<long long>(k) * m];
    const double u = u_of(static_cast<long long>(k) * m);
    const double pos = 0.5 * beta_deg + std::copysign(cl.turn(std::abs(u)), u) / kDeg;
    scene.joints.push_back(Joint{first + k - 1, first + k, f[0], f[n], pos});
  }
  *left = cols.front();
  *right = cols.back();

  // Centreline from the left springing, for tests and drawings.
  for (auto it = cl.pieces.rbegin(); it != cl.pieces.rend(); ++it) {
    const double sweep = it->length / it->radius;
    scene.centreline.push_back(
        ArcPiece{mirror_x(it->centre), it->radius, kPi - (it->theta0 - sweep), -sweep});
  }
  for (const Piece& p : cl.pieces)
    scene.centreline.push_back(ArcPiece{p.centre, p.radius, p.theta0, -p.length / p.radius});
  scene.centreline_length = 2.0 * cl.half_length;
  scene.arch_thickness = t;
  scene.through_thickness = n;
  scene.cells_along = m;
  scene.element_size = h;
  scene.symmetric = true;
}

// Fixed abutments whose top faces are the springing joints.
void add_abutments(const SceneParams& params, Scene& scene, const std::vector<Vec2>& left,
                   const std::vector<Vec2>& right) {
  const double t = params.model.thickness, h = scene.element_size;
  const Index nv = static_cast<Index>(scene.blocks.size());
  const std::size_t n = right.size() - 1;
  const Vec2 ip = right.front(), ep = right.back();
  // A t-deep rectangle hung under the joint: its sides continue the centreline's direction
  // beyond the springing, D = the joint direction (I -> E) turned clockwise by 90 degrees.
  const Vec2 f = (1.0 / distance(ip, ep)) * (ep - ip);
  const Vec2 down{f.y, -f.x};
  const Vec2 ib = ip + t * down, eb = ep + t * down;
  if (!(std::min(ib.x, eb.x) > 0.0))
    geometry_error(params, VOUSSOIR_KEY(model.embrace), params.model.embrace,
                   "the springings are too close together for their abutments (the arch closes "
                   "on itself); use a smaller embrace");

  BlockSpec r;
  r.role = "abutment";
  r.fixed = true;
  r.mesher = BlockSpec::Mesher::Polygon;
  r.size = kFixedCoarsening * std::sqrt(2.0) * h;
  PointChain chain;
  chain.segment(ip, ib, h);
  chain.segment(ib, eb, h);
  chain.segment(eb, ep, h);
  for (std::size_t i = n; i > 0; --i) chain.add(right[i]);
  r.boundary = chain.loop();
  r.outline = polygon_outline({ip, ib, eb, ep});

  BlockSpec l;
  l.role = "abutment";
  l.fixed = true;
  l.mesher = BlockSpec::Mesher::Mirror;
  l.mirror_of = nv + 1;
  l.outline = mirror_outline(r.outline);
  scene.blocks.push_back(std::move(l));
  scene.blocks.push_back(std::move(r));
  scene.joints.insert(scene.joints.begin(), Joint{nv, 0, left.front(), left.back(), 0.0});
  scene.joints.push_back(Joint{nv - 1, nv + 1, ip, ep, params.model.embrace});
}

// Buttresses (free, monolithic or coursed) and the fixed ground under them.
void add_buttresses(const SceneParams& params, Scene& scene, const std::vector<Vec2>& left,
                    const std::vector<Vec2>& right) {
  const ModelConfig& mc = params.model;
  const double h = scene.element_size;
  const double bw = mc.buttress_width, h1 = mc.base_depth, hc = mc.courses;
  const Index nv = static_cast<Index>(scene.blocks.size());
  const Vec2 ip = right.front(), ep = right.back();
  const double joint_dx = ep.x - ip.x;
  if (!(bw > joint_dx * (1.0 + 1e-9)))
    geometry_error(params, VOUSSOIR_KEY(model.buttress_width), bw,
                   "the buttress must reach past the extrados springing: B must exceed the "
                   "springing joint's horizontal extent " +
                       fmt(joint_dx) + " m");
  const double y_low = std::min(ip.y, ep.y);
  if (!(-h1 < y_low - 1e-9 * mc.thickness))
    geometry_error(params, VOUSSOIR_KEY(model.base_depth), h1,
                   "the ground line y = -H1 must lie below the springing (lowest springing "
                   "point at y = " +
                       fmt(y_low) + " m)");
  const double xi = ip.x, xo = ip.x + bw, yg = -h1;

  // Course cuts from the ground up, strictly below the lowest springing point.
  std::vector<double> cuts{yg};
  if (hc > 0.0) {
    const double top = y_low - 1e-9 * hc;
    if ((top - yg) / hc > 10000.0)
      geometry_error(params, VOUSSOIR_KEY(model.courses), hc,
                     "makes more than 10000 courses per buttress");
    for (int k = 1;; ++k) {
      const double y = yg + k * hc;
      if (!(y < top)) break;
      cuts.push_back(y);
    }
  }
  std::vector<std::vector<Vec2>> rows;
  for (double y : cuts) {
    PointChain c;
    c.segment({xi, y}, {xo, y}, h);
    rows.push_back(c.points);
  }

  // Right buttress courses, bottom to top.
  std::vector<BlockSpec> courses;
  const std::size_t nc = cuts.size();
  for (std::size_t k = 0; k < nc; ++k) {
    BlockSpec b;
    b.role = "buttress";
    b.mesher = BlockSpec::Mesher::Polygon;
    b.size = std::sqrt(2.0) * h;
    PointChain c;
    c.add(rows[k]);
    if (k + 1 < nc) {
      c.segment({xo, cuts[k]}, {xo, cuts[k + 1]}, h);
      c.add_reversed(rows[k + 1]);
      c.segment({xi, cuts[k + 1]}, {xi, cuts[k]}, h);
      b.outline =
          polygon_outline({{xi, cuts[k]}, {xo, cuts[k]}, {xo, cuts[k + 1]}, {xi, cuts[k + 1]}});
    } else {
      c.segment({xo, cuts[k]}, {xo, ep.y}, h);
      c.segment({xo, ep.y}, ep, h);
      c.add_reversed(right);
      c.segment(ip, {xi, cuts[k]}, h);
      b.outline = polygon_outline({{xi, cuts[k]}, {xo, cuts[k]}, {xo, ep.y}, ep, ip});
    }
    b.boundary = c.loop();
    courses.push_back(std::move(b));
  }
  // Left buttress (mirror images) first, then the right one, then the ground.
  const Index left0 = nv, right0 = nv + static_cast<Index>(nc),
              ground = nv + 2 * static_cast<Index>(nc);
  for (std::size_t k = 0; k < nc; ++k) {
    BlockSpec l;
    l.role = "buttress";
    l.mesher = BlockSpec::Mesher::Mirror;
    l.mirror_of = right0 + static_cast<Index>(k);
    l.outline = mirror_outline(courses[k].outline);
    scene.blocks.push_back(std::move(l));
  }
  for (BlockSpec& b : courses) scene.blocks.push_back(std::move(b));

  const double margin = 0.5 * bw, depth = 0.5 * bw;
  const double xg = xo + margin, yb = yg - depth;
  BlockSpec g;
  g.role = "ground";
  g.fixed = true;
  g.mesher = BlockSpec::Mesher::SymmetricPolygon;
  g.size = kFixedCoarsening * std::sqrt(2.0) * h;
  PointChain c;
  c.segment({0.0, yb}, {xg, yb}, kFixedCoarsening * h);
  c.segment({xg, yb}, {xg, yg}, kFixedCoarsening * h);
  c.segment({xg, yg}, {xo, yg}, h);
  c.add_reversed(rows[0]);
  c.segment({xi, yg}, {0.0, yg}, h);
  g.boundary = c.points;
  g.outline = polygon_outline({{-xg, yb}, {xg, yb}, {xg, yg}, {-xg, yg}});
  scene.blocks.push_back(std::move(g));

  // Joints: springings, courses (lower course first), ground.
  const Index top = static_cast<Index>(nc) - 1;
  scene.joints.insert(scene.joints.begin(), Joint{left0 + top, 0, left.front(), left.back(), 0.0});
  scene.joints.push_back(Joint{nv - 1, right0 + top, ip, ep, mc.embrace});
  for (std::size_t k = 1; k < nc; ++k) {
    const Index lo = static_cast<Index>(k) - 1, hi = static_cast<Index>(k);
    scene.joints.push_back(Joint{left0 + lo, left0 + hi, {-xi, cuts[k]}, {-xo, cuts[k]}, kNaN});
    scene.joints.push_back(Joint{right0 + lo, right0 + hi, {xi, cuts[k]}, {xo, cuts[k]}, kNaN});
  }
  scene.joints.push_back(Joint{ground, left0, {-xo, yg}, {-xi, yg}, kNaN});
  scene.joints.push_back(Joint{ground, right0, {xi, yg}, {xo, yg}, kNaN});
}

}  // namespace

Scene build_arch_scene(const SceneParams& params) {
  const ModelConfig& mc = params.model;
  std::string shape;
  if (mc.kind == "circular_arch") shape = "circular";
  if (mc.kind == "basket_arch") shape = "basket";
  if (mc.kind == "buttressed_arch") {
    shape = mc.shape;
    if (shape != "circular" && shape != "basket")
      geometry_error(params, VOUSSOIR_KEY(model.shape), "\"" + shape + "\"",
                     "expected \"circular\" or \"basket\"");
  }
  if (!(mc.embrace > 0.0 && mc.embrace < 360.0))
    geometry_error(params, VOUSSOIR_KEY(model.embrace), mc.embrace,
                   "expected an angle in (0, 360) degrees");
  const HalfCentreline cl =
      shape == "circular" ? circular_centreline(params) : basket_centreline(params);

  Scene scene;
  std::vector<Vec2> left, right;
  add_voussoirs(params, cl, scene, &left, &right);
  if (mc.kind == "buttressed_arch")
    add_buttresses(params, scene, left, right);
  else
    add_abutments(params, scene, left, right);
  return scene;
}

}  // namespace voussoir

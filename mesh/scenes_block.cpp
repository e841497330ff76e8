// The block scene (docs/reference/deck.md, [model]): `stack` rectangular blocks `width` x `height`
// standing on a fixed ground, optionally on an incline.
//
// Geometry, before the incline: the blocks are centred on x = 0, block k spans
// y in [k height, (k + 1) height]; the ground is a fixed rectangle under them whose top is
// y = 0, width / 2 deep, reaching width + stack x height beyond each side of the blocks (room
// for a block to tip over or slide). Blocks are structured meshes (elements about
// mesh.size, or min(width, height) / mesh.through_thickness); the ground is meshed half and
// mirrored and keeps the bottom block's base nodes on its top face.
// Incline: the whole scene (ground and blocks) is rotated counter-clockwise by `incline`
// about the origin (the middle of the bottom block's base), so the ground rises to the right
// and a sliding block moves towards -x. Gravity stays vertical.

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include "mesh/scene_spec.hpp"

namespace voussoir {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kFixedCoarsening = 3.0;
// Tallest stack (stack x height) accepted, in block widths. The ground is width / 2 deep and
// reaches 1.5 width + stack x height to each side, so a tall stack on a narrow base makes a
// long thin ground strip, whose quality mesh (CGAL) refines down to its depth along its whole
// length and slows superlinearly with that length. Measured with the block deck
// (`check`, CPU seconds, mesh.through_thickness 1): 2000 widths (stack 1000 of the shipped
// blocks) 0.3 s; 6000: refused by the runaway cap of mesh_scene after 0.5 s, but meshed with
// through_thickness 2 and 4 in 2.6 s and 10 s (88 000 and 272 000 triangles); 20 000: refused
// after 7 s; 60 000 after 76 s; 200 000 (height 1e5, a fuzzing input) not done in 16 minutes.
constexpr double kMaxStackToWidth = 2000.0;

Vec2 rotate(Vec2 p, double c, double s) {
  return {c * p.x - s * p.y, s * p.x + c * p.y};
}

}  // namespace

Scene build_block_scene(const SceneParams& params) {
  const ModelConfig& mc = params.model;
  // The published cases give no block height; core/schema.hpp's 5.0 is the church's. A block deck
  // without `height` gets a 1.0 m block.
  const double w = mc.width, ht = mc.has("height") ? mc.height : 1.0, incline = mc.incline;
  const int stack = mc.stack;
  if (!(w > 0.0)) geometry_error(params, VOUSSOIR_KEY(model.width), w, "expected a width > 0 m");
  if (!(ht > 0.0))
    geometry_error(params, VOUSSOIR_KEY(model.height), ht, "expected a height > 0 m");
  if (stack < 1)
    geometry_error(params, VOUSSOIR_KEY(model.stack), stack, "expected at least 1 block");
  if (!(incline >= 0.0 && incline < 90.0))
    geometry_error(params, VOUSSOIR_KEY(model.incline), incline,
                   "expected an angle in [0, 90) degrees");
  if (stack * ht > kMaxStackToWidth * w) {
    std::ostringstream why;
    why << "a stack of " << stack << " block(s) " << ht << " m tall (" << VOUSSOIR_KEY(model.stack)
        << " x " << VOUSSOIR_KEY(model.height) << ") on a base " << w << " m wide ("
        << VOUSSOIR_KEY(model.width) << ") is " << stack * ht / w
        << " times taller than wide (at most " << kMaxStackToWidth
        << "): the ground the scene lays under it would reach " << 1.5 * w + stack * ht
        << " m to each side and be " << 0.5 * w
        << " m deep, a strip whose mesh takes seconds to hours; use a wider base, lower blocks "
           "or fewer";
    geometry_error(params, VOUSSOIR_KEY(model.height), ht, why.str());
  }

  const double h = element_size(params, std::min(w, ht));
  int n = 1, m = 1;  // n rows up the height, m columns across the width
  choose_band_cells(ht, w, 0.0, h, &n, &m);
  check_triangle_budget(params, 2.0 * stack * (static_cast<double>(n) * m + n));

  Scene scene;
  scene.element_size = h;
  scene.symmetric = incline == 0.0;
  const double dx = w / (2.0 * m);
  std::vector<double> xs(m + 1);
  for (int j = 0; j <= m; ++j) xs[j] = (2 * j - m) * dx;  // xs[m - j] == -xs[j] exactly
  for (int k = 0; k < stack; ++k) {
    const double y0 = k * ht, y1 = (k + 1) * ht;
    BlockSpec b;
    b.role = "block";
    b.mesher = BlockSpec::Mesher::Band;
    for (int j = 0; j <= m; ++j) {
      std::vector<Vec2> col(n + 1);
      for (int i = 0; i <= n; ++i) col[i] = {xs[j], i == n ? y1 : y0 + (i * ht) / n};
      b.columns.push_back(std::move(col));
    }
    b.outline = polygon_outline({{xs[0], y0}, {xs[m], y0}, {xs[m], y1}, {xs[0], y1}});
    scene.blocks.push_back(std::move(b));
    if (k > 0) scene.joints.push_back(Joint{k - 1, k, {xs[0], y0}, {xs[m], y0}, kNaN});
  }

  // Ground: right chain from (0, -depth) to (0, 0), keeping the base nodes of block 0.
  const double reach = 0.5 * w + w + stack * ht, depth = 0.5 * w;
  BlockSpec g;
  g.role = "ground";
  g.fixed = true;
  g.mesher = BlockSpec::Mesher::SymmetricPolygon;
  g.size = kFixedCoarsening * std::sqrt(2.0) * h;
  PointChain ch;
  ch.segment({0.0, -depth}, {reach, -depth}, kFixedCoarsening * h);
  ch.segment({reach, -depth}, {reach, 0.0}, kFixedCoarsening * h);
  ch.segment({reach, 0.0}, {xs[m], 0.0}, h);
  for (int j = m; j >= 0 && xs[j] > 0.0; --j) ch.add(Vec2{xs[j], 0.0});
  ch.add(Vec2{0.0, 0.0});
  g.boundary = ch.points;
  g.outline = polygon_outline({{-reach, -depth}, {reach, -depth}, {reach, 0.0}, {-reach, 0.0}});
  const Index gi = static_cast<Index>(scene.blocks.size());
  scene.blocks.push_back(std::move(g));
  scene.joints.insert(scene.joints.begin(), Joint{gi, 0, {xs[0], 0.0}, {xs[m], 0.0}, kNaN});

  if (incline > 0.0) {
    scene.rotation = incline * kDeg;
    const double c = std::cos(scene.rotation), s = std::sin(scene.rotation);
    for (BlockSpec& b : scene.blocks)
      for (OutlineEdge& e : b.outline) {
        e.start = rotate(e.start, c, s);
        e.centre = rotate(e.centre, c, s);
      }
    for (Joint& j : scene.joints) {
      j.a = rotate(j.a, c, s);
      j.b = rotate(j.b, c, s);
    }
  }
  return scene;
}

}  // namespace voussoir

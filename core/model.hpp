#pragma once
// The model: nodes, constant-strain triangles and blocks, in struct-of-arrays form.
//
// Data layout (STYLE.md "Data is flat and says its layout"):
//   - every array is indexed by a 32-bit `Index`; node i of the model is x[i], y[i], ...;
//   - the nodes of one block are contiguous: [Block::first_node, + Block::node_count);
//     likewise its triangles: [Block::first_tri, + Block::tri_count);
//   - triangles are counter-clockwise in the reference configuration (area0 > 0);
//   - per-triangle constants (inverse reference edge matrix, reference area, boundary edge mask)
//     are computed once by `finalize_model` and never change;
//   - hot state (positions, velocities, forces, inverse masses) is split from cold
//     bookkeeping (reference positions, block table, joints).
// Units: SI (m, kg, s, N, Pa); per unit out-of-plane thickness times `out_of_plane`.

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace voussoir {

using Index = std::int32_t;

struct Vec2 {
  double x = 0.0;
  double y = 0.0;
};

// Small vector helpers (scene generators, minimal meshes, joint stiffness).
inline Vec2 operator+(Vec2 a, Vec2 b) {
  return {a.x + b.x, a.y + b.y};
}
inline Vec2 operator-(Vec2 a, Vec2 b) {
  return {a.x - b.x, a.y - b.y};
}
inline Vec2 operator*(double s, Vec2 a) {
  return {s * a.x, s * a.y};
}
inline double dot(Vec2 a, Vec2 b) {
  return a.x * b.x + a.y * b.y;
}
inline double cross(Vec2 a, Vec2 b) {
  return a.x * b.y - a.y * b.x;
}
inline double norm(Vec2 a) {
  return std::hypot(a.x, a.y);
}
inline double distance(Vec2 a, Vec2 b) {
  return std::hypot(a.x - b.x, a.y - b.y);
}
// Distance from p to the segment a-b.
double distance_to_segment(Vec2 p, Vec2 a, Vec2 b);

// Elastic material; the law itself lives in core/cst.hpp.
struct Material {
  double density = 2000.0;  // kg/m3
  double young = 40e9;      // Pa
  double poisson = 0.2;     // -
  bool plane_stress = false;

  double shear_modulus() const { return young / (2.0 * (1.0 + poisson)); }
  // Lamé's first constant of the 3D material (used for the default contact penalty).
  double lame_lambda() const {
    return young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
  }
  // First Lamé constant of the 2D law: plane strain uses the 3D value, plane stress the
  // condensed one 2 lambda mu / (lambda + 2 mu).
  double lame_lambda_2d() const {
    const double l = lame_lambda(), m = shear_modulus();
    return plane_stress ? 2.0 * l * m / (l + 2.0 * m) : l;
  }
  // P-wave modulus of the 2D law (lambda_2d + 2 mu), sets the elastic wave speed.
  double p_modulus_2d() const { return lame_lambda_2d() + 2.0 * shear_modulus(); }
};

struct Nodes {
  // hot
  std::vector<double> x, y;          // current position [m]
  std::vector<double> vx, vy;        // velocity [m/s]
  std::vector<double> fx, fy;        // force accumulator of the current step [N]
  std::vector<double> inv_mass;      // 1 / lumped mass; 0 for nodes of fixed blocks [1/kg]
  // cold
  std::vector<double> x0, y0;        // reference position [m]
  std::vector<double> mass;          // lumped mass (1/3 of each adjacent triangle) [kg]
  std::vector<Index> block;          // owning block

  Index size() const { return static_cast<Index>(x.size()); }
};

struct Triangles {
  std::vector<Index> n0, n1, n2;     // nodes, counter-clockwise in the reference configuration
  std::vector<Index> block;          // owning block
  // Inverse of the reference edge matrix [X1-X0, X2-X0] (2x2, row-major: b00 b01 / b10 b11).
  std::vector<double> b00, b01, b10, b11;
  std::vector<double> area0;         // reference area [m2]
  // Bit e (0, 1, 2) set when edge e = (n_e, n_{e+1 mod 3}) lies on the block's boundary.
  std::vector<std::uint8_t> boundary;

  Index size() const { return static_cast<Index>(n0.size()); }
};

struct Block {
  bool fixed = false;
  // A fixed block whose movement [supports] prescribes (core/supports.hpp): the step puts it
  // where the movement says, and contact detection follows it as it does a free block.
  bool prescribed = false;
  std::string role;                  // "voussoir", "abutment", "buttress", "ground", ...
  std::string name;                  // name in the source file (gmsh physical), or empty
  std::vector<Vec2> polygon;         // outline, counter-clockwise [m]
  Index first_node = 0, node_count = 0;
  Index first_tri = 0, tri_count = 0;
  double area = 0.0;                 // [m2]
  double mass = 0.0;                 // [kg] (includes out_of_plane)
};

// A joint: two blocks whose outlines share the segment a-b (as built by a scene generator).
// Used for hinge reports and limit analysis. `position_deg` is the angular position of the
// joint (degrees from the left springing, or NaN where it has none).
struct Joint {
  Index block_a = 0, block_b = 0;
  Vec2 a, b;                         // a: intrados end, b: extrados end where that applies
  double position_deg = 0.0;
};

// Rigid-body state of the blocks made rigid (core/rigid.hpp has the math). Layout: one entry
// per block (fixed blocks keep zeros and are skipped), rx/ry one per node. The step reads and
// writes only the per-block arrays; the nodes of rigid blocks follow the bodies when a reader
// asks (sync_rigid_nodes, core/rigid.hpp).
struct RigidBodies {
  // hot, per block
  std::vector<double> cx, cy, theta;    // centroid [m], rotation [rad] from the reference
  // displacement of the centroid from the reference one [m], the integrated state: c = c0 + u.
  // A settle moves a block by 1e-12 m in steps of 1e-15 m, which c itself (1 m) rounds to
  // 1e-16 m; u keeps them to its own round-off.
  std::vector<double> ux, uy;
  std::vector<double> vx, vy, omega;    // half-step velocity [m/s], angular velocity [rad/s]
  std::vector<double> fx, fy, torque;   // force [N] and moment about the centroid [N m] of the step
  // cold, per block
  std::vector<double> cx0, cy0;         // reference centroid [m]
  std::vector<double> mass, inertia;    // M [kg], polar moment about the centroid [kg m2]
  // the mass the body loads act on [kg]: M, also when the quasi-static phases scale `mass`
  // and `inertia` (engine/step.hpp equalize_rigid_inertia)
  std::vector<double> load_mass;
  // per node: offset from the block's reference centroid [m]
  std::vector<double> rx, ry;

  bool empty() const { return cx.empty(); }
};

struct Model {
  Nodes nodes;
  Triangles tris;
  std::vector<Block> blocks;
  std::vector<Joint> joints;
  Material material;
  double out_of_plane = 1.0;         // out-of-plane thickness [m]
  std::string kind;                  // scene kind that built it
  // Rigid blocks (material.model = "rigid"): every free block is one rigid body, no element
  // stage. Empty for elastic models.
  RigidBodies rigid;
  bool is_rigid() const { return !rigid.empty(); }
};

// Appends one block made of the given nodes and triangles (node indices local to the block,
// any orientation: triangles are made counter-clockwise here). Returns the block index.
Index add_block(Model& model, const std::vector<Vec2>& outline, const std::vector<Vec2>& points,
                const std::vector<std::array<Index, 3>>& triangles, bool fixed,
                const std::string& role);

// Computes every per-triangle constant, boundary masks, lumped masses and block mass/area.
// Call once after the last add_block and after setting `material` and `out_of_plane`.
void finalize_model(Model& model);

// Smallest triangle height over the free (or all, if none free) blocks [m].
double min_triangle_height(const Model& model);

// Sum of reference areas and masses over blocks that are not fixed.
double free_area(const Model& model);
double free_mass(const Model& model);
Index free_node_count(const Model& model);  // nodes of the free blocks

}  // namespace voussoir

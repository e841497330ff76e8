#include "engine/thrust.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "limit/interfaces.hpp"

namespace voussoir {

namespace {

// Mean reference position of the nodes of block b.
Vec2 reference_centre(const Model& model, Index b) {
  const Block& blk = model.blocks[std::size_t(b)];
  Vec2 c;
  for (Index i = blk.first_node; i < blk.first_node + blk.node_count; ++i)
    c = c + Vec2{model.nodes.x0[i], model.nodes.y0[i]};
  return blk.node_count > 0 ? (1.0 / blk.node_count) * c : c;
}

// Mean reference position of triangle e.
Vec2 reference_centroid(const Model& model, Index e) {
  const Nodes& n = model.nodes;
  const Triangles& t = model.tris;
  return {(n.x0[t.n0[e]] + n.x0[t.n1[e]] + n.x0[t.n2[e]]) / 3.0,
          (n.y0[t.n0[e]] + n.y0[t.n1[e]] + n.y0[t.n2[e]]) / 3.0};
}

// Resultants from the triangle pairs' nodal forces (elastic blocks) or from the block pairs'
// forces (rigid blocks): one of the two lists is empty.
std::vector<JointResultant> resultants_of(const Model& model,
                                          const std::vector<TouchingPair>& forces,
                                          const std::vector<BlockPairForce>& block_forces) {
  const std::size_t nj = model.joints.size();
  // The block summed per joint (B, or A when B is fixed), its force and moment about O.
  std::vector<Index> side(nj);
  std::vector<Vec2> mid(nj), force(nj), end_a(nj), end_b(nj);
  std::vector<double> moment(nj, 0.0);
  std::vector<char> touched(nj, 0);
  std::map<std::pair<Index, Index>, std::vector<int>> by_blocks;
  const Nodes& n = model.nodes;
  const std::vector<BlockMotion> motions = block_motions(model);
  for (std::size_t j = 0; j < nj; ++j) {
    const Joint& jt = model.joints[j];
    side[j] = model.blocks[std::size_t(jt.block_b)].fixed ? jt.block_a : jt.block_b;
    end_a[j] = move_point(motions[std::size_t(side[j])], jt.a);
    end_b[j] = move_point(motions[std::size_t(side[j])], jt.b);
    mid[j] = 0.5 * (end_a[j] + end_b[j]);
    by_blocks[{std::min(jt.block_a, jt.block_b), std::max(jt.block_a, jt.block_b)}].push_back(
        int(j));
  }
  const Triangles& t = model.tris;
  for (const TouchingPair& f : forces) {
    const Index bc = t.block[f.tri_c], bt = t.block[f.tri_t];
    const auto it = by_blocks.find({std::min(bc, bt), std::max(bc, bt)});
    if (it == by_blocks.end()) continue;
    // Several joints between the same two blocks: the one nearest to the pair.
    int j = it->second.front();
    if (it->second.size() > 1) {
      const Vec2 c = reference_centroid(model, f.tri_c);
      double best = std::numeric_limits<double>::infinity();
      for (int k : it->second) {
        const double d = distance_to_segment(c, model.joints[k].a, model.joints[k].b);
        if (d < best) best = d, j = k;
      }
    }
    const bool on_c = bc == side[j];
    const Index e = on_c ? f.tri_c : f.tri_t;
    const Vec2* fk = on_c ? f.on_c : f.on_t;
    const Index v[3] = {t.n0[e], t.n1[e], t.n2[e]};
    for (int k = 0; k < 3; ++k) {
      force[j] = force[j] + fk[k];
      moment[j] += cross(Vec2{n.x[v[k]], n.y[v[k]]} - mid[j], fk[k]);
    }
    touched[j] = 1;
  }
  // A rigid block pair: its force on the summed block and the moment about O; several joints
  // between the same two blocks take it at the first.
  for (const BlockPairForce& f : block_forces) {
    const auto it =
        by_blocks.find({std::min(f.block_a, f.block_b), std::max(f.block_a, f.block_b)});
    if (it == by_blocks.end()) continue;
    const int j = it->second.front();
    const double sign = f.block_b == side[j] ? 1.0 : -1.0;  // forces on a are minus those on b
    force[j] = force[j] + sign * f.force;
    moment[j] += sign * (f.moment + cross(f.origin - mid[j], f.force));
    touched[j] = 1;
  }

  std::vector<JointResultant> out(nj);
  for (std::size_t j = 0; j < nj; ++j) {
    const Joint& jt = model.joints[j];
    JointResultant& r = out[j];
    r.joint = int(j);
    r.block_a = jt.block_a;
    r.block_b = jt.block_b;
    if (!touched[j]) continue;
    // Force and moment of A on B.
    const double sign = side[j] == jt.block_b ? 1.0 : -1.0;
    const Vec2 f = sign * force[j];
    const double m = sign * moment[j];
    const Vec2 chord = end_b[j] - end_a[j];
    const double len = norm(chord);
    if (!(len > 0.0)) continue;
    const Vec2 tan = (1.0 / len) * chord;
    // Normal from A into B: the side of the joint's reference line where B's nodes lie.
    const Vec2 towards_b =
        reference_centre(model, jt.block_b) - reference_centre(model, jt.block_a);
    const double orient = cross(jt.b - jt.a, towards_b) >= 0.0 ? 1.0 : -1.0;
    const Vec2 nrm = orient * Vec2{-tan.y, tan.x};
    r.force = f;
    r.normal_force = dot(f, nrm);
    r.shear_force = dot(f, tan);
    const double lever = cross(tan, f);
    if (!(std::abs(lever) > 1e-12 * norm(f))) continue;
    const double s = m / lever;
    r.closed = true;
    r.eccentricity = s / (0.5 * len);
    r.point = mid[j] + s * tan;
  }
  return out;
}

}  // namespace

std::vector<JointResultant> joint_resultants(const Model& model,
                                             const std::vector<TouchingPair>& forces) {
  return resultants_of(model, forces, {});
}

std::vector<JointResultant> joint_resultants(const Model& model, const ContactSystem& contact,
                                             double dt) {
  if (contact.rigid_outlines())
    return resultants_of(model, {}, contact.block_pair_forces(model, dt));
  return joint_resultants(model, contact.pair_forces(model, dt));
}

nlohmann::json joints_json(const std::vector<JointResultant>& joints) {
  nlohmann::json out = nlohmann::json::array();
  const nlohmann::json none(nullptr);
  for (const JointResultant& r : joints)
    out.push_back({{"joint", r.joint},
                   {"blocks", {r.block_a, r.block_b}},
                   {"normal_force", r.normal_force},
                   {"shear_force", r.shear_force},
                   {"eccentricity", r.closed ? nlohmann::json(r.eccentricity) : none},
                   {"point", r.closed ? nlohmann::json({r.point.x, r.point.y}) : none},
                   {"force", {r.force.x, r.force.y}}});
  return out;
}

SnapshotJoints snapshot_joints(const std::vector<JointResultant>& joints) {
  constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  SnapshotJoints out;
  for (const JointResultant& r : joints) {
    out.normal_force.push_back(r.normal_force);
    out.shear_force.push_back(r.shear_force);
    out.eccentricity.push_back(r.closed ? r.eccentricity : kNone);
    out.point.insert(out.point.end(), {r.closed ? r.point.x : kNone, r.closed ? r.point.y : kNone});
  }
  return out;
}

void write_snapshot_thrust(RunWriter& writer, const Model& model, const ContactSystem& contact,
                           double dt, double lambda) {
  writer.write_snapshot_joints(snapshot_joints(joint_resultants(model, contact, dt)));
  writer.write_snapshot_attribute("lambda", lambda);
}

double free_weight_x(const Model& model) {
  double a = 0.0, ax = 0.0;
  for (const Block& b : model.blocks) {
    if (b.fixed) continue;
    Vec2 c;
    const double area = polygon_centroid(b.polygon, &c);
    a += area;
    ax += area * c.x;
  }
  return a > 0.0 ? ax / a : 0.0;
}

SupportThrust support_thrust(const Model& model, const std::vector<JointResultant>& joints) {
  const double xg = free_weight_x(model);
  SupportThrust h;
  for (const JointResultant& j : joints) {
    const bool fixed_a = model.blocks[std::size_t(j.block_a)].fixed;
    const bool fixed_b = model.blocks[std::size_t(j.block_b)].fixed;
    if (fixed_a == fixed_b || !j.closed) continue;
    // j.force acts on block_b: the fixed block takes +force as b, -force as a.
    const double on_fixed = fixed_b ? j.force.x : -j.force.x;
    const Joint& joint = model.joints[std::size_t(j.joint)];
    if (0.5 * (joint.a.x + joint.b.x) < xg)
      h.left -= on_fixed;
    else
      h.right += on_fixed;
  }
  return h;
}

}  // namespace voussoir

#pragma once
// Minimal meshes for rigid blocks (docs/rigid.md: no element work where the blocks'
// deformation does not change the answer; mesh.chord_tolerance).
//
// A rigid block needs triangles only for its contact geometry: its outline. Each block's
// outline (as the scene built it, with a point at every mesh node along its sides) is
// simplified, then triangulated with no interior point:
//   - simplification: a vertex goes when the chord that replaces it stays within
//     `chord_tolerance` x the block's thickness of every original point it replaces (points
//     along a straight side deviate by zero and always go; an arc keeps as many points as its
//     sagitta asks). The block's thickness is its smallest width (the smallest extent of the
//     outline across any of its sides' normals). The vertex whose removal deviates least goes
//     first, until none can go. An outline of more than 256 vertices (a fuzzed arch of radius
//     2000 m has thousands; the shipped decks at most 88) takes its convex hull's width and a
//     Douglas-Peucker pass before that removal, with the same bound on every original point;
//     the n^2 paths took a minute there (mesh/minimal.cpp kFastOutline);
//   - triangulation: ear clipping, each time the ear whose smallest angle is largest (a
//     quadrilateral gives 2 triangles, an n-gon n - 2).
// Joints, roles and fixed flags are kept; a joint's end points are corners of both blocks,
// never removed (a corner deviates from any chord that would cut it).

#include "core/model.hpp"

namespace voussoir {

// Outline simplified as above (counter-clockwise in, counter-clockwise out).
std::vector<Vec2> simplify_outline(const std::vector<Vec2>& outline, double chord_tolerance);

// Triangles of a simple counter-clockwise polygon by ear clipping (indices into it).
std::vector<std::array<Index, 3>> ear_clip(const std::vector<Vec2>& polygon);

// The model rebuilt with every block meshed minimally (material, thickness, joints kept);
// finalize_model has run on it.
Model minimal_model(const Model& model, double chord_tolerance);

}  // namespace voussoir

#pragma once
// Scene generators (docs/reference/deck.md, [model]): build the blocks of a deck's [model] and mesh
// each into constant-strain triangles ([mesh] size or through_thickness). Geometry errors throw
// DeckError naming the key and value. mesh/ reads only the deck's scene parameters
// (SceneParams, core/schema.hpp: [model], [mesh], [material] and the deck's path), never the
// whole Config; callers pass scene_params(config). The kinds and their generators:
// core/scene_kinds.hpp.

#include "core/model.hpp"
#include "core/schema.hpp"

namespace voussoir {

// Builds, meshes and finalizes the model of the scene (material and out_of_plane set).
Model build_model(const SceneParams& params);

// Smallest interior angle of any triangle of the model [deg] (reported by `voussoir check`).
double worst_triangle_angle_deg(const Model& model);

}  // namespace voussoir

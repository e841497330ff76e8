#pragma once
// Scene generators (SPEC.md section 3): build the blocks of a deck's [model] and mesh each
// into constant-strain triangles ([mesh] size or through_thickness). Geometry errors throw
// DeckError naming the key and value.

#include "core/model.hpp"
#include "core/schema.hpp"

namespace voussoir {

// Builds, meshes and finalizes the model of the deck (material and out_of_plane set).
Model build_model(const Config& config);

// Smallest interior angle of any triangle of the model [deg] (reported by `voussoir check`).
double worst_triangle_angle_deg(const Model& model);

}  // namespace voussoir

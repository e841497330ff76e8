#pragma once
// Cache-locality ordering of the nodes and triangles of each block (METIS).
//
// Within every block with more than kOrderMinNodes nodes, the node graph (triangle edges) is
// cut by METIS recursive bisection into parts of about kOrderPartNodes nodes; nodes are
// renumbered part by part (recursive-bisection part ids are nested, so consecutive parts are
// neighbours in space), keeping their previous relative order inside a part, and the
// triangles are sorted by the smallest new index of their nodes. Blocks keep their node and
// triangle ranges (Block::first_node, ...), triangles keep their corner order (orientation).
// METIS runs serially with a fixed seed: the order is a function of the mesh only.
//
// Measured effect and why it is not called by the scenes: docs/benchmarks.md, "Measured and
// not used".

#include <vector>

#include "core/model.hpp"

namespace voussoir {

// Renumbers nodes and triangles block by block (above), then calls finalize_model (so the
// model is reset to its reference state). Call at set-up, before contact setup.
void order_for_locality(Model& model);

// Moves node i to node_new[i] and triangle e to tri_new[e] (permutations that keep every
// block's ranges), then calls finalize_model.
void renumber_model(Model& model, const std::vector<Index>& node_new,
                    const std::vector<Index>& tri_new);

}  // namespace voussoir

#pragma once
// The gridded rectangle: one block [x0, x0 + width] x [y0, y0 + height] meshed as nx x ny
// cells of two triangles each. The test and benchmark scenes built by hand (a free block, a
// ground slab, stacks, the benchmark wall of bench/wall.hpp) all use it, so that it is
// written once.
//
// Layout: node (i, j), 0 <= i <= nx, 0 <= j <= ny, has index j (nx + 1) + i and sits at
// (x0 + width i / nx, y0 + height j / ny) (that expression, so that a grid's nodes are the
// same doubles wherever it is built). Cell (i, j) gives two triangles, in the order of the
// cells (j outer, i inner):
//   diagonal from (i, j) to (i + 1, j + 1):  {(i, j), (i + 1, j), (i + 1, j + 1)},
//                                             {(i, j), (i + 1, j + 1), (i, j + 1)};
//   the other diagonal:                       {(i, j), (i + 1, j), (i, j + 1)},
//                                             {(i + 1, j), (i + 1, j + 1), (i, j + 1)}.
// GridDiagonals::Alternating takes the first for i + j even and the second for i + j odd (a
// criss-cross of differently oriented triangles, no preferred direction); Uniform takes the
// first in every cell.

#include <string>

#include "core/model.hpp"
#include "mesh/triangulate.hpp"

namespace voussoir {

enum class GridDiagonals { Alternating, Uniform };

// The block's outline: its four corners (x0 + width and y0 + height computed directly), or
// every boundary node counter-clockwise from (0, 0) (collinear vertices, like a meshed block).
enum class GridOutline { Corners, Nodes };

// The nodes and triangles of the grid (header comment); nx, ny >= 1.
TriMesh mesh_grid_rectangle(double x0, double y0, double width, double height, int nx, int ny,
                            GridDiagonals diagonals = GridDiagonals::Alternating);

// Appends the grid to `model` as one block (add_block) and returns its index.
Index add_grid_rectangle(Model& model, double x0, double y0, double width, double height, int nx,
                         int ny, bool fixed, const std::string& role,
                         GridDiagonals diagonals = GridDiagonals::Alternating,
                         GridOutline outline = GridOutline::Corners);

}  // namespace voussoir

// The gridded rectangle (layout in rectangle.hpp).

#include "mesh/rectangle.hpp"

#include <vector>

namespace voussoir {

TriMesh mesh_grid_rectangle(double x0, double y0, double width, double height, int nx, int ny,
                            GridDiagonals diagonals) {
  TriMesh mesh;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i)
      mesh.points.push_back({x0 + width * i / nx, y0 + height * j / ny});
  auto id = [nx](int i, int j) { return Index(j * (nx + 1) + i); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      if (diagonals == GridDiagonals::Uniform || (i + j) % 2 == 0) {
        mesh.tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        mesh.tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      } else {
        mesh.tris.push_back({id(i, j), id(i + 1, j), id(i, j + 1)});
        mesh.tris.push_back({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      }
    }
  return mesh;
}

Index add_grid_rectangle(Model& model, double x0, double y0, double width, double height, int nx,
                         int ny, bool fixed, const std::string& role, GridDiagonals diagonals,
                         GridOutline outline) {
  const TriMesh mesh = mesh_grid_rectangle(x0, y0, width, height, nx, ny, diagonals);
  std::vector<Vec2> loop;
  if (outline == GridOutline::Corners) {
    loop = {{x0, y0}, {x0 + width, y0}, {x0 + width, y0 + height}, {x0, y0 + height}};
  } else {
    auto at = [&](int i, int j) { return mesh.points[j * (nx + 1) + i]; };
    for (int i = 0; i < nx; ++i) loop.push_back(at(i, 0));
    for (int j = 0; j < ny; ++j) loop.push_back(at(nx, j));
    for (int i = nx; i > 0; --i) loop.push_back(at(i, ny));
    for (int j = ny; j > 0; --j) loop.push_back(at(0, j));
  }
  return add_block(model, loop, mesh.points, mesh.tris, fixed, role);
}

}  // namespace voussoir

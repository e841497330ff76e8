// A dry-stone wall of 3 x 2 stacked blocks (0.4 m x 0.3 m) on a fixed ground, for
// cases/wall.toml and docs/gmsh.md. Mesh it with (MSH 4.1 ASCII, triangles):
//     gmsh -2 -format msh41 cases/wall.geo -o cases/wall.msh
// Each block is its own surface with its own physical surface; voussoir numbers the blocks in
// the order of the physical tags, so the ground (tag 1) is block 0 (model.fixed = [0]) and the
// wall blocks follow row by row, bottom row first, left to right.
SetFactory("OpenCASCADE");

w = 0.4;   // block width [m]
h = 0.3;   // block height [m]
lc = 0.1;  // element size [m]

// The ground: 0.2 m deep, reaching 0.2 m beyond the wall on each side.
Rectangle(1) = {-0.2, -0.2, 0, 3 * w + 0.4, 0.2};
Physical Surface("ground", 1) = {1};

// The blocks: surface and physical tag 2 + 3 * row + column.
For row In {0 : 1}
  For col In {0 : 2}
    s = 2 + 3 * row + col;
    Rectangle(s) = {col * w, row * h, 0, w, h};
    Physical Surface(Sprintf("block_r%g_c%g", row, col), s) = {s};
  EndFor
EndFor

// No BooleanFragments: the blocks stay apart (each meshed on its own), as dry joints are.
Mesh.MeshSizeMax = lc;
Mesh.MshFileVersion = 4.1;

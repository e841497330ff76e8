#pragma once
// The scene kinds of a deck's [model] (docs/reference/deck.md, [model]): one registry that the deck
// reader (io/deck.cpp: the allowed `model.kind` values and their required keys), the scene builder
// (mesh/scene.cpp: which generator builds the kind) and the drivers (is it an arch: its
// reference length is the centreline radius) all read. Adding a kind is one row here plus its
// generator in mesh/ (a new SceneBuilder value is a new case of mesh/scene.cpp's switch, which
// the compiler asks for).

#include <string>
#include <vector>

namespace voussoir {

// The generator of a kind (mesh/scene_spec.hpp: build_arch_scene, build_church_scene, ...).
enum class SceneBuilder { Arch, Church, Block, Polygons };

// A key a kind cannot do without, and what it is for (the deck reader's message).
struct RequiredKey {
  const char* key;
  const char* why;
};

struct SceneKind {
  const char* name;  // model.kind
  SceneBuilder builder;
  bool arch;                          // an arch scene: centreline radius model.radius
  std::vector<RequiredKey> required;  // beyond model.kind
};

inline const std::vector<SceneKind>& scene_kinds() {
  static const std::vector<SceneKind> kinds = {
      {"circular_arch", SceneBuilder::Arch, true, {}},
      {"basket_arch", SceneBuilder::Arch, true, {}},
      {"buttressed_arch", SceneBuilder::Arch, true, {}},
      {"church", SceneBuilder::Church, false, {}},
      {"block", SceneBuilder::Block, false, {}},
      {"polygons",
       SceneBuilder::Polygons,
       false,
       {{"model.file", "reads its blocks from a polygon text file or a gmsh .msh file"}}},
  };
  return kinds;
}

// The kind named `name`, or nullptr.
inline const SceneKind* find_scene_kind(const std::string& name) {
  for (const SceneKind& k : scene_kinds())
    if (name == k.name) return &k;
  return nullptr;
}

// The names of every kind, in registry order.
inline std::vector<std::string> scene_kind_names() {
  std::vector<std::string> names;
  for (const SceneKind& k : scene_kinds()) names.emplace_back(k.name);
  return names;
}

// Whether `name` is an arch kind (false for an unknown name).
inline bool is_arch_kind(const std::string& name) {
  const SceneKind* k = find_scene_kind(name);
  return k != nullptr && k->arch;
}

}  // namespace voussoir

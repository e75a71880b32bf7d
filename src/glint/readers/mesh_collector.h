// Triangles of a text scene (NFF polygons, Tachyon triangles and vertex arrays) gathered into
// inline mesh objects ({type: mesh, positions, normals, colors, indices}, DESIGN.md §13): one per
// material and kind of vertex data, vertices written identically shared, so that a scene of many
// triangles holds a few mesh entities instead of one entity per triangle.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include "glint/core/seeded_hash.h"
#include "glint/readers/text_statements.h"

namespace glint {

// A vertex as scalars already added to the tree: a position, and optionally a normal and a colour.
struct CollectedVertex {
  std::array<ValueId, 3> position{kNoValue, kNoValue, kNoValue};
  std::array<ValueId, 3> normal{kNoValue, kNoValue, kNoValue};  // kNoValue: none
  std::array<ValueId, 3> color{kNoValue, kNoValue, kNoValue};   // kNoValue: none
};

class MeshCollector {
 public:
  // Adds triangle (a, b, c) — right-handed order — to the mesh of `material` ("" for none) whose
  // vertices have the same kinds of data as these. `at` is where messages about it point (its line
  // is noted in `tree` now: emit() adds the triangle's values there).
  void add(ValueTree& tree, const std::string& material, const CollectedVertex& a,
           const CollectedVertex& b, const CollectedVertex& c, const TextPosition& at);
  // Emits the meshes as object entities, in the order their first triangles came, each with
  // `smooth` true when it has normals and false otherwise.
  void emit(SceneEmitter& out);
  std::size_t triangles() const { return triangles_; }

 private:
  struct Group {
    std::string material;
    bool normals = false;
    bool colors = false;
    TextPosition first;
    std::vector<CollectedVertex> vertices;
    std::vector<std::uint32_t> indices;
    std::vector<TextPosition> triangleAt;
    std::unordered_map<std::string, std::uint32_t, SeededHash, std::equal_to<>>
        shared;  // vertex text → index
  };
  std::uint32_t vertexIndex(const ValueTree& tree, Group& g, const CollectedVertex& v);
  std::vector<Group> groups_;
  std::map<std::string, std::size_t> groupOf_;  // material + kinds → groups_ index
  std::size_t triangles_ = 0;
};

}  // namespace glint

// libFuzzer target: glint's OBJ parser (mesh/obj_fast_parse.h) on the input bytes, in this process
// (in glint it runs in the import child, where a crash would only refuse the file and so go
// unseen by mesh_obj_fuzz). What it takes must be consistent (indices within the arrays, faces of
// 3 or more corners, one corner form); and then, differentially, the mesh glint makes of it must
// be the one assimp's OBJ importer makes, to the bit, or both must refuse the file. The checker of
// malformed statements (mesh/obj_check.h) runs on every input: it must find nothing in a file the
// parser takes, and a file glint refuses at a place must be one it finds at fault there.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string_view>
#include <type_traits>

#include "glint/core/file_access.h"
#include "glint/mesh/assimp_import.h"
#include "glint/mesh/obj_check.h"
#include "glint/mesh/obj_fast_parse.h"
#include "mesh_fuzz.h"

namespace {

using glint::fuzz::require;

template <typename T>
bool sameBits(const std::vector<T>& a, const std::vector<T>& b) {
  static_assert(std::is_trivially_copyable_v<T>);
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

void requireSame(const glint::MeshFile& a, const glint::MeshFile& b) {
  require(a.droppedTriangles == b.droppedTriangles);
  require(a.parts.size() == b.parts.size() && a.materials.size() == b.materials.size());
  for (std::size_t i = 0; i < a.parts.size(); ++i) {
    const glint::TriangleMesh& p = a.parts[i];
    const glint::TriangleMesh& q = b.parts[i];
    require(sameBits(p.positions, q.positions) && sameBits(p.normals, q.normals) &&
            sameBits(p.indices, q.indices) && sameBits(p.uvs, q.uvs) &&
            sameBits(p.colors, q.colors) && p.materialIndex == q.materialIndex);
  }
  for (std::size_t i = 0; i < a.materials.size(); ++i) {
    require(a.materials[i].name == b.materials[i].name &&
            a.materials[i].fromFile == b.materials[i].fromFile);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const std::optional<glint::SimpleObj> obj = glint::parseSimpleObj(text);
  const std::optional<glint::ObjFault> fault = glint::findObjFault(text);
  if (fault) {
    require(!obj);
    require(fault->line >= 1 && fault->column >= 1 && !fault->what.empty());
    std::size_t lines = 1;
    for (const char c : text) lines += c == '\n' || c == '\r' ? 1 : 0;
    require(fault->line <= lines);
  }
  if (!obj) {
    if (!fault) return 0;
    // Refused through the reader's path, at the fault's place.
    const std::filesystem::path path = glint::fuzz::workFolder() / "input.obj";
    glint::fuzz::writeFile(path, text);
    const glint::ReferencedFileRule rule(path, path.parent_path());
    try {
      glint::importSimpleObj(path, rule);
      require(false);
    } catch (const glint::MeshLoadError& e) {
      const std::optional<glint::MeshErrorPlace> place = glint::meshErrorPlace(e.what());
      require(place && place->line == static_cast<int>(fault->line) &&
              place->column == static_cast<int>(fault->column));
    }
    return 0;
  }
  std::size_t corners = 0;
  for (const std::uint32_t n : obj->faceSizes) {
    require(n >= 3);
    corners += n;
  }
  require(!obj->faceSizes.empty() && corners == obj->vertexIndices.size());
  require(obj->normalIndices.empty() || obj->normalIndices.size() == corners);
  require(obj->texcoordIndices.empty() || obj->texcoordIndices.size() == corners);
  require(obj->positions.size() % 3 == 0 && obj->normals.size() % 3 == 0 &&
          obj->texcoords.size() % 3 == 0);
  for (const std::uint32_t i : obj->vertexIndices) require(i < obj->positions.size() / 3);
  for (const std::uint32_t i : obj->normalIndices) require(i < obj->normals.size() / 3);
  for (const std::uint32_t i : obj->texcoordIndices) require(i < obj->texcoords.size() / 3);

  // The differential check, on the file as glint reads it.
  const std::filesystem::path path = glint::fuzz::workFolder() / "input.obj";
  glint::fuzz::writeFile(path, text);
  const glint::ReferencedFileRule rule(path, path.parent_path());
  std::optional<glint::MeshFile> reference;
  try {
    reference = glint::importMeshWithAssimp(path, ".obj", rule);
  } catch (const glint::MeshLoadError&) {
  }
  std::optional<glint::MeshFile> fast;
  try {
    fast = glint::importSimpleObj(path, rule);
  } catch (const glint::MeshLoadError&) {
    // A refusal at a place needs a fault, which a file the parser takes has not.
    require(false);
  }
  require(fast.has_value() == reference.has_value());
  if (fast) {
    glint::fuzz::checkMeshFile(*fast);
    requireSame(*fast, *reference);
  }
  return 0;
}

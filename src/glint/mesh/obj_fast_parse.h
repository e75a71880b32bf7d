// A fast reader for the plain subset of Wavefront OBJ that large generated and scanned meshes use
// (`v`, `vn`, `vt`, `f` with one corner form, comments), giving exactly the numbers and faces
// assimp's OBJ importer gives for such a file. Everything outside the subset is left to assimp
// (parseSimpleObj returns nothing), so a file reads the same either way or is assimp's alone.
// Internal to the mesh loader: it runs in the import child (import_child.h), never in the
// renderer's own process.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace glint {

// An OBJ file of the subset, as assimp 5.2's OBJ parser (ObjFileParser) holds it before its
// importer builds the mesh: the file's vertex arrays and its faces' corners, 0-based.
struct SimpleObj {
  std::vector<float> positions;          // x, y, z per `v` line
  std::vector<float> normals;            // x, y, z per `vn` line
  std::vector<float> texcoords;          // u, v, w per `vt` line (w 0 for two components)
  unsigned texcoordDimension = 0;        // the most components of any `vt` line (2 or 3)
  std::vector<std::uint32_t> faceSizes;  // corners of each face, ≥ 3
  // Per corner, in face order. texcoordIndices / normalIndices are empty when the faces' corner
  // form (`v`, `v/t`, `v//n`, `v/t/n` — one form in the whole file) has no such index.
  std::vector<std::uint32_t> vertexIndices;
  std::vector<std::uint32_t> texcoordIndices;
  std::vector<std::uint32_t> normalIndices;
  // assimp's name of the one object (its node and mesh): an `o` line's name, else its default.
  std::string objectName = "defaultobject";
};

// The file `text` when it lies in the subset and assimp reads it without error; nothing
// otherwise — a line of another kind (materials, groups, lines, points, free-form curves...), a
// number or index in another spelling, a relative or out-of-range index, corner forms that differ
// from face to face, a line continuation, a carriage return not before a line feed, a NUL. The
// numbers are parsed by assimp's own routine (fast_atof.h), so positions, normals and texture
// coordinates are the same floats to the bit.
std::optional<SimpleObj> parseSimpleObj(std::string_view text);

// Whether the OBJ fast path is turned off: the environment variable GLINT_OBJ_READER set to
// "assimp" (for benchmarks and the differential tests; any other value or none: the fast path).
bool objFastPathDisabled();

}  // namespace glint

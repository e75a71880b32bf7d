// The checks a mesh file passes before assimp sees it (DESIGN.md §7): a regular file with an
// extension glint reads, a PLY header whose counts the file can hold, glTF primitives with the
// vertices their mode needs. Internal to the mesh loader.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "glint/readers/value_tree.h"
#include "glint/readers/yaml_reader.h"

namespace glint {

// The file extensions glint reads (lower case, any case in the path), one assimp importer each:
// OBJ (+ its MTL), PLY (ASCII and binary), STL (ASCII and binary) and glTF 2.0 (.gltf with its .bin
// files or data URIs, .glb). Any other extension is refused without opening the file, so that none
// of assimp's ~60 other importers (rarely used formats, less hardened) sees hostile input: OFF,
// for one, is not read — fuzzing crashed assimp 5.2's OFF importer within seconds.
inline constexpr const char* kMeshExtensions[] = {".obj", ".ply", ".stl", ".gltf", ".glb"};

// Bytes of a mesh file's start that readHeader returns, and within which a PLY header must end.
inline constexpr std::size_t kMeshHeaderBytes = 64 * 1024;

// The path's extension in lower case ("" when it has none).
std::string lowerExtension(const std::filesystem::path& path);

// The file's extension if glint reads it; otherwise MeshLoadError, before the file is opened.
std::string checkedExtension(const std::filesystem::path& path);

// Fails early, with the system's reason, for what assimp would only call "Unable to open file":
// a missing path, a folder, a device or pipe (which could block or never end), an extension glint
// does not read (checked before opening), no permission.
// Returns the file's first bytes (at most kMeshHeaderBytes) and its size.
std::string readHeader(const std::filesystem::path& path, std::uint64_t& size);

// The element counts a PLY header declares.
struct PlyElementCounts {
  std::uint64_t faces = 0;
  std::uint64_t vertices = 0;
};

// A PLY header checked line by line before assimp sees it:
//  - its structure: a "ply" line, a known format and end_header within the first kMeshHeaderBytes.
//    assimp 5.2's PLY reader loops without end, growing its memory, on a header that never ends
//    (found by fuzzing).
//  - its counts: assimp trusts them, reserving memory before it reads any element: a 200-byte PLY
//    claiming 300 million faces would cost gigabytes and minutes. Counts the file's size cannot
//    hold, or more faces than kMaxMeshTriangles, are refused.
// `header` is the file's start (readHeader), `size` its size. Throws MeshLoadError.
PlyElementCounts checkPlyHeader(const std::string& header, std::uint64_t size);

// glTF primitives checked before assimp sees them. assimp 5.2 makes a strip or fan primitive
// (mode 3, 5, 6) of n vertices into n − 1 or n − 2 faces without checking n: a primitive with too
// few vertices (none when POSITION is missing) asks for 2^32 faces, 64 GiB (found by fuzzing).
// The JSON is read from the .gltf or the GLB's JSON chunk. Throws MeshLoadError.
void checkGltfPrimitives(const std::filesystem::path& path, const std::string& extension,
                         std::uint64_t size);

// A glTF file's JSON as a tree. glint's YAML reader is the JSON parser (JSON is YAML); this is the
// mesh loader's only call of it. Throws MeshLoadError when the text is not valid JSON.
struct GltfJson {
  yaml::Document document;
  ValueView root() const { return {&document.values, document.root}; }
};
GltfJson parseGltfJson(const std::string& text);

}  // namespace glint

// The mesh reader's answer on the wire: what the child (mesh_reader_side.cpp) writes and the
// parent (import_child.cpp) reads — the protocol name both check and the writing side's helpers.
// Internal to the mesh loader.
#pragma once

#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "glint/core/version.h"
#include "glint/mesh/mesh_file.h"

namespace glint::wire {

// The first argument of the reader program: a reader from another glint build refuses to answer.
inline constexpr const char* kMeshReaderProtocol = "glint-mesh-reader/" GLINT_VERSION "/4";

// Writes everything or stops silently (the parent sees a short message).
inline bool writeAll(int fd, const void* data, std::size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

template <typename T>
bool writeValue(int fd, const T& value) {
  return writeAll(fd, &value, sizeof value);
}

template <typename T>
bool writeVector(int fd, const std::vector<T>& values) {
  return writeValue(fd, std::uint64_t{values.size()}) &&
         writeAll(fd, values.data(), values.size() * sizeof(T));
}

inline bool writeMessage(int fd, char tag, const std::string& text) {
  return writeValue(fd, tag) && writeValue(fd, std::uint64_t{text.size()}) &&
         writeAll(fd, text.data(), text.size());
}

// The whole answer: 'M', the dropped triangles, whether the importer dropped faces itself (0 or
// 1), the generated normals' two counts (exactPositionNormalParts, crowdedNormalPositions), the
// textures the materials name that glint does not use, the missing material libraries and the one
// read instead (missingMaterialLibraries, fallbackMaterialLibrary), then the file's materials,
// embedded images and parts.
bool writeMeshFile(int fd, const MeshFile& file);

}  // namespace glint::wire

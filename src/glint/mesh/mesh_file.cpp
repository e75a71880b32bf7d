#include "glint/mesh/mesh_file.h"

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <utility>

#include "glint/core/cancel.h"
#include "glint/core/file_access.h"
#include "glint/mesh/format_checks.h"
#include "glint/mesh/import_child.h"

namespace glint {

std::size_t MeshFile::triangleCount() const {
  std::size_t n = 0;
  for (const TriangleMesh& part : parts) n += part.triangleCount();
  return n;
}

std::optional<MeshErrorPlace> meshErrorPlace(const std::string& reason) {
  constexpr std::string_view kPrefix = "invalid file: line ";
  if (reason.compare(0, kPrefix.size(), kPrefix) != 0) return std::nullopt;
  int line = 0;
  int column = 0;
  int consumed = 0;
  if (std::sscanf(reason.c_str() + kPrefix.size(), "%9d, column %9d: %n", &line, &column,
                  &consumed) != 2 ||
      consumed == 0 || line < 1 || column < 1) {
    return std::nullopt;
  }
  return MeshErrorPlace{
      line, column,
      "invalid file: " + reason.substr(kPrefix.size() + static_cast<std::size_t>(consumed))};
}

double meshCopyBytes(double triangles, double vertices) {
  return kMeshBytesPerTriangle * triangles + kMeshBytesPerVertex * vertices;
}

MeshFile readMeshFile(const std::filesystem::path& path, const MeshReadOptions& options) {
  throwIfCancelled(options.cancel);
  std::uint64_t size = 0;
  const std::string header = readHeader(path, size);
  const std::string extension = checkedExtension(path);
  if (extension == ".ply") checkPlyHeader(header, size);
  if (extension == ".gltf" || extension == ".glb") checkGltfPrimitives(path, extension, size);
  return importMeshInChild(path, extension, options.sceneFolder, options.cancel);
}

std::vector<TriangleMesh> instantiateMesh(const MeshFile& file,
                                          const std::optional<Transform>& worldFromFile,
                                          bool smooth, const std::atomic<bool>* cancel, bool uvs) {
  bool mirror = false;
  if (worldFromFile) {
    const auto& m = worldFromFile->matrix().m;
    const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                       m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                       m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    mirror = det < 0;
  }
  std::vector<TriangleMesh> out;
  out.reserve(file.parts.size());
  // Vertices transformed between two looks at the cancel flag (a few milliseconds).
  constexpr std::size_t kBlock = std::size_t{1} << 16;
  for (const TriangleMesh& part : file.parts) {
    throwIfCancelled(cancel);
    TriangleMesh mesh;
    mesh.materialIndex = part.materialIndex;
    mesh.emission = part.emission;
    mesh.indices = part.indices;
    if (uvs) mesh.uvs = part.uvs;
    mesh.colors = part.colors;
    if (mirror) {
      for (std::size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
        std::swap(mesh.indices[i + 1], mesh.indices[i + 2]);
      }
    }
    if (!worldFromFile) {
      mesh.positions = part.positions;
      if (smooth) mesh.normals = part.normals;
    } else {
      const Transform& t = *worldFromFile;
      mesh.positions.reserve(part.positions.size());
      for (const Point3& p : part.positions) {
        if (mesh.positions.size() % kBlock == 0) throwIfCancelled(cancel);
        mesh.positions.push_back(t(p));
      }
      if (smooth) {
        mesh.normals.reserve(part.normals.size());
        for (const Normal3& n : part.normals) {
          if (mesh.normals.size() % kBlock == 0) throwIfCancelled(cancel);
          mesh.normals.push_back(normalize(t(n)));
        }
      }
    }
    out.push_back(std::move(mesh));
  }
  return out;
}

std::string meshFileRefusal(const ReadableFile& file) {
  switch (file.refusal) {
    case FileRefusal::None:
      return "";
    case FileRefusal::Missing:
      return "no such file";
    case FileRefusal::Folder:
      return "it is a folder, not a mesh file";
    case FileRefusal::NotRegular:
      return "it is not a regular file";
    case FileRefusal::System:
      break;
  }
  return systemReason(file.error);
}

ReadableFile openMeshFile(const std::filesystem::path& path) {
  ReadableFile file = openForReading(path);
  if (file.refusal != FileRefusal::None) throw MeshLoadError(meshFileRefusal(file));
  return file;
}

}  // namespace glint

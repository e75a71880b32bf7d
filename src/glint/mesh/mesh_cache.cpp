#include "glint/mesh/mesh_cache.h"

#include <string>
#include <system_error>

#include <fmt/format.h>

#include "glint/core/cancel.h"
#include "glint/core/file_access.h"
#include "glint/mesh/format_checks.h"
#include "glint/mesh/mesh_size_estimate.h"
#include "glint/scene/scene_limits.h"

namespace glint {

double meshInstanceBytes(double triangles, double vertices) {
  return meshCopyBytes(triangles, vertices) + kBvhBuildBytesPerTriangle * triangles;
}

std::filesystem::path MeshCache::keyOf(const std::filesystem::path& path) {
  std::error_code error;
  std::filesystem::path key = std::filesystem::weakly_canonical(path, error);
  if (error) key = std::filesystem::absolute(path, error).lexically_normal();
  if (error) key = path.lexically_normal();
  return key;
}

std::shared_ptr<const MeshFile> MeshCache::read(const std::filesystem::path& key,
                                                const std::filesystem::path& path,
                                                const MeshReadOptions& options) {
  if (const auto it = entries_.find(key); it != entries_.end()) {
    if (it->second.file) return it->second.file;
    throw MeshLoadError(it->second.error);
  }
  ++filesRead_;
  try {
    auto file = std::make_shared<const MeshFile>(readMeshFile(path, options));
    entries_[key] = {file, {}};
    return file;
  } catch (const MeshLoadError& e) {
    entries_[key] = {nullptr, e.what()};
    throw;
  }
}

void MeshCache::adopt(const std::filesystem::path& path, std::shared_ptr<const MeshFile> file) {
  if (!file) return;
  entries_.try_emplace(keyOf(path), Entry{std::move(file), {}, false});
}

std::shared_ptr<const MeshFile> MeshCache::load(const std::filesystem::path& path,
                                                const MeshReadOptions& options) {
  throwIfCancelled(options.cancel);
  return read(keyOf(path), path, options);
}

std::shared_ptr<const MeshFile> MeshCache::load(const std::filesystem::path& path,
                                                const MeshBudget& budget,
                                                const MeshReadOptions& options) {
  throwIfCancelled(options.cancel);
  const std::filesystem::path key = keyOf(path);
  const auto it = entries_.find(key);
  if (it != entries_.end() && !it->second.file) throw MeshLoadError(it->second.error);
  // present: no estimate needed (read, or adopted with its real sizes); cached: its own copy is
  // counted already.
  const bool present = it != entries_.end();
  const bool cached = present && it->second.counted;
  // An OBJ or STL whose size alone shows that no estimate could exceed the budget is not scanned
  // (a 100k-triangle OBJ: ~10 ms saved). A file that cannot be read fails in read() instead.
  bool bounded = false;
  const std::string ext = lowerExtension(path);
  if (!present && (ext == ".obj" || ext == ".stl")) {
    const ReadableFile file = statForReading(path);
    if (file.refusal == FileRefusal::None) {
      const double bound =
          kMeshBudgetBytesPerFileByte * static_cast<double>(file.size) + kMeshBudgetSlackBytes;
      bounded = meshBytes_ + bound + static_cast<double>(budget.otherBytes) <=
                static_cast<double>(budget.limit);
    }
  }
  if (!present && !bounded) {
    MeshSizeEstimate size;
    try {
      size = estimateMeshSize(path, options);
    } catch (const MeshLoadError& e) {
      entries_[key] = {nullptr, e.what()};
      ++filesRead_;
      throw;
    }
    const double triangles = static_cast<double>(size.triangles);
    const double vertices = static_cast<double>(size.vertices);
    // The cached file, this object's world copy and its share of the BVH build.
    const double bytes =
        meshCopyBytes(triangles, vertices) + meshInstanceBytes(triangles, vertices);
    const double total = meshBytes_ + bytes + static_cast<double>(budget.otherBytes);
    if (total > static_cast<double>(budget.limit)) {
      throw MeshTooLargeError(fmt::format(
          "its estimated {} triangles need about {} as a mesh and its BVH; with {} already "
          "committed (the image's film and the meshes before it) that is more than the memory "
          "limit of {}",
          formatCount(triangles), formatBytes(bytes),
          formatBytes(meshBytes_ + static_cast<double>(budget.otherBytes)),
          formatBytes(static_cast<double>(budget.limit))));
    }
  }
  std::shared_ptr<const MeshFile> file = read(key, path, options);
  // The real sizes replace the estimate.
  double triangles = 0;
  double vertices = 0;
  double uvBytes = 0;        // the file's texture coordinates (world copies keep them only when
                             // textured: counted with the textures' bindings)
  double embeddedBytes = 0;  // the compressed images the file embeds
  for (const TriangleMesh& part : file->parts) {
    triangles += static_cast<double>(part.triangleCount());
    vertices += static_cast<double>(part.positions.size());
    uvBytes += static_cast<double>(part.uvs.size() * sizeof(Point2));
  }
  for (const auto& image : file->embeddedImages) embeddedBytes += static_cast<double>(image.size());
  const double bytes = (cached ? 0 : meshCopyBytes(triangles, vertices) + uvBytes + embeddedBytes) +
                       meshInstanceBytes(triangles, vertices);
  if (meshBytes_ + bytes + static_cast<double>(budget.otherBytes) >
      static_cast<double>(budget.limit)) {
    const std::string what =
        cached ? fmt::format("another instance of its {} triangles needs about {} with its BVH",
                             formatCount(triangles), formatBytes(bytes))
               : fmt::format("its {} triangles need about {} as a mesh and its BVH",
                             formatCount(triangles), formatBytes(bytes));
    throw MeshTooLargeError(fmt::format(
        "{}; with {} already committed (the image's film and the meshes before it) that is more "
        "than the memory limit of {}",
        what, formatBytes(meshBytes_ + static_cast<double>(budget.otherBytes)),
        formatBytes(static_cast<double>(budget.limit))));
  }
  meshBytes_ += bytes;
  entries_[key].counted = true;
  return file;
}

}  // namespace glint

// Shared body of the mesh loader targets (mesh_*_fuzz.cpp): the input becomes a file with the
// target's extension and goes through glint::readMeshFile, exactly as a scene's `mesh` object
// reads it. Any bytes give a MeshFile that satisfies the loader's promises or a MeshLoadError;
// another exception, a broken promise, a crash, a hang or a sanitizer report is a finding.
//
// Formats with a second file (OBJ's MTL, a .gltf's .bin buffer) take it from the input too:
// everything after the first kSideSeparator line is written beside the main file as input.mtl /
// input.bin, which the main file names (`mtllib input.mtl`, `"uri": "input.bin"`; both in the
// dictionaries).
#pragma once

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>

#include "glint/core/transform.h"
#include "glint/mesh/import_child.h"
#include "glint/mesh/mesh_loader.h"

namespace glint::fuzz {

inline constexpr std::string_view kSideSeparator = "\n#--glint-side-file--\n";

// A broken contract is a finding: abort so libFuzzer saves the input.
inline void require(bool condition) {
  if (!condition) std::abort();
}

// One folder per fuzzing process, in memory when /dev/shm exists; removed at exit.
inline const std::filesystem::path& workFolder() {
  static const std::filesystem::path folder = [] {
    std::error_code error;
    std::filesystem::path base = "/dev/shm";
    if (!std::filesystem::is_directory(base, error)) base = std::filesystem::temp_directory_path();
    std::filesystem::path path = base / ("glint-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(path);
    // glint stops a mesh reader that runs past its limit (30 s and more) and refuses the file: a
    // designed refusal (assimp loops, or reads past a file's end into a huge allocation, on some
    // malformed files), which the fuzzer's own 10 s per input would report as a timeout. The
    // readers here get 3 s; inputs this small take milliseconds.
    glint::setMeshReadTimeLimitForTesting(std::chrono::seconds(3));
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(workFolder(), ignored);
    });
    return path;
  }();
  return folder;
}

inline void writeFile(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  require(static_cast<bool>(out));
}

// The promises of MeshFile (mesh_file.h) for a file that loaded.
inline void checkMeshFile(const MeshFile& file) {
  require(!file.parts.empty());
  require(file.triangleCount() > 0 && file.triangleCount() <= kMaxMeshTriangles);
  for (const TriangleMesh& part : file.parts) {
    require(!part.indices.empty() && part.indices.size() % 3 == 0);
    require(part.normals.size() == part.positions.size());
    require(part.materialIndex < file.materials.size());
    for (const Point3& p : part.positions) {
      require(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
    }
    for (const Normal3& n : part.normals) require(std::abs(length(n) - 1) < 1e-9);
    for (const std::uint32_t i : part.indices) require(i < part.positions.size());
    for (std::size_t t = 0; t < part.triangleCount(); ++t) {
      const Point3& a = part.positions[part.indices[3 * t]];
      const Point3& b = part.positions[part.indices[3 * t + 1]];
      const Point3& c = part.positions[part.indices[3 * t + 2]];
      require(length(cross(b - a, c - a)) > 0);
    }
  }
  for (const MeshMaterial& m : file.materials) {
    for (const Color& c : {m.material.kd, m.material.ks, m.material.kt, m.emission}) {
      require(std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b));
      require(c.r >= 0 && c.g >= 0 && c.b >= 0);
    }
    require(std::isfinite(m.material.shininess) && m.material.shininess >= 0);
    require(std::isfinite(m.material.ior) && m.material.ior > 0);
  }
}

// Writes the input as input<extension> (and its side file) and loads it.
inline int runMeshInput(const std::uint8_t* data, std::size_t size, const char* extension,
                        const char* sideName) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  std::string_view main = bytes;
  std::string_view side;
  if (sideName != nullptr) {
    const std::size_t at = bytes.find(kSideSeparator);
    if (at != std::string_view::npos) {
      main = bytes.substr(0, at);
      side = bytes.substr(at + kSideSeparator.size());
    }
  }
  const std::filesystem::path folder = workFolder();
  const std::filesystem::path path = folder / (std::string("input") + extension);
  writeFile(path, main);
  if (sideName != nullptr) {
    const std::filesystem::path sidePath = folder / sideName;
    std::error_code ignored;
    std::filesystem::remove(sidePath, ignored);
    if (side.data() != nullptr) writeFile(sidePath, side);
  }
  try {
    const MeshFile file = readMeshFile(path);
    checkMeshFile(file);
    // The estimate reads only what readMeshFile already accepted: it must not fail now.
    const MeshSizeEstimate estimate = estimateMeshSize(path);
    (void)estimate;
    // A mirroring, rotating instance keeps every promise too.
    const Transform worldFromFile = Transform::translate({1, 2, 3}) *
                                    Transform::rotate({1, 1, 0}, 30) * Transform::scale(-2, 0.5, 1);
    for (const bool smooth : {true, false}) {
      const std::vector<TriangleMesh> world = instantiateMesh(file, worldFromFile, smooth);
      require(world.size() == file.parts.size());
      for (std::size_t i = 0; i < world.size(); ++i) {
        require(world[i].indices.size() == file.parts[i].indices.size());
        require(world[i].normals.size() == (smooth ? world[i].positions.size() : 0));
      }
    }
  } catch (const MeshTooLargeError&) {
    std::abort();  // readMeshFile has no budget: never thrown here
  } catch (const MeshLoadError& error) {
    require(std::string_view(error.what()).size() > 0);
  }
  std::error_code ignored;
  std::filesystem::remove(path, ignored);
  return 0;
}

}  // namespace glint::fuzz

// What the mesh loader's tests share: Debian's assimp-testmodels (real files no one here wrote),
// a temporary folder per test, the bounds and well-formedness of a loaded MeshFile, the reason a
// file is refused, and a watchdog that keeps a test with a FIFO bounded in time.
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "glint/core/bounds.h"
#include "glint/mesh/mesh_file.h"

namespace glint::mesh_test {

namespace fs = std::filesystem;

// Where Debian's assimp-testmodels puts the models (dpkg -L assimp-testmodels).
inline const fs::path kModels = "/usr/share/assimp/models";

// Fails (never skips) when the package is missing, saying how to install it.
inline ::testing::AssertionResult installed(const fs::path& model) {
  if (fs::is_regular_file(model)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << model << " is missing: the mesh tests read Debian's assimp-testmodels package; run "
         << "scripts/setup.sh (or apt-get install assimp-testmodels)";
}

inline std::string readText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// A folder of its own under the system's temporary folder, removed with everything in it.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            ("glint_mesh_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path file = path_ / name;
    std::ofstream(file, std::ios::binary) << text;
    return file;
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// A glTF quad (two triangles) and a third triangle 0, 1, lastIndex over its four vertices:
// lastIndex 3 is valid, 4 or more out of range (assimp's glTF reader then drops that triangle).
// Positions and 16-bit indices in a .bin beside the .gltf; returns the .gltf's path.
inline fs::path writeQuadGltf(const TempDir& dir, std::uint16_t lastIndex) {
  const std::string name = "quad" + std::to_string(lastIndex);
  const float positions[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  const std::uint16_t indices[10] = {0, 1, 2, 1, 3, 2, 0, 1, lastIndex, 0};
  std::string bytes(sizeof positions + sizeof indices, '\0');
  std::memcpy(bytes.data(), positions, sizeof positions);
  std::memcpy(bytes.data() + sizeof positions, indices, sizeof indices);
  dir.write(name + ".bin", bytes);
  return dir.write(
      name + ".gltf",
      R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
"meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
"buffers": [{"byteLength": 68, "uri": ")" +
          name + R"(.bin"}],
"bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 18}],
"accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
  {"bufferView": 1, "componentType": 5123, "count": 9, "type": "SCALAR"}]})");
}

inline Bounds3 boundsOf(const std::vector<TriangleMesh>& parts) {
  Bounds3 b;
  for (const TriangleMesh& part : parts) {
    for (std::uint32_t i : part.indices) b = unite(b, part.positions[i]);
  }
  return b;
}

inline void expectBounds(const Bounds3& actual, const Bounds3& expected, double tolerance) {
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(actual.lo[axis], expected.lo[axis], tolerance) << "axis " << axis;
    EXPECT_NEAR(actual.hi[axis], expected.hi[axis], tolerance) << "axis " << axis;
  }
}

// Every vertex normal of every part is unit length, and every triangle is non-degenerate.
inline void expectWellFormed(const MeshFile& file) {
  for (const TriangleMesh& part : file.parts) {
    ASSERT_EQ(part.indices.size() % 3, 0u);
    ASSERT_EQ(part.normals.size(), part.positions.size());
    for (const Normal3& n : part.normals) ASSERT_NEAR(length(n), 1, 1e-12);
    for (std::uint32_t i : part.indices) ASSERT_LT(i, part.positions.size());
    for (std::size_t t = 0; t < part.triangleCount(); ++t) {
      const Point3& a = part.positions[part.indices[3 * t]];
      const Point3& b = part.positions[part.indices[3 * t + 1]];
      const Point3& c = part.positions[part.indices[3 * t + 2]];
      ASSERT_GT(length(cross(b - a, c - a)), 0);
    }
    ASSERT_LT(part.materialIndex, file.materials.size());
  }
}

// What readMeshFile says about a file it refuses, or "(loaded)".
inline std::string reasonFor(const fs::path& path) {
  try {
    readMeshFile(path);
  } catch (const MeshLoadError& e) {
    return e.what();
  }
  return "(loaded)";
}

// Runs `body`; if it has not returned within `limit`, fails the test and opens the FIFO `fifo` for
// writing (and closes it) until it returns: a reader blocked in open() on it goes on and reads the
// end of the file, so a test of "a FIFO is never opened" ends even when the code under test does
// open it (also from the mesh reader's child process).
inline void withFifoWatchdog(const fs::path& fifo, const std::function<void()>& body,
                             std::chrono::milliseconds limit = std::chrono::seconds(5)) {
  std::atomic<bool> done{false};
  std::thread watchdog([&] {
    const auto deadline = std::chrono::steady_clock::now() + limit;
    bool failed = false;
    while (!done.load()) {
      if (std::chrono::steady_clock::now() > deadline) {
        if (!failed)
          ADD_FAILURE() << "blocked on the FIFO " << fifo << " for " << limit.count()
                        << " ms: it was opened";
        failed = true;
        const int writer = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
        if (writer >= 0) ::close(writer);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  });
  body();
  done = true;
  watchdog.join();
}

}  // namespace glint::mesh_test

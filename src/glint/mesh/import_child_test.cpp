// The import child seen from the parent: a cancelled read stops at once, killing the child, and
// every step that may take long on a big mesh (waiting for the child, the estimate's scan, the
// instancing) stops on the cancel flag; a cancelled load is not remembered as a failure.
#include "glint/mesh/import_child.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <thread>

#include "glint/core/cancel.h"
#include "glint/mesh/mesh_cache.h"
#include "glint/mesh/mesh_file.h"
#include "glint/mesh/mesh_size_estimate.h"
#include "glint/mesh/mesh_test_support.h"

namespace glint::mesh_test {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// Every import child of the test sleeps `delay` before reading; undone at the end of the scope.
class SlowImportChild {
 public:
  explicit SlowImportChild(std::chrono::milliseconds delay) {
    setImportChildDelayForTesting(delay);
  }
  ~SlowImportChild() { setImportChildDelayForTesting(0ms); }
  SlowImportChild(const SlowImportChild&) = delete;
  SlowImportChild& operator=(const SlowImportChild&) = delete;
};

const std::string kTriangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

TEST(MeshImportChild, ACancelledReadStopsWithinASecondAndKillsTheChild) {
  TempDir dir;
  const fs::path obj = dir.write("t.obj", kTriangle);
  // The child would take 10 s (a slow importer); the cancel comes after 200 ms.
  const SlowImportChild slow(10s);
  for (const bool throughTheCache : {false, true}) {
    std::atomic<bool> cancel{false};
    Clock::time_point cancelledAt;
    std::thread canceller([&] {
      std::this_thread::sleep_for(200ms);
      cancelledAt = Clock::now();
      cancel = true;
    });
    const MeshReadOptions options{.cancel = &cancel};
    MeshCache cache;
    EXPECT_THROW(throughTheCache ? static_cast<void>(cache.load(
                                       obj, MeshBudget{std::uint64_t{1} << 30, 0}, options))
                                 : static_cast<void>(readMeshFile(obj, options)),
                 Cancelled);
    const Clock::time_point stopped = Clock::now();
    canceller.join();
    // The parent returns only after it has reaped the child it killed: a child left sleeping would
    // hold it for the rest of the 10 s.
    EXPECT_LT(stopped - cancelledAt, 1s) << (throughTheCache ? "MeshCache::load" : "readMeshFile");
  }
}

TEST(MeshImportChild, EveryLongStepStopsOnTheCancelFlag) {
  TempDir dir;
  const fs::path obj = dir.write("t.obj", kTriangle);
  const std::atomic<bool> cancelled{true};
  const MeshReadOptions options{.cancel = &cancelled};
  EXPECT_THROW(readMeshFile(obj, options), Cancelled);
  EXPECT_THROW(estimateMeshSize(obj, options), Cancelled);
  const MeshFile file = readMeshFile(obj);
  EXPECT_THROW(instantiateMesh(file, Transform::scale(2, 2, 2), true, &cancelled), Cancelled);
  // A cancelled load is no failure of the file: the cache reads it when asked again.
  MeshCache cache;
  EXPECT_THROW(cache.load(obj, MeshBudget{std::uint64_t{1} << 30, 0}, options), Cancelled);
  EXPECT_THROW(cache.load(obj, options), Cancelled);
  EXPECT_EQ(cache.load(obj)->triangleCount(), 1u);
}

}  // namespace
}  // namespace glint::mesh_test

// DESIGN.md §1 and §8: modules depend one way only. Reads every library source file's
// `#include "glint/<module>/..."` lines and checks each against the modules it may use:
//   core ← geometry ← accel ← scene ← render;  readers (scene files as entities) use core only;
//   mesh uses readers, scene and below; image (files of pictures) uses render's Film and below;
//   factories turn entities into scene parts; writers write scene descriptions (readers' entities)
//   as YAML; job runs renders and conversions; cluster spreads a job's render over MPI ranks
//   (above job: it hooks the job's render step, and the job must not know MPI); preview serves a
//   running job's picture over HTTP (it consumes job events, so it sits above job); cli only turns
//   arguments into jobs; mesh_reader (the glint-mesh-reader program) runs mesh's import child;
//   modules (the shared objects glint loads on demand) implement an interface header of image,
//   preview or cluster and may include nothing more of glint than those and core;
//   glint/glint.h, the umbrella header, includes the public API of every
//   module but cluster (built only with MPI).
// Tests (*_test.cpp) may use anything.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

const std::map<std::string, std::set<std::string>>& allowedModules() {
  static const std::map<std::string, std::set<std::string>> allowed = {
      {"core", {"core"}},
      {"geometry", {"core", "geometry"}},
      {"accel", {"core", "geometry", "accel"}},
      {"scene", {"core", "geometry", "accel", "scene"}},
      {"render", {"core", "geometry", "accel", "scene", "render"}},
      {"readers", {"core", "readers"}},
      {"mesh", {"core", "geometry", "accel", "scene", "readers", "mesh"}},
      {"image", {"core", "geometry", "accel", "scene", "render", "image"}},
      {"factories",
       {"core", "geometry", "accel", "scene", "readers", "mesh", "image", "factories"}},
      {"writers", {"core", "readers", "writers"}},
      {"job",
       {"core", "geometry", "accel", "scene", "render", "readers", "mesh", "image", "factories",
        "writers", "job"}},
      {"cluster",
       {"core", "geometry", "accel", "scene", "render", "readers", "mesh", "image", "factories",
        "writers", "job", "cluster"}},
      {"preview",
       {"core", "geometry", "accel", "scene", "render", "readers", "mesh", "image", "factories",
        "writers", "job", "preview"}},
      {"mesh_reader", {"core", "geometry", "accel", "scene", "readers", "mesh", "mesh_reader"}},
      {"modules", {"core", "image", "preview", "cluster", "modules"}},
      {"cli",
       {"core", "geometry", "accel", "scene", "render", "readers", "mesh", "image", "factories",
        "writers", "job", "cluster", "preview", "cli"}},
      {"glint",
       {"core", "geometry", "accel", "scene", "render", "readers", "mesh", "image", "factories",
        "writers", "job", "preview"}},
  };
  return allowed;
}

TEST(ModuleLayers, NoModuleIncludesOneItMustNotDependOn) {
  const fs::path root = fs::path(GLINT_SOURCE_DIR) / "src" / "glint";
  std::vector<std::string> violations;
  std::size_t files = 0;
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(root)) {
    if (!entry.is_regular_file()) continue;
    const fs::path& path = entry.path();
    const std::string name = path.filename().string();
    if (name.ends_with("_test.cpp") || name.ends_with("_test_support.h")) continue;
    if (path.extension() != ".h" && path.extension() != ".cpp") continue;
    const std::string module = path.parent_path().filename().string();
    const auto allowed = allowedModules().find(module);
    ASSERT_NE(allowed, allowedModules().end()) << "a module the layering does not know: " << module;
    ++files;
    std::ifstream in(path);
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
      ++number;
      const std::string prefix = "#include \"glint/";
      if (line.rfind(prefix, 0) != 0) continue;
      const std::string used =
          line.substr(prefix.size(), line.find('/', prefix.size()) - prefix.size());
      if (allowed->second.count(used) == 0) {
        violations.push_back(fs::relative(path, root).string() + ":" + std::to_string(number) +
                             ": " + module + " uses " + used);
      }
    }
  }
  EXPECT_GT(files, 50u);
  for (const std::string& v : violations) ADD_FAILURE() << v;
}

}  // namespace

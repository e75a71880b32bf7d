// Images do not depend on the instruction set (core/isa.h): every scene in scenes/ renders the same
// film, bit for bit, under each ISA this processor runs as under the baseline. Small (48 pixels
// wide, at most 4 samples per pixel) so that all of them take seconds; the ISA changes only the BVH
// queries, which every pixel's camera and shadow rays go through.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "glint/core/isa.h"
#include "glint/job/render_job.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 48;  // pixels; the height follows the scene's aspect
constexpr int kSamples = 4;

std::vector<std::string> sceneNames() {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(fs::path(GLINT_SOURCE_DIR) / "scenes")) {
    const fs::path& path = entry.path();
    if (path.extension() == ".yaml" || path.extension() == ".nff" || path.extension() == ".dat")
      names.push_back(path.filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

// The film of `scene` rendered with the kernels of `isa`, and the ISA the job reports.
std::vector<Color> renderWith(const fs::path& scene, Isa isa, Isa& used) {
  RenderJobSpec spec;
  spec.scene = scene;
  spec.output = fs::temp_directory_path() /
                ("glint-isa-" + std::to_string(::getpid()) + "-" + scene.stem().string() + ".ppm");
  spec.overrides.width = kWidth;
  spec.overrides.samples = kSamples;
  spec.threads = 2;
  spec.isa = isa;
  std::vector<Color> pixels;
  RenderJobEvents events;
  events.imageFinished = [&pixels](const Film& film) {
    pixels.assign(film.pixels().begin(), film.pixels().end());
  };
  const RenderJobResult result = runRenderJob(spec, events);
  fs::remove(spec.output);
  used = result.scene.isa;
  return pixels;
}

class IsaRender : public ::testing::TestWithParam<std::string> {};

TEST_P(IsaRender, EveryIsaRendersTheBaselineFilm) {
  const fs::path scene = fs::path(GLINT_SOURCE_DIR) / "scenes" / GetParam();
  const IsaSupport here = isaSupportHere();
  if (!here.runs(Isa::Avx2) && !here.runs(Isa::Avx512))
    GTEST_SKIP() << "this build or processor runs only the baseline kernels";
  Isa used = Isa::Avx512;
  const std::vector<Color> baseline = renderWith(scene, Isa::Baseline, used);
  ASSERT_EQ(used, Isa::Baseline);
  ASSERT_FALSE(baseline.empty());
  for (const Isa isa : {Isa::Avx2, Isa::Avx512}) {
    if (!here.runs(isa)) continue;
    SCOPED_TRACE(std::string(isaName(isa)));
    const std::vector<Color> film = renderWith(scene, isa, used);
    EXPECT_EQ(used, isa);
    ASSERT_EQ(film.size(), baseline.size());
    std::size_t differing = 0;
    for (std::size_t i = 0; i < film.size(); ++i)
      differing += std::memcmp(&film[i], &baseline[i], sizeof(Color)) != 0 ? 1 : 0;
    EXPECT_EQ(differing, 0u) << "of " << film.size() << " pixels differ from the baseline's";
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, IsaRender, ::testing::ValuesIn(sceneNames()),
                         [](const ::testing::TestParamInfo<std::string>& paramInfo) {
                           std::string id = fs::path(paramInfo.param).stem().string();
                           std::replace(id.begin(), id.end(), '-', '_');
                           return id;
                         });

}  // namespace
}  // namespace glint

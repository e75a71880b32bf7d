// Reference-image tests: every scene in scenes/ (glint's YAML, and the NFF and Tachyon scenes of
// other renderers) rendered small by the glint command and compared
// with the checked-in tests/references/<scene>.png. scripts/regenerate-references.sh rewrites the
// references — only on purpose, after looking at the new images.
//
// Tolerance: renders are deterministic, so on the machine that made the references the bytes are
// identical. Other compilers or libm versions may round pow/sin differently, which can move a code
// by one and, through glossy sampling, a few pixels by more. We accept a mean absolute difference
// of at most 0.5 codes per channel and at most 0.5% of pixels with any channel off by more than 8
// codes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "test_png.h"

namespace fs = std::filesystem;

namespace {

constexpr int kReferenceWidth = 160;  // pixels; the height follows the scene's aspect
constexpr double kMaxMeanAbsoluteDifference = 0.5;
constexpr int kLargeDifference = 8;
constexpr double kMaxFractionLarge = 0.005;

// Scene files by name with their extension; the reference image is named after the stem.
std::vector<std::string> sceneNames() {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(fs::path(GLINT_SOURCE_DIR) / "scenes")) {
    const fs::path& path = entry.path();
    if (path.extension() == ".yaml" || path.extension() == ".nff" || path.extension() == ".dat") {
      names.push_back(path.filename().string());
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

class ReferenceImage : public ::testing::TestWithParam<std::string> {};

TEST_P(ReferenceImage, MatchesCheckedInReference) {
  const fs::path scene = fs::path(GLINT_SOURCE_DIR) / "scenes" / GetParam();
  const std::string name = scene.stem().string();
  const fs::path reference = fs::path(GLINT_SOURCE_DIR) / "tests" / "references" / (name + ".png");
  ASSERT_TRUE(fs::exists(reference))
      << reference << " is missing: run scripts/regenerate-references.sh and look at the result";

  const fs::path output = fs::temp_directory_path() / ("glint-reference-" + name + ".png");
  const std::string command = std::string("\"") + GLINT_BINARY_DIR + "/glint\" render \"" +
                              scene.string() + "\" --width " + std::to_string(kReferenceWidth) +
                              " --quiet -o \"" + output.string() + "\"";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;

  const auto actual = glint::testing::readPng(output);
  const auto expected = glint::testing::readPng(reference);
  fs::remove(output);
  ASSERT_EQ(actual.width, expected.width);
  ASSERT_EQ(actual.height, expected.height);

  double sumAbsolute = 0;
  std::size_t largePixels = 0;
  for (std::size_t pixel = 0; pixel < actual.rgb.size() / 3; ++pixel) {
    int worst = 0;
    for (std::size_t channel = 0; channel < 3; ++channel) {
      const int difference =
          std::abs(int(actual.rgb[3 * pixel + channel]) - int(expected.rgb[3 * pixel + channel]));
      sumAbsolute += difference;
      worst = std::max(worst, difference);
    }
    if (worst > kLargeDifference) ++largePixels;
  }
  const double mean = sumAbsolute / static_cast<double>(actual.rgb.size());
  const double fractionLarge =
      static_cast<double>(largePixels) / static_cast<double>(actual.rgb.size() / 3);
  EXPECT_LE(mean, kMaxMeanAbsoluteDifference) << name << ": mean absolute difference per channel";
  EXPECT_LE(fractionLarge, kMaxFractionLarge) << name << ": fraction of pixels off by > 8 codes";
}

INSTANTIATE_TEST_SUITE_P(Scenes, ReferenceImage, ::testing::ValuesIn(sceneNames()),
                         [](const ::testing::TestParamInfo<std::string>& paramInfo) {
                           std::string id = fs::path(paramInfo.param).stem().string();
                           std::replace(id.begin(), id.end(), '-', '_');
                           return id;
                         });

}  // namespace

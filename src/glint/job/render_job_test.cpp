#include "glint/job/render_job.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <utility>

#include "glint/core/atomic_file.h"
#include "glint/factories/scene_loader.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

const fs::path kSmallScene = fs::path(GLINT_SOURCE_DIR) / "tests" / "cli" / "small.yaml";

std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class RenderJobTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "glint-job-XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    folder_ = pattern;
    fs::copy_file(kSmallScene, folder_ / "scene.yaml");
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(folder_, ignored);
  }

  // small.yaml at 128x96: 8 x 6 tiles of 16 pixels.
  RenderJobSpec spec(const std::string& output) const {
    RenderJobSpec s;
    s.scene = folder_ / "scene.yaml";
    s.output = folder_ / output;
    s.overrides.width = 128;
    s.threads = 2;
    return s;
  }
  std::set<std::string> files() const {
    std::set<std::string> names;
    for (const auto& entry : fs::directory_iterator(folder_)) names.insert(entry.path().filename());
    return names;
  }

  fs::path folder_;
};

TEST_F(RenderJobTest, AnInterruptedJobResumesToTheBytesOfAnUninterruptedOne) {
  const RenderJobResult reference = runRenderJob(spec("reference.ppm"));
  ASSERT_EQ(reference.outcome, RenderJobResult::Outcome::Written);
  EXPECT_EQ(reference.tilesTotal, 48u);
  EXPECT_EQ(reference.pixelsRendered, 128u * 96u);

  // Stopped through the cancel flag from the tile callback, after 5 tiles.
  std::atomic<bool> cancel{false};
  RenderJobSpec interrupted = spec("out.ppm");
  interrupted.checkpoint = folder_ / "run.ckpt";
  interrupted.cancel = &cancel;
  RenderJobEvents events;
  std::size_t tilesSeen = 0;
  events.tileFinished = [&](const FinishedTile& tile) {
    EXPECT_EQ(tile.total, 48u);
    EXPECT_EQ(tile.region.width(), 16);
    EXPECT_EQ(&tile.film.at(0, 0), &tile.film.at(0, 0));
    if (++tilesSeen == 5) cancel.store(true);
  };
  const RenderJobResult stopped = runRenderJob(interrupted, events);
  ASSERT_EQ(stopped.outcome, RenderJobResult::Outcome::Interrupted);
  EXPECT_EQ(stopped.signal, 0) << "no signal: the flag alone";
  ASSERT_TRUE(stopped.checkpointSavedTo.has_value());
  EXPECT_EQ(*stopped.checkpointSavedTo, folder_ / "run.ckpt");
  EXPECT_GE(stopped.tilesSaved, 5u);
  EXPECT_LT(stopped.tilesSaved, 48u);
  EXPECT_EQ(files(), (std::set<std::string>{"reference.ppm", "run.ckpt", "scene.yaml"}))
      << "the checkpoint, no image, no temporary file";

  // Resumed: only the missing tiles are rendered, and the bytes are the uninterrupted ones.
  RenderJobSpec resume = spec("out.ppm");
  resume.resume = folder_ / "run.ckpt";
  resume.threads = 1;
  const RenderJobResult finished = runRenderJob(resume);
  ASSERT_EQ(finished.outcome, RenderJobResult::Outcome::Written);
  EXPECT_EQ(finished.tilesResumed, stopped.tilesSaved);
  EXPECT_EQ(finished.resumedFrom, folder_ / "run.ckpt");
  EXPECT_LT(finished.pixelsRendered, 128u * 96u);
  EXPECT_TRUE(readFile(folder_ / "out.ppm") == readFile(folder_ / "reference.ppm"))
      << "the resumed image differs from the uninterrupted one";
  EXPECT_EQ(files(), (std::set<std::string>{"out.ppm", "reference.ppm", "scene.yaml"}))
      << "the checkpoint goes once the image is written";
}

// A stop while the image is written: the writer stops, no image or temporary file stays, and the
// complete render is in the checkpoint, so a resume only writes the image.
TEST_F(RenderJobTest, AStopWhileWritingKeepsTheFinishedRenderInTheCheckpoint) {
  std::atomic<bool> cancel{false};
  RenderJobSpec job = spec("out.png");
  job.checkpoint = folder_ / "run.ckpt";
  job.cancel = &cancel;
  bool rendered = false;
  RenderJobEvents events;
  events.renderEnded = [&]() { rendered = true; };
  events.committing = [&](bool committing) {
    if (committing && rendered) cancel.store(true);
  };
  const RenderJobResult stopped = runRenderJob(job, events);
  ASSERT_EQ(stopped.outcome, RenderJobResult::Outcome::Interrupted);
  EXPECT_EQ(stopped.tilesSaved, 48u);
  EXPECT_EQ(files(), (std::set<std::string>{"run.ckpt", "scene.yaml"}));

  RenderJobSpec resume = spec("out.png");
  resume.resume = folder_ / "run.ckpt";
  const RenderJobResult written = runRenderJob(resume);
  ASSERT_EQ(written.outcome, RenderJobResult::Outcome::Written);
  EXPECT_EQ(written.tilesResumed, 48u);
  EXPECT_EQ(written.stats.rays.camera, 0u) << "nothing rendered again";
  EXPECT_EQ(files(), (std::set<std::string>{"out.png", "scene.yaml"}));
}

TEST_F(RenderJobTest, ASceneBuiltInCodeRendersThroughTheSameJob) {
  RenderJobSpec job;
  job.sceneParts = loadScene(kSmallScene).parts;
  job.output = folder_ / "code.ppm";
  job.overrides.width = 128;
  const RenderJobResult result = runRenderJob(std::move(job));
  ASSERT_EQ(result.outcome, RenderJobResult::Outcome::Written);
  EXPECT_EQ(result.scene.image.width, 128);
  EXPECT_EQ(result.scene.objects, 4u);
  ASSERT_EQ(runRenderJob(spec("file.ppm")).outcome, RenderJobResult::Outcome::Written);
  EXPECT_TRUE(readFile(folder_ / "code.ppm") == readFile(folder_ / "file.ppm"));

  RenderJobSpec checkpointed;
  checkpointed.sceneParts = loadScene(kSmallScene).parts;
  checkpointed.output = folder_ / "other.ppm";
  checkpointed.checkpoint = folder_ / "run.ckpt";
  try {
    runRenderJob(std::move(checkpointed));
    FAIL() << "expected JobError";
  } catch (const JobError& error) {
    EXPECT_EQ(error.exitCode(), 2);
  }
}

TEST_F(RenderJobTest, ErrorsCarryTheirExitStatusAndScenesTheirPlaces) {
  const auto failure = [](RenderJobSpec job) -> JobError {
    try {
      runRenderJob(std::move(job));
    } catch (const JobError& error) {
      return error;
    }
    ADD_FAILURE() << "expected JobError";
    return JobError(JobFailure::Failure, "");
  };
  const JobError extension = failure(spec("out.jpg"));
  EXPECT_EQ(extension.failure(), JobFailure::BadInput);
  EXPECT_EQ(extension.exitCode(), 2);
  EXPECT_STREQ(extension.what(), ("cannot write '" + (folder_ / "out.jpg").string() +
                                  "': unknown image format '.jpg'; use .png, .ppm or .exr")
                                     .c_str());
  fs::create_directory(folder_ / "taken.png");
  EXPECT_EQ(failure(spec("taken.png")).exitCode(), 2) << "a folder in the way: a wrong argument";

  // The output may not be an input: here the scene file itself.
  fs::copy_file(kSmallScene, folder_ / "scene.png");
  RenderJobSpec overwrite = spec("scene.png");
  overwrite.scene = folder_ / "scene.png";
  const JobError input = failure(overwrite);
  EXPECT_EQ(input.exitCode(), 2);
  EXPECT_NE(std::string(input.what()).find("it is the scene file"), std::string::npos);
  EXPECT_EQ(readFile(folder_ / "scene.png"), readFile(kSmallScene));

  std::ofstream(folder_ / "broken.yaml") << "image: { width: 0, height: 10 }\n";
  RenderJobSpec broken = spec("broken.png");
  broken.scene = folder_ / "broken.yaml";
  const JobError scene = failure(broken);
  EXPECT_EQ(scene.exitCode(), 2);
  ASSERT_FALSE(scene.diagnostics().empty());
  EXPECT_EQ(scene.diagnostics()[0].where.file, (folder_ / "broken.yaml").string());
}

TEST_F(RenderJobTest, CheckReturnsTheFactsAndTheWarnings) {
  std::ofstream(folder_ / "absurd.yaml")
      << readFile(kSmallScene)
      << "  - { type: area, shape: disk, center: [0, 3, 0], normal: [0, -1, 0], radius: 0.5,\n"
         "      samples: 65536 }\n";
  std::string text = readFile(folder_ / "absurd.yaml");
  text.replace(text.find("samples: 4\n"), 11, "samples: 65536\n");
  std::ofstream(folder_ / "absurd.yaml") << text;
  CheckOptions options;
  std::vector<Diagnostic> warnings;
  options.warnings = [&](const std::vector<Diagnostic>& w) { warnings = w; };
  const SceneFacts facts = checkScene(folder_ / "absurd.yaml", options);
  EXPECT_EQ(facts.objects, 4u);
  EXPECT_EQ(facts.lights, 3u);
  EXPECT_EQ(facts.areaLights, 1u);
  EXPECT_TRUE(facts.ambient);
  EXPECT_EQ(facts.samplesPerPixel.minimum, 65536);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].severity, Diagnostic::Severity::Warning);
  EXPECT_NE(warnings[0].message.find("65536 samples"), std::string::npos) << warnings[0].message;

  // The render warns the same way, before it starts; stopping it from there writes nothing.
  std::atomic<bool> cancel{false};
  RenderJobSpec job = spec("absurd.png");
  job.scene = folder_ / "absurd.yaml";
  job.cancel = &cancel;
  RenderJobEvents events;
  events.sceneWarnings = [&](const std::vector<Diagnostic>& w) {
    EXPECT_EQ(w.size(), 1u);
    cancel.store(true);
  };
  EXPECT_EQ(runRenderJob(job, events).outcome, RenderJobResult::Outcome::Interrupted);
  EXPECT_FALSE(fs::exists(folder_ / "absurd.png"));
}

// glint processes killed while writing leave temporary files; the next job in that folder
// removes those of processes that are gone.
TEST_F(RenderJobTest, StaleTemporaryFilesAreRemovedBeforeTheJobWrites) {
  std::string name;
  {
    AtomicFile probe(folder_ / "probe");
    name = probe.temporaryPath().filename();
  }
  // Same host, an impossible PID (beyond pid_max): no such process.
  const std::string host = name.substr(kTemporaryFilePrefix.size(), 8);
  const std::string stale = std::string(kTemporaryFilePrefix) + host + "-2147483646-zzzzzz";
  std::ofstream(folder_ / stale) << "half an image";
  ASSERT_EQ(runRenderJob(spec("out.ppm")).outcome, RenderJobResult::Outcome::Written);
  EXPECT_EQ(files(), (std::set<std::string>{"out.ppm", "scene.yaml"}));
}

}  // namespace
}  // namespace glint

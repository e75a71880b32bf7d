// The live preview from outside: a render job feeding it ends with the written PNG's bytes; the
// command's --preview options, its errors (exit 2), the same output bytes with and without it, and
// serving after the render until Ctrl-C. (The page itself: tests/browser/preview_browser_test.py.)
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <atomic>
#include <regex>

#include "cli_harness.h"
#include "glint/preview/job_preview.h"
#include "glint/scene/seed_scene.h"
#include "test_png.h"

namespace glint_cli_test {
namespace {

// The seed test case, small, with its grid: the grid is painted after the tiles, so the preview's
// last picture must come from the finished image.
TEST(PreviewJob, TheLastPictureIsTheWrittenPng) {
  const fs::path folder = fs::temp_directory_path() / ("glint-preview-" + std::to_string(getpid()));
  fs::create_directories(folder);
  glint::PreviewState state("seed");
  glint::RenderJobSpec job;
  job.scene = "seed test case";
  job.sceneParts = glint::seed::testCaseParts(120, 25);
  job.output = folder / "seed.png";
  glint::RenderJobEvents events;
  glint::attachPreview(events, state);
  const glint::RenderJobResult result = glint::runRenderJob(std::move(job), events);
  state.ended(glint::PreviewPhase::Finished, "done");

  glint::PreviewChanges changes = state.waitForChanges(0, 0ms);
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (changes.status.phase != glint::PreviewPhase::Finished &&
         std::chrono::steady_clock::now() < deadline)
    changes = state.waitForChanges(changes.version, 100ms);
  ASSERT_EQ(changes.status.phase, glint::PreviewPhase::Finished);
  changes = state.waitForChanges(0, 0ms);
  EXPECT_EQ(changes.status.tilesDone, result.tilesTotal);
  const glint::testing::DecodedImage png = glint::testing::readPng(result.output);
  ASSERT_EQ(changes.status.width, png.width);
  std::vector<std::uint8_t> shown(png.rgb.size());
  for (const glint::PreviewTile& tile : changes.tiles)
    for (int y = tile.region.y0; y < tile.region.y1; ++y)
      std::memcpy(&shown[(static_cast<std::size_t>(y) * png.width + tile.region.x0) * 3],
                  &tile.rgb[static_cast<std::size_t>(y - tile.region.y0) * tile.region.width() * 3],
                  static_cast<std::size_t>(tile.region.width()) * 3);
  EXPECT_TRUE(shown == png.rgb) << "the preview's picture differs from the PNG";
  fs::remove_all(folder);
}

// A resumed render's preview shows the checkpoint's tiles when the render starts, not only with
// the finished image: by the first newly rendered tile, every resumed tile is on the page.
TEST(PreviewJob, AResumedRenderShowsItsCheckpointsTilesAtOnce) {
  const fs::path folder =
      fs::temp_directory_path() / ("glint-preview-resume-" + std::to_string(getpid()));
  fs::create_directories(folder);
  const fs::path scene = fs::path(GLINT_SOURCE_DIR) / "scenes" / "first-scene.yaml";
  // Half the tiles, then stop: the checkpoint holds them.
  std::atomic<bool> stop{false};
  glint::RenderJobSpec first;
  first.scene = scene;
  first.overrides.width = 160;
  first.threads = 1;
  first.output = folder / "out.png";
  first.checkpoint = folder / "run.ckpt";
  first.cancel = &stop;
  glint::RenderJobEvents stopHalfway;
  stopHalfway.progress = [&stop](std::size_t done, std::size_t total) {
    if (2 * done >= total) stop = true;
  };
  const glint::RenderJobResult interrupted = glint::runRenderJob(first, stopHalfway);
  ASSERT_EQ(interrupted.outcome, glint::RenderJobResult::Outcome::Interrupted);
  ASSERT_GT(interrupted.tilesSaved, 0u);

  glint::PreviewState state("resume");
  glint::RenderJobSpec second = first;
  second.cancel = nullptr;
  second.resume = folder / "run.ckpt";
  glint::RenderJobEvents events;
  glint::attachPreview(events, state);
  std::size_t shownAtFirstTile = 0;
  bool firstTile = true;
  events.progress = [&, before = events.progress](std::size_t done, std::size_t total) {
    if (firstTile) {
      firstTile = false;
      // The preview publishes on its own thread: wait for it (a bound, not a race).
      const auto deadline = std::chrono::steady_clock::now() + 10s;
      glint::PreviewChanges changes = state.waitForChanges(0, 0ms);
      while (changes.tiles.size() < interrupted.tilesSaved &&
             std::chrono::steady_clock::now() < deadline)
        changes = state.waitForChanges(0, 50ms);
      shownAtFirstTile = changes.tiles.size();
    }
    if (before) before(done, total);
  };
  const glint::RenderJobResult resumed = glint::runRenderJob(second, events);
  state.ended(glint::PreviewPhase::Finished, "done");
  ASSERT_EQ(resumed.outcome, glint::RenderJobResult::Outcome::Written);
  EXPECT_EQ(resumed.tilesResumed, interrupted.tilesSaved);
  EXPECT_GE(shownAtFirstTile, interrupted.tilesSaved);
  fs::remove_all(folder);
}

// The port glint printed in "glint: preview at http://127.0.0.1:PORT/", once it has.
std::optional<int> printedPort(const fs::path& stderrFile) {
  static const std::regex line(R"(glint: preview at http://127\.0\.0\.1:(\d+)/)");
  std::smatch match;
  const std::string text = readFile(stderrFile);
  if (!std::regex_search(text, match, line)) return std::nullopt;
  return std::stoi(match[1]);
}

using PreviewCli = Cli;

TEST_F(PreviewCli, ARenderWithThePreviewWritesTheSameBytes) {
  const std::vector<std::string> render{"render", small(), "--width", "96", "--threads", "2"};
  std::vector<std::string> plain = render;
  plain.insert(plain.end(), {"-o", "plain.png"});
  std::vector<std::string> previewed = render;
  previewed.insert(previewed.end(),
                   {"-o", "previewed.png", "--preview", "0", "--preview-linger", "0"});
  const RunResult without = run(plain);
  const RunResult with = run(previewed);
  ASSERT_EQ(without.status, 0) << without.err;
  ASSERT_EQ(with.status, 0) << with.err;
  EXPECT_TRUE(contains(with.err, "glint: preview at http://127.0.0.1:")) << with.err;
  EXPECT_FALSE(contains(with.err, "stays at")) << with.err;
  EXPECT_EQ(readFile(work_ / "plain.png"), readFile(work_ / "previewed.png"));
}

TEST_F(PreviewCli, APortInUseIsAClearErrorBeforeAnyWork) {
  const int taken = socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(taken, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(bind(taken, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  ASSERT_EQ(listen(taken, 1), 0);
  socklen_t size = sizeof address;
  getsockname(taken, reinterpret_cast<sockaddr*>(&address), &size);
  const std::string port = std::to_string(ntohs(address.sin_port));

  const RunResult result = run({"render", small(), "-o", "out.png", "--preview", port});
  close(taken);
  EXPECT_EQ(result.status, 2);
  EXPECT_TRUE(contains(result.err, "glint: error: cannot serve the preview on 127.0.0.1:" + port +
                                       ": the port is in use"))
      << result.err;
  EXPECT_FALSE(fs::exists(work_ / "out.png"));
}

TEST_F(PreviewCli, BadPreviewOptionsExitWithStatus2) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--preview", "70000"}, "--preview expects a port number from 0 to 65535, got '70000'"},
      {{"--preview=x"}, "--preview expects a port number from 0 to 65535, got 'x'"},
      {{"--preview", "0", "--preview-linger", "-1"}, "--preview-linger expects seconds"},
      {{"--preview-bind", "127.0.0.1"}, "--preview-bind requires --preview"},
      {{"--preview", "0", "--preview-bind", "localhost"}, "not an IP address"},
  };
  for (const auto& [options, message] : cases) {
    std::vector<std::string> args{"render", small(), "-o", "out.png"};
    args.insert(args.end(), options.begin(), options.end());
    const RunResult result = run(args);
    EXPECT_EQ(result.status, 2) << options[0] << ": " << result.err;
    EXPECT_TRUE(contains(result.err, message)) << result.err;
    EXPECT_FALSE(fs::exists(work_ / "out.png"));
  }
}

// The HTTP side is a module (glint-preview-http.so, beside glint in the build tree) loaded only
// for a preview: one that is missing or is another module is a clear error before any work.
TEST_F(PreviewCli, APreviewModuleThatCannotLoadIsAClearError) {
  const std::string missing = (work_ / "no-such-module.so").string();
  const std::string other = (fs::path(GLINT_BINARY_DIR) / "glint-mesh-reader").string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {missing, "cannot start the preview: cannot load " + missing},
      {other, "cannot start the preview: cannot load " + other},
  };
  for (const auto& [module, message] : cases) {
    ASSERT_EQ(::setenv("GLINT_PREVIEW_MODULE", module.c_str(), 1), 0);
    const RunResult result = run({"render", small(), "-o", "out.png", "--preview", "0"});
    ::unsetenv("GLINT_PREVIEW_MODULE");
    EXPECT_EQ(result.status, 2) << result.err;
    EXPECT_TRUE(contains(result.err, "glint: error: " + message)) << result.err;
    EXPECT_FALSE(fs::exists(work_ / "out.png"));
  }
}

#ifdef GLINT_MPI
// A module of this build that is not the preview's is refused by its identity, not called.
TEST_F(PreviewCli, AnotherModuleInPlaceOfThePreviewsIsRefused) {
  const std::string mpi = (fs::path(GLINT_BINARY_DIR) / "glint-mpi.so").string();
  ASSERT_EQ(::setenv("GLINT_PREVIEW_MODULE", mpi.c_str(), 1), 0);
  const RunResult result = run({"render", small(), "-o", "out.png", "--preview", "0"});
  ::unsetenv("GLINT_PREVIEW_MODULE");
  EXPECT_EQ(result.status, 2) << result.err;
  EXPECT_TRUE(contains(result.err, "glint: error: cannot start the preview: " + mpi +
                                       " is not the module of this glint (it is 'glint "))
      << result.err;
  EXPECT_TRUE(contains(result.err, "module mpi interface 1'; expected 'glint ")) << result.err;
  EXPECT_FALSE(fs::exists(work_ / "out.png"));
}
#endif

TEST_F(PreviewCli, AnAddressOthersCanReachComesWithAWarning) {
  const RunResult result = run({"render", small(), "-o", "out.png", "--preview", "0",
                                "--preview-bind", "0.0.0.0", "--preview-linger", "0"});
  EXPECT_EQ(result.status, 0) << result.err;
  EXPECT_TRUE(contains(result.err,
                       "glint: warning: the preview listens on 0.0.0.0: anyone who "
                       "can reach this port can see the image"))
      << result.err;
}

TEST_F(PreviewCli, KeepsServingAfterTheRenderUntilCtrlC) {
  const pid_t pid = start({"render", small(), "-o", "out.png", "--preview", "0"});
  const fs::path err = root_ / "capture" / "stderr";
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (!contains(readFile(err), "until Ctrl-C") && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(20ms);
  ASSERT_TRUE(contains(readFile(err), "glint: the preview stays at http://127.0.0.1:"))
      << readFile(err);
  EXPECT_TRUE(fs::exists(work_ / "out.png"));
  const std::optional<int> port = printedPort(err);
  ASSERT_TRUE(port);
  httplib::Client client("127.0.0.1", *port);
  const httplib::Result page = client.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  std::string events;
  client.Get("/events", [&events](const char* data, std::size_t length) {
    events.append(data, length);
    return events.find("\"phase\":\"finished\"") == std::string::npos;
  });
  EXPECT_TRUE(contains(events, "glint: wrote ")) << events;  // the summary
  kill(pid, SIGINT);
  const RunResult result = finish(pid, 10s);
  EXPECT_EQ(result.status, 0) << result.err;  // the render succeeded; Ctrl-C only ended serving
}

}  // namespace
}  // namespace glint_cli_test

// The render job behind the command line (issues 12 and 13), tested by running the built binary:
// what it refuses before any work, how it stops, what it leaves behind and what it prints.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <climits>
#include <filesystem>
#include <regex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "cli_harness.h"
#include "glint/core/atomic_file.h"

namespace glint_cli_test {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// Waits until glint handles `signal`, lets it work a moment, sends the signal, and returns how it
// ended and how long it took to end.
struct Stopped {
  RunResult result;
  std::chrono::duration<double> took{};
};

class CliJob : public Cli {
 protected:
  // Runs `args` in the background and stops it with `signal` once stderr matches `ready` and
  // `warmUp` has passed.
  Stopped stopWith(int signal, const std::vector<std::string>& args, const std::regex& ready,
                   std::chrono::milliseconds warmUp = 0ms) {
    const pid_t pid = start(args);
    const auto deadline = std::chrono::steady_clock::now() + 30s;
    while (!catchesSignal(pid, signal) && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(2ms);
    EXPECT_TRUE(catchesSignal(pid, signal)) << "glint never installed its handler for " << signal;
    while (!std::regex_search(readFile(root_ / "capture" / "stderr"), ready) &&
           std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(1ms);
    std::this_thread::sleep_for(warmUp);
    const auto sent = std::chrono::steady_clock::now();
    kill(pid, signal);
    Stopped stopped;
    stopped.result = finish(pid, 10s);
    stopped.took = std::chrono::steady_clock::now() - sent;
    return stopped;
  }

  // small.yaml at 128x96 on one thread (48 tiles, stopped once it has reported progress), with
  // `extra` options.
  std::vector<std::string> slowRender(const std::vector<std::string>& extra) const {
    std::vector<std::string> args{"render", small(), "--width", "128", "--threads", "1"};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  }
  const std::regex someProgress{R"(glint: [1-9][0-9]?% )"};

  // small.yaml with `from` replaced by `to` (which must be there), written into the root folder.
  std::string variant(const std::string& name, const std::string& from, const std::string& to) {
    std::string text = readFile(kScenes / "small.yaml");
    EXPECT_NE(text.find(from), std::string::npos) << from;
    if (text.find(from) != std::string::npos) text.replace(text.find(from), from.size(), to);
    writeFile(root_ / name, text);
    return (root_ / name).string();
  }
};

// --- inputs are read safely and never overwritten -----------------------------------------

// Today's bug: --resume /dev/zero read 6 GB in 17 s, ignoring SIGINT; a FIFO blocked forever.
// Both are refused by their stat, before the scene is even loaded. The memory cap turns a
// runaway read into a quick failure instead of a machine swapping.
TEST_F(CliJob, ResumeRefusesDevicesAndFifosWithoutReadingThem) {
  constexpr std::uint64_t kAddressSpace = std::uint64_t{2} << 30;
  RunResult r =
      run({"render", small(), "-o", "out.png", "--resume", "/dev/zero", "--checkpoint", "new.ckpt"},
          5s, kAddressSpace);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(contains(r.err,
                       "glint: error: cannot resume: cannot read checkpoint '/dev/zero': it "
                       "is not a regular file (a device, FIFO or socket)"))
      << r.err;
  ASSERT_EQ(mkfifo((work_ / "run.ckpt").c_str(), 0600), 0);
  r = run({"render", small(), "-o", "out.png", "--resume", "run.ckpt"}, 5s, kAddressSpace);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "cannot read checkpoint 'run.ckpt': it is not a regular file"))
      << r.err;
  EXPECT_EQ(filesIn(work_), std::set<std::string>{"run.ckpt"});
}

TEST_F(CliJob, AnEmptyResumeNameNamesTheResumeOption) {
  const RunResult r = run({"render", small(), "-o", "out.png", "--resume", ""});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "glint: error: --resume needs a file name\n");
  const RunResult checkpoint = run({"render", small(), "-o", "out.png", "--checkpoint", ""});
  EXPECT_EQ(checkpoint.err, "glint: error: --checkpoint needs a file name\n");
  EXPECT_TRUE(filesIn(work_).empty());
}

// Today's bug: `glint render scene.png -o scene.png` replaced the scene with the image, exit 0.
TEST_F(CliJob, AnOutputThatIsAnInputIsRefused) {
  const std::string scene = readFile(kScenes / "small.yaml");
  writeFile(work_ / "scene.png", scene);
  fs::create_hard_link(work_ / "scene.png", work_ / "alias.png");
  const std::vector<std::vector<std::string>> attempts{
      {"render", "scene.png", "-o", "scene.png"},
      {"render", "scene.png"},  // the default output: the scene's name with .png, here
      {"render", "scene.png", "-o", "./scene.png"},
      {"render", (work_ / "scene.png").string(), "-o", "scene.png"},
      {"render", "scene.png", "-o", "alias.png"}};  // the same file under another name
  for (const std::vector<std::string>& args : attempts) {
    const RunResult r = run(args);
    EXPECT_EQ(r.status, 2) << args.back() << "\n" << r.err;
    EXPECT_TRUE(contains(r.err, "': it is the scene file")) << r.err;
  }
  // A checkpoint being resumed is an input too.
  writeFile(work_ / "run.png", "a checkpoint with an odd name");
  const RunResult resumed =
      run({"render", small(), "-o", "run.png", "--resume", "run.png", "--checkpoint", "new.ckpt"});
  EXPECT_EQ(resumed.status, 2);
  EXPECT_EQ(resumed.err, "glint: error: the checkpoint 'run.png' cannot be the output image\n");
  EXPECT_EQ(readFile(work_ / "scene.png"), scene);
  EXPECT_EQ(filesIn(work_), (std::set<std::string>{"alias.png", "run.png", "scene.png"}));
}

// --- file names, signals and temporary files ----------------------------------------------

// Today's bug: a legal 254-byte output name rendered fully, then failed (exit 1) because the
// temporary file's name was longer than NAME_MAX. Checkpoints had the same problem.
TEST_F(CliJob, TheLongestLegalFileNamesAreWritten) {
  const std::string image = std::string(NAME_MAX - 4, 'i') + ".png";
  const RunResult r = run({"render", small(), "-o", image, "--quiet"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(filesIn(work_), std::set<std::string>{image});
  fs::remove(work_ / image);

  const std::string checkpoint = std::string(NAME_MAX - 5, 'c') + ".ckpt";
  const Stopped stopped =
      stopWith(SIGINT, slowRender({"-o", image, "--checkpoint", checkpoint}), someProgress);
  EXPECT_EQ(stopped.result.status, 130) << stopped.result.err;
  EXPECT_EQ(filesIn(work_), std::set<std::string>{checkpoint}) << stopped.result.err;
}

// Today's bug: SIGHUP (the terminal or the ssh session closed) killed the render outright.
TEST_F(CliJob, SighupStopsTheRenderWith129AndSavesTheCheckpoint) {
  const Stopped stopped =
      stopWith(SIGHUP, slowRender({"-o", "out.png", "--checkpoint", "run.ckpt"}), someProgress);
  EXPECT_EQ(stopped.result.status, 129) << stopped.result.err;
  EXPECT_TRUE(std::regex_search(stopped.result.err,
                                std::regex(R"(glint: interrupted; \d+ of \d+ tiles saved to )")))
      << stopped.result.err;
  EXPECT_EQ(filesIn(work_), std::set<std::string>{"run.ckpt"}) << "no image, no temporary file";
  EXPECT_EQ(readFile(work_ / "run.ckpt").substr(0, 8), "GLINTCKP");
}

// Today's bug: SIGKILL while writing left ".out.png.tmp-PID-0" beside the output for good. A
// killed run's temporary file (the name glint gives it, with a PID no process has) goes on the
// next run into that folder; those of living processes, of other hosts, and files that merely
// look alike stay.
TEST_F(CliJob, TemporaryFilesOfKilledRunsAreRemovedByTheNextRun) {
  std::string probeName;
  {
    glint::AtomicFile probe(work_ / "probe");
    probeName = probe.temporaryPath().filename();
  }
  const std::string prefix(glint::kTemporaryFilePrefix);
  const std::string host = probeName.substr(prefix.size(), 8);
  const std::string otherHost = host == "00000000" ? "11111111" : "00000000";
  const std::string killed = prefix + host + "-2147483646-a1b2c3";  // beyond any pid_max
  const std::string living = prefix + host + "-" + std::to_string(getpid()) + "-a1b2c3";
  const std::string elsewhere = prefix + otherHost + "-2147483646-a1b2c3";
  const std::string lookalike = ".out.png.tmp-2147483646-0";
  fs::create_directory(work_ / "ckpt");
  for (const fs::path& file : {work_ / killed, work_ / living, work_ / elsewhere, work_ / lookalike,
                               work_ / "ckpt" / killed})
    writeFile(file, "half an image");
  const RunResult r =
      run({"render", small(), "-o", "out.png", "--checkpoint", "ckpt/run.ckpt", "--quiet"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(filesIn(work_),
            (std::set<std::string>{"ckpt", "out.png", living, elsewhere, lookalike}));
  EXPECT_TRUE(filesIn(work_ / "ckpt").empty());
}

// --- absurd work per pixel ----------------------------------------------------------------

// Today's bug: a 1x1 image at 65536 samples under a 65536-sample area light (every value in range)
// never finished and ignored SIGINT/SIGTERM: the renderer polled only between pixels.
TEST_F(CliJob, APixelOfBillionsOfRaysWarnsAndStopsWithinASecond) {
  const std::string scene = variant("absurd.yaml", "  width: 32\n  height: 24\n  samples: 4\n",
                                    "  width: 1\n  height: 1\n  samples: 65536\n");
  std::string text = readFile(scene);
  text +=
      "  - { type: area, shape: disk, center: [0, 3, 0], normal: [0, -1, 0], radius: 0.5,\n"
      "      samples: 65536 }\n";
  writeFile(scene, text);
  const std::string warning = "absurd.yaml:1:1: warning: one pixel may trace about ";
  const RunResult check = run({"check", scene});
  ASSERT_EQ(check.status, 0) << check.err;
  EXPECT_TRUE(contains(check.err, warning)) << check.err;
  EXPECT_TRUE(contains(check.err, "65536 samples × ")) << check.err;
  EXPECT_TRUE(contains(check.err, "65538 shadow")) << check.err;  // the area light, two others
  EXPECT_TRUE(filesIn(work_).empty());

  for (const int signal : {SIGINT, SIGTERM}) {
    const Stopped stopped =
        stopWith(signal, {"render", scene, "-o", "out.png"}, std::regex(warning), 300ms);
    EXPECT_EQ(stopped.result.status, 128 + signal) << stopped.result.err;
    EXPECT_TRUE(contains(stopped.result.err, warning)) << stopped.result.err;
    // The renderer stops within one sample; the bound leaves room for a loaded machine.
    EXPECT_LT(stopped.took, 2s) << "signal " << signal;
    EXPECT_TRUE(filesIn(work_).empty());
  }
}

// --- what the summaries and --quiet print -------------------------------------------------

// Every pixel takes at least 4 samples under adaptive sampling, so `samples: 1` is not "1 to 64".
TEST_F(CliJob, TheAdaptiveRangeStartsAtTheSamplesEveryPixelTakes) {
  const std::string scene =
      variant("adaptive.yaml", "  samples: 4\n",
              "  samples: 1\n  adaptive: { max_samples: 64, threshold: 0.05 }\n");
  const RunResult check = run({"check", scene});
  ASSERT_EQ(check.status, 0) << check.err;
  EXPECT_TRUE(contains(check.out, "32x24, 4 to 64 samples per pixel (adaptive, threshold 0.05)"))
      << check.out;
  const RunResult r = run({"render", scene, "-o", "out.png", "--stats"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(std::regex_search(
      r.err, std::regex(R"(glint: samples: \d+ \([0-9.]+ per pixel on average, 4 to 64\))")))
      << r.err;
  EXPECT_TRUE(contains(r.err, "4 to 64 samples per pixel (adaptive")) << r.err;
}

// Today's bug: oneTBB printed "TBB Warning: The number of workers is currently limited to 1 ..."
// under --quiet when --threads exceeded the cores.
TEST_F(CliJob, QuietWithMoreThreadsThanCoresPrintsNothing) {
  for (const char* threads : {"64", "4096"}) {
    const RunResult r = run({"render", small(), "-o", "out.png", "--quiet", "--threads", threads});
    EXPECT_EQ(r.status, 0) << threads;
    EXPECT_EQ(r.err, "") << threads;
    EXPECT_EQ(r.out, "") << threads;
  }
}

}  // namespace
}  // namespace glint_cli_test

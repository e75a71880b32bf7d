// `glint render` under mpirun (docs/distributed.md), run by these tests themselves: any number of
// ranks and threads per rank gives the bytes of a plain render (crops, adaptive sampling, every
// effect, the grid); a rank killed mid-render fails the job within seconds and leaves no image, and
// the resumed rerun renders only the missing tiles; a rank that loaded another scene or options is
// refused with exit 2; a rank that stops answering fails the job after GLINT_MPI_TIMEOUT; SIGINT
// to mpirun saves the checkpoint. OpenMPI is told to run as root, oversubscribed, over shared
// memory only (CI runs in a container as root, with no network).
#include <dirent.h>

#include <cstdlib>
#include <numbers>
#include <regex>

#include <fmt/format.h>
#include <httplib.h>

#include "cli_harness.h"

namespace glint_cli_test {
namespace {

const fs::path kShowcase = fs::path(GLINT_SOURCE_DIR) / "scenes" / "showcase.yaml";

// The showcase small: adaptive sampling, an area light, depth of field, glossy reflection and
// refraction, every shape and light type, a mesh.
const std::vector<std::string> kShowcaseSmall{kShowcase.string(), "--width", "64", "--height",
                                              "36"};

std::vector<std::string> operator+(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// The ranks mpirun `launcher` started: (rank, pid) from their environment.
std::map<int, pid_t> ranksOf(pid_t launcher) {
  std::map<int, pid_t> ranks;
  DIR* proc = opendir("/proc");
  if (proc == nullptr) return ranks;
  while (const dirent* entry = readdir(proc)) {
    const pid_t pid = static_cast<pid_t>(std::atoi(entry->d_name));
    if (pid <= 0) continue;
    const std::string stat = readFile(fs::path("/proc") / entry->d_name / "stat");
    const std::size_t close = stat.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream fields(stat.substr(close + 2));
    std::string state;
    pid_t parent = 0;
    fields >> state >> parent;
    if (parent != launcher) continue;
    const std::string environment = readFile(fs::path("/proc") / entry->d_name / "environ");
    const std::string key = std::string("OMPI_COMM_WORLD_RANK=");
    std::size_t at = environment.find(key);
    if (at == std::string::npos || (at > 0 && environment[at - 1] != '\0')) continue;
    ranks[std::atoi(environment.c_str() + at + key.size())] = pid;
  }
  closedir(proc);
  return ranks;
}

class Mpi : public Cli {
 protected:
  // mpirun's arguments before the program: root allowed, more ranks than cores, shared memory
  // between ranks (no network), no CPU binding (the CI machine is shared). `graceSeconds`: the
  // odls_base_sigkill_timeout between the SIGTERM and the SIGKILL that mpirun sends the ranks when
  // it is interrupted (time for rank 0 to save its checkpoint; 1 s by default). When a rank dies,
  // mpirun also waits that long before the SIGTERM.
  static std::vector<std::string> launcher(int ranks, int graceSeconds = 1) {
    return {GLINT_MPIEXEC,
            "--mca",
            "odls_base_sigkill_timeout",
            std::to_string(graceSeconds),
            "--allow-run-as-root",
            "--oversubscribe",
            "--bind-to",
            "none",
            "--mca",
            "btl",
            "self,vader",
            "--mca",
            "btl_vader_single_copy_mechanism",
            "none",
            "-np",
            std::to_string(ranks)};
  }
  static std::vector<std::string> glint(const std::vector<std::string>& args) {
    return std::vector<std::string>{kGlint.string(), "render"} + args;
  }

  // Starts `command` (a program and its arguments) in the work folder, output captured.
  pid_t startCommand(const std::vector<std::string>& command,
                     std::vector<std::string> environment = {}) {
    // Under the address sanitizer, no leak check in the ranks: OpenMPI leaves thousands of blocks
    // at MPI_Finalize, many from plugins already unloaded (so no suppression can name them), and
    // LeakSanitizer would fail every rank at exit. glint's own leaks are checked by the other
    // tests.
    if (kAddressSanitizer) {
      const char* options = std::getenv("ASAN_OPTIONS");
      environment.insert(environment.begin(),
                         std::string("ASAN_OPTIONS=") + (options != nullptr ? options : "") +
                             (options != nullptr && *options != '\0' ? ":" : "") +
                             "detect_leaks=0");
    }
    const int outFd =
        open((root_ / "capture" / "stdout").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int errFd =
        open((root_ / "capture" / "stderr").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const pid_t pid = fork();
    if (pid == 0) {
      for (const std::string& setting : environment) putenv(strdup(setting.c_str()));
      std::vector<char*> argv;
      std::vector<std::string> copies = command;
      for (std::string& arg : copies) argv.push_back(arg.data());
      argv.push_back(nullptr);
      const int in = open("/dev/null", O_RDONLY);
      if (in < 0 || dup2(in, STDIN_FILENO) < 0 || dup2(outFd, STDOUT_FILENO) < 0 ||
          dup2(errFd, STDERR_FILENO) < 0 || chdir(work_.c_str()) != 0)
        _exit(127);
      execv(argv[0], argv.data());
      _exit(127);
    }
    close(outFd);
    close(errFd);
    running_ = pid;
    return pid;
  }
  RunResult runCommand(const std::vector<std::string>& command,
                       std::chrono::milliseconds timeout = 120s) {
    return finish(startCommand(command), timeout);
  }
  RunResult mpirun(int ranks, const std::vector<std::string>& args) {
    return runCommand(launcher(ranks) + glint(args));
  }
  std::string stderrSoFar() const { return readFile(root_ / "capture" / "stderr"); }

  // Waits until the captured stderr matches `pattern`; false after `limit`.
  bool awaitStderr(const std::regex& pattern, std::chrono::milliseconds limit) {
    const auto deadline = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < deadline) {
      if (std::regex_search(stderrSoFar(), pattern)) return true;
      std::this_thread::sleep_for(20ms);
    }
    return false;
  }

  std::string renderPlain(const std::vector<std::string>& args, const std::string& output) {
    const RunResult plain = run(std::vector<std::string>{"render"} + args +
                                std::vector<std::string>{"-o", output, "--quiet"});
    EXPECT_EQ(plain.status, 0) << plain.err;
    return readFile(work_ / output);
  }
};

TEST_F(Mpi, AnyRanksAndThreadsGiveThePlainRendersBytes) {
  const std::vector<std::string> crop{"--crop", "5,3,53,29"};
  const std::string whole = renderPlain(kShowcaseSmall, "plain.exr");
  const std::string cropped = renderPlain(kShowcaseSmall + crop, "plain-crop.exr");
  ASSERT_FALSE(whole.empty());
  for (const int ranks : {1, 2, 3, 4}) {
    for (const char* threads : {"1", "2"}) {
      const RunResult result = mpirun(
          ranks, kShowcaseSmall + std::vector<std::string>{"--threads", threads, "-o", "mpi.exr"});
      ASSERT_EQ(result.status, 0) << result.err;
      EXPECT_TRUE(readFile(work_ / "mpi.exr") == whole)
          << ranks << " ranks, " << threads << " threads";
      const RunResult part =
          mpirun(ranks, kShowcaseSmall + crop +
                            std::vector<std::string>{"--threads", threads, "-o", "mpi-crop.exr"});
      ASSERT_EQ(part.status, 0) << part.err;
      EXPECT_TRUE(readFile(work_ / "mpi-crop.exr") == cropped)
          << "crop, " << ranks << " ranks, " << threads << " threads";
    }
  }
}

TEST_F(Mpi, FixedSamplingAndTheGridMatchToo) {
  std::string scene = readFile(kScenes / "small.yaml");
  const std::string image = "  samples: 4\n";
  ASSERT_NE(scene.find(image), std::string::npos);
  scene.replace(scene.find(image), image.size(),
                image + "  grid: { interval: 5, color: [1, 1, 0] }\n");
  writeFile(work_ / "grid.yaml", scene);
  const std::string plain = renderPlain({"grid.yaml", "--threads", "2"}, "plain.png");
  const RunResult result = mpirun(3, {"grid.yaml", "--threads", "1", "-o", "mpi.png", "--stats"});
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_TRUE(readFile(work_ / "mpi.png") == plain);
  // Progress, summary and per-rank figures come from rank 0 only.
  EXPECT_TRUE(contains(result.err, "glint: wrote mpi.png")) << result.err;
  EXPECT_TRUE(contains(result.err, "glint: ranks: 3")) << result.err;
  EXPECT_TRUE(contains(result.err, "rank 2 on ")) << result.err;
  EXPECT_EQ(result.err.find("glint: wrote"), result.err.rfind("glint: wrote")) << result.err;
}

TEST_F(Mpi, ARankWithAnotherSceneOrOptionsIsRefused) {
  std::string scene = readFile(kScenes / "small.yaml");
  writeFile(work_ / "a.yaml", scene);
  scene.replace(scene.find("intensity: 1.2"), 14, "intensity: 1.3");
  writeFile(work_ / "b.yaml", scene);
  // mpirun's MPMD form: rank 0 runs the first command, rank 1 the second.
  RunResult result =
      runCommand(launcher(1) + glint({"a.yaml", "-o", "out.png"}) +
                 std::vector<std::string>{":", "-np", "1"} + glint({"b.yaml", "-o", "out.png"}));
  EXPECT_EQ(result.status, 2) << result.err;
  EXPECT_TRUE(std::regex_search(result.err, std::regex("rank 1 on [^ ]+ does not render what rank "
                                                       "0 on [^ ]+ renders: its scene file "
                                                       "'b.yaml'")))
      << result.err;
  EXPECT_FALSE(fs::exists(work_ / "out.png"));

  result = runCommand(launcher(2) + glint({"a.yaml", "-o", "out.png"}) +
                      std::vector<std::string>{":", "-np", "1"} +
                      glint({"a.yaml", "-o", "out.png", "--samples", "9"}));
  EXPECT_EQ(result.status, 2) << result.err;
  EXPECT_TRUE(contains(result.err, "rank 2 on ")) << result.err;
  EXPECT_TRUE(contains(result.err, "samples per pixel 9, rank 0's has 4")) << result.err;

  // With a preview, a refused job still exits at once (the preview stays only after a render).
  result = runCommand(launcher(1) + glint({"a.yaml", "-o", "out.png", "--preview", "0"}) +
                      std::vector<std::string>{":", "-np", "1"} +
                      glint({"a.yaml", "-o", "out.png", "--samples", "9"}));
  EXPECT_EQ(result.status, 2) << result.err;
  EXPECT_FALSE(contains(result.err, "the preview stays")) << result.err;
}

// The heavy scene small enough to render in seconds.
const std::vector<std::string> kHeavySmall{
    (kScenes / "heavy.yaml").string(), "--width", "200", "--height", "150", "--samples", "32"};
const std::vector<std::string> kOneThread{"--threads", "1"};

TEST_F(Mpi, AKilledRankFailsTheJobAndTheResumeRendersOnlyTheRest) {
  const std::vector<std::string> scene{
      (kScenes / "heavy.yaml").string(), "--width", "320", "--height", "240", "--samples", "32"};
  const std::string plain = renderPlain(scene, "plain.png");
  // When a rank dies, mpirun waits odls_base_sigkill_timeout, sends SIGTERM (rank 0 saves the
  // checkpoint), waits as long again and sends SIGKILL: 3 s is time enough to save on a busy
  // machine.
  const pid_t launcherPid =
      startCommand(launcher(3, 3) +
                   glint(scene + kOneThread +
                         std::vector<std::string>{"-o", "out.png", "--checkpoint", "run.ckpt"}));
  ASSERT_TRUE(awaitStderr(std::regex("glint: [1-9]0%"), 60s)) << stderrSoFar();
  const std::map<int, pid_t> ranks = ranksOf(launcherPid);
  ASSERT_EQ(ranks.count(1), 1u) << "the render ended before the kill: " << stderrSoFar();
  const auto killed = std::chrono::steady_clock::now();
  kill(ranks.at(1), SIGKILL);
  const RunResult failed = finish(launcherPid, 30s);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - killed).count();
  EXPECT_NE(failed.status, 0);
  EXPECT_LT(seconds, 15) << "mpirun took that long to end the job";
  EXPECT_EQ(filesIn(work_), (std::set<std::string>{"plain.png", "run.ckpt"})) << failed.err;

  const RunResult resumed =
      mpirun(2, scene + kOneThread +
                    std::vector<std::string>{"-o", "out.png", "--resume", "run.ckpt", "--stats"});
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_TRUE(readFile(work_ / "out.png") == plain);
  std::smatch counts;
  ASSERT_TRUE(std::regex_search(resumed.err, counts, std::regex("(\\d+) of (\\d+) tiles resumed")))
      << resumed.err;
  const int resumedTiles = std::stoi(counts[1]);
  const int totalTiles = std::stoi(counts[2]);
  EXPECT_GT(resumedTiles, 0);
  EXPECT_LT(resumedTiles, totalTiles);
  // The ranks rendered exactly the missing tiles between them.
  int rendered = 0;
  const std::regex rankLine("rank \\d+ on [^ ]+ \\(\\d+ threads?\\): (\\d+) tiles");
  for (std::sregex_iterator it(resumed.err.begin(), resumed.err.end(), rankLine), end; it != end;
       ++it)
    rendered += std::stoi((*it)[1]);
  EXPECT_EQ(rendered, totalTiles - resumedTiles) << resumed.err;
  EXPECT_EQ(filesIn(work_), (std::set<std::string>{"plain.png", "out.png"}));
}

TEST_F(Mpi, ThePreviewShowsWhichRankRenderedEachTile) {
  // Rank 0 serves the page; the tiles of both ranks reach it, each marked with its rank.
  const pid_t launcherPid = startCommand(
      launcher(2) + glint(kShowcaseSmall + std::vector<std::string>{"--threads", "1", "-o",
                                                                    "out.png", "--preview", "0"}));
  ASSERT_TRUE(awaitStderr(std::regex("glint: the preview stays at http://127\\.0\\.0\\.1:"), 120s))
      << stderrSoFar();
  std::smatch port;
  const std::string err = stderrSoFar();
  ASSERT_TRUE(std::regex_search(err, port, std::regex(R"(preview at http://127\.0\.0\.1:(\d+)/)")))
      << err;
  httplib::Client client("127.0.0.1", std::stoi(port[1]));
  std::string events;
  client.Get("/events", [&events](const char* data, std::size_t length) {
    events.append(data, length);
    return events.find("\"phase\":\"finished\"") == std::string::npos;
  });
  kill(launcherPid, SIGINT);  // ends serving
  finish(launcherPid, 30s);
  EXPECT_TRUE(contains(events, "\"rank\":0,")) << events.substr(0, 1000);
  EXPECT_TRUE(contains(events, "\"rank\":1,")) << events.substr(0, 1000);
}

TEST_F(Mpi, InterruptingMpirunSavesTheCheckpoint) {
  // Never rendered to the end: big enough to be interrupted halfway on a fast machine. Five
  // seconds for rank 0 to save the checkpoint on a busy one (fsync).
  const pid_t launcherPid =
      startCommand(launcher(2, 5) +
                   glint({(kScenes / "heavy.yaml").string(), "--width", "400", "--height", "300",
                          "--threads", "1", "-o", "out.png", "--checkpoint", "run.ckpt"}));
  ASSERT_TRUE(awaitStderr(std::regex("glint: [1-9]0%"), 60s)) << stderrSoFar();
  kill(launcherPid, SIGINT);
  const RunResult result = finish(launcherPid, 30s);
  EXPECT_NE(result.status, 0);
  EXPECT_TRUE(std::regex_search(result.err, std::regex("glint: interrupted; \\d+ of \\d+ tiles "
                                                       "saved to 'run.ckpt'")))
      << result.err;
  EXPECT_EQ(filesIn(work_), (std::set<std::string>{"run.ckpt"}));
}

// An error rank 0 finds before the render (here the output's folder is missing) ends the job
// without waiting for the other ranks to finish loading the scene: their loads are cancelled. The
// scene: 120 NFF star polygons of 4096 corners, whose ear clipping takes seconds.
TEST_F(Mpi, AnErrorOnRankZeroDoesNotWaitForTheOthersToLoad) {
  std::string nff =
      "v\nfrom 0 0 10\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 32 32\n"
      "b 0 0 0\nl 0 5 5\nf 1 1 1 0.5 0 0 0 1\n";
  for (int k = 0; k < 120; ++k) {
    nff += "p 4096\n";
    for (int i = 0; i < 4096; ++i) {
      const double angle = 2 * std::numbers::pi * i / 4096;
      const double radius = i % 2 == 0 ? 1 : 0.5;
      nff += fmt::format("{:.6f} {:.6f} {:.4f}\n", radius * std::cos(angle),
                         radius * std::sin(angle), -0.01 * k);
    }
  }
  writeFile(work_ / "stars.nff", nff);
  // How long one process takes to load it.
  auto start = std::chrono::steady_clock::now();
  const RunResult check = runCommand({kGlint.string(), "check", "stars.nff"});
  const auto load = std::chrono::steady_clock::now() - start;
  ASSERT_EQ(check.status, 0) << check.err;
  start = std::chrono::steady_clock::now();
  const RunResult result =
      runCommand(launcher(2) + glint({"stars.nff", "--threads", "1", "-o", "missing/out.png"}));
  const auto refused = std::chrono::steady_clock::now() - start;
  EXPECT_EQ(result.status, 2) << result.err;
  EXPECT_TRUE(contains(result.err, "the folder 'missing' does not exist")) << result.err;
  // Without the cancel it took the load and more (rank 0 waited in MPI_Finalize for rank 1).
  EXPECT_LT(refused, load) << "load " << std::chrono::duration<double>(load).count()
                           << " s, refused job " << std::chrono::duration<double>(refused).count()
                           << " s";
}

// A malformed GLINT_MPI_TIMEOUT is a bad request (exit 2), as a malformed GLINT_ISA is.
TEST_F(Mpi, AMalformedTimeoutIsABadRequest) {
  const RunResult result = finish(
      startCommand(launcher(2) + glint(kShowcaseSmall + std::vector<std::string>{"-o", "out.png"}),
                   {"GLINT_MPI_TIMEOUT=abc"}),
      60s);
  EXPECT_EQ(result.status, 2) << result.err;
  EXPECT_TRUE(contains(result.err, "GLINT_MPI_TIMEOUT must be a number of seconds > 0, got 'abc'"))
      << result.err;
  EXPECT_FALSE(fs::exists(work_ / "out.png"));
}

TEST_F(Mpi, ARankThatStopsAnsweringFailsTheJobAfterTheTimeout) {
  const pid_t launcherPid = startCommand(
      launcher(2) + glint(kHeavySmall + kOneThread + std::vector<std::string>{"-o", "out.png"}),
      {"GLINT_MPI_TIMEOUT=2"});
  ASSERT_TRUE(awaitStderr(std::regex("glint: [1-9]0%"), 60s)) << stderrSoFar();
  const std::map<int, pid_t> ranks = ranksOf(launcherPid);
  ASSERT_EQ(ranks.count(0), 1u);
  ASSERT_EQ(ranks.count(1), 1u);
  kill(ranks.at(1), SIGSTOP);
  // Rank 0 gives up on it after 2 s and exits 1; mpirun then ends the job.
  EXPECT_TRUE(awaitStderr(std::regex("rank 1 on [^ ]+ sent nothing for 2 s"), 10s))
      << stderrSoFar();
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (ranksOf(launcherPid).count(0) > 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(20ms);
  EXPECT_EQ(ranksOf(launcherPid).count(0), 0u) << "rank 0 did not exit";
  // mpirun's SIGTERM waits in the stopped rank until it runs again (OpenMPI does not SIGKILL it).
  kill(ranks.at(1), SIGCONT);
  const RunResult result = finish(launcherPid, 30s);
  EXPECT_NE(result.status, 0);
  EXPECT_FALSE(fs::exists(work_ / "out.png"));
}

}  // namespace
}  // namespace glint_cli_test

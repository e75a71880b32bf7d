// The harness of the command-line tests: runs the built `glint` binary in a fresh folder, with
// stdout and stderr captured, time limits, signals, and readers for the images it writes. Shared
// by tests/cli_test.cpp and tests/cli_job_test.cpp.
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/ioctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "sanitizer.h"

namespace glint_cli_test {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

inline const fs::path kGlint = fs::path(GLINT_BINARY_DIR) / "glint";
inline const fs::path kScenes = fs::path(GLINT_SOURCE_DIR) / "tests" / "cli";
inline const fs::path kBroken = kScenes / "broken";

// An exit status, or kKilledBy + signal when the process did not exit by itself (a crash, or a
// signal it did not handle), so that "exited with 130" and "died of SIGINT" stay distinguishable.
constexpr int kKilledBy = 1000;

inline int decodeStatus(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return kKilledBy + WTERMSIG(status);
  return -1;
}

inline std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void writeFile(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

inline std::set<std::string> filesIn(const fs::path& folder) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder)) names.insert(entry.path().filename());
  return names;
}

inline bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

struct RunResult {
  int status = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

// Child side of a run: cwd `work`, stdin /dev/null, stdout/stderr to the given descriptors.
[[noreturn]] inline void execGlint(const std::vector<std::string>& args, const fs::path& work,
                                   int outFd, int errFd, std::uint64_t addressSpaceLimit = 0) {
  std::vector<char*> argv;
  std::string program = kGlint.string();
  argv.push_back(program.data());
  std::vector<std::string> copies = args;
  for (std::string& arg : copies) argv.push_back(arg.data());
  argv.push_back(nullptr);
  const int in = open("/dev/null", O_RDONLY);
  // A memory cap (bytes of address space) turns a runaway allocation into a quick failure. Not
  // under the address sanitizer, whose shadow memory alone needs more address space than any cap.
  if (addressSpaceLimit > 0 && !kAddressSanitizer) {
    const rlimit limit{addressSpaceLimit, addressSpaceLimit};
    if (setrlimit(RLIMIT_AS, &limit) != 0) _exit(127);
  }
  if (in < 0 || dup2(in, STDIN_FILENO) < 0 || dup2(outFd, STDOUT_FILENO) < 0 ||
      dup2(errFd, STDERR_FILENO) < 0 || chdir(work.c_str()) != 0)
    _exit(127);
  execv(argv[0], argv.data());
  _exit(127);
}

// Polls waitpid until the child ends; kills it after `timeout` (then the status is the kill).
inline int waitFor(pid_t pid, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      ADD_FAILURE() << "glint did not finish within " << timeout.count() << " ms";
      return -1;
    }
    std::this_thread::sleep_for(5ms);
  }
  return decodeStatus(status);
}

// Whether `pid` has a handler installed for `signal` (the SigCgt mask of /proc/PID/status).
inline bool catchesSignal(pid_t pid, int signal) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("SigCgt:", 0) == 0) {
      const std::uint64_t mask = std::stoull(line.substr(7), nullptr, 16);
      return (mask >> (signal - 1)) & 1;
    }
  }
  return false;
}

// Reads an 8-bit binary PPM (P6): width, height and the RGB bytes.
struct Ppm {
  int width = 0, height = 0;
  std::string rgb;
};

inline Ppm readPpm(const fs::path& path) {
  const std::string bytes = readFile(path);
  std::size_t pos = 0;
  auto token = [&]() {
    while (pos < bytes.size()) {
      if (bytes[pos] == '#') {
        while (pos < bytes.size() && bytes[pos] != '\n') ++pos;
      } else if (std::isspace(static_cast<unsigned char>(bytes[pos]))) {
        ++pos;
      } else {
        break;
      }
    }
    const std::size_t start = pos;
    while (pos < bytes.size() && !std::isspace(static_cast<unsigned char>(bytes[pos]))) ++pos;
    return bytes.substr(start, pos - start);
  };
  Ppm ppm;
  if (token() != "P6") return ppm;
  ppm.width = std::stoi(token());
  ppm.height = std::stoi(token());
  if (token() != "255") return {};
  ++pos;  // the single whitespace byte before the raster
  ppm.rgb = bytes.substr(pos);
  return ppm;
}

// Width and height from a PNG's IHDR chunk (bytes 16–23, big-endian), after checking the signature.
inline std::optional<std::pair<std::uint32_t, std::uint32_t>> pngSize(const fs::path& path) {
  const std::string bytes = readFile(path);
  static const std::string kSignature("\x89PNG\r\n\x1a\n", 8);
  if (bytes.size() < 24 || bytes.compare(0, 8, kSignature) != 0 || bytes.compare(12, 4, "IHDR"))
    return std::nullopt;
  auto be32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(bytes[at + i]);
    return v;
  };
  return std::make_pair(be32(16), be32(20));
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "glint-cli-XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    root_ = pattern;
    work_ = root_ / "work";
    fs::create_directory(work_);
    fs::create_directory(root_ / "capture");
    ASSERT_TRUE(fs::exists(kGlint)) << "build the glint_cli target first: " << kGlint;
  }
  void TearDown() override {
    if (running_ > 0) {
      kill(running_, SIGKILL);
      waitpid(running_, nullptr, 0);
    }
    std::error_code ignored;
    fs::remove_all(root_, ignored);
  }

  // Runs glint to the end in the work folder (with at most `addressSpaceLimit` bytes of address
  // space when not 0).
  RunResult run(const std::vector<std::string>& args, std::chrono::milliseconds timeout = 60s,
                std::uint64_t addressSpaceLimit = 0) {
    const fs::path outPath = root_ / "capture" / "stdout";
    const fs::path errPath = root_ / "capture" / "stderr";
    const int outFd = open(outPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int errFd = open(errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    RunResult result;
    const pid_t pid = fork();
    if (pid == 0) execGlint(args, work_, outFd, errFd, addressSpaceLimit);
    close(outFd);
    close(errFd);
    if (pid < 0) {
      ADD_FAILURE() << "fork failed";
      return result;
    }
    result.status = waitFor(pid, timeout);
    result.out = readFile(outPath);
    result.err = readFile(errPath);
    return result;
  }

  // Starts glint in the background (stdout/stderr captured to files); see finish().
  pid_t start(const std::vector<std::string>& args) {
    const int outFd =
        open((root_ / "capture" / "stdout").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int errFd =
        open((root_ / "capture" / "stderr").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const pid_t pid = fork();
    if (pid == 0) execGlint(args, work_, outFd, errFd);
    close(outFd);
    close(errFd);
    running_ = pid;
    return pid;
  }

  RunResult finish(pid_t pid, std::chrono::milliseconds timeout) {
    RunResult result;
    result.status = waitFor(pid, timeout);
    running_ = 0;
    result.out = readFile(root_ / "capture" / "stdout");
    result.err = readFile(root_ / "capture" / "stderr");
    return result;
  }

  // Starts the heavy render, waits until it handles `signal`, lets it render a moment, sends it.
  RunResult interruptHeavyRender(int signal, const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args{"render", (kScenes / "heavy.yaml").string(), "-o", "out.png"};
    args.insert(args.end(), extra.begin(), extra.end());
    const pid_t pid = start(args);
    const auto deadline = std::chrono::steady_clock::now() + 20s;
    while (!catchesSignal(pid, signal) && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(2ms);
    EXPECT_TRUE(catchesSignal(pid, signal)) << "glint never installed its signal handler";
    std::this_thread::sleep_for(300ms);
    kill(pid, signal);
    return finish(pid, 30s);
  }

  // Runs glint with stderr on a pseudo-terminal `columns` wide (0: the pty's default); returns its
  // status and everything it wrote to the terminal.
  RunResult runOnTerminal(const std::vector<std::string>& args, unsigned short columns = 0) {
    RunResult result;
    const int master = posix_openpt(O_RDWR | O_NOCTTY);
    EXPECT_GE(master, 0);
    if (master < 0) return result;
    EXPECT_EQ(grantpt(master), 0);
    EXPECT_EQ(unlockpt(master), 0);
    const std::string slaveName = ptsname(master);
    const int slave = open(slaveName.c_str(), O_RDWR | O_NOCTTY);
    EXPECT_GE(slave, 0);
    // Raw mode: the terminal must not turn "\n" into "\r\n", so every '\r' seen is glint's own.
    termios mode{};
    EXPECT_EQ(tcgetattr(slave, &mode), 0);
    cfmakeraw(&mode);
    EXPECT_EQ(tcsetattr(slave, TCSANOW, &mode), 0);
    if (columns != 0) {
      winsize size{};
      size.ws_row = 24;
      size.ws_col = columns;
      EXPECT_EQ(ioctl(slave, TIOCSWINSZ, &size), 0);
    }
    const int outFd =
        open((root_ / "capture" / "stdout").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const pid_t pid = fork();
    if (pid == 0) {
      close(master);
      execGlint(args, work_, outFd, slave);
    }
    close(slave);
    close(outFd);
    // Drain the terminal while glint runs, so it never blocks on a full pty buffer.
    const auto deadline = std::chrono::steady_clock::now() + 60s;
    for (bool exited = false;;) {
      pollfd fd{master, POLLIN, 0};
      if (poll(&fd, 1, 20) > 0) {
        char buffer[4096];
        const ssize_t n = read(master, buffer, sizeof buffer);
        if (n > 0) {
          result.err.append(buffer, static_cast<std::size_t>(n));
          continue;
        }
      }
      if (exited) break;
      int raw = 0;
      if (waitpid(pid, &raw, WNOHANG) == pid) {
        result.status = decodeStatus(raw);
        exited = true;  // one more pass drains what is left
      } else if (std::chrono::steady_clock::now() > deadline) {
        kill(pid, SIGKILL);
        waitpid(pid, nullptr, 0);
        break;
      }
    }
    close(master);
    return result;
  }

  std::string small() const { return (kScenes / "small.yaml").string(); }

  fs::path root_;
  fs::path work_;
  pid_t running_ = 0;
};

}  // namespace glint_cli_test

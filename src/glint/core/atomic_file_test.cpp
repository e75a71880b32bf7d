#include "glint/core/atomic_file.h"

#include <gtest/gtest.h>
#include <stdio_ext.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <climits>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <system_error>

namespace glint {
namespace {

namespace fs = std::filesystem;

class AtomicFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "glint-atomic-XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    folder_ = pattern;
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(folder_, ignored);
  }
  std::set<std::string> files() const {
    std::set<std::string> names;
    for (const auto& entry : fs::directory_iterator(folder_)) names.insert(entry.path().filename());
    return names;
  }
  static std::string read(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  fs::path folder_;
};

// The PID of a process that has ended (and was reaped), so no process has it for now.
pid_t deadPid() {
  const pid_t child = fork();
  if (child == 0) _exit(0);
  waitpid(child, nullptr, 0);
  return child;
}

// This host's tag, read from a temporary file's name.
std::string hostTagOfThisHost(const fs::path& folder) {
  AtomicFile probe(folder / "probe");
  const std::string name = probe.temporaryPath().filename();
  return name.substr(kTemporaryFilePrefix.size(), 8);
}

TEST_F(AtomicFileTest, CommitReplacesTheTargetAndLeavesNothingElse) {
  std::ofstream(folder_ / "out.bin") << "old";
  AtomicFile file(folder_ / "out.bin");
  const std::string name = file.temporaryPath().filename();
  EXPECT_TRUE(isTemporaryFileName(name)) << name;
  EXPECT_EQ(name.front(), '.') << "hidden while it exists";
  file.write("new bytes");
  EXPECT_EQ(read(folder_ / "out.bin"), "old") << "the target is untouched until the commit";
  file.commit();
  EXPECT_EQ(read(folder_ / "out.bin"), "new bytes");
  EXPECT_EQ(files(), std::set<std::string>{"out.bin"});
}

// Images go through stream() in 256 KiB writes: nothing reaches the file until the buffer is full
// or the stream is flushed (glibc's setvbuf without a buffer of our own would keep 4 KiB).
TEST_F(AtomicFileTest, TheStreamWritesInQuarterMebibyteBlocks) {
  AtomicFile file(folder_ / "out.bin");
  std::FILE* stream = file.stream();
  EXPECT_EQ(__fbufsize(stream), std::size_t{1} << 18);
  const std::string block(100'000, 'x');
  ASSERT_EQ(std::fwrite(block.data(), 1, block.size(), stream), block.size());
  EXPECT_EQ(std::filesystem::file_size(file.temporaryPath()), 0u) << "still in the buffer";
  ASSERT_EQ(std::fwrite(block.data(), 1, block.size(), stream), block.size());
  ASSERT_EQ(std::fwrite(block.data(), 1, block.size(), stream), block.size());
  EXPECT_EQ(std::filesystem::file_size(file.temporaryPath()), std::size_t{1} << 18)
      << "one full buffer written";
  file.commit();
  EXPECT_EQ(std::filesystem::file_size(folder_ / "out.bin"), 300'000u);
}

TEST_F(AtomicFileTest, AnUncommittedFileIsRemoved) {
  {
    AtomicFile file(folder_ / "out.bin");
    file.write("half");
    EXPECT_EQ(files().size(), 1u);
  }
  EXPECT_TRUE(files().empty());
}

// A target name of NAME_MAX bytes is legal; its temporary file must be too.
TEST_F(AtomicFileTest, TheLongestLegalTargetNameGetsATemporaryFile) {
  const std::string longest(NAME_MAX - 4, 'n');
  const fs::path target = folder_ / (longest + ".png");
  AtomicFile file(target);
  EXPECT_LE(file.temporaryPath().filename().string().size(), 38u);
  std::fputs("image", file.stream());
  file.commit();
  EXPECT_EQ(read(target), "image");
}

TEST_F(AtomicFileTest, OnlyTemporaryFilesOfDeadProcessesOnThisHostAreRemoved) {
  const std::string host = hostTagOfThisHost(folder_);
  const std::string prefix(kTemporaryFilePrefix);
  const std::string dead = prefix + host + "-" + std::to_string(deadPid()) + "-abc123";
  const std::string alive = prefix + host + "-" + std::to_string(getppid()) + "-abc123";
  const std::string mine = prefix + host + "-" + std::to_string(getpid()) + "-abc123";
  const std::string otherHost = prefix + (host == "00000000" ? "11111111" : "00000000") + "-" +
                                std::to_string(deadPid()) + "-abc123";
  const std::string lookalikes[] = {prefix + host + "-12x-abc123", prefix + "notahost-1-abc123",
                                    ".out.png.tmp-1-0", "image.png"};
  for (const std::string& name : {dead, alive, mine, otherHost}) std::ofstream(folder_ / name);
  for (const std::string& name : lookalikes) std::ofstream(folder_ / name);
  // A link carrying a dead process's name is not followed or removed.
  const std::string link = prefix + host + "-" + std::to_string(deadPid()) + "-lnk000";
  fs::create_symlink(folder_ / "image.png", folder_ / link);

  EXPECT_EQ(removeStaleTemporaryFiles(folder_), 1u);
  std::set<std::string> expected{alive, mine, otherHost, link};
  expected.insert(std::begin(lookalikes), std::end(lookalikes));
  EXPECT_EQ(files(), expected);
  EXPECT_EQ(removeStaleTemporaryFiles(folder_ / "missing"), 0u);
}

TEST_F(AtomicFileTest, FailuresCarryErrno) {
  try {
    AtomicFile file(folder_ / "missing" / "out.bin");
    FAIL() << "expected std::system_error";
  } catch (const std::system_error& error) {
    EXPECT_EQ(error.code().value(), ENOENT);
  }
}

}  // namespace
}  // namespace glint

#include "glint/mesh/import_child.h"

#include <fcntl.h>
#include <malloc.h>
#include <poll.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "glint/core/cancel.h"
#include "glint/core/file_access.h"
#include "glint/core/helper_files.h"
#include "glint/core/huge_pages.h"
#include "glint/mesh/mesh_reader_wire.h"

namespace glint {

namespace {

// Fuzzing found memory corruption in assimp 5.2's importers (heap overflows in the glTF 2.0 and
// PLY readers, a crash in OFF's) that no check before the import can rule out: the child process
// runs assimp and sends the MeshFile back through a pipe; a crash or corruption there is a refused
// file, never a crashed or corrupted renderer. The parent checks what it receives (sizes, indices,
// materials) before using it.

static_assert(std::is_trivially_copyable_v<Material> && std::is_trivially_copyable_v<Color> &&
              std::is_trivially_copyable_v<Point3> && std::is_trivially_copyable_v<Normal3> &&
              std::is_trivially_copyable_v<Point2>);

// Largest embedded image the answer may carry, and most of them: far beyond any real model, small
// enough that a corrupt answer cannot make the parent allocate without end.
constexpr std::uint64_t kMaxEmbeddedImageBytes = std::uint64_t{1} << 30;
constexpr std::uint64_t kMaxEmbeddedImages = 1 << 16;

// While waiting for the child, the parent looks at the cancel flag this often (milliseconds): a
// cancelled load stops within about this time plus the kill of the child.
constexpr int kCancelPollMilliseconds = 20;

// The test hook's delay of the child (setImportChildDelayForTesting), in milliseconds.
std::atomic<std::int64_t> gChildDelayMilliseconds{0};
// The test hook's time limit of the child (setMeshReadTimeLimitForTesting), in milliseconds; 0:
// meshReadTimeLimit's rule.
std::atomic<std::int64_t> gReadLimitMilliseconds{0};

// Reads the child's answer, waiting at most until `deadline` for it: a reader that loops (as
// assimp's importers have on malformed files) must not hang glint. While waiting and between
// reads it polls `cancel` and throws Cancelled when it is set.
class Reader {
 public:
  Reader(int fd, std::chrono::steady_clock::time_point deadline, const std::atomic<bool>* cancel)
      : fd_(fd), cancel_(cancel), deadline_(deadline) {}
  // Reads, from its start, a file the child has finished writing: nothing to wait for.
  Reader(int file, const std::atomic<bool>* cancel) : fd_(file), file_(true), cancel_(cancel) {}
  bool timedOut() const { return timedOut_; }
  const std::atomic<bool>* cancel() const { return cancel_; }
  void bytes(void* data, std::size_t size) {
    char* p = static_cast<char*>(data);
    while (file_ && size > 0) {
      throwIfCancelled(cancel_);
      const ssize_t n = ::pread(fd_, p, size, offset_);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) throw MeshLoadError("invalid file: the mesh reader stopped before its answer");
      p += n;
      offset_ += n;
      size -= static_cast<std::size_t>(n);
    }
    while (size > 0) {
      throwIfCancelled(cancel_);
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline_ - std::chrono::steady_clock::now());
      if (left.count() <= 0) {
        timedOut_ = true;
        throw MeshLoadError("invalid file: the mesh library did not finish reading it within " +
                            formatSeconds(deadline_ - started_));
      }
      pollfd ready{fd_, POLLIN, 0};
      // Without a cancel flag there is nothing to look at until the deadline.
      const std::int64_t wait = std::min<std::int64_t>(
          left.count(), cancel_ != nullptr ? kCancelPollMilliseconds : std::int64_t{1} << 30);
      const int polled = ::poll(&ready, 1, static_cast<int>(wait));
      if ((polled < 0 && errno == EINTR) || polled == 0) continue;
      const ssize_t n = ::read(fd_, p, size);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) throw MeshLoadError("invalid file: the mesh reader stopped before its answer");
      p += n;
      size -= static_cast<std::size_t>(n);
    }
  }
  template <typename T>
  T value() {
    T v{};
    bytes(&v, sizeof v);
    return v;
  }
  std::uint64_t count(std::uint64_t limit) {
    const auto n = value<std::uint64_t>();
    if (n > limit) throw MeshLoadError("invalid file: the mesh reader's answer is inconsistent");
    return n;
  }
  template <typename T>
  void vector(std::vector<T>& out, std::uint64_t limit) {
    const auto n = static_cast<std::size_t>(count(limit));
    // Reserved on huge pages before anything touches it: filling tens of megabytes a 4 KiB page
    // fault at a time cost more than the child's whole import of a 1M-triangle OBJ here (the
    // reader itself runs with glibc.malloc.hugetlb, meshReaderEnvironment; this process's malloc
    // is the user's).
    reserveOnHugePages(out, n);
    out.resize(n);
    bytes(out.data(), out.size() * sizeof(T));
  }
  std::string text() {
    std::string t(static_cast<std::size_t>(count(1 << 20)), '\0');
    bytes(t.data(), t.size());
    return t;
  }

 private:
  static std::string formatSeconds(std::chrono::steady_clock::duration d) {
    return fmt::format("{:.0f} s", std::chrono::duration<double>(d).count());
  }
  int fd_;
  bool file_ = false;
  const std::atomic<bool>* cancel_;
  off_t offset_ = 0;  // in a file
  std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point deadline_;
  bool timedOut_ = false;
};

MeshFile receiveMeshFile(Reader& in) {
  const char tag = in.value<char>();
  if (tag == 'E') throw MeshLoadError(in.text());
  if (tag != 'M') throw MeshLoadError("invalid file: the mesh reader's answer is inconsistent");
  MeshFile file;
  file.droppedTriangles = static_cast<std::size_t>(in.value<std::uint64_t>());
  file.importerDroppedFaces = in.value<std::uint64_t>() != 0;
  file.exactPositionNormalParts = static_cast<std::size_t>(in.value<std::uint64_t>());
  file.crowdedNormalPositions = static_cast<std::size_t>(in.value<std::uint64_t>());
  file.ignoredTextures.resize(static_cast<std::size_t>(in.count(kMaxIgnoredTextures)));
  for (std::string& ignored : file.ignoredTextures) {
    if (in.value<char>() != 'I') {
      throw MeshLoadError("invalid file: the mesh reader's answer is inconsistent");
    }
    ignored = in.text();
  }
  file.missingMaterialLibraries.resize(static_cast<std::size_t>(in.count(kMaxIgnoredTextures)));
  for (std::string& library : file.missingMaterialLibraries) {
    if (in.value<char>() != 'L') {
      throw MeshLoadError("invalid file: the mesh reader's answer is inconsistent");
    }
    library = in.text();
  }
  if (in.value<char>() != 'F') {
    throw MeshLoadError("invalid file: the mesh reader's answer is inconsistent");
  }
  file.fallbackMaterialLibrary = in.text();
  file.materials.resize(static_cast<std::size_t>(in.count(1 << 20)));
  for (MeshMaterial& m : file.materials) {
    if (in.value<char>() != 'N') {
      throw MeshLoadError("invalid file: the mesh reader's answer is inconsistent");
    }
    m.name = in.text();
    m.material = in.value<Material>();
    m.emission = in.value<Color>();
    m.fromFile = in.value<char>() != 0;
    // Texture bindings are the renderer's; none crosses from the child.
    m.material.textures = kUntextured;
    for (MeshTexture& t : m.textures) {
      if (in.value<char>() != 'T') {
        throw MeshLoadError("invalid file: the mesh reader's answer is inconsistent");
      }
      t.file = in.text();
      t.embedded = in.value<std::int32_t>();
    }
  }
  file.embeddedImages.resize(static_cast<std::size_t>(in.count(kMaxEmbeddedImages)));
  for (std::vector<std::uint8_t>& image : file.embeddedImages) {
    in.vector(image, kMaxEmbeddedImageBytes);
  }
  for (const MeshMaterial& m : file.materials) {
    for (const MeshTexture& t : m.textures) {
      if (t.embedded < -1 ||
          (t.embedded >= 0 && static_cast<std::size_t>(t.embedded) >= file.embeddedImages.size())) {
        throw MeshLoadError("invalid file: the mesh reader's answer is inconsistent");
      }
    }
  }
  file.parts.resize(static_cast<std::size_t>(in.count(1 << 20)));
  std::uint64_t triangles = 0;
  for (TriangleMesh& part : file.parts) {
    part.materialIndex = in.value<std::uint32_t>();
    part.emission = in.value<Color>();
    in.vector(part.positions, std::uint64_t{1} << 32);
    in.vector(part.normals, part.positions.size());
    in.vector(part.indices, 3 * kMaxMeshTriangles);
    in.vector(part.uvs, part.positions.size());
    triangles += part.triangleCount();
    bool ok = part.materialIndex < file.materials.size() && part.indices.size() % 3 == 0 &&
              (part.normals.empty() || part.normals.size() == part.positions.size()) &&
              (part.uvs.empty() || part.uvs.size() == part.positions.size()) &&
              triangles <= kMaxMeshTriangles;
    // In blocks, polling the cancel flag between them: a mesh may hold hundreds of millions.
    constexpr std::size_t kBlock = std::size_t{1} << 20;
    for (std::size_t begin = 0; ok && begin < part.indices.size(); begin += kBlock) {
      throwIfCancelled(in.cancel());
      const std::size_t end = std::min(part.indices.size(), begin + kBlock);
      for (std::size_t k = begin; k < end; ++k) ok = ok && part.indices[k] < part.positions.size();
    }
    if (!ok) throw MeshLoadError("invalid file: the mesh reader's answer is inconsistent");
  }
  return file;
}

// How long the child may take: kMeshReadBaseSeconds plus kMeshReadSecondsPerMiB per MiB of the
// file — assimp reads a 85 MB OBJ in ~2.5 s here, so the limit only ends a reader that loops.
std::chrono::steady_clock::duration meshReadTimeLimit(const std::filesystem::path& path) {
  if (const std::int64_t forced = gReadLimitMilliseconds.load(); forced > 0) {
    return std::chrono::milliseconds(forced);
  }
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  const double mib = error ? 0 : static_cast<double>(size) / (1024.0 * 1024.0);
  // At most a day: the limit is added to steady_clock::now(), whose nanosecond count a (sparse)
  // file of petabytes would otherwise carry past 2^63.
  constexpr double kMostSeconds = 24 * 3600;
  const double seconds =
      std::min(kMeshReadBaseSeconds + kMeshReadSecondsPerMiB * mib, kMostSeconds);
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(seconds));
}

}  // namespace

void setImportChildDelayForTesting(std::chrono::milliseconds delay) {
  gChildDelayMilliseconds.store(delay.count());
}

void setMeshReadTimeLimitForTesting(std::chrono::milliseconds limit) {
  gReadLimitMilliseconds.store(limit.count());
}

namespace {

// What the parent and the mesh reader program must agree on: the answer's layout (Material and
// the other records cross as raw bytes) is that of one build, so a reader from another glint
// version is refused.

// The mesh reader program (core/helper_files.h): GLINT_MESH_READER when set, beside the running
// program, ../libexec/glint from it, the build tree's (for programs of that build), the installed
// and the packaged libexec folders.
std::filesystem::path findMeshReader() {
  return findHelperFile(kMeshReaderProgram, "GLINT_MESH_READER", GLINT_HELPER_PATHS, true);
}

// Found once per process.
const std::filesystem::path& meshReader() {
  static const std::filesystem::path found = findMeshReader();
  return found;
}

// The mesh reader's environment: glint's, with glibc's malloc told to back its large blocks with
// transparent huge pages (GLIBC_TUNABLES glibc.malloc.hugetlb=1, where the system leaves huge
// pages to madvise): the reader fills fresh memory of tens of megabytes (the parsed file, the
// joined mesh, its answer), and a page fault per 4 KiB was ~40 % of parsing a 1M-triangle OBJ on
// a virtual machine; per 2 MiB it is noise. A tunable the user set is kept (theirs comes last and
// wins); glibc without the tunable ignores it.
std::vector<std::string> meshReaderEnvironment() {
  constexpr std::string_view kTunables = "GLIBC_TUNABLES=";
  std::vector<std::string> environment;
  std::string tunables = "glibc.malloc.hugetlb=1";
  for (char** e = environ; e != nullptr && *e != nullptr; ++e) {
    const std::string_view entry(*e);
    if (entry.substr(0, kTunables.size()) == kTunables) {
      if (entry.size() > kTunables.size()) {
        tunables += ":" + std::string(entry.substr(kTunables.size()));
      }
    } else {
      environment.emplace_back(entry);
    }
  }
  environment.push_back(std::string(kTunables) + tunables);
  return environment;
}

// Makes `fd` survive execve (every descriptor glint opens is close-on-exec). Async-signal-safe.
bool keepAcrossExec(int fd) { return fd < 0 || ::fcntl(fd, F_SETFD, 0) == 0; }

}  // namespace

MeshFile importMeshInChild(const std::filesystem::path& path, const std::string& extension,
                           const std::filesystem::path& sceneFolder,
                           const std::atomic<bool>* cancel) {
  const std::filesystem::path& reader = meshReader();
  if (reader.empty()) {
    throw MeshLoadError(fmt::format(
        "cannot start the mesh reader: {} was not found beside this program, in ../libexec/glint "
        "from it, or where glint was built or installed (set GLINT_MESH_READER to its path)",
        kMeshReaderProgram));
  }
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw MeshLoadError(systemReason(errno));
  // The answer travels in a memory file when it can: the child writes it whole without waiting for
  // a reader and says 'D' on the pipe; the parent then reads it in a few large reads. Through the
  // pipe alone, 64 KiB at a time with the two processes taking turns, the 3.6 MB answer of a
  // 100k-triangle mesh took 8-18 ms on a busy 2-core machine; through the memory file, 6-9 ms.
  // When there is no memory file (memfd_create refused) or writing it fails (no memory, a file
  // size limit), the child says 'P' and the answer follows on the pipe.
  const int answer = ::memfd_create("glint-mesh-answer", MFD_CLOEXEC);
  // The child's arguments, made before the fork: between fork and execve the child may only make
  // async-signal-safe calls (no allocation).
  const std::vector<std::string> arguments = {reader.string(),
                                              wire::kMeshReaderProtocol,
                                              std::to_string(fds[1]),
                                              std::to_string(answer),
                                              std::to_string(gChildDelayMilliseconds.load()),
                                              extension,
                                              sceneFolder.string(),
                                              path.string()};
  std::vector<char*> argv;
  for (const std::string& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const std::vector<std::string> environment = meshReaderEnvironment();
  std::vector<char*> envp;
  for (const std::string& e : environment) envp.push_back(const_cast<char*>(e.c_str()));
  envp.push_back(nullptr);
  const pid_t parent = ::getpid();
  // fork + execve of a fresh program, not a forked copy that imports: a copy of a multithreaded
  // glint inherits every lock another thread held at the fork, and waits for it forever if it
  // needs it (seen with AddressSanitizer's allocator while a test's watchdog thread started, and
  // with OpenMPI's threads in a rank). The new program inherits no lock.
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int error = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    if (answer >= 0) ::close(answer);
    throw MeshLoadError("cannot start the mesh reader: " + systemReason(error));
  }
  if (pid == 0) {
    // The child until execve: async-signal-safe calls only. It dies with glint (killed or
    // interrupted while loading), never left looping on its own; the death signal survives
    // execve.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(0);  // the parent was already gone
    // Ctrl-C reaches the whole process group, the child too. Its fate is the parent's: a parent
    // that handles the signal cancels the load and kills the child, one that dies of it takes the
    // child along (PR_SET_PDEATHSIG); the child dying of it on its own would read as a crash. An
    // ignored signal stays ignored across execve. A write past a file size limit fails instead
    // of killing the child.
    struct sigaction ignore {};
    ignore.sa_handler = SIG_IGN;
    for (const int stop : {SIGINT, SIGTERM, SIGHUP, SIGXFSZ}) ::sigaction(stop, &ignore, nullptr);
    if (keepAcrossExec(fds[1]) && keepAcrossExec(answer)) {
      ::execve(argv[0], argv.data(), envp.data());
    }
    const int error = errno;
    static_cast<void>(wire::writeValue(fds[1], 'X') && wire::writeValue(fds[1], error));
    ::_exit(127);
  }
  ::close(fds[1]);
  std::optional<MeshFile> file;
  std::string failure;
  bool cancelled = false;
  Reader in(fds[0], std::chrono::steady_clock::now() + meshReadTimeLimit(path), cancel);
  try {
    const char where = in.value<char>();
    if (where == 'X') {
      failure = fmt::format("cannot start the mesh reader {}: {}", reader.string(),
                            systemReason(in.value<int>()));
    } else if (where == 'D' && answer >= 0) {
      Reader written(answer, cancel);
      file = receiveMeshFile(written);
    } else if (where == 'P') {
      file = receiveMeshFile(in);
    } else {
      throw MeshLoadError("invalid file: the mesh reader's answer is inconsistent");
    }
  } catch (const MeshLoadError& e) {
    failure = e.what();
  } catch (const std::bad_alloc&) {
    failure = "not enough memory to load it";
  } catch (const Cancelled&) {
    cancelled = true;
  }
  ::close(fds[0]);  // a child still writing gets EPIPE and ends
  if (answer >= 0) ::close(answer);
  if (in.timedOut() || cancelled) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (cancelled) throw Cancelled();
  if (in.timedOut()) throw MeshLoadError(failure);
  // SIGPIPE: the child was still writing when the parent stopped reading an inconsistent answer.
  if (WIFSIGNALED(status) && WTERMSIG(status) != SIGPIPE) {
    throw MeshLoadError(fmt::format(
        "invalid file: the mesh library crashed reading it ({}; glint read it in a separate "
        "process and is unaffected)",
        strsignal(WTERMSIG(status))));
  }
  if (!file) throw MeshLoadError(failure);
  return std::move(*file);
}

}  // namespace glint

#include "glint/core/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstdint>
#include <limits>
#include <system_error>
#include <utility>

namespace glint {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void throwErrno(int error) { throw std::system_error(error, std::generic_category()); }

// 32-bit FNV-1a: a fixed function, so that every glint version tags a host the same way.
std::uint32_t fnv1a32(std::string_view bytes) {
  std::uint32_t hash = 2166136261u;
  for (const char c : bytes) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 16777619u;
  }
  return hash;
}

// Eight hex digits naming this host in temporary file names.
const std::string& hostTag() {
  static const std::string tag = [] {
    std::array<char, 256> name{};
    if (::gethostname(name.data(), name.size() - 1) != 0) name[0] = '\0';
    const std::uint32_t hash = fnv1a32(std::string_view(name.data()));
    std::string hex(8, '0');
    for (int i = 7; i >= 0; --i) {
      hex[static_cast<std::size_t>(i)] = "0123456789abcdef"[(hash >> (4 * (7 - i))) & 0xf];
    }
    return hex;
  }();
  return tag;
}

constexpr std::size_t kRandomCharacters = 6;

// Six characters from [0-9a-z]; O_EXCL catches the rare collision, so they need only differ
// between attempts and processes, not be unpredictable.
std::string randomSuffix() {
  static std::atomic<std::uint64_t> counter{0};
  std::uint64_t x =
      static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count()) ^
      (counter.fetch_add(1) * 0x9e3779b97f4a7c15ull) ^
      (static_cast<std::uint64_t>(::getpid()) << 32);
  // splitmix64 finaliser: every input bit moves every output character.
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  x ^= x >> 31;
  std::string suffix(kRandomCharacters, '0');
  for (char& c : suffix) {
    c = "0123456789abcdefghijklmnopqrstuvwxyz"[x % 36];
    x /= 36;
  }
  return suffix;
}

// The parts of a temporary file name, or false when `name` is not one.
bool parseTemporaryName(std::string_view name, std::string_view& host, pid_t& pid) {
  if (!name.starts_with(kTemporaryFilePrefix)) return false;
  name.remove_prefix(kTemporaryFilePrefix.size());
  if (name.size() < 8 + 1 + 1 + 1 + kRandomCharacters || name[8] != '-') return false;
  host = name.substr(0, 8);
  for (const char c : host)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  name.remove_prefix(9);
  const std::size_t dash = name.find('-');
  if (dash == std::string_view::npos || name.size() - dash - 1 != kRandomCharacters) return false;
  long long value = 0;
  const auto [end, error] = std::from_chars(name.data(), name.data() + dash, value);
  if (error != std::errc{} || end != name.data() + dash || value <= 0 ||
      value > static_cast<long long>(std::numeric_limits<pid_t>::max()))
    return false;
  for (const char c : name.substr(dash + 1))
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'z'))) return false;
  pid = static_cast<pid_t>(value);
  return true;
}

}  // namespace

AtomicFile::AtomicFile(fs::path target, mode_t mode) : target_(std::move(target)) {
  const fs::path folder = target_.has_parent_path() ? target_.parent_path() : fs::path(".");
  const std::string stem =
      std::string(kTemporaryFilePrefix) + hostTag() + "-" + std::to_string(::getpid()) + "-";
  // A name collision (another process, a file left over) takes the next random suffix.
  for (int attempt = 0; attempt < 100; ++attempt) {
    path_ = folder / (stem + randomSuffix());
    fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, mode);
    if (fd_ >= 0 || errno != EEXIST) break;
  }
  if (fd_ < 0) throwErrno(errno);
}

AtomicFile::~AtomicFile() {
  if (stream_ != nullptr) {
    std::fclose(stream_);
  } else if (fd_ >= 0) {
    ::close(fd_);
  }
  if (!committed_) ::unlink(path_.c_str());
}

void AtomicFile::write(std::string_view bytes) {
  if (fd_ < 0) throwErrno(EBADF);
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd_, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throwErrno(n < 0 ? errno : EIO);
    bytes.remove_prefix(static_cast<std::size_t>(n));
  }
}

std::FILE* AtomicFile::stream() {
  if (stream_ == nullptr) {
    if (fd_ < 0) throwErrno(EBADF);
    stream_ = ::fdopen(fd_, "wb");
    if (stream_ == nullptr) throwErrno(errno);
    // Images go out in 256 KiB writes rather than stdio's default 4 KiB (a 1024×768 PPM: 10
    // system calls instead of 577). Setting the buffer cannot fail before the first write.
    constexpr std::size_t kStreamBufferBytes = std::size_t{1} << 18;
    streamBuffer_ = std::make_unique_for_overwrite<char[]>(kStreamBufferBytes);
    std::setvbuf(stream_, streamBuffer_.get(), _IOFBF, kStreamBufferBytes);
  }
  return stream_;
}

void AtomicFile::close(bool syncToDisk) {
  if (fd_ < 0) return;
  int error = 0;
  if (stream_ != nullptr) {
    if (std::fflush(stream_) != 0 || std::ferror(stream_) != 0) error = errno != 0 ? errno : EIO;
  }
  if (error == 0 && syncToDisk && ::fsync(fd_) != 0) error = errno;
  const int closed = stream_ != nullptr ? std::fclose(stream_) : ::close(fd_);
  if (error == 0 && closed != 0) error = errno;
  stream_ = nullptr;
  fd_ = -1;
  if (error != 0) throwErrno(error);
}

void AtomicFile::commit() {
  close();
  if (::rename(path_.c_str(), target_.c_str()) != 0) throwErrno(errno);
  committed_ = true;
}

bool isTemporaryFileName(std::string_view name) {
  std::string_view host;
  pid_t pid = 0;
  return parseTemporaryName(name, host, pid);
}

std::size_t removeStaleTemporaryFiles(const fs::path& folder) {
  std::size_t removed = 0;
  std::error_code error;
  fs::directory_iterator entries(folder.empty() ? fs::path(".") : folder, error);
  if (error) return 0;
  for (; entries != fs::directory_iterator(); entries.increment(error)) {
    if (error) break;
    const fs::directory_entry& entry = *entries;
    const std::string name = entry.path().filename().string();
    std::string_view host;
    pid_t pid = 0;
    if (!parseTemporaryName(name, host, pid) || host != hostTag() || pid == ::getpid()) continue;
    // kill(pid, 0) probes without sending: ESRCH means no such process. EPERM means it lives
    // (under another user), so its file stays.
    if (::kill(pid, 0) == 0 || errno != ESRCH) continue;
    // Never follow a symbolic link that merely carries the name.
    struct stat info {};
    if (::lstat(entry.path().c_str(), &info) != 0 || !S_ISREG(info.st_mode)) continue;
    if (::unlink(entry.path().c_str()) == 0) ++removed;
  }
  return removed;
}

}  // namespace glint

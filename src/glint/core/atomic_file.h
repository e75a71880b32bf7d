// All-or-nothing file output: a temporary file with a short hidden name in the target's folder,
// renamed over the target once complete; and the removal of such files a killed glint left behind.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

namespace glint {

// Every temporary file glint writes is named ".glint-tmp-HHHHHHHH-PID-XXXXXX": HHHHHHHH a hash of
// the host name, PID the writing process, XXXXXX random. At most 38 bytes whatever the target's
// name, so a target name of up to NAME_MAX (255) bytes still gets a temporary file; hidden, so a
// listing of the folder does not show it while it exists.
inline constexpr std::string_view kTemporaryFilePrefix = ".glint-tmp-";

// A temporary file beside `target`, created exclusively (O_EXCL) and removed on destruction unless
// committed. Failures throw std::system_error carrying errno.
class AtomicFile {
 public:
  // `mode`: permission bits of the file (before the umask): 0666 for images, 0600 for checkpoints.
  explicit AtomicFile(std::filesystem::path target, mode_t mode = 0666);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();

  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& temporaryPath() const { return path_; }

  // Writes all of `bytes` at the current position (retrying short writes and EINTR).
  void write(std::string_view bytes);
  // A stdio stream on the file (libpng wants one); owned by this object, valid until close().
  std::FILE* stream();
  // Flushes and closes the file, after fsync when `syncToDisk` (so that after a power cut the
  // target's name points at complete bytes). The file stays until commit() or destruction; a
  // library that writes by path (OpenEXR) may reopen it in between.
  void close(bool syncToDisk = false);
  // Closes if still open, then renames the file over the target (atomic within a folder).
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path path_;
  int fd_ = -1;
  std::FILE* stream_ = nullptr;
  // stream()'s buffer: glibc's setvbuf ignores the size it is given without a buffer (it keeps
  // st_blksize, 4 KiB), so the stream gets one of its own, freed with this object after the
  // stream is closed (by close() or by the destructor's body).
  std::unique_ptr<char[]> streamBuffer_;
  bool committed_ = false;
};

// Whether `name` (a file name, no folder) is one of glint's temporary files.
bool isTemporaryFileName(std::string_view name);

// Removes from `folder` the temporary files that glint processes of this host left behind when
// they were killed (SIGKILL, a crash, a power cut): only names of the pattern above whose host
// hash is this host's and whose PID is not a living process. Files of other hosts (a shared
// network folder) are left alone, as is everything else. Returns how many were removed; never
// throws (an unreadable folder removes nothing).
std::size_t removeStaleTemporaryFiles(const std::filesystem::path& folder);

}  // namespace glint

#include "glint/mesh/mesh_size_estimate.h"

#include <unistd.h>
#include <cctype>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "glint/core/cancel.h"
#include "glint/core/file_access.h"
#include "glint/mesh/format_checks.h"
#include "glint/mesh/mesh_file.h"

namespace glint {

namespace {

// Calls `line` with every line of the file (without its '\n'), reading 64 KiB at a time and keeping
// at most kMaxScannedLine bytes of a line: counting needs no more, and memory stays bounded for any
// file. Lines are found with memchr and passed as views into the buffer; only a line that spans two
// reads is copied. Throws MeshLoadError when the file cannot be read, Cancelled once `cancel` (may
// be null; polled before every read) is set.
constexpr std::size_t kMaxScannedLine = 256;

template <typename LineFn>
void forEachLine(const std::filesystem::path& path, const std::atomic<bool>* cancel,
                 LineFn&& line) {
  const ReadableFile file = openMeshFile(path);
  const int fd = file.fd;
  std::string carried;  // the start of a line that continues in the next read
  bool carrying = false;
  const auto keep = [&](const char* begin, std::size_t size) {
    carried.append(begin, std::min(size, kMaxScannedLine - carried.size()));
  };
  std::vector<char> buffer(std::size_t{1} << 16);
  for (;;) {
    throwIfCancelled(cancel);
    const ssize_t n = ::read(fd, buffer.data(), buffer.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw MeshLoadError(systemReason(errno));
    if (n == 0) break;
    const char* at = buffer.data();
    const char* const end = at + n;
    while (at < end) {
      const char* newline =
          static_cast<const char*>(std::memchr(at, '\n', static_cast<std::size_t>(end - at)));
      if (newline == nullptr) {
        keep(at, static_cast<std::size_t>(end - at));
        carrying = true;
        break;
      }
      const std::size_t size = static_cast<std::size_t>(newline - at);
      if (carrying) {
        keep(at, size);
        line(std::string_view(carried));
        carried.clear();
        carrying = false;
      } else {
        line(std::string_view(at, std::min(size, kMaxScannedLine)));
      }
      at = newline + 1;
    }
  }
  if (carrying && !carried.empty()) line(std::string_view(carried));
}

bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

// Words of a line separated by blanks, counted up to the first comment.
std::size_t wordCount(std::string_view line) {
  std::size_t words = 0;
  bool inWord = false;
  for (const char c : line) {
    if (c == '#') break;
    const bool blank = isBlank(c);
    if (!blank && !inWord) ++words;
    inWord = !blank;
  }
  return words;
}

// A plain loop rather than find_first_not_of / find_first_of: the OBJ estimate calls it for every
// line of files of millions of lines.
std::string_view firstWord(std::string_view line) {
  std::size_t begin = 0;
  while (begin < line.size() && isBlank(line[begin])) ++begin;
  std::size_t end = begin;
  while (end < line.size() && !isBlank(line[end])) ++end;
  return line.substr(begin, end - begin);
}

}  // namespace

std::uint64_t gltfBytes(const std::filesystem::path& path, std::uint64_t size,
                        const ReferencedFileRule& rule) {
  std::uint64_t total = size;
  if (size > (std::uint64_t{64} << 20)) return total;  // a .gltf this big holds its own data
  std::string text;
  {
    const ReadableFile file = openMeshFile(path);
    char buffer[1 << 16];
    for (;;) {
      const ssize_t n = ::read(file.fd, buffer, sizeof buffer);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0 || text.size() > size) break;
      text.append(buffer, static_cast<std::size_t>(n));
    }
  }
  std::set<std::string> seen;
  for (std::size_t at = text.find("\"uri\""); at != std::string::npos;
       at = text.find("\"uri\"", at + 5)) {
    const std::size_t open = text.find('"', text.find(':', at + 5));
    if (open == std::string::npos) break;
    const std::size_t close = text.find('"', open + 1);
    if (close == std::string::npos) break;
    const std::string written = text.substr(open + 1, close - open - 1);
    if (written.rfind("data:", 0) == 0 || !seen.insert(written).second) continue;
    // URIs are percent-encoded (RFC 3986): "my%20mesh.bin" names "my mesh.bin".
    std::string uri;
    for (std::size_t k = 0; k < written.size(); ++k) {
      if (written[k] == '%' && k + 2 < written.size() &&
          std::isxdigit(static_cast<unsigned char>(written[k + 1])) &&
          std::isxdigit(static_cast<unsigned char>(written[k + 2]))) {
        uri.push_back(static_cast<char>(std::stoi(written.substr(k + 1, 2), nullptr, 16)));
        k += 2;
      } else {
        uri.push_back(written[k]);
      }
    }
    // A file outside the mesh's folder tree is not read (the load refuses it): not counted.
    const std::filesystem::path named = path.parent_path() / uri;
    if (!rule.refusal(named).empty()) continue;
    const ReadableFile file = statForReading(named);
    if (file.refusal == FileRefusal::None) total += file.size;
  }
  return total;
}

MeshSizeEstimate estimateMeshSize(const std::filesystem::path& path,
                                  const MeshReadOptions& options) {
  std::uint64_t size = 0;
  const std::string header = readHeader(path, size);
  const std::string extension = checkedExtension(path);
  if (extension == ".ply") {
    const PlyElementCounts counts = checkPlyHeader(header, size);
    return {counts.faces, counts.vertices};
  }
  MeshSizeEstimate estimate;
  if (extension == ".stl") {
    // Binary STL: 80 bytes of header, a uint32 count (little-endian), 50 bytes per triangle.
    if (header.size() >= 84) {
      std::uint32_t count = 0;
      for (int i = 3; i >= 0; --i) {
        count = (count << 8) | static_cast<unsigned char>(header[80 + static_cast<std::size_t>(i)]);
      }
      if (size == 84 + 50 * std::uint64_t{count}) {
        // Vertices are shared after assimp joins them: about half a vertex per triangle.
        return {count, count / 2};
      }
    }
    forEachLine(path, options.cancel, [&](std::string_view line) {
      if (firstWord(line) == "facet") ++estimate.triangles;
    });
    estimate.vertices = estimate.triangles / 2;
    return estimate;
  }
  if (extension == ".obj") {
    forEachLine(path, options.cancel, [&](std::string_view line) {
      const std::string_view word = firstWord(line);
      if (word == "v") {
        ++estimate.vertices;
      } else if (word == "f") {
        const std::size_t corners = wordCount(line) - 1;
        if (corners >= 3) estimate.triangles += corners - 2;
      }
    });
    return estimate;
  }
  if (extension == ".gltf" || extension == ".glb") {
    estimate.triangles = gltfBytes(path, size, ReferencedFileRule(path, options.sceneFolder)) / 12;
    estimate.vertices = estimate.triangles / 2;
    return estimate;
  }
  return estimate;  // not reached: every extension of kMeshExtensions is handled above
}

}  // namespace glint

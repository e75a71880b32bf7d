#include "glint/mesh/format_checks.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <exception>
#include <sstream>
#include <string_view>

#include <fmt/format.h>

#include "glint/core/file_access.h"
#include "glint/mesh/mesh_file.h"
#include "glint/scene/scene_limits.h"

namespace glint {

std::string readHeader(const std::filesystem::path& path, std::uint64_t& size) {
  const ReadableFile checked = statForReading(path);
  if (checked.refusal != FileRefusal::None) throw MeshLoadError(meshFileRefusal(checked));
  checkedExtension(path);  // before the file is opened
  const ReadableFile file = openMeshFile(path);
  size = file.size;
  std::string header(kMeshHeaderBytes, '\0');
  std::size_t filled = 0;
  while (filled < header.size()) {
    const ssize_t n = ::read(file.fd, header.data() + filled, header.size() - filled);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    filled += static_cast<std::size_t>(n);
  }
  header.resize(filled);
  return header;
}

std::string lowerExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

std::string checkedExtension(const std::filesystem::path& path) {
  const std::string ext = lowerExtension(path);
  for (const char* known : kMeshExtensions) {
    if (ext == known) return ext;
  }
  throw MeshLoadError(fmt::format(
      "not a mesh format glint reads: {} (glint reads .obj with .mtl, .ply, .stl, .gltf and .glb "
      "files)",
      ext.empty() ? std::string("the file name has no extension") : "'" + ext + "'"));
}

namespace {

// Bytes of one PLY property value at the least: its size in binary; in ASCII one digit and one
// separator.
double plyScalarBytes(std::string_view type, bool ascii) {
  if (ascii) return 2;
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "double" || type == "float64") return 8;
  return 4;
}

void refuseCounts(double needed, std::uint64_t size, const std::string& declared) {
  if (needed > static_cast<double>(size)) {
    throw MeshLoadError(
        fmt::format("its header declares {}, more than its {} can hold (a "
                    "damaged or truncated file)",
                    declared, formatBytes(static_cast<double>(size))));
  }
}

void refuseFaces(double faces) {
  if (faces > static_cast<double>(kMaxMeshTriangles)) {
    throw MeshLoadError(fmt::format("its header declares {} faces, more than the limit of {}",
                                    formatCount(faces),
                                    formatCount(static_cast<double>(kMaxMeshTriangles))));
  }
}

// Vertices past 2^32 cannot be addressed by a mesh's 32-bit indices (and a count past 2^64 would
// not even convert to an integer: a header's count is any number it spells).
void refuseVertices(double vertices) {
  constexpr double kMaxVertices = 4294967296.0;  // 2^32
  if (vertices > kMaxVertices) {
    throw MeshLoadError(fmt::format("its header declares {} vertices, more than the limit of {}",
                                    formatCount(vertices), formatCount(kMaxVertices)));
  }
}

// The first `limit` characters of a line from a file, printable, for a message.
std::string shown(std::string_view text, std::size_t limit = 40) {
  std::string out;
  for (const char c : text.substr(0, limit)) {
    out.push_back(std::isprint(static_cast<unsigned char>(c)) ? c : '?');
  }
  return text.size() > limit ? out + "..." : out;
}

}  // namespace

PlyElementCounts checkPlyHeader(const std::string& header, std::uint64_t size) {
  std::istringstream in(header);
  std::string line;
  std::getline(in, line);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line != "ply") throw MeshLoadError("not a PLY file: it does not start with a 'ply' line");
  bool ascii = true;
  bool formatSeen = false;
  double needed = 0;
  double elementBytes = 0;
  double elementCount = 0;
  double vertexCount = 0;
  double faceCount = 0;
  bool ended = false;
  std::string declared;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    // The keyword ends where assimp's PLY reader ends it: at a space or tab, or the line's end.
    // (istream's >> also stops at \v and \f; assimp then never sees its "end_header" and loops,
    // a fuzzing finding.)
    // Leading blanks are skipped, as assimp skips them.
    const std::size_t start = std::min(line.find_first_not_of(" \t"), line.size());
    const std::string keyword = line.substr(start, line.find_first_of(" \t", start) - start);
    words.ignore(static_cast<std::streamsize>(start + keyword.size()));
    if (keyword == "format") {
      std::string format;
      words >> format;
      if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian") {
        throw MeshLoadError(
            fmt::format("its PLY header has an unknown format '{}'", shown(format)));
      }
      ascii = format == "ascii";
      formatSeen = true;
    } else if (keyword == "element" || keyword == "end_header") {
      needed += elementBytes * elementCount;
      std::string name;
      elementCount = 0;
      elementBytes = 0;
      if (keyword == "end_header") {
        ended = true;
        break;
      }
      words >> name >> elementCount;
      if (!words || !(elementCount >= 0) || !std::isfinite(elementCount)) {
        throw MeshLoadError(
            fmt::format("its PLY header has an element without a valid count: '{}'", shown(line)));
      }
      // Checked as the elements add up (several face elements count together).
      if (name == "face") {
        faceCount += elementCount;
        refuseFaces(faceCount);
      }
      if (name == "vertex") {
        vertexCount += elementCount;
        refuseVertices(vertexCount);
      }
      declared +=
          fmt::format("{}{} {}", declared.empty() ? "" : " and ", formatCount(elementCount), name);
    } else if (keyword == "property") {
      std::string type;
      words >> type;
      if (type == "list") words >> type;  // the count's type; the list may be empty
      elementBytes += plyScalarBytes(type, ascii);
    }
    // Other lines (comments, obj_info, and free text some exporters write) are skipped, as assimp
    // skips them.
  }
  if (!ended || !formatSeen) {
    throw MeshLoadError(fmt::format(
        "its PLY header has no {} line in its first {} (a damaged or truncated file)",
        formatSeen ? "end_header" : "format", formatBytes(static_cast<double>(kMeshHeaderBytes))));
  }
  refuseCounts(needed, size, declared + " elements");
  return PlyElementCounts{static_cast<std::uint64_t>(faceCount),
                          static_cast<std::uint64_t>(vertexCount)};
}

GltfJson parseGltfJson(const std::string& text) {
  try {
    return GltfJson{yaml::read(text)};
  } catch (const yaml::SyntaxError& e) {
    throw MeshLoadError(fmt::format("invalid file: its JSON cannot be read ({})", e.what()));
  }
}

namespace {

// The count of accessor `index` of a glTF document, or 0 when there is none.
std::uint64_t accessorCount(const ValueView& accessors, const ValueView& index) {
  if (!index.isScalar()) return 0;
  std::size_t i = 0;
  try {
    i = std::stoul(std::string(index.scalar()));
  } catch (const std::exception&) {
    return 0;
  }
  const ValueView count = accessors[i].find("count");
  if (!count.isScalar()) return 0;
  try {
    return std::stoull(std::string(count.scalar()));
  } catch (const std::exception&) {
    return 0;
  }
}

// A whole number of a glTF document, or `otherwise` when it is absent or not one.
std::uint64_t wholeNumber(const ValueView& value, std::uint64_t otherwise) {
  if (!value.isScalar()) return otherwise;
  const std::string_view text = value.scalar();
  std::uint64_t number = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), number);
  return error == std::errc{} && end == text.data() + text.size() ? number : otherwise;
}

// Bytes of one component of an accessor's componentType (5120 byte ... 5126 float); 0 for none.
std::uint64_t componentBytes(std::string_view componentType) {
  if (componentType == "5120" || componentType == "5121") return 1;
  if (componentType == "5122" || componentType == "5123") return 2;
  if (componentType == "5125" || componentType == "5126") return 4;
  return 0;
}

// Every accessor aligned as glTF 2.0 requires ("Data Alignment": its offset within its buffer view
// and within the buffer, and the view's stride, multiples of its component size). assimp reads a
// misaligned accessor where it lies: vertices of garbage bits, silently.
void checkGltfAlignment(const ValueView& accessors, const ValueView& bufferViews) {
  for (std::size_t a = 0; a < accessors.size(); ++a) {
    const ValueView accessor = accessors[a];
    const std::uint64_t component = componentBytes(accessor.find("componentType").scalar());
    if (component == 0) continue;
    const std::uint64_t offset = wholeNumber(accessor.find("byteOffset"), 0);
    const ValueView view =
        bufferViews[wholeNumber(accessor.find("bufferView"), bufferViews.size())];
    const std::uint64_t viewOffset = wholeNumber(view.find("byteOffset"), 0);
    const std::uint64_t stride = wholeNumber(view.find("byteStride"), 0);
    std::string fault;
    if (offset % component != 0) {
      fault = fmt::format("starts at byte {} of its buffer view", offset);
    } else if ((viewOffset + offset) % component != 0) {
      fault = fmt::format("starts at byte {} of its buffer", viewOffset + offset);
    } else if (stride % component != 0) {
      fault = fmt::format("has a buffer view of stride {}", stride);
    }
    if (!fault.empty()) {
      throw MeshLoadError(fmt::format(
          "invalid file: accessor {} {}, not a multiple of its component size ({} bytes), as glTF "
          "2.0 requires",
          a, fault, component));
    }
  }
}

}  // namespace

void checkGltfPrimitives(const std::filesystem::path& path, const std::string& extension,
                         std::uint64_t size) {
  std::string text;
  {
    const ReadableFile file = openMeshFile(path);
    const int fd = file.fd;
    std::uint64_t want = size;
    if (extension == ".glb") {
      // 12-byte header ("glTF", version, length), then the JSON chunk: length, "JSON", data.
      unsigned char head[20] = {};
      if (::read(fd, head, sizeof head) != static_cast<ssize_t>(sizeof head) ||
          std::memcmp(head + 16, "JSON", 4) != 0) {
        return;  // not a GLB assimp would read past its header: its own error
      }
      want = std::uint64_t{head[12]} | std::uint64_t{head[13]} << 8 |
             std::uint64_t{head[14]} << 16 | std::uint64_t{head[15]} << 24;
      want = std::min(want, size - 20);
    }
    text.resize(static_cast<std::size_t>(want));
    std::size_t filled = 0;
    while (filled < text.size()) {
      const ssize_t n = ::read(fd, text.data() + filled, text.size() - filled);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      filled += static_cast<std::size_t>(n);
    }
    text.resize(filled);
  }
  const GltfJson json = parseGltfJson(text);
  const ValueView accessors = json.root().find("accessors");
  const ValueView meshes = json.root().find("meshes");
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const ValueView primitives = meshes[m].find("primitives");
    for (std::size_t p = 0; p < primitives.size(); ++p) {
      const ValueView primitive = primitives[p];
      const std::string_view mode = primitive.find("mode").scalar();
      const ValueView indices = primitive.find("indices");
      const std::uint64_t count =
          indices.isDefined()
              ? accessorCount(accessors, indices)
              : accessorCount(accessors, primitive.find("attributes").find("POSITION"));
      // Triangles (mode 4, the default): three vertices each. assimp drops what is left over.
      if ((mode.empty() || mode == "4") && count % 3 != 0) {
        throw MeshLoadError(fmt::format(
            "invalid file: primitive {} of mesh {} is a list of triangles of {} {}, not a "
            "multiple of 3",
            p, m, count, indices.isDefined() ? "indices" : "vertices"));
      }
      const std::uint64_t minimum = mode == "3" ? 2 : (mode == "5" || mode == "6") ? 3 : 0;
      if (minimum == 0) continue;
      if (count < minimum) {
        throw MeshLoadError(fmt::format(
            "invalid file: primitive {} of mesh {} is a {} of {} vertices (at least {} needed)", p,
            m,
            mode == "3"   ? "line strip"
            : mode == "5" ? "triangle strip"
                          : "triangle fan",
            count, minimum));
      }
    }
  }
  checkGltfAlignment(accessors, json.root().find("bufferViews"));
}

}  // namespace glint

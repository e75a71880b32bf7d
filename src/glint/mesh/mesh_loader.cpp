#include "glint/mesh/mesh_loader.h"

#include <fcntl.h>
#include <malloc.h>
#include <poll.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <exception>
#include <new>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

#include <assimp/BaseImporter.h>
#include <assimp/DefaultIOSystem.h>
#include <assimp/config.h>
#include <assimp/importerdesc.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>
#include <assimp/Importer.hpp>

#include "glint/readers/yaml_tree.h"
#include "glint/scene/scene_limits.h"

namespace glint {

std::size_t MeshFile::triangleCount() const {
  std::size_t n = 0;
  for (const TriangleMesh& part : parts) n += part.triangleCount();
  return n;
}

namespace {

// Twice a triangle's area may be at most this fraction of its longest edge squared before the
// triangle counts as degenerate: Triangle::make's bound (geometry/shapes.cpp), so a mesh drops
// exactly what a scene file would refuse as a `triangle`. Below it the normal (e1×e2)/|e1×e2| is
// rounding noise, or NaN for coincident vertices.
constexpr double kDegenerateTolerance = 1e-12;

constexpr std::uint32_t kUnused = 0xffffffffu;

// The system's words for an errno, starting lower-case to follow "cannot load mesh file 'x': ".
std::string systemReason(int error) {
  std::string text = std::generic_category().message(error);
  if (!text.empty()) text[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(text[0])));
  return text;
}

std::string checkedExtension(const std::filesystem::path& path);

// Fails early, with the system's reason, for what assimp would only call "Unable to open file":
// a missing path, a folder, a device or pipe (which could block or never end), an extension glint
// does not read (checked before opening), no permission.
// Returns the file's first bytes (at most kHeaderBytes) and its size.
constexpr std::size_t kHeaderBytes = 64 * 1024;

std::string readHeader(const std::filesystem::path& path, std::uint64_t& size) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) {
    const int error = errno;
    throw MeshLoadError(error == ENOENT ? std::string("no such file") : systemReason(error));
  }
  if (S_ISDIR(info.st_mode)) throw MeshLoadError("it is a folder, not a mesh file");
  if (!S_ISREG(info.st_mode)) throw MeshLoadError("it is not a regular file");
  checkedExtension(path);  // before the file is opened
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw MeshLoadError(systemReason(errno));
  size = static_cast<std::uint64_t>(info.st_size);
  std::string header(kHeaderBytes, '\0');
  std::size_t filled = 0;
  while (filled < header.size()) {
    const ssize_t n = ::read(fd, header.data() + filled, header.size() - filled);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    filled += static_cast<std::size_t>(n);
  }
  ::close(fd);
  header.resize(filled);
  return header;
}

std::string lowerExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// The file's extension if glint reads it; otherwise MeshLoadError, before the file is opened.
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

// assimp's file access for one mesh file and the files it names (MTL, glTF buffers): only regular
// files, read-only. A name such as /dev/zero or a FIFO in a hostile file would otherwise be read
// without end or block forever.
class RegularFilesOnly : public Assimp::DefaultIOSystem {
 public:
  using DefaultIOSystem::Exists;
  Assimp::IOStream* Open(const char* file, const char* mode) override {
    if (file == nullptr || mode == nullptr ||
        std::string_view(mode).find_first_of("wa+") != std::string_view::npos) {
      return nullptr;
    }
    return isRegular(file) ? DefaultIOSystem::Open(file, mode) : nullptr;
  }
  // DefaultIOSystem::Exists opens the file with fopen, which blocks on a FIFO.
  bool Exists(const char* file) const override { return isRegular(file); }

 private:
  static bool isRegular(const char* file) {
    struct stat info {};
    return file != nullptr && ::stat(file, &info) == 0 && S_ISREG(info.st_mode);
  }
};

// Leaves `importer` with only the importer(s) for `extension`: the glTF 2.0 one for .gltf/.glb
// (not assimp's glTF 1.0 importer), the one importer of each other extension. assimp falls back to
// trying every importer's signature test when the chosen one declines; with the others gone there
// is nothing to fall back to.
void keepOnlyImporterFor(Assimp::Importer& importer, const std::string& extension) {
  const std::string bare = extension.substr(1);
  std::vector<Assimp::BaseImporter*> unwanted;
  for (std::size_t i = 0; i < importer.GetImporterCount(); ++i) {
    Assimp::BaseImporter* candidate = importer.GetImporter(i);
    if (candidate == nullptr) continue;
    std::set<std::string> extensions;
    candidate->GetExtensionList(extensions);
    bool keep = extensions.count(bare) != 0;
    if (keep && (bare == "gltf" || bare == "glb")) {
      const aiImporterDesc* info = candidate->GetInfo();
      keep = info != nullptr && std::string_view(info->mName).find("glTF2") != std::string::npos;
    }
    if (!keep) unwanted.push_back(candidate);
  }
  for (Assimp::BaseImporter* candidate : unwanted) {
    // UnregisterLoader hands the importer back without deleting it.
    if (importer.UnregisterLoader(candidate) == aiReturn_SUCCESS) delete candidate;
  }
}

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

// The first `limit` characters of a line from a file, printable, for a message.
std::string shown(std::string_view text, std::size_t limit = 40) {
  std::string out;
  for (const char c : text.substr(0, limit)) {
    out.push_back(std::isprint(static_cast<unsigned char>(c)) ? c : '?');
  }
  return text.size() > limit ? out + "..." : out;
}

// A PLY header checked line by line before assimp sees it (DESIGN.md §7):
//  - its structure: a "ply" line, a known format and end_header within the first kHeaderBytes.
//    assimp 5.2's PLY reader loops without end, growing its memory, on a header that never ends
//    (found by fuzzing).
//  - its counts: assimp trusts them, reserving memory before it reads any element: a 200-byte PLY
//    claiming 300 million faces would cost gigabytes and minutes. Counts the file's size cannot
//    hold, or more faces than kMaxMeshTriangles, are refused.
// Returns the declared face and vertex counts (estimateMeshSize's answer).
MeshSizeEstimate checkPlyHeader(const std::string& header, std::uint64_t size) {
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
    const std::string keyword = line.substr(0, line.find_first_of(" \t"));
    words.ignore(static_cast<std::streamsize>(keyword.size()));
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
      if (name == "face") {
        refuseFaces(elementCount);
        faceCount += elementCount;
      }
      if (name == "vertex") vertexCount += elementCount;
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
        formatSeen ? "end_header" : "format", formatBytes(static_cast<double>(kHeaderBytes))));
  }
  refuseCounts(needed, size, declared + " elements");
  return MeshSizeEstimate{static_cast<std::uint64_t>(faceCount),
                          static_cast<std::uint64_t>(vertexCount)};
}

// The count of accessor `index` of a glTF document, or 0 when there is none.
std::uint64_t accessorCount(const yaml::Node& accessors, const yaml::Node& index) {
  if (!index.isScalar()) return 0;
  std::size_t i = 0;
  try {
    i = std::stoul(index.scalar());
  } catch (const std::exception&) {
    return 0;
  }
  const yaml::Node count = accessors[i].find("count");
  if (!count.isScalar()) return 0;
  try {
    return std::stoull(count.scalar());
  } catch (const std::exception&) {
    return 0;
  }
}

// glTF primitives checked before assimp sees them. assimp 5.2 makes a strip or fan primitive
// (mode 3, 5, 6) of n vertices into n − 1 or n − 2 faces without checking n: a primitive with too
// few vertices (none when POSITION is missing) asks for 2^32 faces, 64 GiB (found by fuzzing).
// The JSON is read with the YAML reader (JSON is YAML), from the .gltf or the GLB's JSON chunk.
void checkGltfPrimitives(const std::filesystem::path& path, const std::string& extension,
                         std::uint64_t size) {
  std::string text;
  {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw MeshLoadError(systemReason(errno));
    std::uint64_t want = size;
    if (extension == ".glb") {
      // 12-byte header ("glTF", version, length), then the JSON chunk: length, "JSON", data.
      unsigned char head[20] = {};
      if (::read(fd, head, sizeof head) != static_cast<ssize_t>(sizeof head) ||
          std::memcmp(head + 16, "JSON", 4) != 0) {
        ::close(fd);
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
    ::close(fd);
    text.resize(filled);
  }
  yaml::Stream json;
  try {
    json = yaml::parse(text);
  } catch (const yaml::SyntaxError& e) {
    throw MeshLoadError(fmt::format("invalid file: its JSON cannot be read ({})", e.what()));
  }
  const yaml::Node accessors = json.root.find("accessors");
  const yaml::Node meshes = json.root.find("meshes");
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const yaml::Node primitives = meshes[m].find("primitives");
    for (std::size_t p = 0; p < primitives.size(); ++p) {
      const yaml::Node primitive = primitives[p];
      const std::string mode = primitive.find("mode").scalar();
      const std::uint64_t minimum = mode == "3" ? 2 : (mode == "5" || mode == "6") ? 3 : 0;
      if (minimum == 0) continue;
      const yaml::Node indices = primitive.find("indices");
      const std::uint64_t count =
          indices.isDefined()
              ? accessorCount(accessors, indices)
              : accessorCount(accessors, primitive.find("attributes").find("POSITION"));
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
}

// assimp's message in the user's terms.
std::string assimpReason(std::string_view message) {
  if (message.find("No suitable reader found") != std::string_view::npos) {
    return "the file's content does not match its extension, or it is damaged";
  }
  while (!message.empty() && (message.back() == '.' || message.back() == '\n')) {
    message.remove_suffix(1);
  }
  if (message.empty()) return "the mesh library could not read it";
  return "invalid file: " + std::string(message);
}

// Triangles a face stands for: a polygon of n ≥ 3 corners fans into n − 2.
std::size_t trianglesOf(const aiFace& face) {
  return face.mNumIndices >= 3 ? face.mNumIndices - 2 : 1;
}

// Removes, in place, every face that has no index or one past the mesh's vertices, before
// assimp's post-processing steps (which index vertex arrays without checking) see it. Most
// importers check their indices (OBJ refuses the file); PLY, for one, does not. Returns the
// triangles removed. Faces of one or two indices (points, lines) stay for SortByPType to remove.
std::size_t dropInvalidFaces(aiScene& scene) {
  std::size_t dropped = 0;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    aiMesh* mesh = scene.mMeshes[m];
    if (mesh == nullptr || mesh->mFaces == nullptr) {
      if (mesh != nullptr) mesh->mNumFaces = 0;
      continue;
    }
    unsigned kept = 0;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      aiFace& face = mesh->mFaces[f];
      bool valid = face.mNumIndices > 0 && face.mIndices != nullptr && mesh->mVertices != nullptr;
      for (unsigned i = 0; valid && i < face.mNumIndices; ++i) {
        valid = face.mIndices[i] < mesh->mNumVertices;
      }
      if (!valid) {
        dropped += trianglesOf(face);
        continue;
      }
      if (kept != f) {
        // Swap the members: aiFace's own copy assignment would copy the index arrays.
        aiFace& to = mesh->mFaces[kept];
        std::swap(to.mNumIndices, face.mNumIndices);
        std::swap(to.mIndices, face.mIndices);
      }
      ++kept;
    }
    // The faces past `kept` stay allocated; delete[] mFaces still destroys all of them.
    mesh->mNumFaces = kept;
  }
  return dropped;
}

// Gives every face corner of a mesh without normals its own vertex, before GenSmoothNormals.
// That step first stores each face's normal at its vertices — a vertex shared by several faces
// keeps only the last one — and then averages the normals of the vertices at the same position
// within the crease angle. Indexed files (PLY, glTF) share a vertex among all faces around it, so a
// smooth surface got one face's normal per vertex (faceted, lopsided shading) and a crease could
// not be kept. One vertex per corner, as assimp's OBJ and STL importers already give, lets every
// corner average exactly the faces within the crease angle; glint's join (joinMesh) shares them
// again afterwards. Texture coordinates and colours are dropped (glint reads neither); meshes
// with bones are left alone (their weights index the vertices).
void splitSharedCorners(aiScene& scene) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    aiMesh* mesh = scene.mMeshes[m];
    if (mesh == nullptr || mesh->mNormals != nullptr || mesh->mVertices == nullptr ||
        mesh->mNumBones != 0 || mesh->mNumAnimMeshes != 0) {
      continue;
    }
    std::uint64_t corners = 0;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) corners += mesh->mFaces[f].mNumIndices;
    if (corners == mesh->mNumVertices || corners > kMaxMeshTriangles * 3) continue;
    auto* vertices = new aiVector3D[corners];
    unsigned next = 0;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      aiFace& face = mesh->mFaces[f];
      for (unsigned i = 0; i < face.mNumIndices; ++i) {
        vertices[next] = mesh->mVertices[face.mIndices[i]];  // checked by dropInvalidFaces
        face.mIndices[i] = next++;
      }
    }
    delete[] mesh->mVertices;
    mesh->mVertices = vertices;
    mesh->mNumVertices = next;
    delete[] mesh->mTangents;
    mesh->mTangents = nullptr;
    delete[] mesh->mBitangents;
    mesh->mBitangents = nullptr;
    for (auto*& colors : mesh->mColors) {
      delete[] colors;
      colors = nullptr;
    }
    for (unsigned k = 0; k < AI_MAX_NUMBER_OF_TEXTURECOORDS; ++k) {
      delete[] mesh->mTextureCoords[k];
      mesh->mTextureCoords[k] = nullptr;
      mesh->mNumUVComponents[k] = 0;
    }
  }
}

std::size_t facesWithTriangles(const aiScene& scene) {
  std::size_t n = 0;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* mesh = scene.mMeshes[m];
    for (unsigned f = 0; mesh != nullptr && f < mesh->mNumFaces; ++f) {
      if (mesh->mFaces[f].mNumIndices >= 3) ++n;
    }
  }
  return n;
}

// A file's colour component made valid for glint: finite and ≥ 0.
double component(float value) { return std::isfinite(value) && value > 0 ? value : 0.0; }
Color colorOf(const aiColor3D& c) { return {component(c.r), component(c.g), component(c.b)}; }

MeshMaterial convertMaterial(const aiMaterial& m) {
  MeshMaterial out;
  aiString name;
  const bool named = m.Get(AI_MATKEY_NAME, name) == AI_SUCCESS;
  if (named) out.name = name.C_Str();
  aiColor4D base;
  const bool hasBase = m.Get(AI_MATKEY_BASE_COLOR, base) == AI_SUCCESS;
  // assimp's stand-in when the file has no material: named AI_DEFAULT_MATERIAL_NAME (STL, OBJ
  // without MTL) or, from the PLY reader, without any name. glTF materials carry a base colour
  // even when unnamed (and glTF's own default material is white by its specification).
  if ((named && out.name == AI_DEFAULT_MATERIAL_NAME) || (!named && !hasBase)) {
    out.material = kMeshDefaultMaterial;
    out.fromFile = false;
    return out;
  }
  Material& mat = out.material;
  aiColor3D c;
  if (m.Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS) {
    mat.kd = colorOf(c);
  } else if (hasBase) {
    mat.kd = colorOf(aiColor3D(base.r, base.g, base.b));
  }
  mat.ka = mat.kd;
  if (m.Get(AI_MATKEY_COLOR_SPECULAR, c) == AI_SUCCESS) {
    mat.ks = colorOf(c);
    float strength = 1;
    if (m.Get(AI_MATKEY_SHININESS_STRENGTH, strength) == AI_SUCCESS) {
      mat.ks = mat.ks * component(strength);
    }
  }
  float value = 0;
  if (m.Get(AI_MATKEY_SHININESS, value) == AI_SUCCESS) mat.shininess = component(value);
  if (m.Get(AI_MATKEY_COLOR_EMISSIVE, c) == AI_SUCCESS) out.emission = colorOf(c);
  if (m.Get(AI_MATKEY_OPACITY, value) == AI_SUCCESS && std::isfinite(value) && value < 1) {
    mat.kt = Color(1 - std::max(0.0, static_cast<double>(value)));
    if (m.Get(AI_MATKEY_REFRACTI, value) == AI_SUCCESS && std::isfinite(value) && value > 0) {
      mat.ior = value;
    }
  }
  return out;
}

Vec3 faceNormal(const TriangleMesh& mesh, std::size_t triangle) {
  const Point3& p0 = mesh.positions[mesh.indices[3 * triangle]];
  const Point3& p1 = mesh.positions[mesh.indices[3 * triangle + 1]];
  const Point3& p2 = mesh.positions[mesh.indices[3 * triangle + 2]];
  return cross(p1 - p0, p2 - p0);  // length = twice the area
}

// Makes every vertex normal unit. A file's zero or non-finite normal is replaced by the
// area-weighted mean of the normals of the triangles around the vertex.
void repairNormals(TriangleMesh& mesh) {
  if (mesh.normals.empty()) return;
  std::vector<bool> invalid(mesh.normals.size(), false);
  bool anyInvalid = false;
  for (std::size_t v = 0; v < mesh.normals.size(); ++v) {
    const Vec3 n = toVec(mesh.normals[v]);
    const double len = length(n);
    if (len > 0 && std::isfinite(len)) {
      mesh.normals[v] = Normal3(n / len);
    } else {
      invalid[v] = true;
      anyInvalid = true;
    }
  }
  if (!anyInvalid) return;
  std::vector<Vec3> sum(mesh.normals.size());
  std::vector<Vec3> first(mesh.normals.size());
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    const Vec3 n = faceNormal(mesh, t);
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t v = mesh.indices[3 * t + k];
      if (!invalid[v]) continue;
      sum[v] += n;
      if (first[v] == Vec3{}) first[v] = n;
    }
  }
  for (std::size_t v = 0; v < mesh.normals.size(); ++v) {
    if (!invalid[v]) continue;
    // Opposite faces may cancel exactly; then one face's normal serves. Every vertex left belongs
    // to a non-degenerate triangle, so `first` is non-zero.
    mesh.normals[v] = Normal3(normalize(length(sum[v]) > 0 ? sum[v] : first[v]));
  }
}

// The vertex data glint keeps, as a key for joining: position and normal in assimp's float. −0 is
// made +0 (the two compare equal), and a normal that is not finite becomes 0 — every invalid normal
// is one class, replaced by repairNormals from the triangles around the joined vertex.
struct VertexKey {
  float p[3];
  float n[3];
  bool operator==(const VertexKey& o) const {
    return p[0] == o.p[0] && p[1] == o.p[1] && p[2] == o.p[2] && n[0] == o.n[0] && n[1] == o.n[1] &&
           n[2] == o.n[2];
  }
};

VertexKey keyOf(const aiMesh& mesh, unsigned v) {
  VertexKey key{};
  const aiVector3D& p = mesh.mVertices[v];
  key.p[0] = p.x + 0.0f;
  key.p[1] = p.y + 0.0f;
  key.p[2] = p.z + 0.0f;
  if (mesh.mNormals != nullptr) {
    const aiVector3D& n = mesh.mNormals[v];
    if (std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z)) {
      key.n[0] = n.x + 0.0f;
      key.n[1] = n.y + 0.0f;
      key.n[2] = n.z + 0.0f;
    }
  }
  return key;
}

std::uint64_t hashOf(const VertexKey& key) {
  // FNV-1a over the six floats' bits (positions are finite here: triangles touching a non-finite
  // vertex were dropped), then a 64-bit finaliser (splitmix64) to spread them over the table.
  std::uint64_t h = 1469598103934665603ull;
  for (const float* f : {key.p, key.n}) {
    for (int i = 0; i < 3; ++i) {
      std::uint32_t bits = 0;
      std::memcpy(&bits, &f[i], sizeof bits);
      h = (h ^ bits) * 1099511628211ull;
    }
  }
  h ^= h >> 30;
  h *= 0xbf58476d1ce4e5b9ull;
  h ^= h >> 27;
  h *= 0x94d049bb133111ebull;
  return h ^ (h >> 31);
}

// One assimp mesh's triangles with the degenerate ones left out, over joined vertices: the
// vertices of equal position and normal (VertexKey) are one, numbered in order of first use by
// the kept triangles. assimp's importers give OBJ and STL one vertex per face corner; glint joins
// them here, exactly and in O(n) with a hash table, instead of assimp's JoinIdenticalVertices
// (which compares within an epsilon through a spatial sort, and also compares texture
// coordinates glint does not use: ~0.1 s of a 0.3 s load for a 100k-triangle OBJ).
// GenSmoothNormals has already run (assimp runs it before any join), so the normals of a crease
// differ and its vertices stay split.
struct JoinedMesh {
  std::vector<std::uint32_t> indices;  // three per kept triangle, into `source`
  std::vector<std::uint32_t> source;   // the assimp vertex each joined vertex copies
};

JoinedMesh joinMesh(const aiMesh& in, std::size_t& dropped) {
  JoinedMesh out;
  out.indices.reserve(std::size_t{3} * in.mNumFaces);
  std::vector<VertexKey> keys;  // of the joined vertices, in step with out.source
  std::vector<std::uint32_t> joinedOf(in.mNumVertices, kUnused);  // assimp vertex → joined
  // Open addressing, linear probing, at most half full; sized for the joined vertices (a smooth
  // OBJ surface has about one per six face corners) and doubled as they grow, so that the table
  // stays small enough for the cache. A slot holds the joined vertex in its low 32 bits and the
  // hash's high 32 bits above, which rule out almost every other key without reading it.
  constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
  std::size_t slots = 16;
  while (slots < std::size_t{in.mNumVertices} / 3) slots *= 2;
  std::vector<std::uint64_t> table(slots, kEmpty);
  const auto place = [&](std::uint64_t hash, std::uint32_t j) {
    std::size_t slot = hash & (slots - 1);
    while (table[slot] != kEmpty) slot = (slot + 1) & (slots - 1);
    table[slot] = (hash & 0xffffffff00000000ull) | j;
  };
  // `key` and `hash` are those of assimp vertex v, not yet joined.
  const auto join = [&](unsigned v, const VertexKey& key, std::uint64_t hash) {
    const std::uint64_t tag = hash & 0xffffffff00000000ull;
    for (std::size_t slot = hash & (slots - 1);; slot = (slot + 1) & (slots - 1)) {
      const std::uint64_t entry = table[slot];
      if (entry == kEmpty) break;
      const auto j = static_cast<std::uint32_t>(entry);
      if ((entry & 0xffffffff00000000ull) == tag && keys[j] == key) return joinedOf[v] = j;
    }
    const auto j = static_cast<std::uint32_t>(keys.size());
    keys.push_back(key);
    out.source.push_back(v);
    if (2 * keys.size() > slots) {
      slots *= 2;
      table.assign(slots, kEmpty);
      for (std::uint32_t k = 0; k < keys.size(); ++k) place(hashOf(keys[k]), k);
    } else {
      place(hash, j);
    }
    return joinedOf[v] = j;
  };
  for (unsigned f = 0; f < in.mNumFaces; ++f) {
    const aiFace& face = in.mFaces[f];
    if (face.mNumIndices != 3) {
      if (face.mNumIndices > 3 || face.mNumIndices == 0) dropped += trianglesOf(face);
      continue;
    }
    const unsigned a = face.mIndices[0];
    const unsigned b = face.mIndices[1];
    const unsigned c = face.mIndices[2];
    if (a >= in.mNumVertices || b >= in.mNumVertices || c >= in.mNumVertices) {
      ++dropped;
      continue;
    }
    const auto point = [&](unsigned v) {
      const aiVector3D& p = in.mVertices[v];
      return Point3{p.x, p.y, p.z};
    };
    const Point3 p0 = point(a);
    const Point3 p1 = point(b);
    const Point3 p2 = point(c);
    const double twiceArea = length(cross(p1 - p0, p2 - p0));
    const double longest =
        std::max({distanceSquared(p0, p1), distanceSquared(p1, p2), distanceSquared(p2, p0)});
    // Also false for NaN and infinite coordinates, which make the area or the edges non-finite.
    if (!(twiceArea > kDegenerateTolerance * longest) || !std::isfinite(twiceArea) ||
        !std::isfinite(longest)) {
      ++dropped;
      continue;
    }
    // The three corners' keys and hashes first, their table slots fetched together: the lookups
    // are cache misses more often than not, and three at once overlap.
    const unsigned corners[3] = {a, b, c};
    VertexKey cornerKeys[3] = {};
    std::uint64_t hashes[3] = {};
    for (int k = 0; k < 3; ++k) {
      if (joinedOf[corners[k]] != kUnused) continue;
      cornerKeys[k] = keyOf(in, corners[k]);
      hashes[k] = hashOf(cornerKeys[k]);
      __builtin_prefetch(&table[hashes[k] & (slots - 1)]);
    }
    for (int k = 0; k < 3; ++k) {
      const unsigned v = corners[k];
      out.indices.push_back(joinedOf[v] != kUnused ? joinedOf[v]
                                                   : join(v, cornerKeys[k], hashes[k]));
    }
  }
  return out;
}

// One assimp mesh (triangulated, its node transforms baked), joined, → a TriangleMesh in file
// space.
TriangleMesh convertMesh(const aiMesh& in, JoinedMesh&& joined) {
  TriangleMesh out;
  out.indices = std::move(joined.indices);
  out.positions.resize(joined.source.size());
  for (std::size_t j = 0; j < joined.source.size(); ++j) {
    const aiVector3D& p = in.mVertices[joined.source[j]];
    out.positions[j] = {p.x, p.y, p.z};
  }
  if (in.HasNormals()) {
    out.normals.resize(joined.source.size());
    for (std::size_t j = 0; j < joined.source.size(); ++j) {
      const aiVector3D& n = in.mNormals[joined.source[j]];
      out.normals[j] = {n.x, n.y, n.z};
    }
  }
  repairNormals(out);
  return out;
}

}  // namespace

namespace {

// assimp's import of a checked file and its conversion to glint's MeshFile, in this process.
MeshFile importMesh(const std::filesystem::path& path, const std::string& extension) {
  Assimp::Importer importer;
  importer.SetIOHandler(new RegularFilesOnly);  // the importer owns it
  keepOnlyImporterFor(importer, extension);
  // Points and lines are not surfaces: SortByPType removes them after triangulation.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  importer.SetPropertyFloat(AI_CONFIG_PP_GSN_MAX_SMOOTHING_ANGLE,
                            static_cast<float>(kMeshCreaseAngleDegrees));
  // No JoinIdenticalVertices: joinMesh joins the vertices, faster and exactly.
  unsigned flags = aiProcess_Triangulate | aiProcess_PreTransformVertices |
                   aiProcess_GenSmoothNormals | aiProcess_SortByPType;
  if (extension == ".stl") {
    // STL stores one normal per facet, not per vertex: drop them so that GenSmoothNormals (which
    // keeps normals a mesh already has) smooths the surface, and joinMesh can then share the
    // vertices of neighbouring facets.
    importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS);
    flags |= aiProcess_RemoveComponent;
  }

  MeshFile result;
  try {
    // Read without post-processing first: the faces are checked before any step indexes with them.
    const aiScene* scene = importer.ReadFile(path.string(), 0);
    if (scene == nullptr) throw MeshLoadError(assimpReason(importer.GetErrorString()));
    // The importer owns the scene and its steps edit it in place; so does dropInvalidFaces.
    result.droppedTriangles = dropInvalidFaces(const_cast<aiScene&>(*scene));
    splitSharedCorners(const_cast<aiScene&>(*scene));
    if (scene->mRootNode == nullptr || facesWithTriangles(*scene) == 0) {
      throw MeshLoadError(result.droppedTriangles > 0
                              ? fmt::format("all {} triangles have vertex indices out of range",
                                            result.droppedTriangles)
                              : std::string("the file holds no triangles"));
    }
    scene = importer.ApplyPostProcessing(flags);
    if (scene == nullptr) throw MeshLoadError(assimpReason(importer.GetErrorString()));

    std::uint64_t triangles = 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) triangles += scene->mMeshes[m]->mNumFaces;
    if (triangles > kMaxMeshTriangles) {
      throw MeshLoadError(fmt::format("it holds {} triangles, more than the limit of {}",
                                      formatCount(static_cast<double>(triangles)),
                                      formatCount(static_cast<double>(kMaxMeshTriangles))));
    }
    std::size_t fileTriangles = result.droppedTriangles;
    std::vector<JoinedMesh> joined(scene->mNumMeshes);
    std::uint64_t vertices = 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      const aiMesh& mesh = *scene->mMeshes[m];
      if ((mesh.mPrimitiveTypes & (aiPrimitiveType_TRIANGLE | aiPrimitiveType_POLYGON)) == 0) {
        continue;
      }
      fileTriangles += mesh.mNumFaces;
      joined[m] = joinMesh(mesh, result.droppedTriangles);
      vertices += joined[m].source.size();
    }
    // Refuse before copying: glint's arrays take 12 bytes per triangle and 48 per vertex.
    const double bytes =
        12.0 * static_cast<double>(triangles) + 48.0 * static_cast<double>(vertices);
    const std::uint64_t physical = physicalMemoryBytes();
    if (physical != 0 && bytes > static_cast<double>(physical) / 2) {
      throw MeshLoadError(fmt::format("its {} triangles need {}, more than half the memory ({})",
                                      formatCount(static_cast<double>(triangles)),
                                      formatBytes(bytes),
                                      formatBytes(static_cast<double>(physical))));
    }

    // Only the materials the triangles use, in order of first use.
    std::vector<std::uint32_t> materialOf(scene->mNumMaterials, kUnused);
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      const aiMesh& mesh = *scene->mMeshes[m];
      if (joined[m].indices.empty()) continue;
      TriangleMesh part = convertMesh(mesh, std::move(joined[m]));
      if (part.indices.empty()) continue;
      const unsigned source = mesh.mMaterialIndex;
      if (source < scene->mNumMaterials && scene->mMaterials[source] != nullptr) {
        if (materialOf[source] == kUnused) {
          materialOf[source] = static_cast<std::uint32_t>(result.materials.size());
          result.materials.push_back(convertMaterial(*scene->mMaterials[source]));
        }
        part.materialIndex = materialOf[source];
      } else {
        part.materialIndex = static_cast<std::uint32_t>(result.materials.size());
        result.materials.push_back({"", kMeshDefaultMaterial, Color(), false});
      }
      result.parts.push_back(std::move(part));
    }
    if (result.parts.empty()) {
      throw MeshLoadError(
          fmt::format("all {} triangles are degenerate (zero area, non-finite or "
                      "invalid vertices)",
                      fileTriangles));
    }
  } catch (const std::bad_alloc&) {
    throw MeshLoadError("not enough memory to load it");
  } catch (const MeshLoadError&) {
    throw;
  } catch (const std::exception& e) {  // an importer's exception that escaped assimp
    throw MeshLoadError(assimpReason(e.what()));
  }
  return result;
}

// ---- The import in a child process. Fuzzing found memory corruption in assimp 5.2's importers
// (heap overflows in the glTF 2.0 and PLY readers, a crash in OFF's) that no check before the
// import can rule out: the child process runs assimp and sends the MeshFile back through a pipe;
// a crash or corruption there is a refused file, never a crashed or corrupted renderer. The parent
// checks what it receives (sizes, indices, materials) before using it.

static_assert(std::is_trivially_copyable_v<Material> && std::is_trivially_copyable_v<Color> &&
              std::is_trivially_copyable_v<Point3> && std::is_trivially_copyable_v<Normal3>);

// Writes everything or stops silently (the parent sees a short message).
bool writeAll(int fd, const void* data, std::size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

template <typename T>
bool writeValue(int fd, const T& value) {
  return writeAll(fd, &value, sizeof value);
}

template <typename T>
bool writeVector(int fd, const std::vector<T>& values) {
  return writeValue(fd, std::uint64_t{values.size()}) &&
         writeAll(fd, values.data(), values.size() * sizeof(T));
}

bool writeMessage(int fd, char tag, const std::string& text) {
  return writeValue(fd, tag) && writeValue(fd, std::uint64_t{text.size()}) &&
         writeAll(fd, text.data(), text.size());
}

bool writeMeshFile(int fd, const MeshFile& file) {
  bool ok = writeValue(fd, 'M') && writeValue(fd, std::uint64_t{file.droppedTriangles}) &&
            writeValue(fd, std::uint64_t{file.materials.size()});
  for (const MeshMaterial& m : file.materials) {
    ok = ok && writeMessage(fd, 'N', m.name) && writeValue(fd, m.material) &&
         writeValue(fd, m.emission) && writeValue(fd, static_cast<char>(m.fromFile));
  }
  ok = ok && writeValue(fd, std::uint64_t{file.parts.size()});
  for (const TriangleMesh& part : file.parts) {
    ok = ok && writeValue(fd, part.materialIndex) && writeValue(fd, part.emission) &&
         writeVector(fd, part.positions) && writeVector(fd, part.normals) &&
         writeVector(fd, part.indices);
  }
  return ok;
}

// Reads what the child sent, refusing anything inconsistent.
// Reads the child's answer, waiting at most until `deadline` for it: a reader that loops (as
// assimp's importers have on malformed files) must not hang glint.
class Reader {
 public:
  Reader(int fd, std::chrono::steady_clock::time_point deadline) : fd_(fd), deadline_(deadline) {}
  // Reads, from its start, a file the child has finished writing: nothing to wait for.
  explicit Reader(int file) : fd_(file), file_(true) {}
  bool timedOut() const { return timedOut_; }
  void bytes(void* data, std::size_t size) {
    char* p = static_cast<char*>(data);
    while (file_ && size > 0) {
      const ssize_t n = ::pread(fd_, p, size, offset_);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) throw MeshLoadError("invalid file: the mesh reader stopped before its answer");
      p += n;
      offset_ += n;
      size -= static_cast<std::size_t>(n);
    }
    while (size > 0) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline_ - std::chrono::steady_clock::now());
      pollfd ready{fd_, POLLIN, 0};
      const int polled = left.count() > 0 ? ::poll(&ready, 1,
                                                   static_cast<int>(std::min<std::int64_t>(
                                                       left.count(), std::int64_t{1} << 30)))
                                          : 0;
      if (polled < 0 && errno == EINTR) continue;
      if (polled == 0) {
        timedOut_ = true;
        throw MeshLoadError("invalid file: the mesh library did not finish reading it within " +
                            formatSeconds(deadline_ - started_));
      }
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
    out.resize(static_cast<std::size_t>(count(limit)));
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
  file.materials.resize(static_cast<std::size_t>(in.count(1 << 20)));
  for (MeshMaterial& m : file.materials) {
    if (in.value<char>() != 'N') {
      throw MeshLoadError("invalid file: the mesh reader's answer is inconsistent");
    }
    m.name = in.text();
    m.material = in.value<Material>();
    m.emission = in.value<Color>();
    m.fromFile = in.value<char>() != 0;
  }
  file.parts.resize(static_cast<std::size_t>(in.count(1 << 20)));
  std::uint64_t triangles = 0;
  for (TriangleMesh& part : file.parts) {
    part.materialIndex = in.value<std::uint32_t>();
    part.emission = in.value<Color>();
    in.vector(part.positions, std::uint64_t{1} << 32);
    in.vector(part.normals, part.positions.size());
    in.vector(part.indices, 3 * kMaxMeshTriangles);
    triangles += part.triangleCount();
    bool ok = part.materialIndex < file.materials.size() && part.indices.size() % 3 == 0 &&
              (part.normals.empty() || part.normals.size() == part.positions.size()) &&
              triangles <= kMaxMeshTriangles;
    for (const std::uint32_t i : part.indices) ok = ok && i < part.positions.size();
    if (!ok) throw MeshLoadError("invalid file: the mesh reader's answer is inconsistent");
  }
  return file;
}

// How long the child may take: kMeshReadBaseSeconds plus kMeshReadSecondsPerMiB per MiB of the
// file — assimp reads a 85 MB OBJ in ~2.5 s here, so the limit only ends a reader that loops.
std::chrono::steady_clock::duration meshReadTimeLimit(const std::filesystem::path& path) {
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  const double mib = error ? 0 : static_cast<double>(size) / (1024.0 * 1024.0);
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(kMeshReadBaseSeconds + kMeshReadSecondsPerMiB * mib));
}

MeshFile importMeshInChild(const std::filesystem::path& path, const std::string& extension) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw MeshLoadError(systemReason(errno));
  // The answer travels in a memory file when it can: the child writes it whole without waiting for
  // a reader and says 'D' on the pipe; the parent then reads it in a few large reads. Through the
  // pipe alone, 64 KiB at a time with the two processes taking turns, the 3.6 MB answer of a
  // 100k-triangle mesh took 8-18 ms on a busy 2-core machine; through the memory file, 6-9 ms.
  // When there is no memory file (memfd_create refused) or writing it fails (no memory, a file
  // size limit), the child says 'P' and the answer follows on the pipe.
  const int answer = ::memfd_create("glint-mesh-answer", MFD_CLOEXEC);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int error = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    if (answer >= 0) ::close(answer);
    throw MeshLoadError("cannot start the mesh reader: " + systemReason(error));
  }
  if (pid == 0) {
    // The child: no destructor, atexit handler or stdio flush of the parent's state runs here.
    // It dies with glint (killed or interrupted while loading), never left looping on its own.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(0);  // the parent was already gone
    ::close(fds[0]);
    // Large blocks from the heap rather than each from its own mmap: assimp's OBJ reader and the
    // post-processing free buffers of megabytes (the file, a line buffer of the file's size, the
    // meshes PreTransformVertices replaces) that later ones then reuse instead of faulting in
    // fresh pages (~4 ms of a 100k-triangle OBJ). 32 MiB is the most glibc accepts. The child
    // ends with _exit, so its heap is never given back in any case.
    ::mallopt(M_MMAP_THRESHOLD, 32 << 20);
    ::signal(SIGXFSZ, SIG_IGN);  // a write past a file size limit fails instead
    MeshFile result;
    std::string error;
    try {
      result = importMesh(path, extension);
    } catch (const MeshLoadError& e) {
      error = e.what();
    } catch (...) {
      error = "invalid file: the mesh library failed reading it";
    }
    const auto send = [&](int fd) {
      return error.empty() ? writeMeshFile(fd, result) : writeMessage(fd, 'E', error);
    };
    if (answer >= 0 && send(answer)) {
      writeValue(fds[1], 'D');
      ::_exit(0);
    }
    // A partly written memory file would hold its pages until the parent closes it, after the
    // whole answer has come through the pipe as well: under the memory pressure that made the
    // write fail, give them back first.
    if (answer >= 0) static_cast<void>(::ftruncate(answer, 0));
    if (writeValue(fds[1], 'P')) {
      send(fds[1]);
    }
    ::_exit(0);
  }
  ::close(fds[1]);
  std::optional<MeshFile> file;
  std::string failure;
  Reader in(fds[0], std::chrono::steady_clock::now() + meshReadTimeLimit(path));
  try {
    const char where = in.value<char>();
    if (where == 'D' && answer >= 0) {
      Reader written(answer);
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
  }
  ::close(fds[0]);  // a child still writing gets EPIPE and ends
  if (answer >= 0) ::close(answer);
  if (in.timedOut()) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
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

}  // namespace

MeshFile readMeshFile(const std::filesystem::path& path) {
  std::uint64_t size = 0;
  const std::string header = readHeader(path, size);
  const std::string extension = checkedExtension(path);
  if (extension == ".ply") checkPlyHeader(header, size);
  if (extension == ".gltf" || extension == ".glb") checkGltfPrimitives(path, extension, size);
  return importMeshInChild(path, extension);
}

namespace {

// Calls `line` with every line of the file (without its '\n'), reading 64 KiB at a time and keeping
// at most kMaxScannedLine bytes of a line: counting needs no more, and memory stays bounded for any
// file. Lines are found with memchr and passed as views into the buffer; only a line that spans two
// reads is copied. Throws MeshLoadError when the file cannot be read.
constexpr std::size_t kMaxScannedLine = 256;

template <typename LineFn>
void forEachLine(const std::filesystem::path& path, LineFn&& line) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw MeshLoadError(systemReason(errno));
  std::string carried;  // the start of a line that continues in the next read
  bool carrying = false;
  const auto keep = [&](const char* begin, std::size_t size) {
    carried.append(begin, std::min(size, kMaxScannedLine - carried.size()));
  };
  std::vector<char> buffer(std::size_t{1} << 16);
  for (;;) {
    const ssize_t n = ::read(fd, buffer.data(), buffer.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int error = errno;
      ::close(fd);
      throw MeshLoadError(systemReason(error));
    }
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
  ::close(fd);
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

// Bytes of the glTF file plus the regular files its "uri" strings name (data: URIs are inside the
// file already). A plain scan for `"uri"`, not a JSON parse: an estimate needs no more.
std::uint64_t gltfBytes(const std::filesystem::path& path, std::uint64_t size) {
  std::uint64_t total = size;
  if (size > (std::uint64_t{64} << 20)) return total;  // a .gltf this big holds its own data
  std::string text;
  {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw MeshLoadError(systemReason(errno));
    char buffer[1 << 16];
    for (;;) {
      const ssize_t n = ::read(fd, buffer, sizeof buffer);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0 || text.size() > size) break;
      text.append(buffer, static_cast<std::size_t>(n));
    }
    ::close(fd);
  }
  std::set<std::string> seen;
  for (std::size_t at = text.find("\"uri\""); at != std::string::npos;
       at = text.find("\"uri\"", at + 5)) {
    const std::size_t open = text.find('"', text.find(':', at + 5));
    if (open == std::string::npos) break;
    const std::size_t close = text.find('"', open + 1);
    if (close == std::string::npos) break;
    const std::string uri = text.substr(open + 1, close - open - 1);
    if (uri.rfind("data:", 0) == 0 || !seen.insert(uri).second) continue;
    struct stat info {};
    const std::filesystem::path file = path.parent_path() / uri;
    if (::stat(file.c_str(), &info) == 0 && S_ISREG(info.st_mode)) {
      total += static_cast<std::uint64_t>(info.st_size);
    }
  }
  return total;
}

}  // namespace

double meshCopyBytes(double triangles, double vertices) {
  return kMeshBytesPerTriangle * triangles + kMeshBytesPerVertex * vertices;
}

MeshSizeEstimate estimateMeshSize(const std::filesystem::path& path) {
  std::uint64_t size = 0;
  const std::string header = readHeader(path, size);
  const std::string extension = checkedExtension(path);
  if (extension == ".ply") return checkPlyHeader(header, size);
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
    forEachLine(path, [&](std::string_view line) {
      if (firstWord(line) == "facet") ++estimate.triangles;
    });
    estimate.vertices = estimate.triangles / 2;
    return estimate;
  }
  if (extension == ".obj") {
    forEachLine(path, [&](std::string_view line) {
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
    estimate.triangles = gltfBytes(path, size) / 12;
    estimate.vertices = estimate.triangles / 2;
    return estimate;
  }
  return estimate;  // not reached: every extension of kMeshExtensions is handled above
}

std::filesystem::path MeshCache::keyOf(const std::filesystem::path& path) {
  std::error_code error;
  std::filesystem::path key = std::filesystem::weakly_canonical(path, error);
  if (error) key = std::filesystem::absolute(path, error).lexically_normal();
  if (error) key = path.lexically_normal();
  return key;
}

std::shared_ptr<const MeshFile> MeshCache::read(const std::filesystem::path& key,
                                                const std::filesystem::path& path) {
  if (const auto it = entries_.find(key); it != entries_.end()) {
    if (it->second.file) return it->second.file;
    throw MeshLoadError(it->second.error);
  }
  ++filesRead_;
  try {
    auto file = std::make_shared<const MeshFile>(readMeshFile(path));
    entries_[key] = {file, {}};
    return file;
  } catch (const MeshLoadError& e) {
    entries_[key] = {nullptr, e.what()};
    throw;
  }
}

std::shared_ptr<const MeshFile> MeshCache::load(const std::filesystem::path& path) {
  return read(keyOf(path), path);
}

std::shared_ptr<const MeshFile> MeshCache::load(const std::filesystem::path& path,
                                                const MeshBudget& budget) {
  const std::filesystem::path key = keyOf(path);
  const auto it = entries_.find(key);
  if (it != entries_.end() && !it->second.file) throw MeshLoadError(it->second.error);
  const bool cached = it != entries_.end();
  // An OBJ or STL whose size alone shows that no estimate could exceed the budget is not scanned
  // (a 100k-triangle OBJ: ~10 ms saved). A file that cannot be read fails in read() instead.
  bool bounded = false;
  if (!cached) {
    const std::string ext = lowerExtension(path);
    struct stat info {};
    if ((ext == ".obj" || ext == ".stl") && ::stat(path.c_str(), &info) == 0 &&
        S_ISREG(info.st_mode)) {
      const double bound =
          kMeshBudgetBytesPerFileByte * static_cast<double>(info.st_size) + kMeshBudgetSlackBytes;
      bounded = meshBytes_ + bound + static_cast<double>(budget.otherBytes) <=
                static_cast<double>(budget.limit);
    }
  }
  if (!cached && !bounded) {
    MeshSizeEstimate size;
    try {
      size = estimateMeshSize(path);
    } catch (const MeshLoadError& e) {
      entries_[key] = {nullptr, e.what()};
      ++filesRead_;
      throw;
    }
    const double triangles = static_cast<double>(size.triangles);
    const double vertices = static_cast<double>(size.vertices);
    // The cached file, this object's world copy and its share of the BVH.
    const double bytes = 2 * meshCopyBytes(triangles, vertices) + kBvhBytesPerTriangle * triangles;
    const double total = meshBytes_ + bytes + static_cast<double>(budget.otherBytes);
    if (total > static_cast<double>(budget.limit)) {
      throw MeshTooLargeError(fmt::format(
          "its estimated {} triangles need about {} as a mesh and its BVH; with {} already "
          "committed (the image's film and the meshes before it) that is more than the memory "
          "limit of {}",
          formatCount(triangles), formatBytes(bytes),
          formatBytes(meshBytes_ + static_cast<double>(budget.otherBytes)),
          formatBytes(static_cast<double>(budget.limit))));
    }
  }
  std::shared_ptr<const MeshFile> file = read(key, path);
  // The real sizes replace the estimate.
  double triangles = 0;
  double vertices = 0;
  for (const TriangleMesh& part : file->parts) {
    triangles += static_cast<double>(part.triangleCount());
    vertices += static_cast<double>(part.positions.size());
  }
  const double copy = meshCopyBytes(triangles, vertices);
  const double bytes = (cached ? copy : 2 * copy) + kBvhBytesPerTriangle * triangles;
  if (cached && meshBytes_ + bytes + static_cast<double>(budget.otherBytes) >
                    static_cast<double>(budget.limit)) {
    throw MeshTooLargeError(fmt::format(
        "another instance of its {} triangles needs about {} with its BVH; with {} already "
        "committed (the image's film and the meshes before it) that is more than the memory limit "
        "of {}",
        formatCount(triangles), formatBytes(bytes),
        formatBytes(meshBytes_ + static_cast<double>(budget.otherBytes)),
        formatBytes(static_cast<double>(budget.limit))));
  }
  meshBytes_ += bytes;
  return file;
}

std::vector<TriangleMesh> instantiateMesh(const MeshFile& file,
                                          const std::optional<Transform>& worldFromFile,
                                          bool smooth) {
  bool mirror = false;
  if (worldFromFile) {
    const auto& m = worldFromFile->matrix().m;
    const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                       m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                       m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    mirror = det < 0;
  }
  std::vector<TriangleMesh> out;
  out.reserve(file.parts.size());
  for (const TriangleMesh& part : file.parts) {
    TriangleMesh mesh;
    mesh.materialIndex = part.materialIndex;
    mesh.emission = part.emission;
    mesh.indices = part.indices;
    if (mirror) {
      for (std::size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
        std::swap(mesh.indices[i + 1], mesh.indices[i + 2]);
      }
    }
    if (!worldFromFile) {
      mesh.positions = part.positions;
      if (smooth) mesh.normals = part.normals;
    } else {
      const Transform& t = *worldFromFile;
      mesh.positions.reserve(part.positions.size());
      for (const Point3& p : part.positions) mesh.positions.push_back(t(p));
      if (smooth) {
        mesh.normals.reserve(part.normals.size());
        for (const Normal3& n : part.normals) mesh.normals.push_back(normalize(t(n)));
      }
    }
    out.push_back(std::move(mesh));
  }
  return out;
}

}  // namespace glint

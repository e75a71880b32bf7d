#include "glint/io/mesh_loader.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <exception>
#include <new>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>
#include <assimp/Importer.hpp>

#include "glint/io/scene_limits.h"

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

// Fails early, with the system's reason, for what assimp would only call "Unable to open file":
// a missing path, a folder, a device or pipe (which could block or never end), no permission.
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

// PLY and OFF headers declare element counts that assimp trusts, reserving memory for them before
// it reads any element: a 200-byte PLY claiming 300 million faces would cost gigabytes and minutes.
// Counts that the file's size cannot hold, or more faces than kMaxMeshTriangles, are refused here.
// Other formats carry no counts (OBJ), or assimp checks them against the size (STL, glTF).
void checkDeclaredCounts(const std::string& header, std::uint64_t size) {
  std::istringstream in(header);
  std::string line;
  if (header.rfind("ply", 0) == 0) {
    bool ascii = true;
    double needed = 0;
    double elementBytes = 0;
    double elementCount = 0;
    std::string declared;
    while (std::getline(in, line)) {
      std::istringstream words(line);
      std::string keyword;
      words >> keyword;
      if (keyword == "format") {
        std::string format;
        words >> format;
        ascii = format == "ascii";
      } else if (keyword == "element" || keyword == "end_header") {
        needed += elementBytes * elementCount;
        std::string name;
        elementCount = 0;
        elementBytes = 0;
        if (keyword == "end_header") break;
        words >> name >> elementCount;
        if (!words || !(elementCount >= 0)) return;  // not understood: assimp's to judge
        if (name == "face") refuseFaces(elementCount);
        declared += fmt::format("{}{} {}", declared.empty() ? "" : " and ",
                                formatCount(elementCount), name);
      } else if (keyword == "property") {
        std::string type;
        words >> type;
        if (type == "list") words >> type;  // the count's type; the list may be empty
        elementBytes += plyScalarBytes(type, ascii);
      }
    }
    refuseCounts(needed, size, declared + " elements");
    return;
  }
  // OFF: a keyword ending in "OFF" (COFF, NOFF, ...), then vertex, face and edge counts; comments
  // start with '#'. A vertex takes at least "0 0 0\n", a face "3 0 0 0\n".
  std::vector<std::string> tokens;
  while (tokens.size() < 3 && std::getline(in, line)) {
    std::istringstream words(line.substr(0, line.find('#')));
    std::string token;
    while (tokens.size() < 3 && words >> token) tokens.push_back(token);
    if (tokens.size() == 1 &&
        (tokens[0].size() < 3 || tokens[0].compare(tokens[0].size() - 3, 3, "OFF") != 0)) {
      return;
    }
  }
  if (tokens.size() < 3 || tokens[0].size() < 3 ||
      tokens[0].compare(tokens[0].size() - 3, 3, "OFF") != 0) {
    return;
  }
  double vertices = 0;
  double faces = 0;
  try {
    vertices = std::stod(tokens[1]);
    faces = std::stod(tokens[2]);
  } catch (const std::exception&) {
    return;
  }
  refuseFaces(faces);
  refuseCounts(6 * vertices + 8 * faces, size,
               fmt::format("{} vertices and {} faces", formatCount(vertices), formatCount(faces)));
}

// assimp's message in the user's terms.
std::string assimpReason(std::string_view message) {
  if (message.find("No suitable reader found") != std::string_view::npos) {
    return "not a mesh format glint reads (OBJ, PLY, STL, glTF 2.0 and the other formats of "
           "assimp), or a damaged file";
  }
  while (!message.empty() && (message.back() == '.' || message.back() == '\n')) {
    message.remove_suffix(1);
  }
  if (message.empty()) return "the mesh library could not read it";
  return "invalid file: " + std::string(message);
}

bool hasExtension(const std::filesystem::path& path, std::string_view extension) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == extension;
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

// Keeps only the vertices the triangles use, in order of first use.
void compactVertices(TriangleMesh& mesh) {
  std::vector<std::uint32_t> newIndex(mesh.positions.size(), kUnused);
  std::uint32_t count = 0;
  for (std::uint32_t& index : mesh.indices) {
    if (newIndex[index] == kUnused) newIndex[index] = count++;
    index = newIndex[index];
  }
  std::vector<Point3> positions(count);
  std::vector<Normal3> normals(mesh.normals.empty() ? 0 : count);
  for (std::size_t old = 0; old < newIndex.size(); ++old) {
    if (newIndex[old] == kUnused) continue;
    positions[newIndex[old]] = mesh.positions[old];
    if (!normals.empty()) normals[newIndex[old]] = mesh.normals[old];
  }
  mesh.positions = std::move(positions);
  mesh.normals = std::move(normals);
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

// One assimp mesh (triangulated, its node transforms baked) → a TriangleMesh in file space.
// Degenerate triangles are counted into `dropped` and left out.
TriangleMesh convertMesh(const aiMesh& in, std::size_t& dropped) {
  TriangleMesh out;
  out.positions.resize(in.mNumVertices);
  for (unsigned v = 0; v < in.mNumVertices; ++v) {
    const aiVector3D& p = in.mVertices[v];
    out.positions[v] = {p.x, p.y, p.z};
  }
  if (in.HasNormals()) {
    out.normals.resize(in.mNumVertices);
    for (unsigned v = 0; v < in.mNumVertices; ++v) {
      const aiVector3D& n = in.mNormals[v];
      out.normals[v] = {n.x, n.y, n.z};
    }
  }
  out.indices.reserve(std::size_t{3} * in.mNumFaces);
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
    const Point3& p0 = out.positions[a];
    const Point3& p1 = out.positions[b];
    const Point3& p2 = out.positions[c];
    const double twiceArea = length(cross(p1 - p0, p2 - p0));
    const double longest =
        std::max({distanceSquared(p0, p1), distanceSquared(p1, p2), distanceSquared(p2, p0)});
    // Also false for NaN and infinite coordinates, which make the area or the edges non-finite.
    if (!(twiceArea > kDegenerateTolerance * longest) || !std::isfinite(twiceArea) ||
        !std::isfinite(longest)) {
      ++dropped;
      continue;
    }
    out.indices.insert(out.indices.end(), {a, b, c});
  }
  compactVertices(out);
  repairNormals(out);
  return out;
}

}  // namespace

MeshFile readMeshFile(const std::filesystem::path& path) {
  std::uint64_t size = 0;
  const std::string header = readHeader(path, size);
  checkDeclaredCounts(header, size);

  Assimp::Importer importer;
  // Points and lines are not surfaces: SortByPType removes them after triangulation.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  importer.SetPropertyFloat(AI_CONFIG_PP_GSN_MAX_SMOOTHING_ANGLE,
                            static_cast<float>(kMeshCreaseAngleDegrees));
  unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                   aiProcess_PreTransformVertices | aiProcess_GenSmoothNormals |
                   aiProcess_SortByPType;
  if (hasExtension(path, ".stl")) {
    // STL stores one normal per facet, not per vertex: drop them so that GenSmoothNormals (which
    // keeps normals a mesh already has) smooths the surface, and JoinIdenticalVertices can then
    // share the vertices of neighbouring facets.
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
    if (scene->mRootNode == nullptr || facesWithTriangles(*scene) == 0) {
      throw MeshLoadError(result.droppedTriangles > 0
                              ? fmt::format("all {} triangles have vertex indices out of range",
                                            result.droppedTriangles)
                              : std::string("the file holds no triangles"));
    }
    scene = importer.ApplyPostProcessing(flags);
    if (scene == nullptr) throw MeshLoadError(assimpReason(importer.GetErrorString()));

    // Refuse before copying: glint's arrays take 12 bytes per triangle and 48 per vertex.
    std::uint64_t triangles = 0;
    std::uint64_t vertices = 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      triangles += scene->mMeshes[m]->mNumFaces;
      vertices += scene->mMeshes[m]->mNumVertices;
    }
    if (triangles > kMaxMeshTriangles) {
      throw MeshLoadError(fmt::format("it holds {} triangles, more than the limit of {}",
                                      formatCount(static_cast<double>(triangles)),
                                      formatCount(static_cast<double>(kMaxMeshTriangles))));
    }
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
    std::size_t fileTriangles = result.droppedTriangles;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      const aiMesh& mesh = *scene->mMeshes[m];
      if ((mesh.mPrimitiveTypes & (aiPrimitiveType_TRIANGLE | aiPrimitiveType_POLYGON)) == 0) {
        continue;
      }
      fileTriangles += mesh.mNumFaces;
      TriangleMesh part = convertMesh(mesh, result.droppedTriangles);
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

std::shared_ptr<const MeshFile> MeshCache::load(const std::filesystem::path& path) {
  std::error_code error;
  std::filesystem::path key = std::filesystem::weakly_canonical(path, error);
  if (error) key = std::filesystem::absolute(path, error).lexically_normal();
  if (error) key = path.lexically_normal();
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

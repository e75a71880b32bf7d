#include "glint/mesh/assimp_import.h"

#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <assimp/BaseImporter.h>
#include <assimp/DefaultIOSystem.h>
#include <assimp/config.h>
#include <assimp/importerdesc.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/texture.h>
#include <fmt/format.h>
#include <assimp/DefaultLogger.hpp>
#include <assimp/IOStream.hpp>
#include <assimp/Importer.hpp>
#include <assimp/LogStream.hpp>

#include "glint/core/file_access.h"
#include "glint/mesh/import_child.h"
#include "glint/mesh/mesh_repair.h"
#include "glint/mesh/obj_check.h"
#include "glint/mesh/obj_fast_parse.h"
#include "glint/mesh/ply_check.h"
#include "glint/mesh/stl_check.h"
#include "glint/scene/scene_limits.h"

namespace glint {

namespace {

constexpr std::uint32_t kUnused = 0xffffffffu;

// assimp's stream over a file glint opened itself (DefaultIOStream's constructor from a FILE* is
// protected); closed when assimp deletes it.
class OpenedFileStream : public Assimp::DefaultIOStream {
 public:
  OpenedFileStream(FILE* file, const std::string& name) : DefaultIOStream(file, name) {}
};

// assimp's file access for one mesh file and the files it names (MTL, glTF buffers): regular files
// only (file_access.h: never opened when they are not, and checked again on what was opened),
// read-only, and the named files only inside the folder tree of `rule`. A name such as /dev/zero
// or a FIFO in a hostile file would otherwise be read without end or block forever, and one such
// as ../../etc/passwd would be read from anywhere. A named file that breaks a rule refuses the
// whole mesh file (refusal()), as DESIGN.md §9 asks of every file a mesh names; one that does not
// exist is left to the importer (an OBJ without its MTL still loads).
class MeshFileAccess : public Assimp::DefaultIOSystem {
 public:
  explicit MeshFileAccess(const ReferencedFileRule& rule) : rule_(rule) {}

  using DefaultIOSystem::Exists;
  Assimp::IOStream* Open(const char* file, const char* mode) override {
    if (file == nullptr || mode == nullptr ||
        std::string_view(mode).find_first_of("wa+") != std::string_view::npos) {
      return nullptr;
    }
    ReadableFile opened = openChecked(file);
    if (opened.fd < 0) return nullptr;
    FILE* stream = ::fdopen(opened.fd, "rb");
    if (stream == nullptr) return nullptr;
    opened.release();  // the stream closes it
    opened_.emplace_back(file);
    return new OpenedFileStream(stream, file);
  }
  // The files opened so far, as the importer named them (the mesh file, an OBJ's MTL files...).
  const std::vector<std::string>& opened() const { return opened_; }
  // The file opened for reading when the rules allow it (else fd −1, the refusal kept).
  ReadableFile openChecked(const char* file) {
    ReadableFile opened;
    if (breaksRule(file)) return opened;
    opened = openForReading(file);
    if (!accepted(file, opened) || refused(rule_.openedRefusal(opened.fd, file))) {
      return ReadableFile();
    }
    return opened;
  }
  // DefaultIOSystem::Exists opens the file with fopen, which blocks on a FIFO.
  bool Exists(const char* file) const override {
    return file != nullptr && !breaksRule(file) && accepted(file, statForReading(file));
  }

  // Why a file the mesh file names refuses it ("" when none did), in the user's words.
  const std::string& refusal() const { return refusal_; }

 private:
  // Whether the rules forbid reading `file`; the refusal is kept only when the file exists.
  // Importers probe names that are not the file a mesh names (assimp's glTF importer joins the
  // mesh's folder twice, "../../x.bin" for "../m.gltf"), and a name that leads nowhere reads
  // nothing: a missing buffer is then the importer's "could not open", not a refusal.
  bool breaksRule(const char* file) const {
    const std::string why = rule_.refusal(file);
    if (why.empty()) return false;
    if (statForReading(file).refusal != FileRefusal::Missing) refused(why);
    return true;
  }
  // Keeps the first refusal; true when `why` is one.
  bool refused(const std::string& why) const {
    if (!why.empty() && refusal_.empty()) refusal_ = why;
    return !why.empty();
  }
  bool accepted(const char* file, const ReadableFile& found) const {
    if (found.refusal == FileRefusal::NotRegular) {
      refused(rule_.isMeshFile(file)
                  ? std::string("it is not a regular file")
                  : fmt::format("it refers to '{}', which is not a regular file (a file a mesh "
                                "names is never read from a FIFO or a device)",
                                rule_.asWritten(file)));
    }
    return found.refusal == FileRefusal::None;
  }

  const ReferencedFileRule& rule_;  // outlives the importer (importMesh's caller holds it)
  mutable std::string refusal_;     // set by the first refused file, from the const Exists too
  std::vector<std::string> opened_;
};

// The material names an OBJ file's MTL files define (`newmtl NAME`: the rest of the line, blanks
// trimmed, as assimp reads it): every file the import opened other than the OBJ file itself.
std::set<std::string> mtlMaterialNames(MeshFileAccess& files, const std::string& objFile) {
  std::set<std::string> names;
  for (const std::string& name : files.opened()) {
    if (name == objFile) continue;
    const ReadableFile file = files.openChecked(name.c_str());
    if (file.fd < 0) continue;
    std::string text;
    char buffer[1 << 16];
    for (ssize_t n; (n = ::read(file.fd, buffer, sizeof buffer)) > 0;) {
      text.append(buffer, static_cast<std::size_t>(n));
    }
    const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
    for (std::size_t start = 0; start < text.size();) {
      std::size_t end = text.find('\n', start);
      if (end == std::string::npos) end = text.size();
      std::size_t i = start;
      while (i < end && blank(text[i])) ++i;
      if (text.compare(i, 6, "newmtl") == 0 && i + 6 < end && blank(text[i + 6])) {
        std::size_t from = i + 6;
        std::size_t to = end;
        while (from < to && blank(text[from])) ++from;
        while (to > from && blank(text[to - 1])) --to;
        names.emplace(text, from, to - from);
      }
      start = end + 1;
    }
  }
  return names;
}

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

// Why a file the reader ran out of memory on is refused (kMeshReaderMemory*, import_child.h).
constexpr std::string_view kNotEnoughMemory =
    "not enough memory to read it (the mesh reader may use 512 MiB plus 256 bytes per byte of the "
    "file, and this file asks for more: damaged or malformed counts, or an OBJ whose material "
    "libraries define tens of thousands of materials, ~26 KB each in the mesh library?)";
static_assert(kMeshReaderMemoryBaseBytes == 512.0 * 1024 * 1024 &&
              kMeshReaderMemoryPerFileByte == 256);

// assimp's message in the user's terms.
std::string assimpReason(std::string_view message) {
  if (message.find("No suitable reader found") != std::string_view::npos) {
    return "the file's content does not match its extension, or it is damaged";
  }
  while (!message.empty() && (message.back() == '.' || message.back() == '\n')) {
    message.remove_suffix(1);
  }
  if (message.empty()) return "the mesh library could not read it";
  // assimp reports an allocation that failed by the exception's name; the mesh reader's address
  // space is capped by the file's size (mesh_reader_side.cpp), so a file that claims more than it
  // holds ends here.
  if (message.find("bad_alloc") != std::string_view::npos) {
    return std::string(kNotEnoughMemory);
  }
  return "invalid file: " + std::string(message);
}

// A file's colour component made valid for glint: finite and ≥ 0.
double component(float value) { return std::isfinite(value) && value > 0 ? value : 0.0; }
Color colorOf(const aiColor3D& c) { return {component(c.r), component(c.g), component(c.b)}; }

// The textures a material names (the first of each type), with the images it embeds copied into
// `embedded` once each. An embedded image is named "*N" (glTF's buffers and data: URIs, in assimp's
// form) or by a file name assimp found inside the file; only compressed ones (PNG, JPEG...: width
// = their size in bytes, height 0) are kept; raw texel arrays are named like files and then fail
// to load as such, reported by the scene builder.
void convertTextures(const aiScene& scene, const aiMaterial& m, MeshMaterial& out,
                     std::vector<std::vector<std::uint8_t>>& embedded,
                     std::vector<const aiTexture*>& embeddedFrom) {
  static constexpr std::pair<aiTextureType, MeshTextureSlot> kSlots[] = {
      {aiTextureType_DIFFUSE, kDiffuseTexture},   {aiTextureType_BASE_COLOR, kDiffuseTexture},
      {aiTextureType_SPECULAR, kSpecularTexture}, {aiTextureType_EMISSIVE, kEmissiveTexture},
      {aiTextureType_NORMALS, kNormalTexture},    {aiTextureType_HEIGHT, kBumpTexture}};
  for (const auto& [type, slot] : kSlots) {
    MeshTexture& texture = out.textures[slot];
    if (texture.present() || m.GetTextureCount(type) == 0) continue;
    aiString path;
    if (m.GetTexture(type, 0, &path) != AI_SUCCESS || path.length == 0) continue;
    const aiTexture* image = scene.GetEmbeddedTexture(path.C_Str());
    if (image != nullptr && image->mHeight == 0 && image->pcData != nullptr && image->mWidth > 0) {
      const auto known = std::find(embeddedFrom.begin(), embeddedFrom.end(), image);
      if (known == embeddedFrom.end()) {
        const auto* bytes = reinterpret_cast<const std::uint8_t*>(image->pcData);
        embedded.emplace_back(bytes, bytes + image->mWidth);
        embeddedFrom.push_back(image);
        texture.embedded = static_cast<std::int32_t>(embedded.size() - 1);
      } else {
        texture.embedded = static_cast<std::int32_t>(known - embeddedFrom.begin());
      }
      continue;
    }
    texture.file = path.C_Str();
  }
}

// Adds to `ignored` ("map_Ka 'wood.png'") the textures material `m` names that glint does not use:
// an OBJ's ambient, opacity, shininess, reflection and displacement maps (assimp's texture types
// for them; glTF's PBR maps come as other types, and the documentation says they are ignored).
// At most kMaxIgnoredTextures entries, each named once.
void noteIgnoredTextures(const aiMaterial& m, std::vector<std::string>& ignored) {
  static constexpr std::pair<aiTextureType, const char*> kIgnored[] = {
      {aiTextureType_AMBIENT, "map_Ka"},
      {aiTextureType_OPACITY, "map_d"},
      {aiTextureType_SHININESS, "map_Ns"},
      {aiTextureType_REFLECTION, "refl"},
      {aiTextureType_DISPLACEMENT, "disp"}};
  for (const auto& [type, keyword] : kIgnored) {
    for (unsigned i = 0; i < m.GetTextureCount(type); ++i) {
      aiString path;
      if (m.GetTexture(type, i, &path) != AI_SUCCESS) continue;
      // Escaped by the renderer, which trusts nothing the reader sends.
      std::string entry = fmt::format("{} '{}'", keyword, path.C_Str());
      if (ignored.size() < kMaxIgnoredTextures &&
          std::find(ignored.begin(), ignored.end(), entry) == ignored.end()) {
        ignored.push_back(std::move(entry));
      }
    }
  }
}

// `objDefined`: for an OBJ file, the names its MTL files define (else null).
MeshMaterial convertMaterial(const aiMaterial& m, const std::set<std::string>* objDefined) {
  MeshMaterial out;
  aiString name;
  const bool named = m.Get(AI_MATKEY_NAME, name) == AI_SUCCESS;
  if (named) out.name = name.C_Str();
  aiColor4D base;
  const bool hasBase = m.Get(AI_MATKEY_BASE_COLOR, base) == AI_SUCCESS;
  // assimp's stand-in when the file has no material: named AI_DEFAULT_MATERIAL_NAME (STL, OBJ
  // without MTL) or, from the PLY reader, without any name. glTF materials carry a base colour
  // even when unnamed (and glTF's own default material is white by its specification). An OBJ's
  // `usemtl` of a name no MTL file defines (the MTL missing, or another one) is assimp's own
  // stand-in too (diffuse 0.6): the file has no material for it either.
  const bool undefinedObjMaterial =
      objDefined != nullptr && named && objDefined->count(out.name) == 0;
  if ((named && out.name == AI_DEFAULT_MATERIAL_NAME) || (!named && !hasBase) ||
      undefinedObjMaterial) {
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

// An OBJ file of the simple subset (obj_fast_parse.h), already parsed, as an importer of
// assimp's: it builds the scene assimp's OBJ importer builds for such a file — a root node named
// after the file, one child node and one mesh named after the object, one vertex per face corner
// in face order, polygons left for Triangulate, the one material "DefaultMaterial" — so that the
// same post-processing and glint's repairs then run on the same data.
class SimpleObjImporter : public Assimp::BaseImporter {
 public:
  explicit SimpleObjImporter(const SimpleObj& obj) : obj_(obj) {}
  bool CanRead(const std::string& /*file*/, Assimp::IOSystem* /*io*/,
               bool /*checkSig*/) const override {
    return true;
  }
  const aiImporterDesc* GetInfo() const override {
    static const aiImporterDesc info = {"glint simple OBJ",
                                        "",
                                        "",
                                        "the plain subset of OBJ; the rest goes to assimp's",
                                        0,
                                        0,
                                        0,
                                        0,
                                        0,
                                        "obj"};
    return &info;
  }

 protected:
  void InternReadFile(const std::string& file, aiScene* scene, Assimp::IOSystem* /*io*/) override {
    const std::size_t slash = file.find_last_of("\\/");
    buildScene(obj_, slash == std::string::npos ? file : file.substr(slash + 1), *scene);
  }

 private:
  static void buildScene(const SimpleObj& obj, const std::string& modelName, aiScene& scene) {
    scene.mRootNode = new aiNode(modelName);
    auto* child = new aiNode(obj.objectName);
    child->mParent = scene.mRootNode;
    scene.mRootNode->mNumChildren = 1;
    scene.mRootNode->mChildren = new aiNode* [1] { child };
    child->mNumMeshes = 1;
    child->mMeshes = new unsigned[1]{0};
    auto* mesh = new aiMesh;
    scene.mNumMeshes = 1;
    scene.mMeshes = new aiMesh* [1] { mesh };
    auto* material = new aiMaterial;
    const aiString name(AI_DEFAULT_MATERIAL_NAME);
    material->AddProperty(&name, AI_MATKEY_NAME);
    scene.mNumMaterials = 1;
    scene.mMaterials = new aiMaterial* [1] { material };

    mesh->mName.Set(obj.objectName);
    mesh->mMaterialIndex = 0;
    const auto corners = static_cast<unsigned>(obj.vertexIndices.size());
    mesh->mNumFaces = static_cast<unsigned>(obj.faceSizes.size());
    mesh->mFaces = new aiFace[mesh->mNumFaces];
    mesh->mNumVertices = corners;
    mesh->mVertices = new aiVector3D[corners];
    const bool normals = !obj.normalIndices.empty();
    const bool uvs = !obj.texcoordIndices.empty();
    if (normals) mesh->mNormals = new aiVector3D[corners];
    if (uvs) {
      mesh->mNumUVComponents[0] = obj.texcoordDimension;
      mesh->mTextureCoords[0] = new aiVector3D[corners];
    }
    const auto vector3 = [](const std::vector<float>& values, std::uint32_t i) {
      return aiVector3D(values[3 * std::size_t{i}], values[3 * std::size_t{i} + 1],
                        values[3 * std::size_t{i} + 2]);
    };
    unsigned corner = 0;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      aiFace& face = mesh->mFaces[f];
      face.mNumIndices = obj.faceSizes[f];
      face.mIndices = new unsigned[face.mNumIndices];
      mesh->mPrimitiveTypes |=
          face.mNumIndices > 3 ? aiPrimitiveType_POLYGON : aiPrimitiveType_TRIANGLE;
      for (unsigned k = 0; k < face.mNumIndices; ++k, ++corner) {
        face.mIndices[k] = corner;
        mesh->mVertices[corner] = vector3(obj.positions, obj.vertexIndices[corner]);
        if (normals) mesh->mNormals[corner] = vector3(obj.normals, obj.normalIndices[corner]);
        if (uvs) {
          mesh->mTextureCoords[0][corner] = vector3(obj.texcoords, obj.texcoordIndices[corner]);
        }
      }
    }
  }

  const SimpleObj& obj_;  // outlives the importer (importScene's caller holds it)
};

// What assimp's importers say only in their log, in assimp 5.2's wording, watched while a file is
// read so that it is not silent: faces its glTF readers drop for a vertex index out of range
// (without a count), and an OBJ's material library that is not there (its OBJ reader then tries
// the OBJ's own name with .mtl, the fallback).
class ImporterLogWatch : public Assimp::LogStream {
 public:
  void write(const char* message) override {
    const std::string_view text(message);
    if (text.find("faces had out-of-range indices") != std::string_view::npos) droppedFaces = true;
    if (const std::optional<std::string> name = after(text, "OBJ: Unable to locate material file ");
        name && missingMaterialLibraries.size() < kMaxIgnoredTextures) {
      missingMaterialLibraries.push_back(*name);
    }
    // Opening is said before the try; a failed one is said after it.
    if (const std::optional<std::string> name =
            after(text, "OBJ: Opening fallback material file ")) {
      fallbackMaterialLibrary = std::filesystem::path(*name).filename().string();  // beside the OBJ
    }
    if (text.find("OBJ: Unable to locate fallback material file ") != std::string_view::npos) {
      fallbackMaterialLibrary.clear();
    }
  }
  bool droppedFaces = false;
  std::vector<std::string> missingMaterialLibraries;
  std::string fallbackMaterialLibrary;

 private:
  // The rest of the message after `lead`, its line break trimmed; nothing without `lead`.
  static std::optional<std::string> after(std::string_view text, std::string_view lead) {
    const std::size_t at = text.find(lead);
    if (at == std::string_view::npos) return std::nullopt;
    std::string_view rest = text.substr(at + lead.size());
    while (!rest.empty() && (rest.back() == '\n' || rest.back() == '\r')) rest.remove_suffix(1);
    return std::string(rest);
  }
};

// Attaches an ImporterLogWatch to assimp's logger, a process-wide singleton, for one ReadFile:
// one read at a time in a process (the reader program reads one file; tests read in turn).
class WatchedRead {
 public:
  WatchedRead() : lock_(mutex()) {
    Assimp::DefaultLogger::create(nullptr, Assimp::Logger::NORMAL, 0);
    Assimp::DefaultLogger::get()->attachStream(&watch_, kSeverities);
  }
  ~WatchedRead() {
    Assimp::DefaultLogger::get()->detachStream(&watch_, kSeverities);
    Assimp::DefaultLogger::kill();
  }
  WatchedRead(const WatchedRead&) = delete;
  WatchedRead& operator=(const WatchedRead&) = delete;
  const ImporterLogWatch& seen() const { return watch_; }

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  static constexpr unsigned kSeverities =
      Assimp::Logger::Info | Assimp::Logger::Warn | Assimp::Logger::Err;
  std::lock_guard<std::mutex> lock_;
  ImporterLogWatch watch_;
};

// importMesh with assimp's importer for `extension`, or with SimpleObjImporter alone for
// `simpleObj` when given.
MeshFile importScene(const std::filesystem::path& path, const std::string& extension,
                     const ReferencedFileRule& rule, const SimpleObj* simpleObj) {
  Assimp::Importer importer;
  auto* files = new MeshFileAccess(rule);
  importer.SetIOHandler(files);  // the importer owns it
  if (simpleObj != nullptr) {
    keepOnlyImporterFor(importer, ".");                          // none
    importer.RegisterLoader(new SimpleObjImporter(*simpleObj));  // the importer owns it
  } else {
    keepOnlyImporterFor(importer, extension);
  }
  // Points and lines are not surfaces: SortByPType removes them after triangulation.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  // No JoinIdenticalVertices: joinMesh joins the vertices, faster and exactly.
  // Normals a mesh lacks are generated by glint (generateSmoothNormals) after these steps, where
  // assimp's GenSmoothNormals would run, in O(n) instead of its O(n^1.5).
  unsigned flags = aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType;
  if (extension == ".stl") {
    // STL stores one normal per facet, not per vertex: drop them so that generateSmoothNormals
    // (which keeps normals a mesh already has) smooths the surface, and joinMesh can then share the
    // vertices of neighbouring facets.
    importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS);
    flags |= aiProcess_RemoveComponent;
  }

  MeshFile result;
  try {
    // Read without post-processing first: the faces are checked before any step indexes with them.
    const aiScene* scene = nullptr;
    {
      const WatchedRead watched;
      scene = importer.ReadFile(path.string(), 0);
      result.importerDroppedFaces = watched.seen().droppedFaces;
      result.missingMaterialLibraries = watched.seen().missingMaterialLibraries;
      if (!result.missingMaterialLibraries.empty()) {
        result.fallbackMaterialLibrary = watched.seen().fallbackMaterialLibrary;
      }
    }
    if (!files->refusal().empty()) throw MeshLoadError(files->refusal());
    if (scene == nullptr) throw MeshLoadError(assimpReason(importer.GetErrorString()));
    std::optional<std::set<std::string>> objDefined;
    if (extension == ".obj") objDefined = mtlMaterialNames(*files, path.string());
    // The importer owns the scene and its steps edit it in place; so does dropInvalidFaces.
    result.droppedTriangles = dropInvalidFaces(const_cast<aiScene&>(*scene));
    // A PLY face of one or two corners is a malformed polygon (PLY has no points or lines in its
    // faces): dropped with the degenerate triangles and counted in their warning, where
    // SortByPType would remove it silently (OBJ's and glTF's points and lines are meant so).
    std::size_t malformedFaces = 0;
    for (unsigned m = 0; extension == ".ply" && m < scene->mNumMeshes; ++m) {
      const aiMesh* mesh = scene->mMeshes[m];
      for (unsigned f = 0; mesh != nullptr && f < mesh->mNumFaces; ++f) {
        const unsigned corners = mesh->mFaces[f].mNumIndices;
        if (corners == 1 || corners == 2) ++malformedFaces;
      }
    }
    splitSharedCorners(const_cast<aiScene&>(*scene));
    // Before Triangulate, whose time grows with the square of a polygon's corners.
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      const aiMesh* mesh = scene->mMeshes[m];
      for (unsigned f = 0; mesh != nullptr && f < mesh->mNumFaces; ++f) {
        if (mesh->mFaces[f].mNumIndices > kMaxFaceCorners) {
          throw MeshLoadError(fmt::format("a face has {} corners, more than the limit of {}",
                                          mesh->mFaces[f].mNumIndices, kMaxFaceCorners));
        }
      }
    }
    if (scene->mRootNode == nullptr || facesWithTriangles(*scene) == 0) {
      throw MeshLoadError(result.droppedTriangles > 0
                              ? fmt::format("all {} triangles have vertex indices out of range",
                                            result.droppedTriangles)
                              : std::string("the file holds no triangles"));
    }
    result.droppedTriangles += malformedFaces;
    scene = importer.ApplyPostProcessing(flags);
    if (scene == nullptr) throw MeshLoadError(assimpReason(importer.GetErrorString()));
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      aiMesh* mesh = scene->mMeshes[m];
      if (mesh->mNormals == nullptr &&
          (mesh->mPrimitiveTypes & (aiPrimitiveType_TRIANGLE | aiPrimitiveType_POLYGON)) != 0) {
        const SmoothNormalsReport smoothed = generateSmoothNormals(*mesh, kMeshCreaseAngleDegrees);
        if (smoothed.exactPositionsOnly) ++result.exactPositionNormalParts;
        result.crowdedNormalPositions += smoothed.crowdedPositions;
      }
    }

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
    std::vector<const aiTexture*> embeddedFrom;  // per embedded image, where it came from
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      const aiMesh& mesh = *scene->mMeshes[m];
      if (joined[m].indices.empty()) continue;
      TriangleMesh part = convertMesh(mesh, std::move(joined[m]));
      if (part.indices.empty()) continue;
      const unsigned source = mesh.mMaterialIndex;
      if (source < scene->mNumMaterials && scene->mMaterials[source] != nullptr) {
        if (materialOf[source] == kUnused) {
          materialOf[source] = static_cast<std::uint32_t>(result.materials.size());
          result.materials.push_back(
              convertMaterial(*scene->mMaterials[source], objDefined ? &*objDefined : nullptr));
          convertTextures(*scene, *scene->mMaterials[source], result.materials.back(),
                          result.embeddedImages, embeddedFrom);
          noteIgnoredTextures(*scene->mMaterials[source], result.ignoredTextures);
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
    throw MeshLoadError(std::string(kNotEnoughMemory));
  } catch (const MeshLoadError&) {
    throw;
  } catch (const std::exception& e) {  // an importer's exception that escaped assimp
    throw MeshLoadError(assimpReason(e.what()));
  }
  return result;
}

// Calls read(bytes) with the mesh file's bytes, opened as assimp's importers open it
// (MeshFileAccess) and mapped rather than copied: reading them into fresh memory costs a page
// fault per 4 KiB, mapping them with MAP_POPULATE one call. (A file cut short while mapped kills
// this child with SIGBUS: a refused file, as any crash here.) False when the file cannot be
// opened or mapped, or is empty: the importer then says why in its words.
template <class Read>
bool readMapped(const std::filesystem::path& path, const ReferencedFileRule& rule, Read read) {
  MeshFileAccess files(rule);
  const ReadableFile file = files.openChecked(path.c_str());
  struct stat status {};
  if (file.fd < 0 || ::fstat(file.fd, &status) != 0 || status.st_size <= 0) return false;
  const auto size = static_cast<std::size_t>(status.st_size);
  void* mapped = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, file.fd, 0);
  if (mapped == MAP_FAILED) return false;
  struct Unmap {
    void* bytes;
    std::size_t size;
    ~Unmap() { ::munmap(bytes, size); }
  } unmap{mapped, size};
  read(std::string_view(static_cast<const char*>(mapped), size));
  return true;
}

}  // namespace

std::optional<MeshFile> importSimpleObj(const std::filesystem::path& path,
                                        const ReferencedFileRule& rule) {
  bool located = false;
  try {
    std::optional<SimpleObj> obj;
    std::optional<ObjFault> fault;
    if (!readMapped(path, rule, [&](std::string_view text) {
          obj = parseSimpleObj(text);
          // A file outside the subset: its first malformed statement, if any, said at its place.
          if (!obj) fault = findObjFault(text);
        })) {
      return std::nullopt;
    }
    if (fault) {
      // In the reason's words, as meshErrorPlace reads them.
      located = true;
      throw MeshLoadError(fmt::format("invalid file: line {}, column {}: {}", fault->line,
                                      fault->column, fault->what));
    }
    if (!obj) return std::nullopt;
    const bool triangles = std::all_of(obj->faceSizes.begin(), obj->faceSizes.end(),
                                       [](std::uint32_t corners) { return corners == 3; });
    if (!triangles || obj->normalIndices.empty()) {
      // Polygons to triangulate or normals to generate: assimp's steps on the scene its OBJ
      // importer would have made.
      return importScene(path, ".obj", rule, &*obj);
    }
    // Nothing for assimp's steps to change: importScene's conversion straight from the arrays.
    MeshFile result;
    const std::uint64_t triangleCount = obj->faceSizes.size();
    if (triangleCount > kMaxMeshTriangles) return std::nullopt;  // assimp's words for it
    TriangleMesh part = joinSimpleObj(*obj, result.droppedTriangles);
    obj.reset();
    const double bytesNeeded = 12.0 * static_cast<double>(triangleCount) +
                               48.0 * static_cast<double>(part.positions.size());
    const std::uint64_t physical = physicalMemoryBytes();
    if (part.indices.empty() ||
        (physical != 0 && bytesNeeded > static_cast<double>(physical) / 2)) {
      return std::nullopt;
    }
    MeshMaterial material;
    material.name = AI_DEFAULT_MATERIAL_NAME;
    material.material = kMeshDefaultMaterial;
    material.fromFile = false;
    result.materials.push_back(std::move(material));
    part.materialIndex = 0;
    result.parts.push_back(std::move(part));
    return result;
  } catch (const MeshLoadError&) {
    if (located) throw;
    // Otherwise an error: assimp's importer says it in its own words.
  } catch (const std::bad_alloc&) {
  }
  return std::nullopt;
}

MeshFile importMeshWithAssimp(const std::filesystem::path& path, const std::string& extension,
                              const ReferencedFileRule& rule) {
  return importScene(path, extension, rule, nullptr);
}

namespace {

// Refuses a PLY file whose body disagrees with its header (ply_check.h), or an ASCII STL file with
// a malformed statement (stl_check.h), at its place; `find` is the check.
void checkMeshText(const std::filesystem::path& path, const ReferencedFileRule& rule,
                   std::optional<MeshFileFault> (*find)(std::string_view)) {
  std::optional<MeshFileFault> fault;
  readMapped(path, rule, [&](std::string_view bytes) { fault = find(bytes); });
  if (!fault) return;
  // In the reason's words, as meshErrorPlace reads them.
  if (fault->line > 0) {
    throw MeshLoadError(fmt::format("invalid file: line {}, column {}: {}", fault->line,
                                    fault->column, fault->what));
  }
  throw MeshLoadError("invalid file: " + fault->what);
}

}  // namespace

MeshFile importMesh(const std::filesystem::path& path, const std::string& extension,
                    const ReferencedFileRule& rule) {
  if (extension == ".ply") checkMeshText(path, rule, findPlyFault);
  if (extension == ".stl") checkMeshText(path, rule, findStlFault);
  if (extension == ".obj" && !objFastPathDisabled()) {
    if (std::optional<MeshFile> file = importSimpleObj(path, rule)) return std::move(*file);
  }
  return importMeshWithAssimp(path, extension, rule);
}

}  // namespace glint

#include "glint/factories/mesh_textures.h"

#include <cmath>
#include <limits>
#include <string>

#include <fmt/format.h>

#include "glint/core/file_access.h"
#include "glint/readers/diagnostics.h"

namespace glint {

namespace {

const char* slotName(MeshTextureSlot slot) {
  switch (slot) {
    case kDiffuseTexture:
      return "diffuse";
    case kSpecularTexture:
      return "specular";
    case kEmissiveTexture:
      return "emissive";
    case kNormalTexture:
      return "normal";
    case kBumpTexture:
      return "bump";
    case kMeshTextureSlots:
      break;
  }
  return "";
}

int hexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

double boundsDiagonal(const MeshFile& file) {
  Point3 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
            std::numeric_limits<double>::infinity()};
  Point3 hi{-lo.x, -lo.y, -lo.z};
  for (const TriangleMesh& part : file.parts) {
    for (const Point3& p : part.positions) {
      lo = min(lo, p);
      hi = max(hi, p);
    }
  }
  const double d = distance(lo, hi);
  return std::isfinite(d) ? d : 1;
}

}  // namespace

std::string meshTexturePath(std::string_view written) {
  std::string out;
  out.reserve(written.size());
  for (std::size_t i = 0; i < written.size(); ++i) {
    const char c = written[i];
    if (c == '\\') {
      out += '/';
    } else if (c == '%' && i + 2 < written.size() && hexValue(written[i + 1]) >= 0 &&
               hexValue(written[i + 2]) >= 0) {
      out += static_cast<char>(hexValue(written[i + 1]) * 16 + hexValue(written[i + 2]));
      i += 2;
    } else {
      out += c;
    }
  }
  return out;
}

MaterialTextures meshMaterialTextures(const MeshFile& file, const MeshMaterial& material,
                                      const std::filesystem::path& meshPath,
                                      const std::filesystem::path& sceneFolder,
                                      TextureLibrary& textures) {
  const ReferencedFileRule rule(meshPath, sceneFolder, "mesh file");
  MaterialTextures b;
  for (int s = 0; s < kMeshTextureSlots; ++s) {
    const auto slot = static_cast<MeshTextureSlot>(s);
    const MeshTexture& t = material.textures[slot];
    if (!t.present()) continue;
    const bool data = slot == kNormalTexture || slot == kBumpTexture;
    const ImageEncoding encoding = data ? ImageEncoding::Linear : ImageEncoding::Srgb;
    std::shared_ptr<const MipMap> image;
    try {
      if (t.embedded >= 0) {
        image = textures.loadEmbedded(fmt::format("{}#{}", meshPath.string(), t.embedded),
                                      file.embeddedImages[static_cast<std::size_t>(t.embedded)],
                                      encoding);
      } else {
        const std::filesystem::path path = meshPath.parent_path() / meshTexturePath(t.file);
        image = textures.load(path, encoding, &rule);
      }
    } catch (const ImageReadError& e) {
      const std::string name = t.embedded >= 0 ? fmt::format("embedded image {}", t.embedded)
                                               : "'" + escapeForMessage(t.file) + "'";
      throw ImageReadError(fmt::format("its {} texture {}: {}", slotName(slot), name, e.what()));
    }
    const TextureId id = textures.add(ImageTexture{image, TextureFilter::Trilinear, {}});
    switch (slot) {
      case kDiffuseTexture:
        b.kd = b.ka = id;
        break;
      case kSpecularTexture:
        b.ks = id;
        break;
      case kEmissiveTexture:
        b.emission = id;
        break;
      case kNormalTexture:
        b.normalMap = id;
        break;
      case kBumpTexture:
        b.bumpMap = id;
        b.bumpScale = kMeshBumpFraction * boundsDiagonal(file);
        break;
      case kMeshTextureSlots:
        break;
    }
  }
  return b;
}

}  // namespace glint

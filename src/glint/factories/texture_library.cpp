#include "glint/factories/texture_library.h"

#include <cctype>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "glint/readers/spelling.h"
#include "glint/scene/scene_limits.h"

namespace glint {

namespace {

std::string typeList() {
  std::vector<std::string_view> names;
  for (const TextureFactory& f : textureFactories()) names.push_back(f.type);
  return fmt::format("{}", fmt::join(names, ", "));
}

std::vector<std::string_view> typeNames() {
  std::vector<std::string_view> names;
  for (const TextureFactory& f : textureFactories()) names.push_back(f.type);
  return names;
}

bool equalsIgnoringCase(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(a[i])) != b[i]) return false;
  }
  return true;
}

}  // namespace

bool TextureLibrary::isTexture(const ParameterDictionary& params, std::string_view key) const {
  const ValueId key_ = params.keyPlace(key);
  if (key_ == kNoValue) return false;
  // The value: look it up through a copy-free scan of the mapping.
  const ValueTree& tree = params.reader().tree();
  const ValueId map = params.place();
  ValueId value = kNoValue;
  for (std::size_t i = 0; tree.isMap(map) && i < tree.size(map); ++i) {
    if (tree.key(map, i) == key_) value = tree.value(map, i);
  }
  if (tree.isMap(value)) return true;
  if (!tree.isScalar(value)) return false;
  const std::string_view text = tree.scalar(value);
  if (text.empty()) return false;
  const auto first = static_cast<unsigned char>(text[0]);
  if (!std::isalpha(first) && first != '_') return false;
  // Words that are numbers to the number reader.
  for (const char* number : {"nan", "inf", "infinity"}) {
    if (equalsIgnoringCase(text, number)) return false;
  }
  return true;
}

void TextureLibrary::buildNamed(const Entity& e) {
  const ValueReader reader(scene_.fileOf(e).source(), ctx_.sink);
  const std::string name(reader.tree().scalar(e.name));
  if (const auto it = namedWhere_.find(name); it != namedWhere_.end()) {
    // Both places; the file too when the first is in another one (an included file).
    const auto& [firstFile, first] = it->second;
    const std::string where =
        firstFile == e.file
            ? fmt::format("line {}, column {}", first.line, first.column)
            : fmt::format("{}:{}:{}", escapeForMessage(scene_.files[firstFile]->name), first.line,
                          first.column);
    reader.error(e.name, fmt::format("duplicate texture '{}': defined twice (first at {})",
                                     escapeForMessage(name), where));
    return;
  }
  namedWhere_.emplace(name, std::pair{e.file, reader.tree().position(e.name)});
  const std::string path = "textures." + name;
  std::optional<TextureId> id;
  if (std::optional<Texture> texture =
          readMapping(reader, e.value, e.name, path, TextureRole::Color)) {
    id = add(std::move(*texture));
  }
  named_.emplace(name, id);
}

std::optional<Texture> TextureLibrary::readMapping(const ValueReader& reader, ValueId map,
                                                   ValueId place, const std::string& path,
                                                   TextureRole role) {
  const ValueTree& tree = reader.tree();
  if (!tree.isMap(map)) {
    reader.error(place, fmt::format("{}: expected a texture mapping with a 'type' ({}), got {}",
                                    path, typeList(), reader.describe(map)));
    return std::nullopt;
  }
  ValueId type = kNoValue;
  for (std::size_t i = 0; i < tree.size(map); ++i) {
    if (tree.isScalar(tree.key(map, i)) && tree.scalar(tree.key(map, i)) == "type") {
      type = tree.value(map, i);
    }
  }
  const TextureFactory* factory =
      tree.isScalar(type) ? findTextureFactory(tree.scalar(type)) : nullptr;
  if (factory == nullptr) {
    if (type == kNoValue) {
      reader.error(map,
                   fmt::format("{} is missing required key 'type' (one of: {})", path, typeList()));
    } else if (!tree.isScalar(type)) {
      reader.error(tree.isNull(type) ? map : type,
                   fmt::format("{}.type: expected a texture type ({}), got {}", path, typeList(),
                               reader.describe(type)));
    } else {
      reader.error(type, fmt::format("{}: unknown texture type {}; expected one of: {}{}", path,
                                     quoteForMessage(tree.scalar(type)), typeList(),
                                     didYouMean(tree.scalar(type), typeNames())));
    }
    ParameterDictionary(reader, map, {"in " + path, path, path}).finish();
    return std::nullopt;
  }
  const std::string owner = std::string(factory->type) + " texture";
  ParameterDictionary params(reader, map, {"in " + owner + " " + path, path, owner});
  params.declareHidden("type");
  params.find("type");
  params.declare(factory->keys);
  const TextureReadContext context{ctx_.encoding, role, this};
  std::optional<Texture> texture = factory->read(params, context);
  params.finish();
  if (params.errors() != 0) return std::nullopt;
  return texture;
}

std::optional<TextureId> TextureLibrary::read(ParameterDictionary& params, std::string_view key,
                                              TextureRole role) {
  const auto entry = params.find(key);
  if (!entry) return std::nullopt;
  const ValueTree& tree = params.reader().tree();
  if (tree.isMap(entry->value)) return readInline(params, *entry, key, role);
  const std::string path = params.pathOf(key).str();
  if (!tree.isScalar(entry->value)) {
    params.error(entry->where, fmt::format("{}: expected a texture name or a texture mapping, got "
                                           "{}",
                                           path, params.reader().describe(entry->value)));
    return std::nullopt;
  }
  const std::string_view name = tree.scalar(entry->value);
  if (const auto it = named_.find(name); it != named_.end()) return it->second;
  const std::string hint = undefinedNameHint(
      name, named_, "; no textures are defined (top-level 'textures')", hintsLeft_);
  params.error(entry->where,
               fmt::format("{}: undefined texture '{}'{}", path, nameForMessage(name), hint));
  return std::nullopt;
}

std::optional<TextureId> TextureLibrary::readInline(ParameterDictionary& params,
                                                    const ParameterDictionary::Entry& e,
                                                    std::string_view key, TextureRole role) {
  std::optional<Texture> texture =
      readMapping(params.reader(), e.value, e.where, params.pathOf(key).str(), role);
  if (!texture) return std::nullopt;
  return add(std::move(*texture));
}

TextureId TextureLibrary::add(Texture texture) {
  ctx_.parts.textures.push_back(std::move(texture));
  return static_cast<TextureId>(ctx_.parts.textures.size() - 1);
}

std::uint32_t TextureLibrary::addBindings(MaterialTextures b) {
  const std::vector<Texture>& textures = ctx_.parts.textures;
  b.needsUv = b.normalMap != kNoTexture || b.bumpMap != kNoTexture;
  for (const TextureId id : {b.kd, b.ks, b.kr, b.kt, b.ka, b.emission}) {
    b.needsUv = b.needsUv || (id != kNoTexture && usesUv(textures[id]));
  }
  ctx_.parts.materialTextures.push_back(b);
  return static_cast<std::uint32_t>(ctx_.parts.materialTextures.size() - 1);
}

std::filesystem::path TextureLibrary::folderOf(const ParameterDictionary& params) const {
  for (const auto& file : scene_.files) {
    if (&file->values == &params.reader().tree()) return file->baseDirectory;
  }
  return scene_.files.at(0)->baseDirectory;
}

void TextureLibrary::checkBudget(const ImageHeader& header, const std::string& shown) {
  const double bytes = static_cast<double>(MipMap::bytesFor(header.width, header.height));
  // While the texture is made, more is held for a moment: the decoder's samples beside the float
  // image (16-bit RGB for PNG: 6 B a pixel; OpenEXR's half RGBA: 8), then the first mip level's
  // half-width rows (6 B a pixel). Measured on an 8000 × 8000 PNG: a peak of 20.1 B a pixel, the
  // lasting mip-map 16.
  constexpr double kTransientBytesPerPixel = 8;
  const double transient =
      kTransientBytesPerPixel * static_cast<double>(header.width) * header.height;
  const double committed = bytes_ + otherBytes_();
  const double limit = static_cast<double>(ctx_.options.imageMemoryBudget);
  if (committed + bytes + transient > limit) {
    throw TextureTooLargeError(fmt::format(
        "{} {}×{} image needs about {} as a texture with its mip-maps (and {} more while it is "
        "decoded); with {} already committed (the image's film, meshes and textures before it) "
        "that is more than the memory limit of {}",
        shown, header.width, header.height, formatBytes(bytes), formatBytes(transient),
        formatBytes(committed), formatBytes(limit)));
  }
}

std::shared_ptr<const MipMap> TextureLibrary::load(const std::filesystem::path& path,
                                                   ImageEncoding encoding,
                                                   const ReferencedFileRule* rule) {
  if (rule != nullptr) {
    const std::string why = rule->refusal(path);
    if (!why.empty()) throw ImageReadError(why);
  }
  std::error_code error;
  std::filesystem::path key = std::filesystem::weakly_canonical(path, error);
  if (error) key = path.lexically_normal();
  auto& slot = images_[{key.string(), encoding}];
  if (slot != nullptr) return slot;
  ctx_.parts.readFiles.push_back(path);
  bool floatingPoint = false;
  RgbImage decoded = readImageFile(path, encoding, [&](const ImageHeader& header) {
    checkBudget(header, fmt::format("its {}", formatName(header.format)));
    floatingPoint = header.floatingPoint;
  });
  auto image = std::make_shared<const MipMap>(std::move(decoded));
  if (floatingPoint) linearFiles_.insert(image.get());
  bytes_ += static_cast<double>(image->memoryBytes());
  ++filesDecoded_;
  slot = image;
  return image;
}

std::shared_ptr<const MipMap> TextureLibrary::loadEmbedded(const std::string& key,
                                                           const std::vector<std::uint8_t>& bytes,
                                                           ImageEncoding encoding) {
  auto& slot = images_[{key, encoding}];
  if (slot != nullptr) return slot;
  const ImageHeader header = readImageHeader(bytes);
  checkBudget(header, fmt::format("its embedded {}", formatName(header.format)));
  auto image = std::make_shared<const MipMap>(decodeImage(bytes, encoding));
  if (header.floatingPoint) linearFiles_.insert(image.get());
  bytes_ += static_cast<double>(image->memoryBytes());
  ++filesDecoded_;
  slot = image;
  return image;
}

std::shared_ptr<const MipMap> TextureLibrary::image(ParameterDictionary& params, ValueId where,
                                                    std::string_view file, ImageEncoding encoding,
                                                    ValueId srgbGiven) {
  const std::filesystem::path written(file);
  const std::filesystem::path path = written.is_relative() ? folderOf(params) / written : written;
  try {
    std::shared_ptr<const MipMap> image = load(path, encoding);
    if (srgbGiven != kNoValue && linearFiles_.contains(image.get())) {
      ctx_.sink.warning(params.location(srgbGiven),
                        fmt::format("encoding: srgb has no effect on '{}': an EXR or HDR file "
                                    "holds linear values, which are used as they are",
                                    escapeForMessage(file)));
    }
    return image;
  } catch (const ImageReadError& e) {
    std::string reason = e.what();
    if (path != written && reason == "no such file") {
      reason += fmt::format(" (looked for {}: relative paths start at the scene file's folder)",
                            escapeForMessage(path.string()));
    }
    params.error(where,
                 fmt::format("cannot load texture file '{}': {}", escapeForMessage(file), reason));
    return nullptr;
  }
}

}  // namespace glint

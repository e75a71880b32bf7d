// The texture family (DESIGN.md §9): one factory per texture `type`, in one table. A factory reads
// its own keys and returns the texture; image files are read through the ImageSource it is given
// (the scene's texture cache: each file decoded once, counted against the memory budget).
#pragma once

#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "glint/image/image_decoder.h"
#include "glint/readers/parameter_dictionary.h"
#include "glint/scene/scene.h"
#include "glint/scene/texture.h"

namespace glint {

// What a texture is used for: a colour (8-bit images sRGB-decoded by default), or data — a normal
// or bump map, whose 8-bit images are linear by default.
enum class TextureRole : std::uint8_t { Color, Data };

// Where image textures come from: the file at a value (relative to the scene's folder), decoded
// once per (file, encoding); reports its own errors at `where` and returns null then.
class ImageSource {
 public:
  virtual ~ImageSource() = default;
  // `srgbGiven`: where the scene asks for sRGB decoding in so many words (`encoding: srgb`), or
  // kNoValue; on a file whose values are linear (EXR, HDR) that has no effect, and is a warning.
  virtual std::shared_ptr<const MipMap> image(ParameterDictionary& params, ValueId where,
                                              std::string_view file, ImageEncoding encoding,
                                              ValueId srgbGiven = kNoValue) = 0;
};

struct TextureReadContext {
  Encoding sceneEncoding = Encoding::Srgb;  // decodes "#rrggbb" colours
  TextureRole role = TextureRole::Color;
  ImageSource* images = nullptr;
};

struct TextureFactory {
  std::string_view type;
  std::vector<std::string_view> keys;  // in the order messages list them
  std::optional<Texture> (*read)(ParameterDictionary& params,
                                 const TextureReadContext& ctx) = nullptr;
};

// The built-in texture types: checker, checker2d, noise, marble, wood, image.
const std::vector<TextureFactory>& textureFactories();
const TextureFactory* findTextureFactory(std::string_view type);

// The uv transform keys every uv-mapped texture takes (repeat, offset, rotate), read from params.
std::optional<UvTransform> readUvTransform(ParameterDictionary& params, Point2 defaultRepeat);

}  // namespace glint

// The textures of one scene build: the named ones of `textures:`, inline texture mappings, the
// texture-valued material keys, and the image files behind them — each (file, encoding) decoded
// once, its mip-map counted against the memory budget from the file's header before decoding.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>

#include "glint/core/file_access.h"
#include "glint/factories/build_context.h"
#include "glint/factories/texture_factories.h"
#include "glint/readers/scene_description.h"
#include "glint/readers/spelling.h"

namespace glint {

// A texture refused by the memory estimate (over BuildOptions::imageMemoryBudget).
class TextureTooLargeError : public ImageReadError {
 public:
  using ImageReadError::ImageReadError;
};

class TextureLibrary : public ImageSource {
 public:
  // `otherBytes` gives the bytes committed besides textures (the film and the meshes so far) at
  // the moment a texture is estimated.
  TextureLibrary(const SceneDescription& scene, BuildContext& ctx,
                 std::function<double()> otherBytes)
      : scene_(scene), ctx_(ctx), otherBytes_(std::move(otherBytes)) {}

  // A named texture of `textures:` (built in file order; names are unique).
  void buildNamed(const Entity& e);

  // Whether the value of `key` names or describes a texture rather than a number, a colour or a
  // list: a mapping, or a text that starts like a name ("tiles", not "0.5" or "#ff0000").
  bool isTexture(const ParameterDictionary& params, std::string_view key) const;
  // The texture at `key` (a name of `textures:` or an inline mapping with a `type`), added to the
  // scene's textures; nullopt when absent or wrong (reported at the value).
  std::optional<TextureId> read(ParameterDictionary& params, std::string_view key,
                                TextureRole role);

  // An image file the scene names (relative to `folder`): decoded once per (file, encoding).
  // Throws ImageReadError (or TextureTooLargeError) on failure; `rule`, when given, must accept the
  // path first (files a mesh names).
  std::shared_ptr<const MipMap> load(const std::filesystem::path& path, ImageEncoding encoding,
                                     const ReferencedFileRule* rule = nullptr);
  // A decoded image of a mesh file's own (embedded in a .glb or a data: URI), under `key`.
  std::shared_ptr<const MipMap> loadEmbedded(const std::string& key,
                                             const std::vector<std::uint8_t>& bytes,
                                             ImageEncoding encoding);
  // Adds a texture to the scene; returns its id.
  TextureId add(Texture texture);
  // Adds a material's texture bindings to the scene (needsUv filled in); returns their index for
  // Material::textures.
  std::uint32_t addBindings(MaterialTextures bindings);

  // Estimated bytes of every image texture decoded so far (their mip-maps).
  double bytes() const { return bytes_; }
  std::size_t filesDecoded() const { return filesDecoded_; }

  // ImageSource: the file at a texture's `file` value, errors reported there.
  std::shared_ptr<const MipMap> image(ParameterDictionary& params, ValueId where,
                                      std::string_view file, ImageEncoding encoding,
                                      ValueId srgbGiven = kNoValue) override;

 private:
  std::optional<TextureId> readInline(ParameterDictionary& params,
                                      const ParameterDictionary::Entry& e, std::string_view key,
                                      TextureRole role);
  std::optional<Texture> readMapping(const ValueReader& reader, ValueId map, ValueId place,
                                     const std::string& path, TextureRole role);
  std::filesystem::path folderOf(const ParameterDictionary& params) const;
  // Refuses a width × height image whose mip-map would pass the budget (before decoding).
  void checkBudget(const ImageHeader& header, const std::string& shown);
  // The images decoded from floating-point files (EXR, HDR), whose values are linear whatever
  // the encoding asked for.
  std::set<const MipMap*> linearFiles_;

  const SceneDescription& scene_;
  BuildContext& ctx_;
  std::function<double()> otherBytes_;
  // name → its texture, or nullopt when its definition was wrong (so uses are not reported again).
  std::map<std::string, std::optional<TextureId>, std::less<>> named_;
  int hintsLeft_ = kMaxNameHints;  // undefined names that may still get a hint (undefinedNameHint)
  std::map<std::string, std::pair<std::uint32_t, TextPosition>, std::less<>>
      namedWhere_;  // file, place
  std::map<std::pair<std::string, ImageEncoding>, std::shared_ptr<const MipMap>> images_;
  double bytes_ = 0;
  std::size_t filesDecoded_ = 0;
};

}  // namespace glint

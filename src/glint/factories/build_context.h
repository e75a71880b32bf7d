// What every factory shares while a SceneDescription becomes SceneParts: the diagnostics, the image
// encoding that decodes "#rrggbb" colours, and the range checks written once (> 0, >= 0, between,
// non-zero directions), each reporting at the value with the value's path.
#pragma once

#include <atomic>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "glint/core/color.h"
#include "glint/core/vec.h"
#include "glint/factories/object_factories.h"
#include "glint/readers/diagnostics.h"
#include "glint/readers/parameter_dictionary.h"
#include "glint/scene/scene.h"
#include "glint/scene/scene_limits.h"
#include "glint/scene/scene_overrides.h"

namespace glint {

// Values as messages show them: 2, [0, 0, -1].
std::string show(double v);
std::string show(const Vec3& v);
std::string show(const Color& c);  // one number when grey

struct BuildOptions {
  // Largest film (width · height · sizeof(Color) bytes) plus meshes and BVH the scene may ask for.
  std::uint64_t imageMemoryBudget = defaultImageMemoryBudget();
  // The caller's replacements of the image size, samples and seed, applied before the film and the
  // meshes are estimated; the caller checks the overridden image against the limits.
  SceneOverrides overrides{};
  // Object types beyond the built-in table (found first): a program's or a test's own shapes.
  std::vector<ObjectFactory> extraObjectFactories{};
  // Polled between entities and while meshes load; when set the build throws Cancelled.
  const std::atomic<bool>* cancel = nullptr;
};

class TextureLibrary;

// The state the factories of one scene share.
struct BuildContext {
  const BuildOptions& options;
  Diagnostics& sink;
  SceneParts& parts;
  Encoding encoding = Encoding::Srgb;  // set once the image entity is built
  bool imageOk = false;                // the image entity built without error
  ImageSize sceneImage;                // the image size the scene asked for, before overrides
  TextureLibrary* textures = nullptr;  // the scene's textures and their image files
};

// The parameters of an entity that must be a mapping, or nullopt after the error
// "{path}: expected {what}, got {describe}" at the entity's place.
std::optional<ParameterDictionary> entityParameters(const ValueReader& reader, ValueId value,
                                                    ValueId place, std::string_view what,
                                                    DictionaryNames names);

// A colour in linear RGB: [r, g, b] as written (components ≥ 0), "#rrggbb" decoded as a display
// code under `encoding`. Reports "{path} components must be >= 0".
std::optional<Color> decodeColor(ParameterDictionary& params, const Located<ColorValue>& value,
                                 const std::string& path, Encoding encoding);
std::optional<Color> readColor(ParameterDictionary& params, std::string_view key,
                               Encoding encoding);

// Numbers with their range checked; nullopt when absent (Presence::Required: reported missing),
// of the wrong type or out of range (reported at the value).
std::optional<double> readPositive(ParameterDictionary& params, std::string_view key,
                                   Presence presence = Presence::Optional);
std::optional<double> readNonNegative(ParameterDictionary& params, std::string_view key,
                                      Presence presence = Presence::Optional);
// A whole number in [lo, hi]; with hi == INT_MAX the message says only ">= lo".
std::optional<std::int64_t> readIntegerInRange(ParameterDictionary& params, std::string_view key,
                                               std::int64_t lo, std::int64_t hi,
                                               Presence presence = Presence::Optional);
// A colour-valued material coefficient (DESIGN.md §9): a number (grey) or [r, g, b] with every
// component >= 0, or "#rrggbb" decoded as readColor decodes it.
std::optional<Color> readCoefficient(ParameterDictionary& params, std::string_view key,
                                     Encoding encoding);
// The unit vector along a non-zero vector of any length ("{path} must be non-zero, got [0, 0, 0]");
// tiny and huge components (1e-200, 1e200) are divided by the largest one first, so only a zero
// vector is refused.
std::optional<Vec3> readDirection(ParameterDictionary& params, std::string_view key,
                                  Presence presence = Presence::Optional);
std::optional<Vec3> unitVector(const Vec3& v);

// The range checks alone, for values already read: true when in range, else reported.
bool checkPositive(ParameterDictionary& params, const Located<double>& v, const std::string& path);
bool checkNonNegative(ParameterDictionary& params, const Located<double>& v,
                      const std::string& path);
bool checkInRange(ParameterDictionary& params, const Located<std::int64_t>& v, std::int64_t lo,
                  std::int64_t hi, const std::string& path);

}  // namespace glint

// Surface materials: the Phong/Whitted coefficients of DESIGN.md §3.
#pragma once

#include <cstdint>

#include "glint/core/color.h"

namespace glint {

// Material::textures of a material without textures: the renderer then reads the constants alone.
inline constexpr std::uint32_t kUntextured = 0xffffffffu;

// Every coefficient may be an RGB triple (a number in a scene file means the same value in r, g,
// b). Defaults are the scene format's: all 0 but ka = 1 and ior = 1.
struct Material {
  Color kd;                   // diffuse
  Color ks;                   // specular (Phong highlight)
  double shininess = 0;       // Phong exponent
  Color kr;                   // mirror reflection
  Color kt;                   // transmission; also the factor a shadow ray keeps per crossing
  Color ka{1, 1, 1};          // ambient
  double ior = 1;             // index of refraction; 1 = straight through
  double reflectionBlur = 0;  // glossy cone half-angle, degrees
  double refractionBlur = 0;  // glossy cone half-angle, degrees
  // Nested dielectrics (scene/media.h): where transparent solids overlap, the medium of higher
  // priority owns the overlap; equal priorities: the one the ray entered last.
  int priority = 0;
  // Index of its MaterialTextures (scene/texture.h) in SceneParts::materialTextures, or
  // kUntextured. A textured coefficient is its constant above times the texture's value.
  std::uint32_t textures = kUntextured;
};

}  // namespace glint

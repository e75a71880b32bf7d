// John Stone's Tachyon scene language (.dat; what VMD writes, and what Tachyon's manual lists as
// common) → a SceneDescription of the same entities the YAML reader emits (DESIGN.md §13), every
// value placed at its token's line:column. Keywords are case-insensitive, as in Tachyon.
//
// Tachyon's camera is left-handed (its right vector is up × view: looking along +z with +y up, +x
// is on the right), glint's right-handed; the reader mirrors the scene in x (every point, vector
// and normal) so that glint shows the image Tachyon shows.
//
//   BEGIN_SCENE RESOLUTION w h … END_SCENE → image (linear encoding: Tachyon writes its values
//       unconverted), plus ambient light 1 (a texture's AMBIENT is the material's ka)
//   CAMERA [PROJECTION PERSPECTIVE|ORTHOGRAPHIC] ZOOM z ASPECTRATIO a ANTIALIASING n RAYDEPTH d
//       CENTER c VIEWDIR v UPDIR u END_CAMERA → camera with a view plane of height 1/z and width
//       (w/h)/a/z at distance 1 (orthographic: that size, parallel rays), image.samples n + 1,
//       render.max_depth d, render.min_weight 0
//   LIGHT CENTER c RAD r [ATTENUATION CONSTANT LINEAR QUADRATIC] COLOR → point light (its sphere is
//       not drawn); DIRECTIONAL_LIGHT DIRECTION COLOR; SPOTLIGHT … FALLOFF_START FALLOFF_END …
//   BACKGROUND r g b; FOG LINEAR|EXP|EXP2|OFF START END DENSITY COLOR → fog
//   SHADER_MODE FULL|MEDIUM|LOW|LOWEST [TRANS_VMD] [FOG_VMD] [TRANS_ORIG] [SHADOW_FILTER_ON]
//       END_SHADER_MODE (glint always shades fully; TRANS_VMD scales a transparent surface's own
//       colour by its opacity; FOG_VMD fogs by view depth)
//   SPHERE, FCYLINDER (an open cone of equal radii), CYLINDER (tube), RING (disk with
//   inner_radius), PLANE, BOX, TRI, STRI, VCSTRI, VERTEXARRAY (COORDS, NORMALS, COLORS, TEXTURE,
//   TRISTRIP, TRIMESH)
//       → objects; triangles gathered into inline meshes per texture
//   TEXDEF name, TEXALIAS, TEXTURE … → materials: kd = DIFFUSE·COLOR, ka = AMBIENT·COLOR,
//       kr = SPECULAR, kt = 1 − OPACITY (straight through, as Tachyon), ks = PHONG (METAL: ×COLOR),
//       shininess = PHONG_SIZE (default 100)
// Anything else (TEXFUNC other than 0, BACKGROUND_GRADIENT, SPHEREARRAY, INCLUDE, …) is an error
// naming the statement and the nearest supported one.
#pragma once

#include <atomic>
#include <filesystem>
#include <string>
#include <string_view>

#include "glint/readers/yaml_scene_reader.h"

namespace glint {

ParseResult parseTachyon(std::string_view text, const std::string& file,
                         const std::filesystem::path& baseDirectory = ".",
                         const std::atomic<bool>* cancel = nullptr);

// Reads a .dat file (whole, at most kMaxSceneFileBytes). Throws SceneError naming only the file
// when it cannot be read, glint::Cancelled when cancelled.
ParseResult readTachyonFile(const std::filesystem::path& path, const std::string& name,
                            const std::atomic<bool>* cancel = nullptr);

}  // namespace glint

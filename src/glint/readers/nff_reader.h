// Eric Haines' Neutral File Format (NFF.TXT, version 3.9; the Standard Procedural Databases) → a
// SceneDescription of the same entities the YAML reader emits (DESIGN.md §13), every value placed
// at its token's line:column:
//   v (from, at, up, angle, hither, resolution) → camera (look_at; a view plane at distance 1 on
//       which the centres of the top and bottom pixel rows lie angle° apart, as NFF.TXT defines
//       the angle; square pixels), image (linear encoding: NFF colours are display values),
//       render (max_depth 5, min_weight 0: the SPD testing procedure's tree depth, no adaptive
//       cut-off); hither is read and ignored (glint has no near plane)
//   b r g b → background;  l x y z [r g b] → point light of intensity 1/√(number of lights)
//       (the project's choice for the unspecified NFF intensity; no ambient light)
//   f r g b Kd Ks Shine T ior → material "fill<k>": kd = Kd·colour, ks = kr = Ks, shininess =
//       Shine, kt = T, ior (when T > 0)
//   s x y z r → sphere;  c base r0 apex r1 → open cone
//   p n v… / pp n (v n)… → triangles of inline meshes, one per material (and with or without
//       normals), polygons triangulated by ear clipping (NFF polygons may be concave)
//   # → comment to the end of the line
// A negative radius (both radii of a cone) marks an object whose inside is visible: glint shades
// both sides of every surface (the SPD testing procedure allows it, and its teapot needs it), so
// the surface is the same and only its orientation matters — for a transparent object, light
// entering it leaves a cavity, which glint renders as the object with 1/ior.
#pragma once

#include <atomic>
#include <filesystem>
#include <string>
#include <string_view>

#include "glint/readers/yaml_scene_reader.h"

namespace glint {

// Reads NFF text; `file` names it in messages.
ParseResult parseNff(std::string_view text, const std::string& file,
                     const std::filesystem::path& baseDirectory = ".",
                     const std::atomic<bool>* cancel = nullptr);

// Reads an NFF file (whole, at most kMaxSceneFileBytes). Throws SceneError naming only the file
// when it cannot be read, glint::Cancelled when cancelled.
ParseResult readNffFile(const std::filesystem::path& path, const std::string& name,
                        const std::atomic<bool>* cancel = nullptr);

}  // namespace glint

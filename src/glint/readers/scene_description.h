// SceneDescription: a scene file as plain data (DESIGN.md §5), with the file:line:col of every
// entity and value, before any validation of ranges or construction of render objects. Filled by
// readers/scene_parser (structure, types, unknown/duplicate/missing keys, conflicts, finiteness)
// and turned into SceneParts by factories/scene_builder (ranges, references, colours, shapes).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "glint/core/color.h"
#include "glint/core/vec.h"
#include "glint/readers/diagnostics.h"
#include "glint/scene/scene.h"

namespace glint {

// A value as written in the file, with where it was written.
template <class T>
struct Located {
  T value{};
  SourceLocation where;
};

// A colour as written: [r, g, b] (linear) or "#rrggbb" (a display code, converted by the builder
// once image.encoding is known).
struct ColorValue {
  bool isHex = false;
  Color rgb;                           // when !isHex: linear components as written
  std::array<std::uint8_t, 3> code{};  // when isHex: the 8-bit display code
  SourceLocation where;
};

// Material keys (DESIGN.md §5); absent keys take the defaults of Material. A coefficient written as
// one number is stored as that grey.
struct MaterialDescription {
  std::string name;  // empty for an inline material
  SourceLocation where;
  std::string context;  // how messages name it: "materials.glass" or "sphere.material"
  std::optional<Located<Color>> kd, ks, kr, kt, ka;
  std::optional<Located<double>> shininess, ior, reflectionBlur, refractionBlur;
};

enum class ShapeType {
  Sphere,
  Plane,
  Triangle,
  Polygon,
  Rectangle,
  Quadrangle,
  Tube,
  Cylinder,
  Box,
  Disk,
  Mesh  // triangles from a mesh file, loaded by the builder (mesh/mesh_loader)
};

// One transform step: translate by `vector`, scale by `vector` (sx, sy, sz), or rotate by `angle`
// degrees about `vector` (the axis, any non-zero length).
struct TransformStep {
  enum class Kind { Translate, Scale, Rotate };
  Kind kind = Kind::Translate;
  Located<Vec3> vector;
  Located<double> angle;  // Rotate only
  SourceLocation where;   // the step's mapping
};

// An object of any shape type. Only the geometry keys of its type are filled; which ones are
// present is checked by the parser (required keys) and the builder (choices such as plane's
// point/normal or points).
struct ObjectDescription {
  ShapeType type = ShapeType::Sphere;
  std::string typeName;   // as written: "sphere"
  std::size_t index = 0;  // position in `objects`
  SourceLocation where;   // the object's mapping
  bool complete = true;   // false when the parser reported an error inside this object

  std::optional<Located<Point3>> center, point, origin, base, corner, min, max;
  std::optional<Located<Vec3>> normal, axis;
  std::optional<Located<double>> radius, height;
  std::optional<Located<std::vector<Point3>>> vertices, points;
  std::optional<Located<std::vector<Vec3>>> edges;
  std::optional<Located<std::string>> file;  // mesh: as written; relative to baseDirectory
  std::optional<Located<bool>> smooth;       // mesh: interpolated vertex normals (default true)

  std::optional<Located<std::string>> materialName;  // a name from `materials`
  std::optional<MaterialDescription> inlineMaterial;
  std::optional<ColorValue> emission;
  std::vector<TransformStep> transform;  // applied in file order
};

enum class LightType { Directional, Point, Spot, Area };

struct LightDescription {
  LightType type = LightType::Point;
  std::string typeName;
  std::size_t index = 0;  // position in `lights`
  SourceLocation where;
  bool complete = true;

  std::optional<ColorValue> color;           // default white
  std::optional<Located<double>> intensity;  // default 1
  std::optional<Located<Point3>> position;
  std::optional<Located<Vec3>> direction;
  std::optional<Located<std::array<double, 3>>> attenuation;  // [kc, kl, kq]
  std::optional<Located<double>> exponent;

  // Area lights only. `surface` is the emitting shape, read with the geometry keys of the object of
  // that shape (type Rectangle, Disk or Sphere; typeName "area light" names it in messages; no
  // material, emission or transform). Absent when `shape` is missing or unknown.
  std::optional<ObjectDescription> surface;
  std::optional<Located<std::string>> shape;     // as written: "rectangle", "disk", "sphere"
  std::optional<Located<std::int64_t>> samples;  // shadow rays per shading point
};

struct ViewPlaneDescription {
  SourceLocation where;
  std::optional<Located<double>> width, height, distance;
};

struct CameraDescription {
  SourceLocation where;
  bool complete = true;
  std::optional<Located<Point3>> position;
  std::optional<Located<Vec3>> direction;
  std::optional<Located<Point3>> lookAt;
  std::optional<Located<Vec3>> up;
  std::optional<ViewPlaneDescription> viewPlane;
  std::optional<Located<double>> fov, aperture, focusDistance;
};

struct GridDescription {
  SourceLocation where;
  std::optional<Located<std::int64_t>> interval;
  std::optional<ColorValue> color;
};

// image.adaptive; absent keys take the defaults of AdaptiveSampling.
struct AdaptiveDescription {
  SourceLocation where;
  std::optional<Located<std::int64_t>> maxSamples;
  std::optional<Located<double>> threshold;
};

struct ImageDescription {
  SourceLocation where;
  std::optional<Located<std::int64_t>> width, height, samples;
  std::optional<Located<Encoding>> encoding;
  std::optional<GridDescription> grid;
  std::optional<AdaptiveDescription> adaptive;
};

struct RenderDescription {
  SourceLocation where;
  std::optional<Located<std::int64_t>> maxDepth, blurSamples;
  std::optional<Located<double>> minWeight;
  std::optional<Located<std::uint64_t>> seed;
};

struct AmbientDescription {
  SourceLocation where;
  std::optional<ColorValue> color;           // default white
  std::optional<Located<double>> intensity;  // default 1
};

struct SceneDescription {
  bool complete = true;                 // false when the parser reported any error
  std::string file;                     // the file name as the user gave it (for messages)
  std::filesystem::path baseDirectory;  // relative paths inside the file resolve from here
  std::optional<Located<std::string>> name;
  std::optional<ColorValue> background;
  std::optional<AmbientDescription> ambient;
  std::optional<CameraDescription> camera;
  std::optional<ImageDescription> image;
  std::optional<RenderDescription> render;
  std::vector<MaterialDescription> materials;  // named, in file order
  std::vector<ObjectDescription> objects;      // objects that could be read
  std::vector<LightDescription> lights;
};

}  // namespace glint

#include "glint/factories/object_factories.h"

#include <cmath>
#include <limits>
#include <memory>

#include <fmt/format.h>

#include "glint/factories/build_context.h"
#include "glint/mesh/inline_mesh.h"

namespace glint {
namespace {

constexpr Presence kRequired = Presence::Required;

std::optional<ObjectGeometry> readSphere(ParameterDictionary& p) {
  const auto center = p.point3("center", kRequired);
  const auto radius = readPositive(p, "radius", kRequired);
  if (!center || !radius) return std::nullopt;
  return Shape(Sphere::make(center->value, *radius));
}

// A plane through `point` with `normal`, or through three `points` — one form or the other.
std::optional<ObjectGeometry> readPlane(ParameterDictionary& p) {
  const bool pointNormal = p.has("point") || p.has("normal");
  const bool threePoints = p.has("points");
  if (threePoints && pointNormal) {
    // At the last of the keys in the file, as for every either/or conflict.
    ValueId later = kNoValue;
    for (const char* key : {"points", "point", "normal"}) {
      const ValueId at = p.keyPlace(key);
      if (at == kNoValue) continue;
      if (later == kNoValue) {
        later = at;
        continue;
      }
      const TextPosition a = p.reader().tree().position(at);
      const TextPosition b = p.reader().tree().position(later);
      if (a.line > b.line || (a.line == b.line && a.column > b.column)) later = at;
    }
    p.error(later, "plane has both 'points' and 'point'/'normal'; give only one of them");
  } else if (!threePoints && !pointNormal) {
    p.error(p.place(), "plane needs 'point' and 'normal', or 'points'");
  }
  // `point` alone or `normal` alone asks for the other; with neither, the error above says both.
  const Presence pointNormalPresence = pointNormal && !threePoints ? kRequired : Presence::Optional;
  const auto point = p.point3("point", pointNormalPresence);
  const auto normal = readDirection(p, "normal", pointNormalPresence);
  const auto points = p.pointList("points", 3, 3);
  if (threePoints && pointNormal) return std::nullopt;
  if (threePoints) {
    if (!points) return std::nullopt;
    const std::vector<Point3>& v = points->value;
    return Shape(Plane::fromPoints(v[0], v[1], v[2]));
  }
  if (!point || !normal) return std::nullopt;
  return Shape(Plane::make(point->value, *normal));
}

std::optional<ObjectGeometry> readTriangle(ParameterDictionary& p) {
  const auto v = p.pointList("vertices", 3, 3, kRequired);
  if (!v) return std::nullopt;
  return Shape(Triangle::make(v->value[0], v->value[1], v->value[2]));
}

std::optional<ObjectGeometry> readPolygon(ParameterDictionary& p) {
  auto v = p.pointList("vertices", 3, std::numeric_limits<std::size_t>::max(), kRequired);
  if (!v) return std::nullopt;
  return Shape(Polygon::make(std::move(v->value)));
}

std::optional<ObjectGeometry> readRectangle(ParameterDictionary& p) {
  const auto corner = p.point3("corner", kRequired);
  const auto edges = p.vectorList("edges", 2, kRequired);
  if (!corner || !edges) return std::nullopt;
  return Shape(Rectangle::make(corner->value, edges->value[0], edges->value[1]));
}

std::optional<ObjectGeometry> readQuadrangle(ParameterDictionary& p) {
  const auto v = p.pointList("vertices", 4, 4, kRequired);
  if (!v) return std::nullopt;
  const std::vector<Point3>& q = v->value;
  return Shape(Quadrangle::make(q[0], q[1], q[2], q[3]));
}

std::optional<ObjectGeometry> readTube(ParameterDictionary& p) {
  const auto origin = p.point3("origin", kRequired);
  const auto axis = readDirection(p, "axis", kRequired);
  const auto radius = readPositive(p, "radius", kRequired);
  if (!origin || !axis || !radius) return std::nullopt;
  return Shape(Tube::make(origin->value, *axis, *radius));
}

std::optional<ObjectGeometry> readCylinder(ParameterDictionary& p) {
  const auto base = p.point3("base", kRequired);
  const auto axis = readDirection(p, "axis", kRequired);
  const auto radius = readPositive(p, "radius", kRequired);
  const auto height = readPositive(p, "height", kRequired);
  if (!base || !axis || !radius || !height) return std::nullopt;
  return Shape(Cylinder::make(base->value, *axis, *radius, *height));
}

std::optional<ObjectGeometry> readBox(ParameterDictionary& p) {
  const auto lo = p.point3("min", kRequired);
  const auto hi = p.point3("max", kRequired);
  if (!lo || !hi) return std::nullopt;
  return Shape(Box::make(lo->value, hi->value));
}

std::optional<ObjectGeometry> readDisk(ParameterDictionary& p) {
  const auto center = p.point3("center", kRequired);
  const auto normal = readDirection(p, "normal", kRequired);
  const auto radius = readPositive(p, "radius", kRequired);
  const auto inner = readNonNegative(p, "inner_radius");  // an annulus (Tachyon's RING)
  if (!center || !normal || !radius) return std::nullopt;
  return Shape(Disk::make(center->value, *normal, *radius, inner.value_or(0)));
}

// An open cone frustum from base to apex; equal radii make an open cylinder.
std::optional<ObjectGeometry> readCone(ParameterDictionary& p) {
  const auto base = p.point3("base", kRequired);
  const auto baseRadius = readNonNegative(p, "base_radius", kRequired);
  const auto apex = p.point3("apex", kRequired);
  const auto apexRadius = readNonNegative(p, "apex_radius", kRequired);
  if (!base || !baseRadius || !apex || !apexRadius) return std::nullopt;
  return Shape(Cone::make(base->value, *baseRadius, apex->value, *apexRadius));
}

// Inline mesh arrays (DESIGN.md §13: what readers of other formats emit for large polygon sets,
// and what `glint convert` writes back): positions, indices (triangles as [a, b, c]), and
// optionally normals and colors, one per position.
std::optional<ObjectGeometry> readInlineMesh(ParameterDictionary& p, bool smooth) {
  auto positions = p.pointList("positions", 3, std::numeric_limits<std::size_t>::max(), kRequired);
  const auto indices = p.find("indices");
  if (!indices) p.requireKey("indices");
  if (!positions) {
    p.markUsed({"normals", "colors"});
    return std::nullopt;
  }
  const std::size_t count = positions->value.size();
  const ValueReader& reader = p.reader();
  const ValueTree& tree = reader.tree();
  MeshArrays arrays;
  arrays.positions = std::move(positions->value);
  if (p.has("normals")) {
    const auto normals = p.vectorList("normals", count);
    if (!normals) return std::nullopt;
    arrays.normals = normals->value;
  }
  bool ok = true;
  // A list of `width`-number items (indices: whole numbers below the vertex count; colors:
  // components >= 0), each reported at its place.
  const auto readItems = [&](const ParameterDictionary::Entry& e, std::string_view key,
                             const auto& take) {
    const ValuePath path = p.pathOf(key);
    if (!tree.isList(e.value)) {
      reader.error(e.where, fmt::format("{}: expected a list of [a, b, c] triples, got {}",
                                        path.str(), reader.describe(e.value)));
      ok = false;
      return;
    }
    for (std::size_t i = 0; i < tree.size(e.value); ++i) {
      const ValuePath itemPath = path.item(i);
      const auto triple = reader.triple(
          tree.item(e.value, i), reader.itemPlace(e.value, e.where, i), itemPath, "[a, b, c]");
      if (!triple || !take(*triple, reader.itemPlace(e.value, e.where, i), itemPath)) ok = false;
    }
  };
  if (indices) {
    readItems(*indices, "indices",
              [&](const std::array<double, 3>& t, ValueId where, const ValuePath& path) {
                for (const double v : t) {
                  if (!(v >= 0 && v < static_cast<double>(count) && v == std::floor(v))) {
                    reader.error(where, fmt::format("{}: vertex indices must be whole numbers "
                                                    "from 0 to {}, got {}",
                                                    path.str(), count - 1, show(v)));
                    return false;
                  }
                  arrays.indices.push_back(static_cast<std::uint32_t>(v));
                }
                return true;
              });
  }
  if (const auto colors = p.find("colors")) {
    readItems(*colors, "colors",
              [&](const std::array<double, 3>& t, ValueId where, const ValuePath& path) {
                if (t[0] < 0 || t[1] < 0 || t[2] < 0) {
                  reader.error(where, fmt::format("{} components must be >= 0, got {}", path.str(),
                                                  show(Vec3{t[0], t[1], t[2]})));
                  return false;
                }
                arrays.colors.push_back(Color{t[0], t[1], t[2]});
                return true;
              });
    if (ok && arrays.colors.size() != count) {
      reader.error(colors->where,
                   fmt::format("{}: expected one colour per position ({}), got {}",
                               p.pathOf("colors").str(), count, arrays.colors.size()));
      ok = false;
    }
  }
  if (!ok || !indices) return std::nullopt;
  if (arrays.indices.empty()) {
    p.error(indices->where, p.names().path + ".indices must hold at least one triangle");
    return std::nullopt;
  }
  MeshFile file = meshFromArrays(arrays);
  if (file.triangleCount() == 0) {
    p.error(indices->where, fmt::format("{}: all {} triangles are degenerate (zero area)",
                                        p.names().path, arrays.indices.size() / 3));
    return std::nullopt;
  }
  return MeshRequest{"", positions->where, smooth, std::make_shared<MeshFile>(std::move(file))};
}

// A mesh: a file (OBJ, PLY, STL, glTF), read by the scene builder through its mesh cache, or
// inline arrays.
std::optional<ObjectGeometry> readMesh(ParameterDictionary& p) {
  const auto smooth = p.boolean("smooth");
  const bool arrays = p.has("positions") || p.has("indices");
  if (p.has("file") && arrays) {
    const ValueId later = p.laterKey("file", p.has("positions") ? "positions" : "indices");
    p.error(later, "mesh has both 'file' and inline 'positions'/'indices'; give only one of them");
    p.markUsed({"file", "positions", "indices", "normals", "colors"});
    return std::nullopt;
  }
  if (arrays) return readInlineMesh(p, smooth ? smooth->value : true);
  const auto file = p.text("file", kRequired);
  if (file && file->value.empty()) {
    p.error(file->where, p.names().path + ".file must not be empty");
    return std::nullopt;
  }
  if (!file) return std::nullopt;
  return MeshRequest{std::string(file->value), file->where, smooth ? smooth->value : true, {}};
}

}  // namespace

const std::vector<ObjectFactory>& objectFactories() {
  static const std::vector<ObjectFactory> factories = {
      {"sphere", {"center", "radius"}, readSphere},
      {"plane", {"point", "normal", "points"}, readPlane},
      {"triangle", {"vertices"}, readTriangle},
      {"polygon", {"vertices"}, readPolygon},
      {"rectangle", {"corner", "edges"}, readRectangle},
      {"quadrangle", {"vertices"}, readQuadrangle},
      {"tube", {"origin", "axis", "radius"}, readTube},
      {"cylinder", {"base", "axis", "radius", "height"}, readCylinder},
      {"box", {"min", "max"}, readBox},
      {"disk", {"center", "normal", "radius", "inner_radius"}, readDisk},
      {"cone", {"base", "base_radius", "apex", "apex_radius"}, readCone},
      {"mesh", {"file", "smooth", "positions", "normals", "colors", "indices"}, readMesh},
  };
  return factories;
}

const ObjectFactory* findObjectFactory(std::string_view type,
                                       const std::vector<ObjectFactory>& extra) {
  for (const ObjectFactory& f : extra) {
    if (f.type == type) return &f;
  }
  for (const ObjectFactory& f : objectFactories()) {
    if (f.type == type) return &f;
  }
  return nullptr;
}

std::vector<const ObjectFactory*> areaShapeFactories() {
  return {findObjectFactory("rectangle"), findObjectFactory("disk"), findObjectFactory("sphere")};
}

}  // namespace glint

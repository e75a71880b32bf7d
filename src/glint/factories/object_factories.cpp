#include "glint/factories/object_factories.h"

#include <limits>

#include <fmt/format.h>

#include "glint/factories/build_context.h"

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
  if (!center || !normal || !radius) return std::nullopt;
  return Shape(Disk::make(center->value, *normal, *radius));
}

// A mesh file (OBJ, PLY, STL, glTF): read by the scene builder through its mesh cache.
std::optional<ObjectGeometry> readMesh(ParameterDictionary& p) {
  const auto file = p.text("file", kRequired);
  const auto smooth = p.boolean("smooth");
  if (file && file->value.empty()) {
    p.error(file->where, p.names().path + ".file must not be empty");
    return std::nullopt;
  }
  if (!file) return std::nullopt;
  return MeshRequest{std::string(file->value), file->where, smooth ? smooth->value : true};
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
      {"disk", {"center", "normal", "radius"}, readDisk},
      {"mesh", {"file", "smooth"}, readMesh},
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

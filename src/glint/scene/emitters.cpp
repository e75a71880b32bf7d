// Emissive surfaces as lights: the power distribution over them and area sampling of each.
#include "glint/scene/emitters.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <variant>

#include "glint/core/sampling.h"

namespace glint {

void EmitterSampler::add(const Unit& unit, double area) {
  const double power = luminance(unit.emission) * area;
  if (!(power > 0) || !std::isfinite(power)) return;
  units_.push_back(unit);
  totalPower_ += power;
  cdf_.push_back(totalPower_);
}

std::shared_ptr<const EmitterSampler> EmitterSampler::make(
    const std::vector<Primitive>& primitives, const std::vector<TriangleMesh>& meshes,
    const std::vector<Material>& materials, const std::vector<MaterialTextures>& textures) {
  std::shared_ptr<EmitterSampler> sampler(new EmitterSampler());
  EmitterSampler& s = *sampler;
  s.cdf_.push_back(0);
  s.sampledPrimitive_.assign(primitives.size(), false);
  s.sampledMesh_.assign(meshes.size(), false);
  const auto textured = [&](std::uint32_t material) {
    const std::uint32_t bindings = materials[material].textures;
    return bindings != kUntextured && textures[bindings].emission != kNoTexture;
  };
  const auto addTriangle = [&](const Point3& a, const Point3& b, const Point3& c,
                               const Color& emission) {
    const Vec3 cross = glint::cross(b - a, c - a);
    const double area = 0.5 * length(cross);
    if (!(area > 0)) return;
    Unit unit;
    unit.a = a;
    unit.b = b;
    unit.c = c;
    unit.normal = Normal3(cross / (2 * area));
    unit.emission = emission;
    s.add(unit, area);
  };
  for (std::size_t i = 0; i < primitives.size(); ++i) {
    const Primitive& primitive = primitives[i];
    const Color& emission = primitive.emission();
    if (!(luminance(emission) > 0) || textured(primitive.materialIndex())) continue;
    const Transform* transform = primitive.worldFromObject();
    const auto world = [&](const Point3& p) { return transform ? (*transform)(p) : p; };
    const std::size_t before = s.units_.size();
    const Shape& shape = primitive.shape();
    if (const auto* triangle = std::get_if<Triangle>(&shape)) {
      addTriangle(world(triangle->v0), world(triangle->v1), world(triangle->v2), emission);
    } else if (const auto* rectangle = std::get_if<Rectangle>(&shape)) {
      const Point3 p0 = world(rectangle->corner);
      const Point3 p1 = world(rectangle->corner + rectangle->edge0);
      const Point3 p2 = world(rectangle->corner + rectangle->edge0 + rectangle->edge1);
      const Point3 p3 = world(rectangle->corner + rectangle->edge1);
      addTriangle(p0, p1, p2, emission);
      addTriangle(p0, p2, p3, emission);
    } else if (const auto* quadrangle = std::get_if<Quadrangle>(&shape)) {
      const auto& q = quadrangle->corners;
      addTriangle(world(q[0]), world(q[1]), world(q[2]), emission);
      addTriangle(world(q[0]), world(q[2]), world(q[3]), emission);
    } else if (const auto* polygon = std::get_if<Polygon>(&shape)) {
      const auto& v = polygon->vertices;  // convex: a fan from the first vertex
      for (std::size_t k = 1; k + 1 < v.size(); ++k) {
        addTriangle(world(v[0]), world(v[k]), world(v[k + 1]), emission);
      }
    } else if (const auto* sphere = std::get_if<Sphere>(&shape); sphere && !transform) {
      Unit unit;
      unit.kind = Kind::Sphere;
      unit.a = sphere->center;
      unit.radius = sphere->radius;
      unit.emission = emission;
      s.add(unit, 4 * std::numbers::pi * sphere->radius * sphere->radius);
    } else if (const auto* disk = std::get_if<Disk>(&shape); disk && !transform) {
      Unit unit;
      unit.kind = Kind::Disk;
      unit.a = disk->center;
      unit.normal = disk->normal;
      unit.radius = disk->radius;
      unit.innerRadius = disk->innerRadius;
      unit.emission = emission;
      s.add(unit, std::numbers::pi *
                      (disk->radius * disk->radius - disk->innerRadius * disk->innerRadius));
    }
    s.sampledPrimitive_[i] = s.units_.size() > before;
  }
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const TriangleMesh& mesh = meshes[m];
    if (!(luminance(mesh.emission) > 0) || textured(mesh.materialIndex)) continue;
    const std::size_t before = s.units_.size();
    for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
      addTriangle(mesh.positions[mesh.indices[3 * t]], mesh.positions[mesh.indices[3 * t + 1]],
                  mesh.positions[mesh.indices[3 * t + 2]], mesh.emission);
    }
    s.sampledMesh_[m] = s.units_.size() > before;
  }
  if (s.units_.empty()) return nullptr;
  for (double& c : s.cdf_) c /= s.totalPower_;
  s.cdf_.back() = 1;
  return sampler;
}

EmitterSampler::Sample EmitterSampler::sample(const Point2& u) const {
  // The emitter: the first whose running share exceeds u.x; u.x rescaled within its share.
  const auto it = std::upper_bound(cdf_.begin() + 1, cdf_.end(), u.x);
  const std::size_t i =
      std::min<std::size_t>(static_cast<std::size_t>(it - cdf_.begin()) - 1, units_.size() - 1);
  const double span = cdf_[i + 1] - cdf_[i];
  const double x = span > 0 ? std::clamp((u.x - cdf_[i]) / span, 0.0, 1.0 - 1e-16) : 0.5;
  const Unit& unit = units_[i];
  Sample out;
  out.emission = unit.emission;
  out.areaPdf = luminance(unit.emission) / totalPower_;
  switch (unit.kind) {
    case Kind::Triangle: {
      // Uniform on the triangle: barycentrics (1 − √x, y·√x).
      const double root = std::sqrt(x);
      const double b1 = (1 - u.y) * root;
      const double b2 = u.y * root;
      out.point = unit.a + (unit.b - unit.a) * b1 + (unit.c - unit.a) * b2;
      out.normal = unit.normal;
      break;
    }
    case Kind::Sphere: {
      const Vec3 d = sampleUniformSphere({x, u.y});
      out.point = unit.a + d * unit.radius;
      out.normal = Normal3(d);
      break;
    }
    case Kind::Disk: {
      Vec3 t;
      Vec3 b;
      orthonormalBasis(toVec(unit.normal), t, b);
      const double r2 = unit.innerRadius * unit.innerRadius;
      const double r = std::sqrt(r2 + x * (unit.radius * unit.radius - r2));
      const double phi = 2 * std::numbers::pi * u.y;
      out.point = unit.a + t * (r * std::cos(phi)) + b * (r * std::sin(phi));
      out.normal = unit.normal;
      break;
    }
  }
  return out;
}

double EmitterSampler::areaPdf(const Hit& hit, const Color& emission) const {
  // Instanced surfaces are not sampled as lights (only reached by BRDF sampling).
  const bool sampled =
      hit.instance == kNoInstance &&
      (hit.mesh == kNoMesh
           ? hit.primitive < sampledPrimitive_.size() && sampledPrimitive_[hit.primitive]
           : hit.mesh < sampledMesh_.size() && sampledMesh_[hit.mesh]);
  return sampled ? luminance(emission) / totalPower_ : 0;
}

}  // namespace glint

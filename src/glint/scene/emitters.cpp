// Emissive surfaces as lights: the power distribution over them and area sampling of each.
#include "glint/scene/emitters.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <variant>

#include "glint/core/sampling.h"

namespace glint {
namespace {

// The factor by which `transform` scales every length when it is a similarity (a rotation or
// reflection, a uniform scale and a translation), else 0: its linear part's columns must be
// orthogonal and of one length, to a relative 1e-9.
double similarityScale(const Transform& transform) {
  const Vec3 x = transform(Vec3{1, 0, 0});
  const Vec3 y = transform(Vec3{0, 1, 0});
  const Vec3 z = transform(Vec3{0, 0, 1});
  const double xx = dot(x, x);
  constexpr double kTolerance = 1e-9;
  const auto same = [&](double a) { return std::abs(a - xx) <= kTolerance * xx; };
  const auto orthogonal = [&](const Vec3& a, const Vec3& b) {
    return std::abs(dot(a, b)) <= kTolerance * xx;
  };
  if (!(xx > 0) || !same(dot(y, y)) || !same(dot(z, z)) || !orthogonal(x, y) || !orthogonal(y, z) ||
      !orthogonal(x, z)) {
    return 0;
  }
  return std::sqrt(xx);
}

}  // namespace

void EmitterSampler::add(const Unit& unit, double area) {
  const double power = luminance(unit.emission) * area;
  if (!(power > 0) || !std::isfinite(power)) return;
  units_.push_back(unit);
  totalPower_ += power;
  cdf_.push_back(totalPower_);
}

std::shared_ptr<const EmitterSampler> EmitterSampler::make(
    const std::vector<Primitive>& primitives, const std::vector<TriangleMesh>& meshes,
    const std::vector<Material>& materials, const std::vector<MaterialTextures>& textures,
    const InstanceSet* instances, const std::function<std::uint32_t(const Hit&)>& materialOf) {
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
    unit.origin = a;
    unit.e0 = b - a;
    unit.e1 = c - a;
    unit.normal = Normal3(cross / (2 * area));
    unit.emission = emission;
    s.add(unit, area);
  };
  // A disk or ring of object-space centre `center`, unit normal `normal` and radii, through the
  // primitive's map to world space (null: none).
  const auto addDisk = [&](const Transform* transform, const Point3& center, const Vec3& normal,
                           double radius, double innerRadius, const Color& emission) {
    Vec3 t;
    Vec3 b;
    orthonormalBasis(normal, t, b);
    Unit unit;
    unit.kind = Kind::Disk;
    unit.origin = transform ? (*transform)(center) : center;
    unit.e0 = transform ? (*transform)(t) : t;
    unit.e1 = transform ? (*transform)(b) : b;
    // World area per object area in the disk's plane (exactly 1 without a transform).
    double stretch = 1;
    unit.normal = Normal3(normal);
    if (transform) {
      const Vec3 cross = glint::cross(unit.e0, unit.e1);
      stretch = length(cross);
      if (!(stretch > 0)) return;
      unit.normal = Normal3(cross / stretch);
    }
    unit.radius = radius;
    unit.innerRadius = innerRadius;
    unit.emission = emission;
    s.add(unit, std::numbers::pi * (radius * radius - innerRadius * innerRadius) * stretch);
  };
  // One primitive of emission `emission`, placed in the world by its own transform and then by
  // `placement` (an instance's; null: none). Whether its whole surface is now sampled.
  const auto addPrimitive = [&](const Primitive& primitive, const Color& emission,
                                const Transform* placement) {
    std::optional<Transform> composed;
    const Transform* transform = primitive.worldFromObject();
    if (placement != nullptr) {
      composed = transform ? *placement * *transform : *placement;
      transform = &*composed;
    }
    const auto world = [&](const Point3& p) { return transform ? (*transform)(p) : p; };
    const auto worldVector = [&](const Vec3& v) { return transform ? (*transform)(v) : v; };
    // Round shapes stay round only under a similarity: its scale factor, or 0 for another map.
    const double scale = transform ? similarityScale(*transform) : 1;
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
    } else if (const auto* box = std::get_if<Box>(&shape)) {
      // Each face as two triangles between its corners (corner k has bit 0 for x, 1 y, 2 z).
      const auto corner = [&](int k) {
        return world(Point3{(k & 1) != 0 ? box->hi.x : box->lo.x,
                            (k & 2) != 0 ? box->hi.y : box->lo.y,
                            (k & 4) != 0 ? box->hi.z : box->lo.z});
      };
      constexpr int kFaces[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                    {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
      for (const auto& face : kFaces) {
        addTriangle(corner(face[0]), corner(face[1]), corner(face[2]), emission);
        addTriangle(corner(face[0]), corner(face[2]), corner(face[3]), emission);
      }
    } else if (const auto* disk = std::get_if<Disk>(&shape)) {
      addDisk(transform, disk->center, toVec(disk->normal), disk->radius, disk->innerRadius,
              emission);
    } else if (const auto* sphere = std::get_if<Sphere>(&shape); sphere && scale > 0) {
      Unit unit;
      unit.kind = Kind::Sphere;
      unit.origin = world(sphere->center);
      unit.radius = sphere->radius * scale;
      unit.emission = emission;
      s.add(unit, 4 * std::numbers::pi * unit.radius * unit.radius);
    } else if (const auto* cylinder = std::get_if<Cylinder>(&shape); cylinder && scale > 0) {
      Vec3 t;
      Vec3 b;
      orthonormalBasis(cylinder->axis, t, b);
      Unit side;
      side.kind = Kind::CylinderSide;
      side.origin = world(cylinder->base);
      side.e0 = worldVector(t);
      side.e1 = worldVector(b);
      side.e2 = worldVector(cylinder->axis * cylinder->height);
      side.radius = cylinder->radius;
      side.emission = emission;
      s.add(side, 2 * std::numbers::pi * cylinder->radius * cylinder->height * scale * scale);
      addDisk(transform, cylinder->base, cylinder->axis, cylinder->radius, 0, emission);
      addDisk(transform, cylinder->base + cylinder->axis * cylinder->height, cylinder->axis,
              cylinder->radius, 0, emission);
    } else if (const auto* cone = std::get_if<Cone>(&shape); cone && scale > 0) {
      Vec3 t;
      Vec3 b;
      orthonormalBasis(cone->axis, t, b);
      Unit side;
      side.kind = Kind::ConeSide;
      side.origin = world(cone->base);
      side.e0 = worldVector(t);
      side.e1 = worldVector(b);
      side.e2 = worldVector(cone->axis * cone->height);
      side.radius = cone->baseRadius;
      side.apexRadius = cone->apexRadius;
      side.emission = emission;
      // Lateral area of a frustum: π·(r0 + r1)·slant height.
      const double dr = cone->apexRadius - cone->baseRadius;
      const double slant = std::sqrt(cone->height * cone->height + dr * dr);
      s.add(side, std::numbers::pi * (cone->baseRadius + cone->apexRadius) * slant * scale * scale);
    }
    // Only a primitive whose whole surface is sampled has the sampler's density at its points.
    return s.units_.size() > before;
  };
  const auto addMesh = [&](const TriangleMesh& mesh, const Transform* placement) {
    const std::size_t before = s.units_.size();
    const auto world = [&](std::uint32_t v) {
      return placement ? (*placement)(mesh.positions[v]) : mesh.positions[v];
    };
    for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
      addTriangle(world(mesh.indices[3 * t]), world(mesh.indices[3 * t + 1]),
                  world(mesh.indices[3 * t + 2]), mesh.emission);
    }
    return s.units_.size() > before;
  };
  for (std::size_t i = 0; i < primitives.size(); ++i) {
    const Primitive& primitive = primitives[i];
    if (!(luminance(primitive.emission()) > 0) || textured(primitive.materialIndex())) continue;
    s.sampledPrimitive_[i] = addPrimitive(primitive, primitive.emission(), nullptr);
  }
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const TriangleMesh& mesh = meshes[m];
    if (!(luminance(mesh.emission) > 0) || textured(mesh.materialIndex)) continue;
    s.sampledMesh_[m] = addMesh(mesh, nullptr);
  }
  if (instances != nullptr) {
    // Emissive objects inside groups, once per instance, placed by the instance's transform and
    // lit by the instance's material where it gives one. Each instance's emissive objects get
    // consecutive bits of sampledInstanced_ from instanceBase_[instance] on, in the order of
    // emissiveSlot_ (the group's primitives, then its meshes). Units past kInstancedUnitBudget
    // are not added: the instances after that are found only by the paths that hit them.
    const InstanceSet& set = *instances;
    s.instances_ = instances;
    s.emissiveSlot_.resize(set.groupCount());
    std::vector<std::uint32_t> slotCount(set.groupCount(), 0);
    bool anyEmissive = false;
    for (std::uint32_t g = 0; g < set.groupCount(); ++g) {
      const Aggregate& group = set.group(g);
      std::vector<std::uint32_t>& slots = s.emissiveSlot_[g];
      slots.assign(group.primitives().size() + group.meshes().size(), kNotEmissive);
      for (std::size_t i = 0; i < group.primitives().size(); ++i) {
        if (luminance(group.primitives()[i].emission()) > 0) slots[i] = slotCount[g]++;
      }
      for (std::size_t m = 0; m < group.meshes().size(); ++m) {
        if (luminance(group.meshes()[m].emission) > 0) {
          slots[group.primitives().size() + m] = slotCount[g]++;
        }
      }
      anyEmissive = anyEmissive || slotCount[g] > 0;
    }
    if (anyEmissive) {
      s.instanceBase_.assign(set.instanceCount(), kNotEmissive);
      const std::size_t budgetEnd = s.units_.size() + kInstancedUnitBudget;
      for (std::uint32_t i = 0; i < set.instanceCount() && s.units_.size() < budgetEnd; ++i) {
        const std::uint32_t g = set.instance(i).group;
        if (slotCount[g] == 0) continue;
        const Aggregate& group = set.group(g);
        const Transform placement = set.placement(i);
        const auto base = static_cast<std::uint32_t>(s.sampledInstanced_.size());
        s.instanceBase_[i] = base;
        s.sampledInstanced_.resize(base + slotCount[g], false);
        Hit hit;
        hit.instance = i;
        for (std::size_t k = 0; k < s.emissiveSlot_[g].size(); ++k) {
          const std::uint32_t slot = s.emissiveSlot_[g][k];
          if (slot == kNotEmissive) continue;
          const bool isPrimitive = k < group.primitives().size();
          hit.primitive = isPrimitive ? static_cast<std::uint32_t>(k) : 0;
          hit.mesh =
              isPrimitive ? kNoMesh : static_cast<std::uint32_t>(k - group.primitives().size());
          if (textured(materialOf(hit))) continue;
          s.sampledInstanced_[base + slot] =
              isPrimitive ? addPrimitive(group.primitives()[k], group.primitives()[k].emission(),
                                         &placement)
                          : addMesh(group.meshes()[hit.mesh], &placement);
        }
      }
    }
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
      out.point = unit.origin + unit.e0 * b1 + unit.e1 * b2;
      out.normal = unit.normal;
      break;
    }
    case Kind::Sphere: {
      const Vec3 d = sampleUniformSphere({x, u.y});
      out.point = unit.origin + d * unit.radius;
      out.normal = Normal3(d);
      break;
    }
    case Kind::Disk: {
      // Uniform in the object-space ring: ρ² uniform between the radii²; the linear map to
      // world space scales every area alike.
      const double r2 = unit.innerRadius * unit.innerRadius;
      const double r = std::sqrt(r2 + x * (unit.radius * unit.radius - r2));
      const double phi = 2 * std::numbers::pi * u.y;
      out.point = unit.origin + unit.e0 * (r * std::cos(phi)) + unit.e1 * (r * std::sin(phi));
      out.normal = unit.normal;
      break;
    }
    case Kind::CylinderSide: {
      // φ and the height uniform: the side unrolls to a rectangle.
      const double phi = 2 * std::numbers::pi * u.y;
      const Vec3 radial = unit.e0 * std::cos(phi) + unit.e1 * std::sin(phi);
      out.point = unit.origin + radial * unit.radius + unit.e2 * x;
      out.normal = Normal3(normalize(radial));
      break;
    }
    case Kind::ConeSide: {
      // The side's area grows with the radius ρ(v) = r0 + (r1 − r0)·v: v has density
      // ∝ ρ(v), inverted as v = x·(r0 + r1) / (r0 + √(r0² + (r1 − r0)·x·(r0 + r1))), the
      // quadratic's root in a form without cancellation (also for r0 = r1 and r0 = 0).
      const double r0 = unit.radius;
      const double r1 = unit.apexRadius;
      const double v =
          x * (r0 + r1) / (r0 + std::sqrt(std::max(0.0, r0 * r0 + (r1 - r0) * x * (r0 + r1))));
      const double rho = r0 + (r1 - r0) * v;
      const double phi = 2 * std::numbers::pi * u.y;
      const Vec3 radial = unit.e0 * std::cos(phi) + unit.e1 * std::sin(phi);
      const Vec3 around = unit.e1 * std::cos(phi) - unit.e0 * std::sin(phi);
      out.point = unit.origin + radial * rho + unit.e2 * v;
      // The normal: across the two tangents, along the side (∂/∂v) and around it (∂/∂φ).
      out.normal = Normal3(normalize(cross(radial * (r1 - r0) + unit.e2, around)));
      break;
    }
  }
  return out;
}

double EmitterSampler::areaPdf(const Hit& hit, const Color& emission) const {
  bool sampled = false;
  if (hit.instance == kNoInstance) {
    sampled = hit.mesh == kNoMesh
                  ? hit.primitive < sampledPrimitive_.size() && sampledPrimitive_[hit.primitive]
                  : hit.mesh < sampledMesh_.size() && sampledMesh_[hit.mesh];
  } else if (hit.instance < instanceBase_.size() && instanceBase_[hit.instance] != kNotEmissive) {
    const std::uint32_t g = instances_->instance(hit.instance).group;
    const std::size_t k =
        hit.mesh == kNoMesh ? hit.primitive : instances_->group(g).primitives().size() + hit.mesh;
    const std::uint32_t slot = emissiveSlot_[g][k];
    sampled = slot != kNotEmissive && sampledInstanced_[instanceBase_[hit.instance] + slot];
  }
  return sampled ? luminance(emission) / totalPower_ : 0;
}

}  // namespace glint

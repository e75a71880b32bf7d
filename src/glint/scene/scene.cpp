// Scene construction: camera from the image size, material validation, the frozen aggregate.
#include "glint/scene/scene.h"

#include <algorithm>
#include <bit>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <variant>

#include "glint/core/seeded_hash.h"
#include "glint/core/spawn.h"
#include "glint/geometry/csg.h"
#include "glint/scene/scene_instances.h"

namespace glint {

Color shadowTransmission(const Material& material, const std::vector<Texture>& textures,
                         const std::vector<MaterialTextures>& bindings) {
  if (material.textures == kUntextured) return material.kt;
  const TextureId kt = bindings[material.textures].kt;
  return kt == kNoTexture ? material.kt : material.kt * meanOf(textures[kt]);
}

namespace {

CameraSpec cameraSpecFor(const SceneParts& parts) {
  CameraSpec spec = parts.camera;
  spec.imageWidth = parts.image.width;
  spec.imageHeight = parts.image.height;
  return spec;
}

// Every material's texture bindings and texture ids must be in range.
void checkTextures(const SceneParts& parts) {
  for (std::size_t i = 0; i < parts.materials.size(); ++i) {
    const std::uint32_t t = parts.materials[i].textures;
    if (t != kUntextured && t >= parts.materialTextures.size()) {
      throw std::invalid_argument("material " + std::to_string(i) + " uses texture binding " +
                                  std::to_string(t) + ", but the scene has only " +
                                  std::to_string(parts.materialTextures.size()));
    }
  }
  for (const MaterialTextures& m : parts.materialTextures) {
    for (const TextureId id : {m.kd, m.ks, m.kr, m.kt, m.ka, m.emission, m.normalMap, m.bumpMap}) {
      if (id != kNoTexture && id >= parts.textures.size()) {
        throw std::invalid_argument("texture " + std::to_string(id) +
                                    " is used, but the scene has only " +
                                    std::to_string(parts.textures.size()) + " textures");
      }
    }
  }
  for (const Texture& texture : parts.textures) {
    const auto* image = std::get_if<ImageTexture>(&texture);
    if (image != nullptr && image->image == nullptr) {
      throw std::invalid_argument("an image texture has no image");
    }
  }
  if (parts.environment.kind == BackgroundKind::Image && parts.environment.image == nullptr) {
    throw std::invalid_argument("an image background has no image");
  }
}

// Checks every material index and pairs each primitive and mesh with its material's kt, the factor
// a shadow ray keeps per crossing.
Aggregate buildAggregate(SceneParts& parts, const std::vector<Material>& materials,
                         const std::vector<Texture>& textures,
                         const std::vector<MaterialTextures>& bindings,
                         std::vector<GroupMaterialTakers>& takers) {
  std::shared_ptr<const InstanceSet> instances =
      buildInstanceSet(parts, materials, textures, bindings, takers);
  const auto checkMaterial = [&](const char* what, std::size_t i, std::uint32_t material) {
    if (material >= materials.size()) {
      throw std::invalid_argument(std::string(what) + " " + std::to_string(i) + " uses material " +
                                  std::to_string(material) + ", but the scene has only " +
                                  std::to_string(materials.size()) + " materials");
    }
    return shadowTransmission(materials[material], textures, bindings);
  };
  std::vector<Color> transmission;
  transmission.reserve(parts.primitives.size());
  for (std::size_t i = 0; i < parts.primitives.size(); ++i) {
    Primitive& primitive = parts.primitives[i];
    const Color kt = checkMaterial("primitive", i, primitive.materialIndex());
    const std::optional<Color> csgKt = setCsgTransmission(primitive, [&](std::uint32_t material) {
      return checkMaterial("csg operand of primitive", i, material);
    });
    transmission.push_back(csgKt ? *csgKt : kt);
  }
  std::vector<Color> meshTransmission;
  meshTransmission.reserve(parts.meshes.size());
  for (std::size_t m = 0; m < parts.meshes.size(); ++m) {
    meshTransmission.push_back(checkMaterial("mesh", m, parts.meshes[m].materialIndex));
  }
  // The node width of the ISA the queries will run with, not of the one the Aggregate starts with.
  Aggregate aggregate(std::move(parts.primitives), std::move(transmission), std::move(parts.meshes),
                      std::move(meshTransmission), accelerationFor(parts.acceleration, parts.isa),
                      std::move(instances));
  if (parts.isa) aggregate.setIsa(*parts.isa);
  return aggregate;
}

// Whether a shape bounds a volume with outward normals, so that a ray crossing it enters or leaves
// a medium (nested dielectrics). Flat shapes, the open cone and planes are surfaces without an
// inside. One overload per shape: a new shape does not compile until it is classified here.
struct BoundsVolume {
  bool operator()(const Sphere&) const { return true; }
  bool operator()(const Box&) const { return true; }
  bool operator()(const Cylinder&) const { return true; }
  bool operator()(const Tube&) const { return true; }
  bool operator()(const Plane&) const { return false; }
  bool operator()(const Triangle&) const { return false; }
  bool operator()(const Polygon&) const { return false; }
  bool operator()(const Rectangle&) const { return false; }
  bool operator()(const Quadrangle&) const { return false; }
  bool operator()(const Disk&) const { return false; }
  bool operator()(const Cone&) const { return false; }
  // A csg is closed, but its operands may be of several materials: it refracts against the
  // medium around it, as before nested dielectrics (documented).
  bool operator()(const Csg&) const { return false; }
};

// Whether a mesh is the boundary of a volume with outward normals, so that it can be a medium:
// closed and consistently oriented — with vertices of equal position taken as one, every edge is
// used by exactly two triangles, once in each direction — and of positive signed volume
// (Σ p0·(p1 × p2) / 6 over its triangles, the divergence theorem). Degenerate triangles are
// already gone (Aggregate).
bool meshBoundsVolume(const TriangleMesh& mesh) {
  const std::size_t triangles = mesh.triangleCount();
  if (triangles < 4) return false;
  struct PositionHash {
    std::uint64_t seed = processHashSeed();
    std::size_t operator()(const Point3& p) const noexcept {
      SeededHasher h(seed);
      for (const double c : {p.x + 0.0, p.y + 0.0, p.z + 0.0}) {  // + 0.0: −0 and 0 alike
        h.add(std::bit_cast<std::uint64_t>(c));
      }
      return static_cast<std::size_t>(h.value());
    }
  };
  std::unordered_map<Point3, std::uint32_t, PositionHash> welded;
  std::vector<std::uint32_t> weldedId(mesh.positions.size());
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    weldedId[i] =
        welded.emplace(mesh.positions[i], static_cast<std::uint32_t>(welded.size())).first->second;
  }
  std::unordered_map<std::uint64_t, int, SeededHash> directedEdges;  // (from << 32 | to) → uses
  double volume6 = 0;
  for (std::size_t t = 0; t < triangles; ++t) {
    const std::uint32_t* index = mesh.indices.data() + 3 * t;
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t from = weldedId[index[k]];
      const std::uint64_t to = weldedId[index[(k + 1) % 3]];
      if (from == to || ++directedEdges[from << 32 | to] > 1) return false;
    }
    volume6 += dot(toVec(mesh.positions[index[0]]),
                   cross(mesh.positions[index[1]] - mesh.positions[index[0]],
                         mesh.positions[index[2]] - mesh.positions[index[0]]));
  }
  for (const auto& [edge, uses] : directedEdges) {
    if (directedEdges.find(edge >> 32 | (edge & 0xffffffffu) << 32) == directedEdges.end()) {
      return false;
    }
  }
  return volume6 > 0;
}

// Whether some transparent solid's bounds overlap another transparent object's (solid or flat):
// the only way a ray can be inside two media at once, or meet a flat transparent surface inside a
// medium. `primitiveMedium` / `meshMedium`: each object's medium (kNoMedium: not a solid). Sweep
// and prune along x; past a budget of box tests the answer is a conservative yes.
bool transparentSolidsOverlap(const std::vector<Primitive>& primitives,
                              const std::vector<std::uint32_t>& primitiveMedium,
                              const std::vector<TriangleMesh>& meshes,
                              const std::vector<std::uint32_t>& meshMedium,
                              const std::vector<Material>& materials) {
  struct Candidate {
    Bounds3 bounds;
    bool solid;
  };
  std::vector<Candidate> candidates;
  bool anySolid = false;
  for (std::size_t i = 0; i < primitives.size(); ++i) {
    if (isBlack(materials[primitives[i].materialIndex()].kt)) continue;
    const bool solid = primitiveMedium[i] != kNoMedium;
    anySolid = anySolid || solid;
    candidates.push_back({primitives[i].bounds(), solid});
  }
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const TriangleMesh& mesh = meshes[m];
    if (isBlack(materials[mesh.materialIndex].kt) || mesh.positions.empty()) continue;
    Bounds3 bounds;
    for (const Point3& p : mesh.positions) bounds = unite(bounds, Bounds3(p, p));
    const bool solid = meshMedium[m] != kNoMedium;
    anySolid = anySolid || solid;
    candidates.push_back({bounds, solid});
  }
  if (!anySolid) return false;
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.bounds.lo.x < b.bounds.lo.x; });
  constexpr std::size_t kTestBudget = std::size_t{1} << 24;
  std::size_t tests = 0;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const Candidate& a = candidates[i];
    for (std::size_t j = i + 1; j < candidates.size() && candidates[j].bounds.lo.x <= a.bounds.hi.x;
         ++j) {
      if (++tests > kTestBudget) return true;
      const Candidate& b = candidates[j];
      if (!(a.solid || b.solid)) continue;
      if (a.bounds.lo.y <= b.bounds.hi.y && b.bounds.lo.y <= a.bounds.hi.y &&
          a.bounds.lo.z <= b.bounds.hi.z && b.bounds.lo.z <= a.bounds.hi.z) {
        return true;
      }
    }
  }
  return false;
}

// Whether, in a scene with nested media, every boundary a ray can meet is still a surface, so that
// a shadow ray's product of kt over the surfaces it crosses is its product over all crossings (the
// order-free Aggregate query). True when all media have one priority and every two transparent
// solids whose bounds overlap are untransformed spheres of different materials, one strictly inside
// the other: a ray then enters a solid only from a different medium of equal priority, and leaves
// only the innermost solid it is in, into a different medium (media.h: both are surfaces). A solid
// overlapping another in any other way (partly, of the same material, a mesh, a box) answers
// false, conservatively: the walk one crossing at a time stays.
bool everyBoundaryIsASurface(const std::vector<Primitive>& primitives,
                             const std::vector<std::uint32_t>& primitiveMedium,
                             const std::vector<TriangleMesh>& meshes,
                             const std::vector<std::uint32_t>& meshMedium,
                             const std::vector<Material>& materials) {
  std::optional<int> priority;
  const auto samePriority = [&](std::uint32_t medium) {
    if (medium == kNoMedium) return true;
    if (!priority) priority = materials[medium].priority;
    return materials[medium].priority == *priority;
  };
  if (!std::all_of(primitiveMedium.begin(), primitiveMedium.end(), samePriority) ||
      !std::all_of(meshMedium.begin(), meshMedium.end(), samePriority)) {
    return false;
  }
  struct Solid {
    Bounds3 bounds;
    const Sphere* sphere;  // null: another solid
    std::uint32_t medium;
  };
  std::vector<Solid> solids;
  for (std::size_t i = 0; i < primitives.size(); ++i) {
    if (primitiveMedium[i] == kNoMedium) continue;
    const Sphere* sphere = primitives[i].worldFromObject() == nullptr
                               ? std::get_if<Sphere>(&primitives[i].shape())
                               : nullptr;
    solids.push_back({primitives[i].bounds(), sphere, primitiveMedium[i]});
  }
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    if (meshMedium[m] == kNoMedium) continue;
    Bounds3 bounds;
    for (const Point3& p : meshes[m].positions) bounds = unite(bounds, Bounds3(p, p));
    solids.push_back({bounds, nullptr, meshMedium[m]});
  }
  // A few solids overlap in the scenes this serves; past a budget of pairs the answer is no.
  constexpr std::size_t kPairBudget = std::size_t{1} << 20;
  if (solids.size() > 1 && solids.size() * (solids.size() - 1) / 2 > kPairBudget) return false;
  constexpr double kMargin = 1e-9;  // relative: far above the offsets of spawned rays
  for (std::size_t i = 0; i < solids.size(); ++i) {
    for (std::size_t j = i + 1; j < solids.size(); ++j) {
      const Solid& a = solids[i];
      const Solid& b = solids[j];
      const bool boundsOverlap = a.bounds.lo.x <= b.bounds.hi.x && b.bounds.lo.x <= a.bounds.hi.x &&
                                 a.bounds.lo.y <= b.bounds.hi.y && b.bounds.lo.y <= a.bounds.hi.y &&
                                 a.bounds.lo.z <= b.bounds.hi.z && b.bounds.lo.z <= a.bounds.hi.z;
      if (!boundsOverlap) continue;
      if (a.sphere == nullptr || b.sphere == nullptr || a.medium == b.medium) return false;
      const double d = length(a.sphere->center - b.sphere->center);
      const double big = std::max(a.sphere->radius, b.sphere->radius);
      const double small = std::min(a.sphere->radius, b.sphere->radius);
      const bool inside = d + small < big * (1 - kMargin);
      const bool apart = d > (big + small) * (1 + kMargin);
      if (!inside && !apart) return false;
    }
  }
  return true;
}

}  // namespace

bool Scene::intersect(const Ray& ray, double tMax, Hit& hit, MediumStack& media) const {
  Ray segment = ray;
  double travelled = 0;
  for (int passed = 0;; ++passed) {
    if (!aggregate_.intersect(segment, 0, tMax - travelled, hit)) return false;
    MediumStack beyond;
    if (passed == kMaxPassedBoundaries || boundaryAt(hit, ray.direction, media, beyond).surface) {
      hit.t += travelled;
      return true;
    }
    media = beyond;
    travelled += hit.t;
    segment = spawnRay(hit.point, hit.pointError, hit.normal, ray.direction);
  }
}

Color Scene::transmittance(const Ray& ray, double tMax, const MediumStack& start) const {
  if (boundariesAreSurfaces_) return aggregate_.transmittance(ray, 0, tMax);
  if (mediaKtInUnitInterval_) {
    // Every crossing keeps at most 1 of each channel and a medium's more than 0, so a product over
    // all crossings of exactly 1 (nothing that dims in the way) or 0 (something that is not a
    // medium, hence always a surface, blocks; barring underflow) is also the product over the
    // crossings that are surfaces. Only the rays in between need the ordered walk.
    const Color all = aggregate_.transmittance(ray, 0, tMax);
    if (all == Color(1) || isBlack(all)) return all;
  }
  MediumStack media = start;
  Color result(1);
  Ray segment = ray;
  double travelled = 0;
  Hit hit;
  for (int crossing = 0; crossing < kMaxShadowCrossings; ++crossing) {
    if (!aggregate_.intersect(segment, 0, tMax - travelled, hit)) return result;
    MediumStack beyond;
    if (boundaryAt(hit, ray.direction, media, beyond).surface) {
      const Color& kt = materialTransmission_[materialIndexOf(hit)];
      if (isBlack(kt)) return Color();
      result *= kt;
      if (isBlack(result)) return Color();
    }
    media = beyond;
    travelled += hit.t;
    segment = spawnRay(hit.point, hit.pointError, hit.normal, ray.direction);
  }
  return result * aggregate_.transmittance(segment, 0, tMax - travelled);
}

Scene::Scene(SceneParts parts)
    : name_((checkTextures(parts), std::move(parts.name))),
      includedFiles_(std::move(parts.includedFiles)),
      readFiles_(std::move(parts.readFiles)),
      materials_(std::move(parts.materials)),
      textures_(std::move(parts.textures)),
      materialTextures_(std::move(parts.materialTextures)),
      lights_(std::move(parts.lights)),
      ambient_(parts.ambient),
      background_(parts.background),
      environment_(std::move(parts.environment)),
      environmentSampler_(parts.render.integrator == Integrator::Path
                              ? EnvironmentSampler::make(environment_)
                              : nullptr),
      fog_(parts.fog),
      camera_(cameraSpecFor(parts)),
      image_(std::move(parts.image)),
      render_(parts.render),
      aggregate_(
          buildAggregate(parts, materials_, textures_, materialTextures_, groupTakesMaterial_)),
      emitterSampler_(
          render_.integrator == Integrator::Path
              ? EmitterSampler::make(aggregate_.primitives(), aggregate_.meshes(), materials_,
                                     materialTextures_, aggregate_.instances(),
                                     [this](const Hit& hit) { return materialIndexOf(hit); })
              : nullptr) {
  initialiseMedia();
  if (render_.integrator != Integrator::Path) return;
  for (const Light& light : lights_) {
    const auto* area = std::get_if<AreaLight>(&light);
    if (area == nullptr) continue;
    switch (area->shape) {
      case AreaShape::Rectangle:
        lightSurfaces_.push_back(
            {Rectangle::make(area->corner, area->edge1, area->edge2), area->intensity});
        break;
      case AreaShape::Disk:
        lightSurfaces_.push_back(
            {Disk::make(area->center, area->normal, area->radius), area->intensity});
        break;
      case AreaShape::Sphere:
        lightSurfaces_.push_back({Sphere::make(area->center, area->radius), area->intensity});
        break;
    }
  }
}

void Scene::initialiseMedia() {
  const std::vector<Primitive>& primitives = aggregate_.primitives();
  primitiveMedium_.reserve(primitives.size());
  for (const Primitive& primitive : primitives) {
    const std::uint32_t material = primitive.materialIndex();
    const bool medium =
        !isBlack(materials_[material].kt) && std::visit(BoundsVolume{}, primitive.shape());
    primitiveMedium_.push_back(medium ? material : kNoMedium);
  }
  const std::vector<TriangleMesh>& meshes = aggregate_.meshes();
  meshMedium_.reserve(meshes.size());
  for (const TriangleMesh& mesh : meshes) {
    const std::uint32_t material = mesh.materialIndex;
    const bool medium = !isBlack(materials_[material].kt) && meshBoundsVolume(mesh);
    meshMedium_.push_back(medium ? material : kNoMedium);
  }
  materialTransmission_.reserve(materials_.size());
  for (const Material& material : materials_) {
    materialTransmission_.push_back(shadowTransmission(material, textures_, materialTextures_));
  }
  nestedMedia_ =
      transparentSolidsOverlap(primitives, primitiveMedium_, meshes, meshMedium_, materials_);
  // The shortcut of transmittance(ray, tMax, media): no material's shadow kt exceeds 1 in any
  // channel, and no medium's is 0 in any.
  const auto atMostOne = [](const Color& kt) { return kt.r <= 1 && kt.g <= 1 && kt.b <= 1; };
  const auto positiveMedium = [&](std::uint32_t medium) {
    if (medium == kNoMedium) return true;
    const Color& kt = materialTransmission_[medium];
    return kt.r > 0 && kt.g > 0 && kt.b > 0;
  };
  mediaKtInUnitInterval_ =
      std::all_of(materialTransmission_.begin(), materialTransmission_.end(), atMostOne) &&
      std::all_of(primitiveMedium_.begin(), primitiveMedium_.end(), positiveMedium) &&
      std::all_of(meshMedium_.begin(), meshMedium_.end(), positiveMedium);
  if (!nestedMedia_) return;
  boundariesAreSurfaces_ =
      everyBoundaryIsASurface(primitives, primitiveMedium_, meshes, meshMedium_, materials_);

  // The camera's media: march along its view direction through every surface; a solid whose first
  // crossing leaves it contains the camera. (A thin lens's other ray origins are taken to lie in
  // the same media.)
  struct Leaving {
    double t;
    std::uint32_t medium;
  };
  std::vector<Leaving> leaving;
  std::unordered_set<std::uint64_t, SeededHash> seen;  // objects met: primitive, or mesh << 32
  constexpr int kMaxCameraCrossings = 4096;
  const Vec3 direction = camera_.toward();
  Ray segment{camera_.position(), direction};
  double travelled = 0;
  Hit hit;
  for (int k = 0; k < kMaxCameraCrossings; ++k) {
    if (!aggregate_.intersect(segment, 0, kInfinity, hit)) break;
    travelled += hit.t;
    const std::uint64_t object = hit.mesh == kNoMesh
                                     ? hit.primitive
                                     : (std::uint64_t{hit.mesh} << 32 | std::uint64_t{1} << 63);
    if (seen.insert(object).second && mediumOf(hit) != kNoMedium &&
        dot(hit.normal, direction) > 0) {
      leaving.push_back({travelled, mediumOf(hit)});
    }
    segment = spawnRay(hit.point, hit.pointError, hit.normal, direction);
  }
  std::stable_sort(leaving.begin(), leaving.end(),
                   [](const Leaving& a, const Leaving& b) { return a.t > b.t; });
  for (const Leaving& l : leaving) cameraMedia_.push(l.medium);
}

std::uint32_t Scene::instancedMaterialIndex(const Hit& hit) const {
  const PlacedInstance& in = aggregate_.instances()->instance(hit.instance);
  const GroupMaterialTakers& takers = groupTakesMaterial_[in.group];
  const bool takes =
      hit.mesh == kNoMesh ? takers.primitives[hit.primitive] != 0 : takers.meshes[hit.mesh] != 0;
  if (takes && in.material != kNoMaterialOverride) return in.material;
  return hit.mesh == kNoMesh ? aggregate_.primitiveOf(hit).materialIndexAt(hit.part)
                             : aggregate_.meshOf(hit).materialIndex;
}

}  // namespace glint

// The frozen scene: primitives in their acceleration structure, materials, lights, camera and the
// image and render settings. Built once (by code or by factories/scene_builder), then only queried
// (const), shared by all render threads without locks.
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "glint/accel/aggregate.h"
#include "glint/accel/instances.h"
#include "glint/core/color.h"
#include "glint/scene/camera.h"
#include "glint/scene/emitters.h"
#include "glint/scene/environment.h"
#include "glint/scene/fog.h"
#include "glint/scene/light.h"
#include "glint/scene/material.h"
#include "glint/scene/media.h"
#include "glint/scene/texture.h"

namespace glint {

enum class Encoding { Srgb, Linear };

// The seed's printGrid: after rendering, every pixel whose column or row is a multiple of interval
// (0 included) is painted with color.
struct GridOverlay {
  int interval = 100;  // pixels, > 0
  Color color;         // linear
};

// Adaptive anti-aliasing (image.adaptive; in the spirit of POV-Ray's adaptive mode): a pixel takes
// ImageSettings::samples first and more, up to maxSamples, only while its samples disagree by more
// than threshold (linear color units).
struct AdaptiveSampling {
  int maxSamples = 64;      // per pixel, ≥ ImageSettings::samples
  double threshold = 0.02;  // > 0
};

struct ImageSettings {
  int width = 1;  // pixels (also given to the camera)
  int height = 1;
  int samples = 1;  // per pixel, stratified; with `adaptive`, the minimum per pixel
  Encoding encoding = Encoding::Srgb;
  std::optional<GridOverlay> grid;
  std::optional<AdaptiveSampling> adaptive;
};

// Ambient occlusion for the Whitted integrator (render.ambient_occlusion, DESIGN.md §10, as
// Tachyon has it): at every hit the ambient term ka·Ia is scaled by the transmittance, averaged
// over `samples` cosine-weighted directions about the shading normal on the viewer's side, of
// shadow-style rays that travel `distance` (scene units; infinite by default).
struct AmbientOcclusion {
  int samples = 16;  // rays per hit (fewer below a glossy split, as area-light samples)
  double distance = std::numeric_limits<double>::infinity();  // > 0
};

// render.integrator (DESIGN.md §10): Whitted's model (§3, the default) or unidirectional path
// tracing with the normalised Phong BRDF.
enum class Integrator { Whitted, Path };

// How the path integrator combines its two ways of finding emitters and the image sky: multiple
// importance sampling (the default), or one of them alone — for tests and benchmarks that
// compare them (all three converge to the same image); not a scene key.
enum class PathLightSampling { Mis, LightsOnly, BrdfOnly };

struct RenderSettings {
  Integrator integrator = Integrator::Whitted;
  int minDepth = 3;          // path: Russian roulette from this many surface hits on
  int maxDepth = 10;         // surface hits per path, the primary hit included
  double minWeight = 0.001;  // a branch stops when the product of kr/kt factors falls below this
  int blurSamples = 16;      // rays per glossy reflection/refraction
  std::uint64_t seed = 0;    // varies every random number, deterministically
  std::optional<AmbientOcclusion> ambientOcclusion;  // none by default
  PathLightSampling lightSampling = PathLightSampling::Mis;
};

// A group of the scene file's `groups` (DESIGN.md §11), in the group's own space, placed by
// SceneParts::instances. Material indices point into SceneParts::materials.
struct GroupParts {
  std::vector<Primitive> primitives;
  std::vector<TriangleMesh> meshes;
  // Per primitive and per mesh: 1 when it was written without a `material`, so that an instance's
  // material replaces it; empty means all 0.
  std::vector<std::uint8_t> primitiveTakesMaterial;
  std::vector<std::uint8_t> meshTakesMaterial;
};

// Of a built group: which primitives and meshes take an instance's material (1) or keep theirs.
struct GroupMaterialTakers {
  std::vector<std::uint8_t> primitives;
  std::vector<std::uint8_t> meshes;
};

// Everything needed to build a Scene. The scene builder fills this from a scene file; programs may
// fill it directly. Primitive material indices point into `materials`.
struct SceneParts {
  std::string name;
  // The files the scene file includes (`include`), as they were opened: they belong to what the
  // scene is, so a checkpoint's or an MPI rank's fingerprint covers their bytes too.
  std::vector<std::filesystem::path> includedFiles;
  // Every other file the scene reads — mesh files and image files (textures, the sky) — as they
  // were opened; a render's output must not replace one of them.
  std::vector<std::filesystem::path> readFiles;
  std::vector<Primitive> primitives;
  std::vector<TriangleMesh> meshes;  // mesh material indices point into `materials`
  std::vector<GroupParts> groups;    // what `instances` place
  // Instance::group indexes `groups`; Instance::material is a material index or
  // kNoMaterialOverride.
  std::vector<Instance> instances;
  Acceleration acceleration = Acceleration::Bvh;
  // The instruction set of the BVH queries (core/isa.h); none: defaultIsa(). Never changes a pixel.
  std::optional<Isa> isa;
  std::vector<Material> materials{Material{}};     // index 0: the default material
  std::vector<Texture> textures;                   // MaterialTextures' TextureIds index these
  std::vector<MaterialTextures> materialTextures;  // Material::textures index these
  std::vector<Light> lights;
  Color ambient;            // Ia = ambient color × ambient intensity
  Color background;         // linear; what a ray that misses returns (environment.kind Uniform)
  Environment environment;  // a gradient or an image instead of the one colour
  std::optional<Fog> fog;   // none by default
  CameraSpec camera;        // imageWidth/imageHeight are overwritten from `image`
  ImageSettings image;
  RenderSettings render;
};

class Scene {
 public:
  // Builds the camera and the acceleration structure. Throws CameraError / std::invalid_argument
  // for an invalid camera, a primitive or mesh whose material index is out of range, or a mesh
  // with invalid indices (see Aggregate).
  explicit Scene(SceneParts parts);

  const std::string& name() const { return name_; }
  const std::vector<std::filesystem::path>& includedFiles() const { return includedFiles_; }
  const std::vector<std::filesystem::path>& readFiles() const { return readFiles_; }
  const Aggregate& aggregate() const { return aggregate_; }
  const std::vector<Primitive>& primitives() const { return aggregate_.primitives(); }
  const std::vector<Material>& materials() const { return materials_; }
  const std::vector<TriangleMesh>& meshes() const { return aggregate_.meshes(); }
  const Material& materialOf(std::uint32_t primitive) const {
    return materials_[aggregate_.primitives()[primitive].materialIndex()];
  }
  // The material and the emission of what a ray hit: its primitive's, or its mesh's.
  // (A csg's operands may each have their own: Primitive::materialIndexAt(hit.part).)
  const Material& materialOf(const Hit& hit) const { return materials_[materialIndexOf(hit)]; }
  // The index of that material: a primitive's (a csg's operand's, Primitive::materialIndexAt) or
  // a mesh's; inside an instance, the instance's own for group objects written without one.
  std::uint32_t materialIndexOf(const Hit& hit) const {
    if (hit.instance != kNoInstance) return instancedMaterialIndex(hit);
    return hit.mesh == kNoMesh ? aggregate_.primitives()[hit.primitive].materialIndexAt(hit.part)
                               : aggregate_.meshes()[hit.mesh].materialIndex;
  }
  const Color& emissionOf(const Hit& hit) const {
    return hit.mesh == kNoMesh ? aggregate_.primitiveOf(hit).emissionAt(hit.part)
                               : aggregate_.meshOf(hit).emission;
  }
  // The mesh (hit.mesh != kNoMesh) or primitive a hit is on, inside an instance's group too.
  const TriangleMesh& meshOf(const Hit& hit) const { return aggregate_.meshOf(hit); }
  const Primitive& primitiveOf(const Hit& hit) const { return aggregate_.primitiveOf(hit); }
  const std::vector<Texture>& textures() const { return textures_; }
  const std::vector<MaterialTextures>& materialTextures() const { return materialTextures_; }
  // Whether any material or the background has a texture: the renderer then tracks ray
  // differentials and evaluates textures; without, it never looks at them.
  bool hasTextures() const { return !textures_.empty(); }
  const std::vector<Light>& lights() const { return lights_; }
  const Color& ambient() const { return ambient_; }
  const Color& background() const { return background_; }
  const Environment& environment() const { return environment_; }
  // The image environment's importance sampler for the path integrator; null for other
  // backgrounds and under the Whitted integrator.
  const EnvironmentSampler* environmentSampler() const { return environmentSampler_.get(); }
  // The emissive surfaces sampled as lights by the path integrator; null when there are none and
  // under the Whitted integrator.
  const EmitterSampler* emitterSampler() const { return emitterSampler_.get(); }
  // Under the path integrator, the area lights as surfaces that camera and mirror rays see (their
  // shape and its radiance, colour × intensity); empty otherwise.
  struct LightSurface {
    Shape shape;
    Color radiance;
  };
  const std::vector<LightSurface>& lightSurfaces() const { return lightSurfaces_; }
  bool uniformBackground() const { return environment_.kind == BackgroundKind::Uniform; }
  // What a ray leaving the scene along the unit direction d sees (from anywhere: an environment
  // light's direction), and what the ray itself sees (a sky by height looks at its origin).
  Color backgroundAlong(const Vec3& d) const { return environment_.along(d, background_); }
  Color backgroundSeenBy(const Ray& ray) const {
    return environment_.along(ray.direction, background_, ray.origin);
  }
  const std::optional<Fog>& fog() const { return fog_; }
  const Camera& camera() const { return camera_; }
  const ImageSettings& image() const { return image_; }
  const RenderSettings& render() const { return render_; }

  bool intersect(const Ray& ray, double tMax, Hit& hit) const {
    return aggregate_.intersect(ray, 0, tMax, hit);
  }
  Color transmittance(const Ray& ray, double tMax) const {
    return aggregate_.transmittance(ray, 0, tMax);
  }

  // ---- Nested dielectrics (DESIGN.md §11, scene/media.h) ----
  // A transparent solid is a sphere, box, cylinder, tube or closed mesh (closed and consistently
  // oriented, outward) whose material has kt > 0; its medium is its material. Rays track the media
  // they are inside only when some transparent solid's bounds overlap another transparent object's:
  // otherwise no ray can be inside two media at once or meet a boundary that is no surface, every
  // surface refracts against air exactly as the queries above assume, and the renderer uses them
  // unchanged.
  bool nestedMedia() const { return nestedMedia_; }
  // The media the camera's position is inside (nestedMedia only, else empty): the transparent
  // solids that the ray from the camera along its view direction leaves before entering, the one it
  // leaves farthest away outermost.
  const MediumStack& cameraMedia() const { return cameraMedia_; }
  // The medium the hit's surface bounds: its material index for a transparent solid, else
  // kNoMedium. These queries follow the nested rule in any scene; the renderer uses them only
  // when nestedMedia().
  // Objects inside instances are no media: they refract against the medium around them.
  std::uint32_t mediumOf(const Hit& hit) const {
    if (hit.instance != kNoInstance) return kNoMedium;
    return hit.mesh == kNoMesh ? primitiveMedium_[hit.primitive] : meshMedium_[hit.mesh];
  }
  // The boundary a ray with unit `direction` inside `media` meets at `hit` (crossBoundary).
  Boundary boundaryAt(const Hit& hit, const Vec3& direction, const MediumStack& media,
                      MediumStack& beyond) const {
    return crossBoundary(media, materialIndexOf(hit), mediumOf(hit), dot(hit.normal, direction) < 0,
                         materials_, beyond);
  }
  // The closest hit on a surface for a ray inside `media`: the boundaries before it that are no
  // surface are passed, and `media` becomes the stack at the hit. hit.t is the distance along
  // `ray` (summed over the passed segments). After kMaxPassedBoundaries passed in a row the next
  // boundary counts as a surface (a bound on hostile scenes of many coincident solids).
  static constexpr int kMaxPassedBoundaries = 64;
  bool intersect(const Ray& ray, double tMax, Hit& hit, MediumStack& media) const;
  // Shadow transmittance for a ray that starts inside `media`: the product of kt over the surfaces
  // it crosses in (0, tMax), boundaries that are no surface left out (a glass sphere inside a glass
  // sphere of the same material costs one sphere's kt²). Crossings are visited in order, one
  // closest-hit query each; past kMaxShadowCrossings the rest of the way counts every crossing.
  static constexpr int kMaxShadowCrossings = 256;
  Color transmittance(const Ray& ray, double tMax, const MediumStack& media) const;

 private:
  void initialiseMedia();
  // The material of a hit on an instance: the instance's own for group objects written without
  // one, else the object's.
  std::uint32_t instancedMaterialIndex(const Hit& hit) const;

  std::string name_;
  std::vector<std::filesystem::path> includedFiles_;
  std::vector<std::filesystem::path> readFiles_;
  std::vector<Material> materials_;
  std::vector<Texture> textures_;
  std::vector<MaterialTextures> materialTextures_;
  std::vector<Light> lights_;
  Color ambient_;
  Color background_;
  Environment environment_;
  std::shared_ptr<const EnvironmentSampler> environmentSampler_;
  std::optional<Fog> fog_;
  Camera camera_;
  ImageSettings image_;
  RenderSettings render_;
  // Per group the Aggregate of instances() holds (instances.h): which of its primitives and meshes
  // take an instance's material (GroupParts). Before aggregate_: filled while it is built.
  std::vector<GroupMaterialTakers> groupTakesMaterial_;
  Aggregate aggregate_;
  std::shared_ptr<const EmitterSampler> emitterSampler_;  // after aggregate_: built from it
  std::vector<LightSurface> lightSurfaces_;
  bool nestedMedia_ = false;
  std::vector<std::uint32_t> primitiveMedium_;  // per primitive: mediumOf
  std::vector<std::uint32_t> meshMedium_;       // per mesh: mediumOf
  std::vector<Color> materialTransmission_;     // per material: the kt a shadow ray keeps
  MediumStack cameraMedia_;
  // Every material's shadow kt is at most 1 and every medium's above 0 in each channel:
  // transmittance(ray, tMax, media) may answer from the order-free query when it gives 1 or 0.
  bool mediaKtInUnitInterval_ = false;
  // No boundary can be "no surface" (nested spheres of distinct materials, one priority):
  // transmittance(ray, tMax, media) is the order-free query (everyBoundaryIsASurface in scene.cpp).
  bool boundariesAreSurfaces_ = false;
};

}  // namespace glint

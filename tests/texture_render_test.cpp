// Textures in whole renders (DESIGN.md §9): a solid checker exact at cell centres on every shape,
// image orientation on a rectangle, the environment in a mirror sphere and through glass, real
// textured mesh files no one here wrote (Debian's assimp-testmodels: an OBJ with map_Kd, a binary
// glTF with baseColorTexture, a glTF with normalTexture), determinism on threads and crops, and
// the refusals (a missing texture at the mesh's line, a path leaving the folder, over budget).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "glint/factories/scene_loader.h"
#include "glint/geometry/surface_coordinates.h"
#include "glint/image/image_decoder.h"
#include "glint/image/image_writer.h"
#include "glint/job/checkpoint.h"
#include "glint/render/renderer.h"
#include "glint/render/texturing.h"
#include "glint/scene/scene.h"

namespace glint {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const fs::path kModels = "/usr/share/assimp/models";

fs::path scratchFolder() {
  const fs::path dir =
      fs::temp_directory_path() / ("glint_texture_render_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

Scene sceneOf(const std::string& text, const fs::path& folder = ".") {
  return Scene(loadSceneFromString(text, "test.yaml", folder).parts);
}

std::string sceneErrors(const std::string& text, const fs::path& folder,
                        std::uint64_t budget = defaultImageMemoryBudget()) {
  try {
    LoadOptions options;
    options.memoryBudget = budget;
    loadSceneFromString(text, "test.yaml", folder, options);
  } catch (const SceneError& e) {
    std::string all;
    for (const Diagnostic& d : e.diagnostics()) {
      all += std::to_string(d.where.line) + ": " + d.message + "\n";
    }
    return all;
  }
  return "";
}

// The camera ray through pixel (x, y)'s centre, as render() traces it.
Ray cameraRay(const Scene& scene, int x, int y) {
  const Ray ray = scene.camera().generateRay(x, y, {0.5, 0.5}, {0.5, 0.5});
  return Ray{ray.origin, normalize(ray.direction)};
}

// Ambient light only (intensity 1) and ka textured: a pixel is exactly the texture's colour.
const char* kAmbientOnly = R"(
camera: { position: [0, 3, 6], look_at: [0, 0.6, 0], fov: 50 }
image: { width: 48, height: 36 }
ambient: { color: [1, 1, 1], intensity: 1 }
textures:
  tiles: { type: checker, colors: [[0.2, 0.2, 0.2], [0.8, 0.8, 0.8]], scale: 0.5 }
materials:
  m: { ka: tiles }
objects:
)";

TEST(TextureRender, SolidCheckerIsExactAtCellCentresOnEveryShape) {
  // Flat shapes and box faces lie on cell-centre planes (y = 0.25, z = -0.25, ...) so that no pixel
  // sits on a cell boundary along their constant axis; the transformed box checks the object's own
  // space.
  const std::vector<std::string> objects = {
      "{ type: sphere, center: [0, 0.6, 0], radius: 1.3, material: m }",
      "{ type: plane, point: [0, 0.25, 0], normal: [0, 1, 0], material: m }",
      "{ type: triangle, vertices: [[-3, 0.25, 2], [3, 0.25, 2], [0, 0.25, -3]], material: m }",
      "{ type: polygon, vertices: [[-2, 0.25, 2], [2, 0.25, 2], [2, 0.25, -2], [-2, 0.25, -2]], "
      "material: m }",
      "{ type: rectangle, corner: [-3, -1, -0.25], edges: [[6, 0, 0], [0, 4, 0]], material: m }",
      "{ type: quadrangle, vertices: [[-2, 0.25, 2], [2, 0.25, 2], [1, 0.25, -2], [-2, 0.25, -2]], "
      "material: m }",
      "{ type: tube, origin: [0, 0, 0], axis: [1, 0, 0], radius: 1.1, material: m }",
      "{ type: cylinder, base: [0, -0.5, 0], axis: [0, 1, 0], radius: 1.2, height: 2, material: m "
      "}",
      "{ type: box, min: [-1.25, -0.25, -1.25], max: [1.25, 1.25, 0.75], material: m }",
      "{ type: disk, center: [0, 0.25, 0], normal: [0, 1, 0], radius: 2.5, material: m }",
      "{ type: box, min: [-0.75, -0.25, -0.75], max: [0.75, 1.25, 0.75], material: m, transform: "
      "[{ rotate: { axis: [0, 1, 0], angle: 30 } }, { translate: [0.3, 0.1, 0] }] }",
  };
  for (const std::string& object : objects) {
    const Scene scene = sceneOf(std::string(kAmbientOnly) + "  - " + object + "\n");
    RenderOptions options;
    options.threads = 1;
    const Film film = render(scene, options);
    int checked = 0;
    for (int y = 0; y < 36; ++y) {
      for (int x = 0; x < 48; ++x) {
        Hit hit;
        if (!scene.intersect(cameraRay(scene, x, y), kInfinity, hit)) continue;
        Point3 p = hit.point;
        if (const Transform* t = scene.primitives()[hit.primitive].worldFromObject()) {
          p = t->inverse()(p);
        }
        // Only points within a quarter cell of a cell centre along every axis.
        bool nearCentre = true;
        long cells = 0;
        for (int k = 0; k < 3; ++k) {
          const double c = p[k] / 0.5;
          nearCentre = nearCentre && std::abs(c - std::floor(c) - 0.5) < 0.25;
          cells += static_cast<long>(std::floor(c));
        }
        if (!nearCentre) continue;
        const double expected = (cells % 2 + 2) % 2 == 1 ? 0.8 : 0.2;
        EXPECT_EQ(film.at(x, y).r, expected) << object << " at pixel " << x << ", " << y;
        ++checked;
      }
    }
    EXPECT_GT(checked, 20) << object;
  }
}

// A 2×2 PNG, rows from the top: red, green / blue, white (linear codes 0 or 255).
fs::path writeTwoByTwo(const fs::path& folder) {
  Film film(2, 2, PixelRegion{0, 0, 2, 2});
  film.at(0, 0) = Color(1, 0, 0);
  film.at(1, 0) = Color(0, 1, 0);
  film.at(0, 1) = Color(0, 0, 1);
  film.at(1, 1) = Color(1, 1, 1);
  writeImage(film, folder / "two.png", Encoding::Linear);
  return folder / "two.png";
}

TEST(TextureRender, ImageReadsUprightOnARectangle) {
  const fs::path folder = scratchFolder();
  writeTwoByTwo(folder);
  // The rectangle from corner (0, 0) along +x and +y fills the view of a camera looking at −z.
  const Scene scene = sceneOf(R"(
camera: { position: [0, 0, 1], direction: [0, 0, -1], view_plane: { width: 2, height: 2, distance: 1 } }
image: { width: 8, height: 8 }
ambient: { color: [1, 1, 1], intensity: 1 }
objects:
  - { type: rectangle, corner: [-1, -1, 0], edges: [[2, 0, 0], [0, 2, 0]],
      material: { ka: { type: image, file: two.png, filter: nearest } } }
)",
                              folder);
  const Film film = render(scene);
  // The image's top-left texel is red at the top-left of the view, and so on.
  EXPECT_EQ(film.at(1, 1), Color(1, 0, 0));
  EXPECT_EQ(film.at(6, 1), Color(0, 1, 0));
  EXPECT_EQ(film.at(1, 6), Color(0, 0, srgbToLinear(1)));
  EXPECT_EQ(film.at(6, 6), Color(1, 1, 1));
}

TEST(TextureRender, MirrorSphereAndGlassShowTheEnvironment) {
  const fs::path folder = scratchFolder();
  Film sky(16, 8, PixelRegion{0, 0, 16, 8});
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 16; ++x) sky.at(x, y) = Color(x / 15.0, y / 7.0, 0.5 + (x % 2) * 0.25);
  }
  writeImage(sky, folder / "sky.exr", Encoding::Linear);
  for (const char* background :
       {"{ type: gradient, zenith: [0, 0, 1], horizon: [1, 1, 1], nadir: [0.3, 0.2, 0] }",
        "{ type: sky, top: [0, 0, 1], bottom: [1, 0.5, 0], up: [0, 1, 0.3], top_value: 0.7, "
        "bottom_value: -0.4 }",
        "{ type: image, file: sky.exr, intensity: 2, rotate: 30 }"}) {
    const Scene scene = sceneOf(std::string(R"(
camera: { position: [0, 0, 4], look_at: [0, 0, 0], fov: 40 }
image: { width: 32, height: 32 }
render: { max_depth: 2 }
background: )") + background + R"(
objects:
  - { type: sphere, center: [0, 0, 0], radius: 1, material: { ka: 0, kr: 1 } }
  - { type: sphere, center: [0, 2.2, 0], radius: 0.6, material: { ka: 0, kt: 1 } }
)",
                                folder);
    ASSERT_FALSE(scene.uniformBackground());
    const Film film = render(scene);
    int mirrored = 0;
    for (int y = 0; y < 32; ++y) {
      for (int x = 0; x < 32; ++x) {
        const Ray ray = cameraRay(scene, x, y);
        Hit hit;
        Color expected = scene.backgroundAlong(ray.direction);  // a miss, or straight through glass
        if (scene.intersect(ray, kInfinity, hit) && hit.point.y < 1.2) {
          const Vec3 n = toVec(hit.normal);
          const Vec3 r = ray.direction - n * (2 * dot(ray.direction, n));
          Hit second;
          if (scene.intersect(Ray{hit.point + n * 1e-9, r}, kInfinity, second)) continue;
          expected = scene.backgroundAlong(r);
          ++mirrored;
        }
        const Color& got = film.at(x, y);
        EXPECT_NEAR(got.r, expected.r, 1e-6) << background << " " << x << ", " << y;
        EXPECT_NEAR(got.g, expected.g, 1e-6) << background << " " << x << ", " << y;
        EXPECT_NEAR(got.b, expected.b, 1e-6) << background << " " << x << ", " << y;
      }
    }
    EXPECT_GT(mirrored, 100);
  }
}

// Renders a mesh file under ambient light 1 (no lights): a textured pixel is ka × texture, and a
// mesh material's ka is its kd. Each of `files` (the pictures the mesh file names) is decoded on
// its own here; a pixel is compared with the one its material's texture came from (the same
// texels), sampled at the hit's (u, v). Returns the mean absolute difference over the pixels
// showing a textured part, and how much the expected colour varies across them (a flat render
// cannot pass).
struct TextureMatch {
  double meanDifference = 0;
  double spread = 0;
  int pixels = 0;
};

std::vector<std::uint8_t> fileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

bool sameTexels(const MipMap& a, const MipMap& b) {
  if (a.width(0) != b.width(0) || a.height(0) != b.height(0)) return false;
  for (int y = 0; y < a.height(0); y += 3) {
    for (int x = 0; x < a.width(0); x += 3) {
      if (!(a.texel(0, x, y) == b.texel(0, x, y))) return false;
    }
  }
  return true;
}

TextureMatch matchMeshTexture(const fs::path& mesh, const std::string& camera,
                              const std::vector<fs::path>& files, int size) {
  const Scene scene = sceneOf("camera: " + camera + "\nimage: { width: " + std::to_string(size) +
                              ", height: " + std::to_string(size) + R"( }
ambient: { color: [1, 1, 1], intensity: 1 }
objects:
  - { type: mesh, file: )" + mesh.string() +
                              " }\n");
  const Film film = render(scene);
  std::vector<MipMap> decoded;
  for (const fs::path& file : files)
    decoded.emplace_back(decodeImage(fileBytes(file), ImageEncoding::Srgb));
  TextureMatch m;
  double lo = 1e9;
  double hi = -1e9;
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      Hit hit;
      if (!scene.intersect(cameraRay(scene, x, y), kInfinity, hit) || hit.mesh == kNoMesh) continue;
      const Material& material = scene.materialOf(hit);
      if (material.textures == kUntextured) continue;
      const TextureId kd = scene.materialTextures()[material.textures].kd;
      if (kd == kNoTexture) continue;
      const MipMap& used = *std::get<ImageTexture>(scene.textures()[kd]).image;
      const MipMap* own = nullptr;
      for (const MipMap& d : decoded) own = sameTexels(d, used) ? &d : own;
      EXPECT_NE(own, nullptr) << "a texture that is none of the mesh's files";
      if (own == nullptr) continue;
      const SurfaceCoordinates sc =
          surfaceCoordinates(scene.meshes()[hit.mesh], hit.triangle, hit.point);
      const Color expected = material.ka * own->bilinear(0, sc.uv);
      const Color& got = film.at(x, y);
      m.meanDifference += (std::abs(got.r - expected.r) + std::abs(got.g - expected.g) +
                           std::abs(got.b - expected.b)) /
                          3;
      lo = std::min(lo, expected.g);
      hi = std::max(hi, expected.g);
      ++m.pixels;
    }
  }
  if (m.pixels > 0) m.meanDifference /= m.pixels;
  m.spread = hi - lo;
  return m;
}

TEST(TextureRender, ObjMapKdIsApplied) {
  const fs::path folder = kModels / "OBJ";
  if (!fs::exists(folder / "spider.obj")) GTEST_SKIP() << "assimp-testmodels is not installed";
  // spider.mtl names its five maps as Windows paths (map_Kd .\\drkwood2.jpg).
  const TextureMatch m = matchMeshTexture(
      folder / "spider.obj", "{ position: [0, 60, 140], look_at: [0, 0, 0], fov: 30 }",
      {folder / "drkwood2.jpg", folder / "SpiderTex.jpg", folder / "wal67ar_small.jpg",
       folder / "wal69ar_small.jpg", folder / "engineflare1.jpg"},
      160);
  ASSERT_GT(m.pixels, 1000);
  EXPECT_GT(m.spread, 0.1);
  EXPECT_LT(m.meanDifference, 0.03);
}

TEST(TextureRender, GlbBaseColorTextureIsApplied) {
  const fs::path glb = kModels / "glTF2/BoxTextured-glTF-Binary/BoxTextured.glb";
  if (!fs::exists(glb)) GTEST_SKIP() << "assimp-testmodels is not installed";
  // The picture the .glb embeds is the text glTF's CesiumLogoFlat.png (211 pixels wide). Rendered
  // large enough that a face spans more pixels than the picture has texels, so that the trilinear
  // lookup stays at the sharpest level.
  const TextureMatch m =
      matchMeshTexture(glb, "{ position: [1.2, 1.4, 2.2], look_at: [0, 0, 0], fov: 40 }",
                       {kModels / "glTF2/BoxTextured-glTF/CesiumLogoFlat.png"}, 480);
  ASSERT_GT(m.pixels, 1000);
  EXPECT_GT(m.spread, 0.2);
  EXPECT_LT(m.meanDifference, 0.03);
}

TEST(TextureRender, GltfDataUriBaseColorTextureIsApplied) {
  const fs::path gltf = kModels / "glTF2/BoxTextured-glTF-Embedded/BoxTextured.gltf";
  if (!fs::exists(gltf)) GTEST_SKIP() << "assimp-testmodels is not installed";
  // The same cube with its picture as a base64 data: URI inside the JSON.
  const TextureMatch m =
      matchMeshTexture(gltf, "{ position: [1.2, 1.4, 2.2], look_at: [0, 0, 0], fov: 40 }",
                       {kModels / "glTF2/BoxTextured-glTF/CesiumLogoFlat.png"}, 480);
  ASSERT_GT(m.pixels, 1000);
  EXPECT_GT(m.spread, 0.2);
  EXPECT_LT(m.meanDifference, 0.03);
}

TEST(TextureRender, GltfNormalTextureTiltsTheShadingNormal) {
  const fs::path gltf = kModels / "glTF2/ClearCoat-glTF/ClearCoatTest.gltf";
  if (!fs::exists(gltf)) GTEST_SKIP() << "assimp-testmodels is not installed";
  const Scene scene = sceneOf(R"(
camera: { position: [0, -2, 14], look_at: [0, -2, 0], fov: 40 }
image: { width: 96, height: 96 }
ambient: { color: [1, 1, 1], intensity: 1 }
objects:
  - { type: mesh, file: )" + gltf.string() +
                              " }\n");
  int checked = 0;
  int tilted = 0;
  for (int y = 0; y < 96; ++y) {
    for (int x = 0; x < 96; ++x) {
      Hit hit;
      if (!scene.intersect(cameraRay(scene, x, y), kInfinity, hit) || hit.mesh == kNoMesh) continue;
      const Material& material = scene.materialOf(hit);
      if (material.textures == kUntextured) continue;
      const MaterialTextures& b = scene.materialTextures()[material.textures];
      if (b.normalMap == kNoTexture) continue;
      const auto& image = std::get<ImageTexture>(scene.textures()[b.normalMap]).image;
      const SurfaceCoordinates sc =
          surfaceCoordinates(scene.meshes()[hit.mesh], hit.triangle, hit.point);
      const Color c = image->bilinear(0, sc.uv);
      const Vec3 m = normalize(Vec3{2 * c.r - 1, 2 * c.g - 1, 2 * c.b - 1});
      TexturedHit shaded;
      shadeTexturedHit(scene, hit, nullptr, shaded);
      // The map's tilt away from the surface normal is the angle the shading normal turns.
      const double expected = std::acos(std::clamp(m.z, -1.0, 1.0));
      const double got =
          std::acos(std::clamp(dot(shaded.shadingNormal, toVec(hit.shadingNormal)), -1.0, 1.0));
      EXPECT_NEAR(got, expected, 0.02) << x << ", " << y;
      ++checked;
      tilted += expected > 0.1 ? 1 : 0;
    }
  }
  EXPECT_GT(checked, 100);
  EXPECT_GT(tilted, 20);
}

const char* kTexturedScene = R"(
camera: { position: [0, 2, 7], look_at: [0, 0.7, 0], fov: 45 }
image: { width: 41, height: 29, samples: 2 }
background: { type: gradient, zenith: [0.1, 0.2, 0.6], horizon: [0.9, 0.9, 1] }
ambient: { color: [1, 1, 1], intensity: 0.2 }
render: { blur_samples: 3 }
textures:
  tiles: { type: checker2d, repeat: [1, 1] }
materials:
  floor: { kd: tiles, kr: 0.3, reflection_blur: 2 }
objects:
  - { type: plane, point: [0, 0, 0], normal: [0, 1, 0], material: floor }
  - { type: sphere, center: [-1, 1, 0], radius: 1, material: { kr: 0.9 } }
  - { type: sphere, center: [1.3, 0.8, 0.5], radius: 0.8,
      material: { kd: { type: image, file: two.png }, bump_map: { type: noise, scale: 0.1 }, bump_scale: 0.02 } }
  - { type: box, min: [0.5, 0, -2], max: [2, 1, -1], material: { kd: { type: wood, scale: 0.2 }, kt: 0.3, ior: 1.3 } }
lights:
  - { type: point, position: [3, 5, 4], intensity: 1 }
)";

TEST(TextureRender, SameBytesOnThreadsAndStitchedCrops) {
  const fs::path folder = scratchFolder();
  writeTwoByTwo(folder);
  const Scene scene = sceneOf(kTexturedScene, folder);
  RenderOptions one;
  one.threads = 1;
  RenderOptions two;
  two.threads = 2;
  two.tileSize = 5;
  const Film a = render(scene, one);
  const Film b = render(scene, two);
  ASSERT_EQ(a.pixels().size(), b.pixels().size());
  EXPECT_EQ(std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(Color)),
            0);
  Film stitched(41, 29, PixelRegion{0, 0, 41, 29});
  const int xs[] = {0, 13, 41};
  const int ys[] = {0, 9, 29};
  for (int cy = 0; cy < 2; ++cy) {
    for (int cx = 0; cx < 2; ++cx) {
      RenderOptions options;
      options.crop = PixelRegion{xs[cx], ys[cy], xs[cx + 1], ys[cy + 1]};
      const Film part = render(scene, options);
      for (int y = 0; y < part.height(); ++y)
        for (int x = 0; x < part.width(); ++x) stitched.at(xs[cx] + x, ys[cy] + y) = part.at(x, y);
    }
  }
  EXPECT_EQ(
      std::memcmp(a.pixels().data(), stitched.pixels().data(), a.pixels().size() * sizeof(Color)),
      0);
}

TEST(TextureRender, ACheckpointBelongsToTheTexturesItWasRenderedWith) {
  // The picture is not in the scene file's bytes: the render fingerprint hashes its pixels, so a
  // checkpoint is not resumed after the texture file changed.
  const fs::path folder = scratchFolder() / "fingerprint";
  fs::create_directories(folder);
  writeTwoByTwo(folder);
  const std::string text =
      std::string(kAmbientOnly).substr(0, std::string(kAmbientOnly).find("textures:")) +
      "objects:\n  - { type: sphere, center: [0, 0.6, 0], radius: 1, material: "
      "{ kd: { type: image, file: two.png } } }\n";
  const Scene before = sceneOf(text, folder);
  const CheckpointSettings settings = checkpointSettingsFor(before, PixelRegion{0, 0, 48, 36}, 16);
  const std::uint64_t a = renderFingerprint(text, before, settings);
  EXPECT_EQ(a, renderFingerprint(text, sceneOf(text, folder), settings));
  Film other(2, 2, PixelRegion{0, 0, 2, 2});
  other.at(0, 0) = Color(0.5, 0, 0);
  writeImage(other, folder / "two.png", Encoding::Linear);
  EXPECT_NE(a, renderFingerprint(text, sceneOf(text, folder), settings));
}

TEST(TextureRender, TextureFilesAreCheckedAndBudgeted) {
  const fs::path folder = scratchFolder() / "refusals";
  fs::create_directories(folder / "inner");
  writeTwoByTwo(folder);
  // A mesh whose MTL names a missing texture: an error at the mesh object's line, naming it.
  std::ofstream(folder / "inner/quad.obj") << "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                              "vt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n";
  std::ofstream(folder / "inner/quad.mtl") << "newmtl m\nKd 1 1 1\nmap_Kd missing.png\n";
  const std::string header =
      "camera: { position: [0, 0, 3], direction: [0, 0, -1], fov: 40 }\n"
      "image: { width: 4, height: 4 }\nobjects:\n";
  EXPECT_THAT(sceneErrors(header + "  - { type: mesh, file: inner/quad.obj }\n", folder),
              HasSubstr("4: mesh file 'inner/quad.obj': its diffuse texture 'missing.png': no such "
                        "file"));
  // A texture outside the folder tree the mesh may use.
  std::ofstream(folder / "inner/quad.mtl") << "newmtl m\nKd 1 1 1\nmap_Kd ../../outside.png\n";
  EXPECT_THAT(sceneErrors(header + "  - { type: mesh, file: inner/quad.obj }\n", folder),
              HasSubstr("outside"));
  // A corrupt image.
  std::ofstream(folder / "bad.png") << "\x89PNG\r\n\x1a\nnot really";
  EXPECT_THAT(sceneErrors(header + "  - { type: sphere, center: [0, 0, 0], radius: 1, material: "
                                   "{ kd: { type: image, file: bad.png } } }\n",
                          folder),
              HasSubstr("4: cannot load texture file 'bad.png': invalid PNG file"));
  // Over the memory budget, from the header alone: the 2×2 image's mip-maps take 60 bytes.
  EXPECT_THAT(sceneErrors(header + "  - { type: sphere, center: [0, 0, 0], radius: 1, material: "
                                   "{ kd: { type: image, file: two.png } } }\n",
                          folder, filmBytes(4, 4) + 30),
              HasSubstr("more than the memory limit"));
  // ... and the moment it is decoded needs 8 bytes a pixel more (32 here): room for the mip-maps
  // alone is not enough.
  EXPECT_THAT(sceneErrors(header + "  - { type: sphere, center: [0, 0, 0], radius: 1, material: "
                                   "{ kd: { type: image, file: two.png } } }\n",
                          folder, filmBytes(4, 4) + 60 + 16),
              HasSubstr("(and 32 B more while it is decoded)"));
  // The same file twice (and under another spelling) is decoded once.
  const LoadedScene twice = loadSceneFromString(
      header +
          "  - { type: sphere, center: [0, 0, 0], radius: 1, material: { kd: { type: image, "
          "file: two.png } } }\n  - { type: sphere, center: [1, 0, 0], radius: 1, material: "
          "{ ks: { type: image, file: ./inner/../two.png } } }\n",
      "test.yaml", folder);
  const auto& first = std::get<ImageTexture>(twice.parts.textures[0]).image;
  const auto& second = std::get<ImageTexture>(twice.parts.textures[1]).image;
  EXPECT_EQ(first.get(), second.get());
}

// Maps of an MTL file that glint does not read are named in a warning at the mesh object, not
// dropped in silence (their files need not exist: they are never opened).
TEST(TextureRender, MtlMapsGlintDoesNotReadAreAWarning) {
  const fs::path folder = scratchFolder() / "ignored-maps";
  fs::create_directories(folder);
  writeTwoByTwo(folder);
  std::ofstream(folder / "quad.obj") << "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                        "vt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n";
  std::ofstream(folder / "quad.mtl")
      << "newmtl m\nKd 1 1 1\nmap_Kd two.png\nmap_Ka missing.png\nmap_d alpha.png\n";
  const LoadedScene loaded = loadSceneFromString(
      "camera: { position: [0, 0, 3], direction: [0, 0, -1], fov: 40 }\n"
      "image: { width: 4, height: 4 }\nlights: [{ type: point, position: [0, 0, 3] }]\n"
      "objects:\n  - { type: mesh, file: quad.obj }\n",
      "test.yaml", folder);
  ASSERT_EQ(loaded.warnings.size(), 1u);
  EXPECT_EQ(loaded.warnings[0].format(),
            "test.yaml:5:5: warning: mesh file 'quad.obj': its materials' map_Ka 'missing.png', "
            "map_d 'alpha.png' are not used (glint reads map_Kd, map_Ks, map_Ke, map_Bump or "
            "bump, and norm)");
}

// An EXR or HDR file holds linear values: `encoding: srgb` on one changes nothing, and says so at
// the key (a texture and the sky); the default encoding or `linear` says nothing, nor does srgb on
// a PNG.
TEST(TextureRender, SrgbEncodingOfALinearFileIsAWarning) {
  const fs::path folder = scratchFolder() / "linear-files";
  fs::create_directories(folder);
  writeTwoByTwo(folder);
  fs::copy_file(fs::path(GLINT_SOURCE_DIR) / "scenes" / "textures" / "sky.hdr", folder / "sky.hdr",
                fs::copy_options::overwrite_existing);
  const std::string header =
      "camera: { position: [0, 0, 3], direction: [0, 0, -1], fov: 40 }\n"
      "image: { width: 4, height: 4 }\n";
  const auto warningsOf = [&](const std::string& text) {
    std::vector<std::string> lines;
    for (const Diagnostic& d : loadSceneFromString(header + text, "test.yaml", folder).warnings) {
      lines.push_back(d.format());
    }
    return lines;
  };
  const std::string sphere = "objects:\n  - { type: sphere, center: [0, 0, 0], radius: 1, ";
  EXPECT_THAT(warningsOf("background: { type: image, file: sky.hdr, encoding: srgb }\n"),
              testing::ElementsAre(
                  HasSubstr("test.yaml:3:53: warning: encoding: srgb has no effect on 'sky.hdr'")));
  EXPECT_THAT(warningsOf(sphere + "material: { kd: { type: image, file: sky.hdr, encoding: srgb } "
                                  "} }\nlights: [{ type: point, position: [0, 0, 3] }]\n"),
              testing::ElementsAre(HasSubstr("test.yaml:4:107: warning: encoding: srgb has no "
                                             "effect on 'sky.hdr': an EXR or HDR file holds "
                                             "linear values")));
  for (const char* quiet : {"{ type: image, file: sky.hdr }",
                            "{ type: image, file: sky.hdr, "
                            "encoding: linear }",
                            "{ type: image, file: two.png, encoding: srgb }"}) {
    EXPECT_THAT(warningsOf(sphere + "material: { kd: " + quiet +
                           " } }\nlights: [{ type: point, position: [0, 0, 3] }]\n"),
                testing::IsEmpty())
        << quiet;
  }
}

}  // namespace
}  // namespace glint

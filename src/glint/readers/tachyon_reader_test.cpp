// The Tachyon reader (tachyon_reader.h): every supported statement as entities, the mirror in x,
// textures as materials, and its errors naming the statement, its place and the nearest supported
// one.
#include "glint/readers/tachyon_reader.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <variant>

#include "glint/factories/scene_loader.h"
#include "glint/scene/environment.h"
#include "glint/scene/light.h"
#include "glint/scene/texture.h"

namespace glint {
namespace {

using ::testing::HasSubstr;

// Every supported statement, in the forms VMD writes (mixed case) and the manual lists.
constexpr const char* kEveryStatement = R"(# VMD-like
Begin_Scene
Resolution 64 48
Shader_Mode Full
  Trans_VMD
  Fog_VMD
End_Shader_Mode
Camera
  Projection Perspective
  Zoom 0.5
  Aspectratio 1
  Antialiasing 3
  Raydepth 6
  Center 1 0 -10
  Viewdir 0 0 1
  Updir 0 1 0
End_Camera
Directional_Light Direction 0.1 -0.1 1 Color 1 1 1
Light Center 4 5 -6 Rad 0 Attenuation Constant 1 Linear 0.1 Quadratic 0 Color 0.5 0.5 0.5
Spotlight Center 0 5 0 Rad 0 Direction 0 -1 0 Falloff_Start 20 Falloff_End 40 Color 1 1 0.8
Background 0.1 0.1 0.2
Fog Exp2 Start 0 End 30 Density 0.05 Color 0.1 0.1 0.2
Texdef txt001 Ambient 0.1 Diffuse 0.65 Specular 0.2 Opacity 1
  Phong Plastic 0.5 Phong_size 40 Color 1 0 0 TexFunc 0
Texdef glass Ambient 0 Diffuse 0.3 Specular 0 Opacity 0.5
  Phong Metal 0.4 Phong_size 20 Color 0 0 1 TexFunc 0
TexAlias red txt001
Sphere Center 2 0 0 Rad 1 red
FCylinder Base 0 0 0 Apex 0 2 0 Rad 0.2 txt001
Cylinder Center 5 0 5 Axis 0 1 0 Rad 0.5 glass
Ring Center 0 -1 0 Normal 0 1 0 Inner 0.5 Outer 1 txt001
Plane Center 0 -2 0 Normal 0 1 0 Texture Ambient 0.1 Diffuse 0.9 Specular 0 Opacity 1 Color 1 1 1 TexFunc 0
Box Min -1 -1 -1 Max 0 0 0 glass
Tri V0 0 0 0 V1 1 0 0 V2 0 1 0 txt001
STri V0 0 0 1 V1 1 0 1 V2 0 1 1 N0 0 0 1 N1 0 0 1 N2 0 0 1 txt001
VCSTri V0 0 0 2 V1 1 0 2 V2 0 1 2 N0 0 0 1 N1 0 0 1 N2 0 0 1 C0 1 0 0 C1 0 1 0 C2 0 0 1
  Ambient 0.1 Diffuse 0.9 Specular 0 Opacity 1 VCST
VertexArray Numverts 4
Coords 0 0 3 1 0 3 1 1 3 0 1 3
Normals 0 0 1 0 0 1 0 0 1 0 0 1
Colors 1 0 0 0 1 0 0 0 1 1 1 1
Texture Ambient 0.1 Diffuse 0.9 Specular 0 Opacity 1 Color 1 1 1 TexFunc 0
TriStrip 4 0 1 3 2
TriMesh 1 0 1 2
End_VertexArray
End_Scene
)";

std::string firstError(const ParseResult& r) {
  for (const Diagnostic& d : r.diagnostics) {
    if (d.severity == Diagnostic::Severity::Error) return d.format();
  }
  return "<no error>";
}

const Entity& nth(const ParseResult& r, EntityKind kind, std::size_t n) {
  for (const Entity& e : r.description.entities) {
    if (e.kind == kind && n-- == 0) return e;
  }
  throw std::logic_error("no such entity");
}

std::string item(const ParseResult& r, const Entity& e, std::string_view key, std::size_t i) {
  const ValueTree& t = r.description.files[0]->values;
  return std::string(t.scalar(t.item(r.description.parameter(e, key), i)));
}

TEST(TachyonReader, EveryStatementBecomesEntitiesAndBuilds) {
  const ParseResult r = parseTachyon(kEveryStatement, "every.dat");
  ASSERT_FALSE(r.hasErrors()) << firstError(r);
  const SceneDescription& d = r.description;
  EXPECT_EQ(d.count(EntityKind::LightEntity), 3u);
  EXPECT_EQ(d.count(EntityKind::FogEntity), 1u);
  EXPECT_EQ(d.count(EntityKind::AmbientEntity), 1u);
  // sphere, cone, tube, disk, plane, box, then the meshes: flat, smooth, vertex-coloured (the
  // VCSTRI and the vertex array share a material and their kinds of data).
  EXPECT_EQ(d.count(EntityKind::ObjectEntity), 9u);

  // Mirrored in x: the camera's centre and the sphere's centre.
  const Entity& camera = nth(r, EntityKind::CameraEntity, 0);
  EXPECT_EQ(item(r, camera, "position", 0), "-1");
  const Entity& sphere = nth(r, EntityKind::ObjectEntity, 0);
  EXPECT_EQ(item(r, sphere, "center", 0), "-2");
  EXPECT_EQ(d.text(sphere, d.parameter(sphere, "material")), "txt001");
  // The box's x extent runs from −0 to 1 once mirrored.
  const Entity& box = nth(r, EntityKind::ObjectEntity, 5);
  EXPECT_EQ(item(r, box, "min", 0), "0");
  EXPECT_EQ(item(r, box, "max", 0), "1");

  // txt001 under TRANS_VMD (opacity 1: unscaled): kd = 0.65·red, ka = 0.1·red, kr = 0.2,
  // plastic highlight 0.5 (white), shininess 40.
  const Entity& txt = nth(r, EntityKind::MaterialEntity, 0);
  EXPECT_EQ(d.text(txt, txt.name), "txt001");
  EXPECT_EQ(item(r, txt, "kd", 0), "0.65");
  EXPECT_EQ(item(r, txt, "ka", 0), "0.1");
  EXPECT_EQ(item(r, txt, "ks", 1), "0.5");
  // glass: opacity 0.5 under TRANS_VMD scales its own terms by 0.5; kt = 0.5; metal highlight.
  const Entity& glass = nth(r, EntityKind::MaterialEntity, 1);
  EXPECT_EQ(item(r, glass, "kd", 2), "0.15");
  EXPECT_EQ(item(r, glass, "ks", 0), "0");
  EXPECT_EQ(item(r, glass, "ks", 2), "0.2");
  EXPECT_EQ(d.text(glass, d.parameter(glass, "kt")), "0.5");

  // The image: antialiasing 3 → 4 samples; the view plane 1/zoom high.
  const Entity& image = nth(r, EntityKind::ImageEntity, 0);
  EXPECT_EQ(d.text(image, d.parameter(image, "samples")), "4");
  const Entity& fog = nth(r, EntityKind::FogEntity, 0);
  EXPECT_EQ(d.text(fog, d.parameter(fog, "distance")), "depth");

  const LoadedScene loaded = buildDescribedScene(r);
  ASSERT_EQ(loaded.parts.meshes.size(), 3u);
  EXPECT_FALSE(loaded.parts.meshes[2].colors.empty());
  EXPECT_EQ(loaded.parts.meshes[2].triangleCount(), 4u);  // 1 VCSTRI + 2 strip + 1 mesh
  EXPECT_TRUE(loaded.parts.fog.has_value());
  EXPECT_TRUE(loaded.parts.camera.viewPlaneHeight == 2);
}

// Tachyon's checker_texture at a point q of its own (left-handed) space: per axis
// round(3·|q − centre|), odd sum orange (1, 0.2, 0), even blue (0, 0.2, 1).
Color tachyonChecker(const Vec3& q, const Vec3& centre) {
  long sum = 0;
  for (const double d : {q.x - centre.x, q.y - centre.y, q.z - centre.z}) {
    sum += static_cast<long>(std::abs(d) * 3 + 0.5) % 2;
  }
  return sum % 2 == 1 ? Color(1, 0.2, 0) : Color(0, 0.2, 1);
}

TEST(TachyonReader, Texfunc1IsTachyonsCheckerExactly) {
  const ParseResult r = parseTachyon(
      "BEGIN_SCENE RESOLUTION 8 8\n"
      "PLANE CENTER 0 -1 0 NORMAL 0 1 0 TEXTURE AMBIENT 0.1 DIFFUSE 0.5 SPECULAR 0 OPACITY 1 "
      "COLOR 1 1 1 TEXFUNC 1 CENTER 0.3 -1 0.2 ROTATE 0 0 0 SCALE 1 1 1\nEND_SCENE\n",
      "checker.dat");
  ASSERT_FALSE(r.hasErrors()) << firstError(r);
  const LoadedScene loaded = buildDescribedScene(r);
  ASSERT_EQ(loaded.parts.primitives.size(), 1u);
  const Material& m = loaded.parts.materials.at(loaded.parts.primitives[0].materialIndex());
  ASSERT_NE(m.textures, kUntextured);
  const MaterialTextures& bound = loaded.parts.materialTextures.at(m.textures);
  ASSERT_NE(bound.kd, kNoTexture);
  ASSERT_NE(bound.ka, kNoTexture);
  const Vec3 centre{0.3, -1, 0.2};
  int compared = 0;
  // Points of the plane y = −1 in glint's space (x mirrored from Tachyon's), off the cell edges.
  for (double x = -2.04; x < 2; x += 0.0913) {
    for (double z = -2.01; z < 2; z += 0.1071) {
      const Vec3 tachyonPoint{-x, -1, z};
      const Color expected = tachyonChecker(tachyonPoint, centre);
      const TextureLookup at{Point3{x, -1, z}, {}, {}, {}};
      const Color kd = m.kd * evaluate(loaded.parts.textures.at(bound.kd), at);
      const Color ka = m.ka * evaluate(loaded.parts.textures.at(bound.ka), at);
      ASSERT_NEAR(kd.r, 0.5 * expected.r, 1e-12) << x << " " << z;
      ASSERT_NEAR(kd.b, 0.5 * expected.b, 1e-12) << x << " " << z;
      ASSERT_NEAR(ka.r, 0.1 * expected.r, 1e-12) << x << " " << z;
      ++compared;
    }
  }
  EXPECT_GT(compared, 1500);
  // Marble and wood are glint's own patterns, with a warning saying so.
  const ParseResult wood = parseTachyon(
      "BEGIN_SCENE RESOLUTION 8 8\n"
      "SPHERE CENTER 0 0 0 RAD 1 TEXTURE AMBIENT 0.1 DIFFUSE 0.5 SPECULAR 0 OPACITY 1 "
      "COLOR 1 1 1 TEXFUNC 4 CENTER 0 0 0 ROTATE 0 0 0 SCALE 0.01 0.01 0.01\nEND_SCENE\n",
      "wood.dat");
  ASSERT_FALSE(wood.hasErrors()) << firstError(wood);
  bool warned = false;
  for (const Diagnostic& d : wood.diagnostics) {
    warned = warned || d.message.find("TEXFUNC 4 (wood) is drawn with glint's wood pattern") == 0;
  }
  EXPECT_TRUE(warned);
  const LoadedScene woodScene = buildDescribedScene(wood);
  const Material& w = woodScene.parts.materials.at(woodScene.parts.primitives[0].materialIndex());
  ASSERT_NE(w.textures, kUntextured);
  const auto* rings = std::get_if<NoiseTexture>(
      &woodScene.parts.textures.at(woodScene.parts.materialTextures.at(w.textures).kd));
  ASSERT_NE(rings, nullptr);
  EXPECT_EQ(rings->pattern, NoisePattern::Wood);
  EXPECT_DOUBLE_EQ(rings->scale, 0.6);  // Tachyon's rings, 60 scale units apart
}

// BACKGROUND_GRADIENT as Tachyon blends it (measured with Tachyon 0.99: a column of pixels of an
// empty scene is bottom + (top − bottom) · clamp((t − BOTTOMVAL) / (TOPVAL − BOTTOMVAL), 0, 1) to
// within a unit of 255, with t = d·UPDIR for SKY_SPHERE — UPDIR as written, not made unit — and
// o·UPDIR for SKY_ORTHO_PLANE, o the ray's origin); the colour of BACKGROUND is then unused.
TEST(TachyonReader, BackgroundGradientIsTachyonsSky) {
  const auto skyOf = [](const std::string& gradient) {
    const ParseResult r = parseTachyon(
        "BEGIN_SCENE RESOLUTION 8 8\nBACKGROUND 0.2 0.2 0.2\n" + gradient + "\nEND_SCENE\n",
        "sky.dat");
    EXPECT_FALSE(r.hasErrors()) << firstError(r);
    return buildDescribedScene(r).parts.environment;
  };
  const Environment sphere = skyOf(
      "Background_Gradient Sky_Sphere UpDir 0 2 0 TopVal 1 BottomVal -1 TopColor 0 0 1 "
      "BottomColor 1 1 1");
  ASSERT_EQ(sphere.kind, BackgroundKind::Sky);
  EXPECT_FALSE(sphere.skyByHeight);
  // Tachyon: t = d·(0, 2, 0) = 2·d.y, blended over −1 .. 1: a quarter of the way up at d.y = −0.25.
  const double s = std::sqrt(1 - 0.25 * 0.25);
  const Color quarter = sphere.along({0, -0.25, s}, Color());
  EXPECT_NEAR(quarter.r, 0.75, 1e-12);
  EXPECT_NEAR(quarter.b, 1, 1e-12);
  EXPECT_EQ(sphere.along({0, 0.6, 0.8}, Color()), Color(0, 0, 1));  // 2·0.6 > 1: the top
  // SKY_ORTHO_PLANE, UPDIR along Tachyon's +x (glint's −x: the scene is mirrored in x): by the
  // origin's Tachyon x, here 0.5 of the range −1 .. 3 (o·UPDIR = 1 at Tachyon x = 1).
  const Environment plane = skyOf(
      "Background_Gradient Sky_Ortho_Plane UpDir 1 0 0 TopVal 3 BottomVal -1 TopColor 1 0 0 "
      "BottomColor 0 1 0");
  ASSERT_EQ(plane.kind, BackgroundKind::Sky);
  EXPECT_TRUE(plane.skyByHeight);
  const Color atOne = plane.along({0, 0, 1}, Color(), {-1, 5, 5});
  EXPECT_NEAR(atOne.r, 0.5, 1e-12);
  EXPECT_NEAR(atOne.g, 0.5, 1e-12);
}

// VMD's ambient occlusion (SHADER_MODE ... AMBIENT_OCCLUSION AMBIENT_COLOR RESCALE_DIRECT SAMPLES):
// Tachyon adds AMBIENT_COLOR × DIFFUSE × COLOR × the cosine-weighted open fraction of the
// hemisphere to a surface, keeps its AMBIENT × COLOR unoccluded and scales the lights: glint's
// ambient occlusion on an ambient light of that colour with ka = DIFFUSE·COLOR, emission =
// AMBIENT·COLOR, and the lights' colours scaled.
TEST(TachyonReader, VmdAmbientOcclusionIsGlintsOnTheDiffuseColour) {
  const std::string header =
      "Begin_Scene\nResolution 8 8\nShader_Mode Full\n  Trans_VMD\n  Ambient_Occlusion\n"
      "    Ambient_Color 0.8 0.7 0.6\n    Rescale_Direct 0.5\n    Samples 12\n"
      "End_Shader_Mode\n";
  const std::string body =
      "Directional_Light Direction 0 0 1 Color 1 0.5 0.25\n"
      "Light Center 0 5 0 Rad 0 Color 0.4 0.4 0.4\n"
      "Texdef flat Ambient 0 Diffuse 0.5 Specular 0 Opacity 1 Color 1 0.5 0 TexFunc 0\n"
      "Texdef glow Ambient 0.2 Diffuse 0.5 Specular 0 Opacity 1 Color 0 1 1 TexFunc 0\n"
      "Sphere Center 0 0 5 Rad 1 flat\nSphere Center 2 0 5 Rad 1 glow\nEnd_Scene\n";
  const ParseResult r = parseTachyon(header + body, "ao.dat");
  ASSERT_FALSE(r.hasErrors()) << firstError(r);
  const SceneParts parts = buildDescribedScene(r).parts;
  ASSERT_TRUE(parts.render.ambientOcclusion.has_value());
  EXPECT_EQ(parts.render.ambientOcclusion->samples, 12);
  EXPECT_EQ(parts.ambient, Color(0.8, 0.7, 0.6));
  ASSERT_EQ(parts.lights.size(), 2u);
  EXPECT_EQ(std::get<DirectionalLight>(parts.lights[0]).intensity, Color(0.5, 0.25, 0.125));
  EXPECT_EQ(std::get<PointLight>(parts.lights[1]).intensity, Color(0.2));
  ASSERT_EQ(parts.primitives.size(), 2u);
  const Material& flat = parts.materials[parts.primitives[0].materialIndex()];
  EXPECT_EQ(flat.kd, Color(0.5, 0.25, 0));
  EXPECT_EQ(flat.ka, flat.kd);
  EXPECT_EQ(parts.primitives[0].emission(), Color());
  const Material& glow = parts.materials[parts.primitives[1].materialIndex()];
  EXPECT_EQ(glow.ka, glow.kd);
  EXPECT_EQ(parts.primitives[1].emission(), Color(0, 0.2, 0.2));  // AMBIENT·COLOR, unoccluded
  // It changes the lights and textures: after them it is an error; SAMPLES 0 is "off".
  const std::string late = "Begin_Scene\nResolution 8 8\n" + body.substr(0, body.find("Texdef")) +
                           "Shader_Mode Full\n  Ambient_Occlusion\n    Ambient_Color 1 1 1\n"
                           "    Rescale_Direct 1\n    Samples 4\nEnd_Shader_Mode\nEnd_Scene\n";
  EXPECT_THAT(firstError(parseTachyon(late, "late.dat")),
              HasSubstr("late.dat:6:3: SHADER_MODE AMBIENT_OCCLUSION must come before the scene's "
                        "lights and textures"));
  std::string off = header + body;
  off.replace(off.find("Samples 12"), 10, "Samples 0");
  const ParseResult offResult = parseTachyon(off, "off.dat");
  ASSERT_FALSE(offResult.hasErrors()) << firstError(offResult);
  EXPECT_FALSE(buildDescribedScene(offResult).parts.render.ambientOcclusion.has_value());
}

// PROJECTION PERSPECTIVE_DOF as VMD writes it (FOCALDIST, APERTURE as an f-number) and as Tachyon's
// manual lists it (FOCALLENGTH): a thin lens of Tachyon's radius FOCALDIST / (2 · APERTURE)
// focused at FOCALDIST; sharp with ANTIALIASING 0, as Tachyon draws it.
TEST(TachyonReader, PerspectiveDofIsAThinLensOfTachyonsRadius) {
  const auto scene = [](const std::string& projection, int antialiasing) {
    return "Begin_Scene\nResolution 8 8\nCamera\n" + projection +
           "\n  Zoom 1\n  Aspectratio 1\n  Antialiasing " + std::to_string(antialiasing) +
           "\n  Raydepth 4\n  Center 0 0 -10\n  Viewdir 0 0 1\n  Updir 0 1 0\nEnd_Camera\n"
           "Texdef a Ambient 0 Diffuse 1 Specular 0 Opacity 1 Color 1 0 0 TexFunc 0\n"
           "Sphere Center 0 0 0 Rad 1 a\nEnd_Scene\n";
  };
  const ParseResult vmd = parseTachyon(
      scene("  Projection Perspective_DoF\n  FocalDist 10\n  Aperture 2.5", 4), "vmd.dat");
  ASSERT_FALSE(vmd.hasErrors()) << firstError(vmd);
  EXPECT_TRUE(vmd.diagnostics.empty());
  const Entity& camera = nth(vmd, EntityKind::CameraEntity, 0);
  const SceneDescription& d = vmd.description;
  EXPECT_EQ(d.text(camera, d.parameter(camera, "aperture")), "2");
  EXPECT_EQ(d.text(camera, d.parameter(camera, "focus_distance")), "10");
  const LoadedScene loaded = buildDescribedScene(vmd);
  EXPECT_EQ(loaded.parts.camera.aperture, 2.0);
  EXPECT_EQ(loaded.parts.camera.focusDistance, 10.0);
  EXPECT_EQ(loaded.parts.camera.viewPlaneHeight, 1.0);  // the field of view is unchanged
  EXPECT_EQ(loaded.parts.image.samples, 5);

  // The manual's keyword, and an f-number below Tachyon's least (0.01).
  const ParseResult manual = parseTachyon(
      scene("  PROJECTION PERSPECTIVE_DOF FOCALLENGTH 0.75 APERTURE 0.001", 8), "manual.dat");
  ASSERT_FALSE(manual.hasErrors()) << firstError(manual);
  const LoadedScene wide = buildDescribedScene(manual);
  EXPECT_EQ(wide.parts.camera.aperture, 0.75 / 0.02);
  EXPECT_EQ(wide.parts.camera.focusDistance, 0.75);

  // One sample per pixel: Tachyon's goes through the lens centre; a warning says so.
  const ParseResult sharp =
      parseTachyon(scene("Projection Perspective_DoF FocalDist 10 Aperture 2.5", 0), "sharp.dat");
  ASSERT_FALSE(sharp.hasErrors()) << firstError(sharp);
  ASSERT_EQ(sharp.diagnostics.size(), 1u);
  EXPECT_EQ(sharp.diagnostics[0].format(),
            "sharp.dat:4:12: warning: PERSPECTIVE_DOF with ANTIALIASING 0: Tachyon traces each "
            "pixel's one sample through the centre of the lens, so the image is sharp, and "
            "glint's is too (depth of field needs ANTIALIASING 1 or more)");
  EXPECT_EQ(buildDescribedScene(sharp).parts.camera.aperture, 0.0);

  EXPECT_EQ(firstError(parseTachyon(scene("Projection Perspective_DoF FocalDist -1 Aperture 2", 4),
                                    "bad.dat")),
            "bad.dat:4:38: camera: the focal distance must be > 0, got -1");
  EXPECT_EQ(firstError(parseTachyon(scene("Projection Perspective_DoF FocalDist 1 Aperture 0", 4),
                                    "bad.dat")),
            "bad.dat:4:49: camera: APERTURE must be > 0, got 0");
  EXPECT_EQ(firstError(parseTachyon(scene("Projection Perspective_DoF Zoom 1", 4), "bad.dat")),
            "bad.dat:4:28: Camera: expected FOCALDIST or FOCALLENGTH, got 'Zoom'");
  // Every error of the camera, and a lens radius past the doubles named in the file's terms.
  const ParseResult both =
      parseTachyon(scene("Projection Perspective_DoF FocalDist -1 Aperture -2", 4), "bad.dat");
  ASSERT_EQ(both.diagnostics.size(), 2u);
  EXPECT_EQ(both.diagnostics[1].format(), "bad.dat:4:50: camera: APERTURE must be > 0, got -2");
  EXPECT_EQ(firstError(parseTachyon(
                scene("Projection Perspective_DoF FocalDist 1e308 Aperture 0.001", 4), "bad.dat")),
            "bad.dat:4:38: camera: the lens radius, focal distance / (2 · APERTURE) = 1e308 / (2 · "
            "0.001), is too large for a number");
  // The warning is about the camera in effect: a later CAMERA replaces the first.
  const std::string twoCameras = scene("Projection Perspective_DoF FocalDist 10 Aperture 2.5", 0);
  const std::string plain =
      "Camera\n  Zoom 1\n  Aspectratio 1\n  Antialiasing 0\n  Raydepth 4\n"
      "  Center 0 0 -10\n  Viewdir 0 0 1\n  Updir 0 1 0\nEnd_Camera\n";
  const ParseResult replaced =
      parseTachyon(twoCameras.substr(0, twoCameras.find("Texdef")) + plain +
                       twoCameras.substr(twoCameras.find("Texdef")),
                   "two.dat");
  ASSERT_FALSE(replaced.hasErrors()) << firstError(replaced);
  EXPECT_TRUE(replaced.diagnostics.empty());
  EXPECT_EQ(firstError(parseTachyon(scene("Projection Fisheye", 4), "bad.dat")),
            "bad.dat:4:12: camera projection 'Fisheye' is not supported (glint reads PERSPECTIVE, "
            "PERSPECTIVE_DOF and ORTHOGRAPHIC)");
}

// Tachyon finds a texture name's first definition: a TEXDEF of a name already defined changes
// nothing (a warning says so).
TEST(TachyonReader, ATexdefOfADefinedNameKeepsTheFirst) {
  const ParseResult r = parseTachyon(
      "Begin_Scene\nResolution 8 8\n"
      "Texdef a Ambient 0 Diffuse 1 Specular 0 Opacity 1 Color 1 0 0 TexFunc 0\n"
      "Sphere Center -1.2 0 5 Rad 1 a\n"
      "Texdef a Ambient 0 Diffuse 1 Specular 0 Opacity 1 Color 0 0 1 TexFunc 0\n"
      "Sphere Center 1.2 0 5 Rad 1 a\nEnd_Scene\n",
      "redef.dat");
  ASSERT_FALSE(r.hasErrors()) << firstError(r);
  const LoadedScene loaded = buildDescribedScene(r);
  ASSERT_EQ(loaded.parts.primitives.size(), 2u);
  for (const Primitive& sphere : loaded.parts.primitives) {
    EXPECT_EQ(loaded.parts.materials[sphere.materialIndex()].kd, Color(1, 0, 0));
  }
  ASSERT_EQ(r.diagnostics.size(), 1u);
  EXPECT_EQ(r.diagnostics[0].format(),
            "redef.dat:5:8: warning: TEXDEF 'a': the name is already defined (line 3); as Tachyon "
            "does, the first definition is kept");
  // TEXALIAS names count alike, both ways.
  const ParseResult aliases = parseTachyon(
      "Begin_Scene\nResolution 8 8\n"
      "Texdef red Ambient 0 Diffuse 1 Specular 0 Opacity 1 Color 1 0 0 TexFunc 0\n"
      "Texdef blue Ambient 0 Diffuse 1 Specular 0 Opacity 1 Color 0 0 1 TexFunc 0\n"
      "TexAlias a red\nTexAlias a blue\n"
      "Texdef a Ambient 0 Diffuse 1 Specular 0 Opacity 1 Color 0 1 0 TexFunc 0\n"
      "Sphere Center 0 0 5 Rad 1 a\nEnd_Scene\n",
      "alias.dat");
  ASSERT_FALSE(aliases.hasErrors()) << firstError(aliases);
  ASSERT_EQ(aliases.diagnostics.size(), 2u);
  EXPECT_EQ(aliases.diagnostics[0].format(),
            "alias.dat:6:10: warning: TEXALIAS 'a': the name is already defined (line 5); as "
            "Tachyon does, the first definition is kept");
  EXPECT_EQ(aliases.diagnostics[1].format(),
            "alias.dat:7:8: warning: TEXDEF 'a': the name is already defined (line 5); as Tachyon "
            "does, the first definition is kept");
  const LoadedScene aliased = buildDescribedScene(aliases);
  ASSERT_EQ(aliased.parts.primitives.size(), 1u);
  EXPECT_EQ(aliased.parts.materials[aliased.parts.primitives[0].materialIndex()].kd,
            Color(1, 0, 0));
}

// Triangles of one texture on fewer than three distinct points (vertices written alike are one)
// are left out with a warning in the file's terms, not refused as a mesh of too few positions.
TEST(TachyonReader, TrianglesOnTwoPointsAreLeftOutWithAWarning) {
  const ParseResult r = parseTachyon(
      "BEGIN_SCENE\nRESOLUTION 8 8\n"
      "TEXDEF t AMBIENT 0 DIFFUSE 1 SPECULAR 0 OPACITY 1 COLOR 1 0 0 TEXFUNC 0\n"
      "TRI V0 1 0 0 V1 1 0 0 V2 2 0 0 t\nEND_SCENE\n",
      "tri.dat");
  ASSERT_FALSE(r.hasErrors()) << firstError(r);
  ASSERT_EQ(r.diagnostics.size(), 1u);
  EXPECT_EQ(r.diagnostics[0].format(),
            "tri.dat:4:1: warning: 1 degenerate triangle (no area: 2 distinct vertices) left out");
  EXPECT_TRUE(buildDescribedScene(r).parts.meshes.empty());
}

TEST(TachyonReader, UnsupportedStatementsNameTheNearestSupportedOne) {
  const auto error = [](const std::string& body) {
    return firstError(
        parseTachyon("BEGIN_SCENE RESOLUTION 8 8\n" + body + "\nEND_SCENE\n", "bad.dat"));
  };
  EXPECT_EQ(error("SPHEREARRAY NUMSPHERES 1"),
            "bad.dat:2:1: the Tachyon statement SPHEREARRAY is not supported by glint (the "
            "nearest supported statement is SPHERE)");
  EXPECT_EQ(error("Background_Gradient Sky_Plane UpDir 0 1 0"),
            "bad.dat:2:21: Background_Gradient: expected SKY_SPHERE or SKY_ORTHO_PLANE, got "
            "'Sky_Plane'");
  EXPECT_EQ(error("Background_Gradient Sky_Sphere UpDir 0 1 0 TopVal 1 BottomVal -1 TopColor 0 0 "
                  "1 BottomColr 1 1 1"),
            "bad.dat:2:81: Background_Gradient: expected BOTTOMCOLOR, got 'BottomColr'");
  EXPECT_EQ(error("SPHER CENTER 0 0 0 RAD 1 x"),
            "bad.dat:2:1: unknown Tachyon statement 'SPHER' (the nearest supported statement is "
            "SPHERE)");
  EXPECT_EQ(error("SPHERE CENTER 0 0 0 RAD 1 TEXTURE AMBIENT 0 DIFFUSE 1 SPECULAR 0 OPACITY 1 "
                  "COLOR 1 1 1 TEXFUNC 7 earth.ppm CENTER 0 0 0 ROTATE 0 0 0 SCALE 1 1 1"),
            "bad.dat:2:96: TEXFUNC 7 (cylindrical image map) is not supported by glint; TEXFUNC 0 "
            "(plain colour), 1 (3D checker), 3 (marble) and 4 (wood) are");
  EXPECT_EQ(error("SPHERE CENTER 0 0 0 RAD 1 TEXTURE AMBIENT 0 DIFFUSE 1 SPECULAR 0 OPACITY 1 "
                  "COLOR 1 1 1 TEXFUNC 1 CENTRE 0 0 0 ROTATE 0 0 0 SCALE 1 1 1"),
            "bad.dat:2:98: SPHERE: expected CENTER, got 'CENTRE'");
  EXPECT_EQ(error("SPHERE CENTER 0 0 0 RAD 1 nowhere"),
            "bad.dat:2:27: SPHERE: undefined texture 'nowhere' (a TEXDEF name, or TEXTURE and its "
            "definition)");
  EXPECT_EQ(error("SPHERE CENTRE 0 0 0"), "bad.dat:2:8: SPHERE: expected CENTER, got 'CENTRE'");
  // Texture values Tachyon would take but glint's materials cannot mean, and a PHONG kind other
  // than PLASTIC or METAL, are errors at the value.
  const std::string sphere = "SPHERE CENTER 0 0 0 RAD 1 TEXTURE ";
  EXPECT_EQ(error(sphere + "AMBIENT 0 DIFFUSE 1 SPECULAR 0 OPACITY 1 PHONG BANANA 0.5 PHONG_SIZE "
                           "10 COLOR 1 0 0 TEXFUNC 0"),
            "bad.dat:2:82: PHONG: expected PLASTIC or METAL, got 'BANANA'");
  EXPECT_EQ(error(sphere + "AMBIENT 0 DIFFUSE 1 SPECULAR 0 OPACITY -1 COLOR 1 0 0 TEXFUNC 0"),
            "bad.dat:2:74: OPACITY must be between 0 and 1, got -1");
  EXPECT_EQ(error(sphere + "AMBIENT 0 DIFFUSE 1 SPECULAR 0 OPACITY 2 COLOR 1 0 0 TEXFUNC 0"),
            "bad.dat:2:74: OPACITY must be between 0 and 1, got 2");
  EXPECT_EQ(error(sphere + "AMBIENT 0 DIFFUSE 0 SPECULAR 0 OPACITY 1 COLOR -1 0 0 TEXFUNC 0"),
            "bad.dat:2:82: COLOR must be >= 0, got -1");
  EXPECT_EQ(error(sphere + "AMBIENT 0 DIFFUSE 1 SPECULAR 0 OPACITY 1 PHONG PLASTIC 0 PHONG_SIZE "
                           "-10 COLOR 1 0 0 TEXFUNC 0"),
            "bad.dat:2:103: PHONG_SIZE must be >= 0, got -10");
  EXPECT_EQ(error("LIGHT CENTER 0 0 0 RAD -1 COLOR 1 1 1"),
            "bad.dat:2:24: light RAD must be >= 0, got -1");
  // A word of any length is compared to the supported statements in its first 64 characters
  // only (the edit distance is quadratic: 4 MB of 'Q' took 5.6 s and 624 MB).
  EXPECT_EQ(error(std::string(1 << 20, 'Q')).substr(0, 40),
            "bad.dat:2:1: unknown Tachyon statement '");
  // A texture name becomes a material name (a YAML key when converted): printable UTF-8 only.
  const std::string body = " AMBIENT 0 DIFFUSE 1 SPECULAR 0 OPACITY 1 COLOR 1 0 0 TEXFUNC 0";
  const std::string nameRule =
      ": a texture name must be UTF-8 text of at most 256 bytes without control characters, got ";
  EXPECT_EQ(error("TEXDEF r\xE9"
                  "d" +
                  body),
            "bad.dat:2:8: TEXDEF" + nameRule + "'r\\xe9d'");
  EXPECT_EQ(error("TEXDEF a\x7F" + body), "bad.dat:2:8: TEXDEF" + nameRule + "'a\\x7f'");
  EXPECT_EQ(error("TEXDEF a\xC2\x85" + body), "bad.dat:2:8: TEXDEF" + nameRule + "'a\\u0085'");
  EXPECT_THAT(error("TEXDEF " + std::string(257, 'a') + body), HasSubstr(nameRule));
  EXPECT_EQ(error("TEXDEF r\xC3\xB8"
                  "d" +
                  body +
                  "\nTEXALIAS x\x01 r\xC3\xB8"
                  "d"),
            "bad.dat:3:10: TEXALIAS" + nameRule + "'x\\x01'");
  EXPECT_EQ(firstError(parseTachyon("RESOLUTION 8 8", "a.dat")),
            "a.dat:1:1: expected BEGIN_SCENE, got 'RESOLUTION'; a Tachyon scene starts with "
            "BEGIN_SCENE and RESOLUTION");
  EXPECT_THAT(firstError(parseTachyon("BEGIN_SCENE RESOLUTION 8 8 SPHERE", "a.dat")),
              HasSubstr("the file ends inside SPHERE"));
  // A statement that read END_SCENE as one of its values has the one error, not also "the file
  // ends without END_SCENE".
  const ParseResult noTexture =
      parseTachyon("BEGIN_SCENE\nRESOLUTION 8 8\nSPHERE CENTER 0 0 0 RAD 1\nEND_SCENE\n", "a.dat");
  ASSERT_EQ(noTexture.diagnostics.size(), 1u);
  EXPECT_EQ(noTexture.diagnostics[0].format(),
            "a.dat:4:1: SPHERE: undefined texture 'END_SCENE' (a TEXDEF name, or TEXTURE and its "
            "definition)");
}

}  // namespace
}  // namespace glint

// The MPI messages round-trip bit for bit and refuse malformed bytes; the identity comparison names
// the first difference between two ranks.
#include "glint/cluster/protocol.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "glint/cluster/rank_identity.h"

namespace glint::cluster {
namespace {

RankIdentity sampleIdentity() {
  RankIdentity identity;
  identity.version = "0.1.0";
  identity.host = "node7";
  identity.threads = 3;
  identity.sceneFile = "scenes/showcase.yaml";
  identity.sceneBytes = 812;
  identity.sceneHash = 0x0123456789abcdefull;
  identity.meshCount = 2;
  identity.meshHash = 0xfedcba9876543210ull;
  identity.settings = CheckpointSettings{
      640, 480, 4, 64, 0.05, 99, PixelRegion{1, 2, 300, 400}, 16, Integrator::Path};
  identity.fingerprint = 42;
  return identity;
}

TEST(ClusterProtocol, IdentityRoundTrips) {
  const RankIdentity identity = sampleIdentity();
  const RankIdentity back = decodeIdentity(encodeIdentity(identity));
  EXPECT_EQ(back.version, identity.version);
  EXPECT_EQ(back.host, identity.host);
  EXPECT_EQ(back.threads, 3);
  EXPECT_EQ(back.sceneFile, identity.sceneFile);
  EXPECT_EQ(back.sceneHash, identity.sceneHash);
  EXPECT_EQ(back.meshHash, identity.meshHash);
  EXPECT_EQ(back.settings, identity.settings);
  EXPECT_EQ(back.fingerprint, 42u);
  EXPECT_FALSE(identityDifference(identity, back));
}

TEST(ClusterProtocol, TilePixelsKeepEveryBit) {
  Film film(8, 6, PixelRegion{2, 1, 8, 6});
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x)
      film.at(x, y) = Color(std::nextafter(0.1 * x, 1.0), 1.0 / 3 + y, -0.0);
  film.at(1, 1).r = std::numeric_limits<double>::denorm_min();
  const PixelRegion tile{3, 2, 6, 5};
  const TileResult result = decodeTile(encodeTile(9, tile, film));
  EXPECT_EQ(result.tile, 9u);
  ASSERT_EQ(result.pixels.size(), 9u);
  std::size_t i = 0;
  for (int y = tile.y0; y < tile.y1; ++y) {
    for (int x = tile.x0; x < tile.x1; ++x) {
      const Color& expected = film.at(x - 2, y - 1);
      EXPECT_EQ(std::memcmp(&result.pixels[i++], &expected, sizeof(Color)), 0) << x << "," << y;
    }
  }
}

TEST(ClusterProtocol, SmallMessagesRoundTrip) {
  EXPECT_EQ(decodeTiles(encodeTiles({0, 7, 4000000000u})), (TileList{0, 7, 4000000000u}));
  EXPECT_TRUE(decodeTiles(encodeTiles({})).empty());
  const StopOrder stop = decodeStop(encodeStop(StopOrder{143, true}));
  EXPECT_EQ(stop.status, 143);
  EXPECT_TRUE(stop.finalize);
  const Leaving leaving = decodeLeaving(encodeLeaving(Leaving{15, "interrupted"}));
  EXPECT_EQ(leaving.signal, 15);
  EXPECT_EQ(leaving.reason, "interrupted");
  RankReport report;
  report.tiles = 12;
  report.rays.shadow = 99;
  report.firstNonFinite = PixelCoord{3, 4};
  report.busySeconds = 1.5;
  const RankReport back = decodeReport(encodeReport(report));
  EXPECT_EQ(back.tiles, 12u);
  EXPECT_EQ(back.rays.shadow, 99u);
  ASSERT_TRUE(back.firstNonFinite);
  EXPECT_EQ(*back.firstNonFinite, (PixelCoord{3, 4}));
  EXPECT_EQ(back.busySeconds, 1.5);
  EXPECT_FALSE(decodeReport(encodeReport(RankReport{})).firstNonFinite);
}

TEST(ClusterProtocol, MalformedMessagesAreRefused) {
  EXPECT_THROW(decodeTiles("abc"), ProtocolError);
  std::string tile = encodeTile(1, PixelRegion{0, 0, 2, 1}, Film(2, 1, PixelRegion{0, 0, 2, 1}));
  EXPECT_THROW(decodeTile(tile.substr(0, tile.size() - 1)), ProtocolError);
  EXPECT_THROW(decodeIdentity(encodeIdentity(sampleIdentity()) + "x"), ProtocolError);
  EXPECT_THROW(decodeStop(""), ProtocolError);
  // Durations no rank measures (they are printed and summed): refused.
  for (const double seconds : {-1.0, 1e19, std::numeric_limits<double>::infinity(),
                               std::numeric_limits<double>::quiet_NaN()}) {
    RankReport report;
    report.busySeconds = seconds;
    EXPECT_THROW(decodeReport(encodeReport(report)), ProtocolError) << seconds;
  }
}

TEST(ClusterProtocol, IdentityDifferenceNamesWhatDiffers) {
  const RankIdentity reference = sampleIdentity();
  const auto differs = [&reference](const RankIdentity& other) {
    return identityDifference(reference, other).value_or("(none)");
  };
  RankIdentity other = reference;
  other.host = "node8";
  other.threads = 1;
  EXPECT_FALSE(identityDifference(reference, other)) << "host and threads may differ";

  other = reference;
  other.sceneFile = "other.yaml";
  other.sceneHash = 1;
  EXPECT_NE(differs(other).find("its scene file 'other.yaml'"), std::string::npos)
      << differs(other);
  other = reference;
  other.settings.samples = 16;
  EXPECT_EQ(differs(other), "its render has samples per pixel 16, rank 0's has 4");
  other = reference;
  other.version = "0.2.0";
  EXPECT_EQ(differs(other), "it runs glint 0.2.0, rank 0 runs glint 0.1.0");
  other = reference;
  other.meshHash = 5;
  EXPECT_NE(differs(other).find("meshes"), std::string::npos);
  other = reference;
  other.fingerprint = 7;
  EXPECT_NE(differs(other).find("texture"), std::string::npos);
  other = reference;
  other.error = "scene.yaml: no such file";
  EXPECT_EQ(differs(other), "it could not load the scene: scene.yaml: no such file");
  other = reference;
  other.protocol = kProtocolVersion + 1;
  EXPECT_EQ(decodeIdentity(encodeIdentity(other)).protocol, kProtocolVersion + 1);
  EXPECT_NE(differs(other).find("protocol"), std::string::npos);
}

// A mesh file's materials (an MTL's Kd) reach the scene only as material values: two ranks whose
// MTL files differ load meshes of different materials, and are told so.
TEST(RankIdentity, TheMeshFingerprintCoversTheMaterialsMeshFilesBring) {
  SceneParts parts;
  parts.image.width = 4;
  parts.image.height = 3;
  parts.camera.position = Point3{0, 0, 5};
  parts.camera.fovDegrees = 45;
  TriangleMesh mesh;
  mesh.positions = {Point3{0, 0, 0}, Point3{1, 0, 0}, Point3{0, 1, 0}};
  mesh.indices = {0, 1, 2};
  mesh.materialIndex = 1;
  parts.meshes.push_back(mesh);
  Material copper;
  copper.kd = Color(0.56, 0.22, 0.09);
  parts.materials.push_back(copper);
  const Scene a{parts};
  parts.materials[1].kd.g = 0.62;
  const Scene b{parts};
  EXPECT_NE(meshFingerprint(a), meshFingerprint(b));
  EXPECT_EQ(meshFingerprint(a), meshFingerprint(Scene{[&] {
              SceneParts same = parts;
              same.materials[1].kd.g = 0.22;
              return same;
            }()}));
}

}  // namespace
}  // namespace glint::cluster

#include "glint/cluster/rank_identity.h"

#include <fmt/format.h>

#include <utility>

namespace glint::cluster {
namespace {

template <typename T>
std::uint64_t hashVector(const std::vector<T>& values, std::uint64_t hash) {
  const std::uint64_t count = values.size();
  hash = fnv1a64(std::string_view(reinterpret_cast<const char*>(&count), sizeof count), hash);
  return fnv1a64(
      std::string_view(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T)),
      hash);
}

std::string fileFacts(std::uint64_t bytes, std::uint64_t hash) {
  return fmt::format("{} bytes, FNV-1a 64 {:016x}", bytes, hash);
}

}  // namespace

std::uint64_t meshFingerprint(const Scene& scene) {
  std::uint64_t hash = kFnvOffsetBasis;
  for (const TriangleMesh& mesh : scene.meshes()) {
    hash = hashVector(mesh.positions, hash);
    hash = hashVector(mesh.normals, hash);
    hash = hashVector(mesh.indices, hash);
    const double emission[3] = {mesh.emission.r, mesh.emission.g, mesh.emission.b};
    hash = fnv1a64(std::string_view(reinterpret_cast<const char*>(&mesh.materialIndex),
                                    sizeof mesh.materialIndex),
                   hash);
    hash =
        fnv1a64(std::string_view(reinterpret_cast<const char*>(emission), sizeof emission), hash);
  }
  // The materials too: an OBJ's MTL or a glTF's materials reach the scene only through them.
  return fnv1a64(materialBytes(scene.materials(), scene.materialTextures(), scene.textures()),
                 hash);
}

RankIdentity identityOf(const std::filesystem::path& sceneFile, std::string_view sceneBytes,
                        const Scene& scene, const CheckpointSettings& settings, int threads,
                        std::string host) {
  RankIdentity identity;
  identity.version = GLINT_VERSION;
  identity.host = std::move(host);
  identity.threads = threads;
  identity.sceneFile = sceneFile.string();
  identity.sceneBytes = sceneBytes.size();
  identity.sceneHash = fnv1a64(sceneBytes);
  identity.meshCount = scene.meshes().size();
  identity.meshHash = meshFingerprint(scene);
  identity.settings = settings;
  identity.fingerprint = renderFingerprint(sceneBytes, scene, settings);
  return identity;
}

std::optional<std::string> identityDifference(const RankIdentity& reference,
                                              const RankIdentity& other) {
  if (other.protocol != reference.protocol)
    return fmt::format("it speaks glint's MPI protocol version {}, rank 0 version {}",
                       other.protocol, reference.protocol);
  if (!other.error.empty()) return fmt::format("it could not load the scene: {}", other.error);
  if (other.version != reference.version)
    return fmt::format("it runs glint {}, rank 0 runs glint {}", other.version, reference.version);
  if (const std::optional<SettingDifference> difference =
          firstSettingDifference(other.settings, reference.settings))
    return fmt::format("its render has {} {}, rank 0's has {}", difference->what, difference->first,
                       difference->second);
  if (other.sceneBytes != reference.sceneBytes || other.sceneHash != reference.sceneHash)
    return fmt::format("its scene file '{}' or a file it includes ({}) differs from rank 0's '{}' "
                       "({})",
                       other.sceneFile,
                       fileFacts(other.sceneBytes, other.sceneHash), reference.sceneFile,
                       fileFacts(reference.sceneBytes, reference.sceneHash));
  if (other.meshCount != reference.meshCount || other.meshHash != reference.meshHash)
    return fmt::format(
        "the meshes its scene loads, or their materials, differ from rank 0's ({} meshes, "
        "FNV-1a 64 {:016x}; rank 0: {} meshes, {:016x})",
        other.meshCount, other.meshHash, reference.meshCount, reference.meshHash);
  if (other.fingerprint != reference.fingerprint)
    return std::string(
        "a file its scene loads (a texture or another referenced file) differs "
        "from rank 0's");
  return std::nullopt;
}

}  // namespace glint::cluster

// The identity of what one rank renders (RankIdentity: scene bytes, meshes, settings, version,
// fingerprint) worked out from its loaded scene, and the comparison that names how two ranks
// differ.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "glint/cluster/protocol.h"
#include "glint/job/checkpoint.h"
#include "glint/scene/scene.h"

namespace glint::cluster {

// FNV-1a 64 over the geometry of every mesh of `scene` (positions, normals, indices, material,
// emission), in scene order, and every material's values: the part of renderFingerprint that comes
// from mesh files (an OBJ's MTL included).
std::uint64_t meshFingerprint(const Scene& scene);

// The identity of rendering `scene`, loaded from `sceneFile` whose bytes are `sceneBytes`, with
// `settings`, on `threads` threads of host `host`.
RankIdentity identityOf(const std::filesystem::path& sceneFile, std::string_view sceneBytes,
                        const Scene& scene, const CheckpointSettings& settings, int threads,
                        std::string host);

// How `other` differs from `reference` (rank 0), worded from other's side ("its scene file 'b.yaml'
// differs from rank 0's 'a.yaml' (…)"), naming the first of: a load error, the protocol, the glint
// version, a render setting, the scene file's bytes, the meshes, anything else the fingerprint
// covers; std::nullopt when both render the same.
std::optional<std::string> identityDifference(const RankIdentity& reference,
                                              const RankIdentity& other);

}  // namespace glint::cluster

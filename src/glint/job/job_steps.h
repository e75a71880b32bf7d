// The steps a scene check and a render job share — loading, the image limits, freezing the scene —
// each turning a failure into a JobError with the message the command line prints.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "glint/factories/scene_loader.h"
#include "glint/scene/scene.h"

namespace glint {

// loadScene; a SceneError becomes JobError(BadInput) carrying its diagnostics. Cancelled passes.
LoadedScene loadSceneFile(const std::filesystem::path& file, const LoadOptions& options);

// The scene file's bytes once more, for a fingerprint (checkpoints, the MPI ranks' comparison);
// JobError(Failure) when it cannot be read again.
std::string readSceneFileAgain(const std::filesystem::path& file);

// What a render's fingerprint covers of its scene's text: the scene file's bytes, then for each
// file it includes (Scene::includedFiles) its path as opened and its bytes, read again — so that a
// changed included file (a texture's colours, a group's shapes) is a changed scene too.
std::string fingerprintedSceneText(const std::filesystem::path& file, const Scene& scene);

// The image limits and memory budget (DESIGN.md §7) for the film that will be allocated, checked
// after the overrides changed the image: a request refused as too large is a bad request (exit 2),
// refused before any allocation. `request` names what changed the image ("--width 70000"), empty
// for nothing. `filmCopies`: films held at once (checkpointing keeps a copy of the finished tiles,
// resuming one more of the checkpoint).
void enforceImageLimits(const ImageSettings& image, const std::string& request,
                        std::uint64_t memoryBudget, int filmCopies = 1);

// Scene construction (camera frame, BVH). The loader validates everything a file can get wrong, so
// a refusal here is still the scene's fault: JobError(BadInput) "FILE: reason".
Scene freezeScene(SceneParts parts, const std::string& file);

}  // namespace glint

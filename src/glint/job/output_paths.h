// Where a render job writes — the image and the checkpoint — checked before any work, so that a
// typo costs no render and no input file is ever overwritten by an output.
#pragma once

#include <filesystem>
#include <optional>
#include <vector>

namespace glint {

// The image a render writes when none is named: the scene file's name with ".png", in the current
// folder.
std::filesystem::path defaultOutputPath(const std::filesystem::path& scene);

// Checks the output image path and throws JobError (job/job_error.h) when it cannot be written:
// BadInput for an unknown extension, a missing folder, or a path that is one of the render's inputs
// (`scene`, the `resume` checkpoint; compared by file identity and lexically, so "-o scene.png" on
// a scene file named scene.png is refused); Failure for problems of writing (a folder in its place,
// an unwritable folder). `scene` may be empty (a scene built in code).
void checkOutputPath(const std::filesystem::path& output, const std::filesystem::path& scene,
                     const std::optional<std::filesystem::path>& resume);

// Why no file can be written at `target` — it is a folder, its folder does not exist or is not a
// folder, its name is longer than the file system allows — worded to follow "cannot write 'X': ";
// empty when nothing stands in the way. Shared by the image's and `glint convert`'s outputs.
std::string targetProblem(const std::filesystem::path& target);

// Whether `a` and `b` name the same file: the same inode when both exist (hard and symbolic links,
// "./" spellings), else the same absolute path spelled lexically.
bool sameFile(const std::filesystem::path& a, const std::filesystem::path& b);

// After the scene is loaded: throws JobError(BadInput) when the output image is one of the files
// the scene read (`files`: its included files, mesh files and image textures), which writing the
// image would replace.
void checkOutputIsNotRead(const std::filesystem::path& output,
                          const std::vector<std::filesystem::path>& files);

// The checkpoint file a render writes: `checkpoint`, or else the `resume` file (a resumed render
// keeps checkpointing, so it can be interrupted again); std::nullopt when neither is given. Throws
// JobError when a name is empty, when it is the output image, when its folder is missing or not
// writable, when it names a folder, when it exists and is not the checkpoint being resumed (work
// saved in it would be lost), and when `resume` is not a regular file (a device or a FIFO would
// never finish reading or never open).
std::optional<std::filesystem::path> resolveCheckpointPath(
    const std::optional<std::filesystem::path>& checkpoint,
    const std::optional<std::filesystem::path>& resume, const std::filesystem::path& output);

}  // namespace glint

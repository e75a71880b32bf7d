#include "glint/job/output_paths.h"

#include <fmt/format.h>
#include <unistd.h>

#include <fstream>
#include <string>
#include <string_view>
#include <system_error>

#include "glint/image/image_writer.h"
#include "glint/job/checkpoint.h"
#include "glint/job/job_error.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

fs::path folderOf(const fs::path& path) {
  return path.parent_path().empty() ? fs::path(".") : path.parent_path();
}

}  // namespace

bool sameFile(const fs::path& a, const fs::path& b) {
  std::error_code error;
  if (fs::equivalent(a, b, error)) return true;
  const fs::path absoluteA = fs::absolute(a, error);
  if (error) return a.lexically_normal() == b.lexically_normal();
  const fs::path absoluteB = fs::absolute(b, error);
  if (error) return a.lexically_normal() == b.lexically_normal();
  return absoluteA.lexically_normal() == absoluteB.lexically_normal();
}

std::string targetProblem(const fs::path& target) {
  std::error_code error;
  if (fs::is_directory(target, error)) return "it is a folder";
  const fs::path folder = folderOf(target);
  if (!fs::is_directory(folder, error)) {
    return fs::exists(folder, error)
               ? fmt::format("'{}' is not a folder", folder.string())
               : fmt::format("the folder '{}' does not exist", folder.string());
  }
  // A name the file system cannot hold would fail only when the finished file is renamed.
  const long nameMax = ::pathconf(folder.c_str(), _PC_NAME_MAX);
  if (nameMax > 0 && target.filename().string().size() > static_cast<std::size_t>(nameMax)) {
    return fmt::format("the file name is {} bytes long, longer than the {} its folder allows",
                       target.filename().string().size(), nameMax);
  }
  return {};
}

fs::path defaultOutputPath(const fs::path& scene) { return scene.stem().concat(".png"); }

void checkOutputPath(const fs::path& out, const fs::path& scene,
                     const std::optional<fs::path>& resume) {
  std::error_code error;
  // Before the extension: "images.png/" or "renders" is a folder, whatever its name says.
  if (fs::is_directory(out, error))
    throw JobError(JobFailure::BadInput,
                   fmt::format("cannot write '{}': it is a folder", out.string()));
  const std::unique_ptr<ImageWriter> writer = writerForPath(out);
  if (!writer) {
    const std::string extension = out.extension().string();
    throw JobError(JobFailure::BadInput,
                   fmt::format("cannot write '{}': {}; use .png, .ppm or .exr", out.string(),
                               extension.empty() ? std::string("the name has no extension")
                                                 : "unknown image format '" + extension + "'"));
  }
  if (const std::string problem = targetProblem(out); !problem.empty())
    throw JobError(JobFailure::BadInput,
                   fmt::format("cannot write '{}': {}", out.string(), problem));
  const fs::path folder = folderOf(out);
  // The image replaces its target only when complete, but it would still replace an input.
  if (!scene.empty() && sameFile(out, scene))
    throw JobError(JobFailure::BadInput,
                   fmt::format("cannot write '{}': it is the scene file", out.string()));
  if (resume && !resume->empty() && sameFile(out, *resume))
    throw JobError(JobFailure::BadInput,
                   fmt::format("the checkpoint '{}' cannot be the output image", resume->string()));
  // Writing problems (exit 1) that can be seen now rather than after the render.
  if (access(folder.c_str(), W_OK | X_OK) != 0)
    throw JobError(JobFailure::Failure,
                   fmt::format("cannot write '{}': the folder '{}' is not writable", out.string(),
                               folder.string()));
  if (const std::string why = writer->unavailable(); !why.empty())
    throw JobError(JobFailure::Failure, fmt::format("cannot write '{}': {}", out.string(), why));
}

void checkOutputIsNotRead(const fs::path& output, const std::vector<fs::path>& files) {
  for (const fs::path& file : files) {
    if (sameFile(output, file)) {
      throw JobError(JobFailure::BadInput,
                     fmt::format("cannot write '{}': the scene reads it (as '{}'); choose another "
                                 "name for the image",
                                 output.string(), file.string()));
    }
  }
}

namespace {

// Whether `path` is a regular file that begins with the checkpoint's magic bytes (never opened
// when it is a FIFO or a device).
bool startsAsCheckpoint(const fs::path& path) {
  std::error_code error;
  if (!fs::is_regular_file(path, error)) return false;
  std::ifstream in(path, std::ios::binary);
  char magic[kCheckpointMagic.size()] = {};
  in.read(magic, static_cast<std::streamsize>(sizeof magic));
  return in.gcount() == static_cast<std::streamsize>(sizeof magic) &&
         std::string_view(magic, sizeof magic) == kCheckpointMagic;
}

}  // namespace

std::optional<fs::path> resolveCheckpointPath(const std::optional<fs::path>& checkpoint,
                                              const std::optional<fs::path>& resume,
                                              const fs::path& out) {
  if (!checkpoint && !resume) return std::nullopt;
  if (checkpoint && checkpoint->empty())
    throw JobError(JobFailure::BadInput, "--checkpoint needs a file name");
  if (resume && resume->empty()) throw JobError(JobFailure::BadInput, "--resume needs a file name");
  const fs::path path = checkpoint ? *checkpoint : *resume;
  std::error_code error;
  if (sameFile(path, out))
    throw JobError(JobFailure::BadInput,
                   fmt::format("the checkpoint '{}' cannot be the output image", path.string()));
  const fs::path folder = folderOf(path);
  if (!fs::is_directory(folder, error))
    throw JobError(JobFailure::BadInput,
                   fmt::format("cannot write checkpoint '{}': the folder '{}' does not exist",
                               path.string(), folder.string()));
  if (fs::is_directory(path, error))
    throw JobError(JobFailure::BadInput,
                   fmt::format("cannot write checkpoint '{}': it is a folder", path.string()));
  if (access(folder.c_str(), W_OK | X_OK) != 0)
    throw JobError(JobFailure::Failure,
                   fmt::format("cannot write checkpoint '{}': the folder '{}' is not writable",
                               path.string(), folder.string()));
  // Named before anything else about it: a device or a FIFO is refused without being opened.
  if (resume) {
    try {
      checkCheckpointFile(*resume);
    } catch (const CheckpointError& problem) {
      throw JobError(JobFailure::BadInput, fmt::format("cannot resume: {}", problem.what()));
    }
  }
  // Starting afresh over an existing checkpoint would throw away the work saved in it.
  const bool continuesIt = resume && sameFile(path, *resume);
  if (!continuesIt && fs::exists(path, error)) {
    // Only a checkpoint is worth continuing; another file (a scene, an image) is simply in the way.
    if (!startsAsCheckpoint(path))
      throw JobError(JobFailure::BadInput,
                     fmt::format("cannot write checkpoint '{}': the file exists and is not a glint "
                                 "checkpoint; choose another --checkpoint path",
                                 path.string()));
    throw JobError(JobFailure::BadInput,
                   fmt::format("the checkpoint '{}' already exists; continue it with --resume {}, "
                               "or delete it to start over",
                               path.string(), path.string()));
  }
  return path;
}

}  // namespace glint

// Opening the files a scene names (the scene itself, later textures and included files) for a
// reader: a regular file (core/file_access.h), or an error naming only the file — a FIFO, a device
// or a folder is refused instead of blocking or reading forever.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "glint/core/file_access.h"

namespace glint {

// Scene files larger than this are refused: a scene file holds a scene description (meshes belong
// in their own files). 256 MiB.
inline constexpr std::uint64_t kMaxSceneFileBytes = std::uint64_t{256} << 20;

// Opens `path` for reading if it is a regular file. Throws SceneError naming only `name`:
// "cannot open file: No such file or directory", "cannot open file: Is a directory",
// "cannot open file: not a regular file (a FIFO)", ...
ReadableFile openRegularFile(const std::filesystem::path& path, const std::string& name);

}  // namespace glint

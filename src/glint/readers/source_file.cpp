#include "glint/readers/source_file.h"

#include <cerrno>
#include <string>
#include <system_error>

#include "glint/readers/diagnostics.h"

namespace glint {

ReadableFile openRegularFile(const std::filesystem::path& path, const std::string& name) {
  ReadableFile file = openForReading(path);
  std::string reason;
  switch (file.refusal) {
    case FileRefusal::None:
      return file;
    case FileRefusal::Folder:
      reason = std::generic_category().message(EISDIR);
      break;
    case FileRefusal::NotRegular:
      reason = "not a regular file (" + nonRegularKind(file.mode) + ")";
      break;
    case FileRefusal::Missing:
    case FileRefusal::System:
      // The system's words ("No such file or directory"), with the file as the user named it.
      reason = std::generic_category().message(file.error);
      break;
  }
  throw SceneError({{Diagnostic::Severity::Error, {name, 0, 0}, "cannot open file: " + reason}});
}

}  // namespace glint

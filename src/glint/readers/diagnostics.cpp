#include "glint/readers/diagnostics.h"

#include <string>
#include <utility>
#include <vector>

namespace glint {

std::string Diagnostic::format() const {
  std::string out = where.file;
  if (where.line > 0) {
    out += ':' + std::to_string(where.line);
    if (where.column > 0) out += ':' + std::to_string(where.column);
  }
  out += ": ";
  if (severity == Severity::Warning) out += "warning: ";
  out += message;
  return out;
}

namespace {

// what(): the reported diagnostics one per line, as the command line prints them, and how many more
// were found beyond the cap.
std::string describeAll(const std::vector<Diagnostic>& diagnostics) {
  if (diagnostics.empty()) return "invalid scene";
  std::string out;
  const std::size_t shown = std::min(diagnostics.size(), SceneError::kMaxReportedErrors);
  for (std::size_t i = 0; i < shown; ++i) {
    if (i > 0) out += '\n';
    out += diagnostics[i].format();
  }
  if (diagnostics.size() > shown) {
    const std::size_t more = diagnostics.size() - shown;
    out +=
        "\n(" + std::to_string(more) + (more == 1 ? " more error" : " more errors") + " not shown)";
  }
  return out;
}

}  // namespace

SceneError::SceneError(std::vector<Diagnostic> diagnostics)
    : std::runtime_error(describeAll(diagnostics)), diagnostics_(std::move(diagnostics)) {
  if (diagnostics_.size() > kMaxReportedErrors) {
    unreported_ = diagnostics_.size() - kMaxReportedErrors;
    diagnostics_.resize(kMaxReportedErrors);
  }
}

}  // namespace glint

#include "glint/readers/diagnostics.h"

#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

namespace glint {

namespace {

std::string escaped(std::string_view text, std::size_t maxCharacters) {
  std::string out;
  std::size_t characters = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    const bool continuation = (c & 0xC0) == 0x80;
    if (!continuation && characters == maxCharacters) {
      out += "...";
      break;
    }
    if (!continuation) ++characters;
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c < 0x20 || c == 0x7F) {
      out += fmt::format("\\x{:02x}", c);
    } else if (c == 0xC2 && i + 1 < text.size() &&
               (static_cast<unsigned char>(text[i + 1]) & 0xE0) == 0x80) {
      // U+0080..U+009F, the C1 controls (0x9B starts a terminal escape sequence on some
      // terminals).
      out += fmt::format("\\u{:04x}", static_cast<unsigned char>(text[++i]));
    } else {
      out += static_cast<char>(c);
    }
  }
  return out;
}

}  // namespace

std::string shortenForMessage(std::string_view text) { return escaped(text, kMaxQuoted); }
std::string escapeForMessage(std::string_view text) { return escaped(text, SIZE_MAX); }

std::string quoteForMessage(std::string_view text) { return "'" + shortenForMessage(text) + "'"; }

bool hasErrors(const std::vector<Diagnostic>& diagnostics) {
  for (const Diagnostic& d : diagnostics) {
    if (d.severity == Diagnostic::Severity::Error) return true;
  }
  return false;
}

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

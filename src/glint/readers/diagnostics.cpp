#include "glint/readers/diagnostics.h"

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

namespace glint {

namespace {}  // namespace

std::size_t utf8Width(std::string_view text, std::size_t i) {
  const auto c = static_cast<unsigned char>(text[i]);
  if (c < 0x80) return 1;
  const std::size_t width = (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
  if (width == 0 || i + width > text.size()) return 0;
  std::uint32_t code = c & (0x7Fu >> width);
  for (std::size_t k = 1; k < width; ++k) {
    const auto next = static_cast<unsigned char>(text[i + k]);
    if ((next & 0xC0) != 0x80) return 0;
    code = (code << 6) | (next & 0x3Fu);
  }
  constexpr std::uint32_t kLeast[] = {0, 0, 0x80, 0x800, 0x10000};
  if (code < kLeast[width] || (code >= 0xD800 && code <= 0xDFFF) || code > 0x10FFFF) return 0;
  return width;
}

namespace {

// Control characters, C1 controls and bytes that are not UTF-8 as escapes (a message is UTF-8
// text, and a terminal must not take a byte of the file for a command).
std::string escaped(std::string_view text, std::size_t maxCharacters) {
  std::string out;
  std::size_t characters = 0;
  for (std::size_t i = 0; i < text.size();) {
    if (characters == maxCharacters) {
      out += "...";
      break;
    }
    ++characters;
    const auto c = static_cast<unsigned char>(text[i]);
    const std::size_t width = utf8Width(text, i);
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c == '\r') {
      out += "\\r";
    } else if (width == 0 || c < 0x20 || c == 0x7F) {
      out += fmt::format("\\x{:02x}", c);
    } else if (c == 0xC2 && (static_cast<unsigned char>(text[i + 1]) & 0xE0) == 0x80) {
      // U+0080..U+009F, the C1 controls (0x9B starts a terminal escape sequence on some
      // terminals).
      out += fmt::format("\\u{:04x}", static_cast<unsigned char>(text[i + 1]));
    } else {
      out.append(text.substr(i, width));
    }
    i += width == 0 ? 1 : width;
  }
  return out;
}

}  // namespace

std::string shortenForMessage(std::string_view text) { return escaped(text, kMaxQuoted); }
std::string escapeForMessage(std::string_view text) { return escaped(text, SIZE_MAX); }

std::string nameForMessage(std::string_view name) {
  return name.size() <= kMaxNameBytes ? escapeForMessage(name) : shortenForMessage(name);
}

std::string quoteForMessage(std::string_view text) { return "'" + shortenForMessage(text) + "'"; }

bool hasErrors(const std::vector<Diagnostic>& diagnostics) {
  for (const Diagnostic& d : diagnostics) {
    if (d.severity == Diagnostic::Severity::Error) return true;
  }
  return false;
}

std::string Diagnostic::format() const {
  // The file's name as the user gave it, but never a control byte or invalid UTF-8 raw on the
  // terminal (a name holding an escape sequence could recolour or rewrite it).
  std::string out = escapeForMessage(where.file);
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

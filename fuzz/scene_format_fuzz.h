// What the fuzz targets of the NFF and Tachyon readers share: the bytes read as a scene of that
// format and built by the factories. Any result but a LoadedScene or a SceneError that keeps the
// loader's promises is a finding.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "glint/factories/scene_loader.h"
#include "glint/readers/diagnostics.h"

namespace glint::fuzz {

// Relative paths resolve here; it does not exist.
inline constexpr const char* kBaseDirectory = "/nonexistent/glint-fuzz";

inline void require(bool condition) {
  if (!condition) std::abort();
}

// Parses with `parse` (parseNff, parseTachyon), then builds.
template <class Parse>
int fuzzSceneFormat(const std::uint8_t* data, std::size_t size, const char* name, Parse parse) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const ParseResult parsed = parse(text, name, kBaseDirectory, nullptr);
  for (const Diagnostic& d : parsed.diagnostics) {
    require(!d.message.empty());
    require(d.where.line >= 1 && d.where.column >= 1);
  }
  require(parsed.description.complete == !parsed.hasErrors());
  try {
    const LoadedScene loaded = buildDescribedScene(parsed);
    require(!parsed.hasErrors());
    for (const Diagnostic& warning : loaded.warnings) {
      require(warning.severity == Diagnostic::Severity::Warning);
    }
  } catch (const SceneError& error) {
    require(!error.diagnostics().empty());
    require(error.diagnostics().size() <= SceneError::kMaxReportedErrors);
    for (const Diagnostic& d : error.diagnostics()) require(!d.message.empty());
  }
  return 0;
}

}  // namespace glint::fuzz

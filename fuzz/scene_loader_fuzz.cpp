// libFuzzer target for the scene loader (DESIGN.md §5, §7): any bytes give a LoadedScene or a
// SceneError. Any other exception, a crash, a hang or a sanitizer report is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "glint/factories/scene_loader.h"
#include "glint/readers/diagnostics.h"

namespace {

// Relative mesh paths resolve here; it does not exist, so fuzzed `mesh` objects fail fast and
// deterministically instead of reading whatever lies in the working directory.
constexpr const char* kBaseDirectory = "/nonexistent/glint-fuzz";

// A broken contract is a finding too: abort so libFuzzer saves the input.
void require(bool condition) {
  if (!condition) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const glint::LoadedScene loaded = glint::loadSceneFromString(text, "fuzz.yaml", kBaseDirectory);
    for (const glint::Diagnostic& warning : loaded.warnings) {
      require(warning.severity == glint::Diagnostic::Severity::Warning);
      require(!warning.format().empty());
    }
  } catch (const glint::SceneError& error) {
    // DESIGN.md §7: every error of a file is reported, at most kMaxReportedErrors, each with a
    // message, and the CLI prints each one with format().
    const auto& diagnostics = error.diagnostics();
    require(!diagnostics.empty());
    require(diagnostics.size() <= glint::SceneError::kMaxReportedErrors);
    for (const glint::Diagnostic& diagnostic : diagnostics) {
      require(!diagnostic.message.empty());
      require(!diagnostic.format().empty());
    }
  }
  return 0;
}

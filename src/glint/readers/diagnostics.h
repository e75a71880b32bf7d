// Diagnostics for scene input: errors and warnings located at FILE:LINE:COL.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace glint {

// 1-based line and column; 0 means "no natural place" (then only the file is named).
struct SourceLocation {
  std::string file;
  int line = 0;
  int column = 0;
};

struct Diagnostic {
  enum class Severity { Error, Warning };
  Severity severity = Severity::Error;
  SourceLocation where;
  std::string
      message;  // what is wrong and what was expected, e.g. "sphere.radius must be > 0, got -2"

  // "FILE:LINE:COL: message" for errors, "FILE:LINE:COL: warning: message" for warnings;
  // "FILE: message" when there is no line.
  std::string format() const;
};

// Thrown by the scene loader with every error found in a file (at most kMaxReportedErrors).
class SceneError : public std::runtime_error {
 public:
  static constexpr std::size_t kMaxReportedErrors = 20;
  explicit SceneError(std::vector<Diagnostic> diagnostics);
  const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }
  // Errors found beyond the kMaxReportedErrors kept in diagnostics().
  std::size_t unreported() const { return unreported_; }

 private:
  std::vector<Diagnostic> diagnostics_;
  std::size_t unreported_ = 0;
};

}  // namespace glint

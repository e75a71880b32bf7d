// Diagnostics for scene input: errors and warnings located at FILE:LINE:COL.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
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

// Text from a file as messages quote it: control characters and terminal escape codes written as
// \n, \t, \x1b, ... (never printed raw), and at most kMaxQuoted characters (a longer text ends
// in "..."), never cutting a UTF-8 sequence. shortenForMessage gives it bare, quoteForMessage in
// single quotes.
inline constexpr std::size_t kMaxQuoted = 40;
std::string shortenForMessage(std::string_view text);
// The same escaping without the length limit: file and material names, shown whole.
std::string escapeForMessage(std::string_view text);
// Names of materials, textures and groups are at most this many bytes (longer ones are errors
// where they are defined): one name is copied into every message about it and compared at every
// use, so megabyte names made valid scenes take minutes and error lists gigabytes.
inline constexpr std::size_t kMaxNameBytes = 256;
// A name the scene uses, as messages show it: escaped, whole up to kMaxNameBytes (as it was
// defined), shortened (shortenForMessage) past that.
std::string nameForMessage(std::string_view name);
std::string quoteForMessage(std::string_view text);

// Bytes of the well-formed UTF-8 sequence starting at text[i] (1 for ASCII), or 0 when it is not
// one (a stray continuation byte, a cut or overlong sequence, a surrogate, past U+10FFFF).
std::size_t utf8Width(std::string_view text, std::size_t i);

// Whether any of `diagnostics` is an error (not only warnings).
bool hasErrors(const std::vector<Diagnostic>& diagnostics);

// Errors and warnings as they are found, in any order (the loader sorts them by place).
class Diagnostics {
 public:
  void error(SourceLocation where, std::string message) {
    list_.push_back({Diagnostic::Severity::Error, std::move(where), std::move(message)});
    ++errors_;
  }
  void warning(SourceLocation where, std::string message) {
    list_.push_back({Diagnostic::Severity::Warning, std::move(where), std::move(message)});
  }
  std::size_t errorCount() const { return errors_; }
  bool hasErrors() const { return errors_ > 0; }
  const std::vector<Diagnostic>& all() const { return list_; }
  std::vector<Diagnostic> take() {
    errors_ = 0;
    return std::move(list_);
  }

 private:
  std::vector<Diagnostic> list_;
  std::size_t errors_ = 0;
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

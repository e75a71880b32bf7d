// The one error a render job or a scene check reports: worded for the user, with the class of exit
// status it deserves (DESIGN.md §6, §7) and, for a bad scene file, every error at its place.
#pragma once

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "glint/readers/diagnostics.h"

namespace glint {

enum class JobFailure {
  // Bad arguments, a bad scene, a request refused as too large, a checkpoint that does not fit:
  // exit status 2. Found before anything was rendered.
  BadInput,
  // A failure while rendering or writing: exit status 1.
  Failure,
};

class JobError : public std::runtime_error {
 public:
  JobError(JobFailure failure, const std::string& message)
      : std::runtime_error(message), failure_(failure) {}
  // A scene file with errors: `diagnostics` at their file:line:col (at most
  // SceneError::kMaxReportedErrors) and how many more were found; what() lists them all.
  explicit JobError(const SceneError& error)
      : std::runtime_error(error.what()),
        failure_(JobFailure::BadInput),
        diagnostics_(error.diagnostics()),
        unreported_(error.unreported()) {}

  JobFailure failure() const { return failure_; }
  // 2 for BadInput, 1 for Failure.
  int exitCode() const { return failure_ == JobFailure::BadInput ? 2 : 1; }
  const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }
  std::size_t unreported() const { return unreported_; }

  // Writing the image failed, but the finished render is saved in this checkpoint (a --resume
  // writes the image without rendering again); empty otherwise.
  const std::filesystem::path& savedCheckpoint() const { return savedCheckpoint_; }
  JobError& withSavedCheckpoint(std::filesystem::path path) {
    savedCheckpoint_ = std::move(path);
    return *this;
  }

 private:
  JobFailure failure_;
  std::vector<Diagnostic> diagnostics_;
  std::size_t unreported_ = 0;
  std::filesystem::path savedCheckpoint_;
};

}  // namespace glint

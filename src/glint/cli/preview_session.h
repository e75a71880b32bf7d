// The render command's live preview: the --preview, --preview-bind and --preview-linger options,
// and for one render the server (glint/preview) started before the job, fed by its events, told
// the outcome, and kept serving afterwards until Ctrl-C or the linger time.
#pragma once

#include <CLI/CLI.hpp>
#include <atomic>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "glint/job/render_job.h"
#include "glint/preview/preview_server.h"
#include "glint/preview/preview_state.h"

namespace glint::cli {

// What the options asked for, checked.
struct PreviewRequest {
  std::string address = "127.0.0.1";
  int port = kDefaultPreviewPort;       // 0: any free port
  std::optional<double> lingerSeconds;  // after the render; empty: until Ctrl-C
};

// The three options on the render command, read as text and checked by request().
class PreviewOptions {
 public:
  explicit PreviewOptions(CLI::App& render);
  // After parsing: the request, or nothing without --preview. Throws PreviewError for a bad value.
  std::optional<PreviewRequest> request() const;

 private:
  std::string port_, bind_, linger_;
  CLI::Option* portOption_ = nullptr;
  CLI::Option* bindOption_ = nullptr;
  CLI::Option* lingerOption_ = nullptr;
};

class PreviewSession {
 public:
  // Starts serving (throws PreviewError: exit 2) and prints the address to `log`, with a warning
  // when the address can be reached from other machines.
  PreviewSession(const PreviewRequest& request, const std::string& sceneFile, std::FILE* log);
  ~PreviewSession();

  // Hooks the preview to the job's events (after those already set).
  void attach(RenderJobEvents& events);
  // The render's outcome, shown on the page (`text`: the summary or the error). When rendering had
  // begun, `stop` is not set and the job was not refused (`refused`: a bad scene or request, exit
  // 2, found before any tile — under MPI a rank's refusal comes after the render step began), keeps
  // serving until `stop` is set (Ctrl-C) or the linger time has passed; then stops the server.
  void end(PreviewPhase phase, const std::string& text, const std::atomic<bool>& stop,
           bool refused = false);

 private:
  PreviewRequest request_;
  std::FILE* log_;
  PreviewState state_;
  std::unique_ptr<PreviewServer> server_;
  std::atomic<bool> renderBegan_{false};
};

}  // namespace glint::cli

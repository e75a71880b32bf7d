#include "glint/cli/preview_session.h"

#include <fmt/format.h>

#include <charconv>
#include <chrono>
#include <cmath>
#include <string_view>
#include <system_error>
#include <thread>
#include <utility>

#include "glint/cli/console.h"
#include "glint/preview/job_preview.h"

namespace glint::cli {
namespace {

// A linger time is a convenience, not a service: more than a day is a typo.
constexpr double kMaxLingerSeconds = 86400;

}  // namespace

PreviewOptions::PreviewOptions(CLI::App& render) {
  portOption_ =
      render
          .add_option("--preview", port_,
                      fmt::format("Show the render in a browser as it goes: serve a page on "
                                  "127.0.0.1:PORT (default {}; 0: any free port); put it after "
                                  "SCENE",
                                  kDefaultPreviewPort))
          ->expected(0, 1)
          ->type_name("[PORT]");
  bindOption_ = render
                    .add_option("--preview-bind", bind_,
                                "Address the preview listens on (default 127.0.0.1, this machine "
                                "only); any other lets whoever reaches the port see the image")
                    ->type_name("ADDR")
                    ->needs(portOption_);
  lingerOption_ = render
                      .add_option("--preview-linger", linger_,
                                  "Keep serving the preview this long after the render "
                                  "(default: until Ctrl-C; 0: stop at once)")
                      ->type_name("SECONDS")
                      ->needs(portOption_);
}

std::optional<PreviewRequest> PreviewOptions::request() const {
  if (portOption_->count() == 0) return std::nullopt;
  PreviewRequest request;
  if (!port_.empty()) {
    int port = -1;
    const char* end = port_.data() + port_.size();
    const auto [stop, error] = std::from_chars(port_.data(), end, port);
    if (error != std::errc{} || stop != end || port < 0 || port > 65535)
      throw PreviewError(fmt::format(
          "--preview expects a port number from 0 to 65535, got '{}' (write the scene before "
          "--preview, or --preview=PORT)",
          port_));
    request.port = port;
  }
  if (bindOption_->count() > 0) request.address = bind_;
  if (lingerOption_->count() > 0) {
    double seconds = -1;
    const char* end = linger_.data() + linger_.size();
    const auto [stop, error] = std::from_chars(linger_.data(), end, seconds);
    if (error != std::errc{} || stop != end || !(seconds >= 0) || seconds > kMaxLingerSeconds)
      throw PreviewError(fmt::format("--preview-linger expects seconds from 0 to {:g}, got '{}'",
                                     kMaxLingerSeconds, linger_));
    request.lingerSeconds = seconds;
  }
  return request;
}

PreviewSession::PreviewSession(const PreviewRequest& request, const std::string& sceneFile,
                               std::FILE* log)
    : request_(request), log_(log), state_(sceneFile) {
  server_ = std::make_unique<PreviewServer>(state_, request.address, request.port);
  emit(log_, fmt::format("glint: preview at {}\n", server_->url()));
  if (!PreviewServer::isLoopback(request.address))
    emit(log_, fmt::format("glint: warning: the preview listens on {}: anyone who can reach this "
                           "port can see the image\n",
                           request.address));
}

PreviewSession::~PreviewSession() { server_->stop(); }

void PreviewSession::attach(RenderJobEvents& events) {
  events.renderStarting = [this, before = std::move(events.renderStarting)](std::size_t resumed,
                                                                            std::size_t total) {
    renderBegan_ = true;
    if (before) before(resumed, total);
  };
  attachPreview(events, state_);
}

void PreviewSession::end(PreviewPhase phase, const std::string& text, const std::atomic<bool>& stop,
                         bool refused) {
  using Clock = std::chrono::steady_clock;
  state_.ended(phase, text);
  if (renderBegan_ && !refused && !stop && request_.lingerSeconds != 0.0) {
    const std::string until = request_.lingerSeconds
                                  ? fmt::format("for {:g} s", *request_.lingerSeconds)
                                  : std::string("until Ctrl-C");
    emit(log_, fmt::format("glint: the preview stays at {} {}\n", server_->url(), until));
    const auto deadline =
        request_.lingerSeconds
            ? Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                 std::chrono::duration<double>(*request_.lingerSeconds))
            : Clock::time_point::max();
    while (!stop && Clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  // The outcome reaches the open pages before the server stops (a second at most: a page that
  // does not read is not waited for longer).
  server_->drain(std::chrono::seconds(1));
  server_->stop();
}

}  // namespace glint::cli

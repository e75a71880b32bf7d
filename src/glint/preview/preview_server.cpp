#include "glint/preview/preview_server.h"

#include <arpa/inet.h>
#include <fmt/format.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <span>
#include <string_view>

#include "glint/core/helper_files.h"
#include "glint/preview/preview_http_module.h"
#include "glint/preview/preview_messages.h"
#include "preview_page.h"  // kPreviewPage: preview_page.html, embedded at build time

namespace glint {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

// Connection threads: each open page holds one for its event stream, the rest serve the page.
constexpr std::size_t kServerThreads = 8;
constexpr int kMaxStreams = 6;
// How long a stream waits for a change before it looks again (and notices a stop).
constexpr auto kStreamWait = 200ms;
// While rendering, the status (progress, elapsed time, ETA) is sent at most this often.
constexpr auto kStatusInterval = 250ms;
// A comment line keeps idle streams open through proxies and finds closed ones: a page closed or
// reloaded gives its stream's place back within this time.
constexpr auto kKeepAliveInterval = 1s;
// Blocks per event: a large image's first update comes as several events of bounded size.
constexpr std::size_t kTilesPerEvent = 256;

// Everything the page may load comes from this server; the page embeds its script and style.
constexpr const char* kContentSecurityPolicy =
    "default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; "
    "connect-src 'self'; img-src data:; base-uri 'none'; form-action 'none'";

bool isIpLiteral(const std::string& address, int& family) {
  in6_addr buffer{};
  if (inet_pton(AF_INET, address.c_str(), &buffer) == 1) {
    family = AF_INET;
    return true;
  }
  if (inet_pton(AF_INET6, address.c_str(), &buffer) == 1) {
    family = AF_INET6;
    return true;
  }
  return false;
}

// Why binding failed, from a probe socket of our own (cpp-httplib reports only failure).
std::string bindFailure(const std::string& address, int family, int port) {
  const int probe = socket(family, SOCK_STREAM, 0);
  if (probe < 0) return std::strerror(errno);
  const int yes = 1;
  setsockopt(probe, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  int error = 0;
  if (family == AF_INET) {
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<std::uint16_t>(port));
    inet_pton(AF_INET, address.c_str(), &addr.sin_addr);
    if (bind(probe, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) error = errno;
  } else {
    sockaddr_in6 addr{};
    addr.sin6_family = AF_INET6;
    addr.sin6_port = htons(static_cast<std::uint16_t>(port));
    inet_pton(AF_INET6, address.c_str(), &addr.sin6_addr);
    if (bind(probe, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) error = errno;
  }
  close(probe);
  if (error == EADDRINUSE)
    return "the port is in use (choose another with --preview PORT, or --preview 0 for any free "
           "port)";
  if (error == EADDRNOTAVAIL) return "the address is not one of this machine's";
  if (error == EACCES) return "permission denied (ports below 1024 need root)";
  return error != 0 ? std::strerror(error) : std::string("the socket could not be opened");
}

// The Host header's host part: "localhost:8642" -> "localhost", "[::1]:8642" -> "::1".
std::string_view hostOf(std::string_view host) {
  if (host.starts_with('[')) {
    const std::size_t close = host.find(']');
    return close == std::string_view::npos ? host : host.substr(1, close - 1);
  }
  return host.substr(0, host.find(':'));
}

// A page on another site could reach a loopback server through a name it makes resolve to
// 127.0.0.1 (DNS rebinding); such requests carry that name, not a loopback one.
bool isLoopbackHost(std::string_view host) {
  const std::string_view name = hostOf(host);
  return name == "localhost" || name.ends_with(".localhost") ||
         PreviewServer::isLoopback(std::string(name));
}

// The module's server (preview_http_module.h), loaded on the first preview of the process.
preview_http::StartFunction loadServerModule() {
  static std::string error;
  static void* const start =
      loadHelperModule(preview_http::kModuleFile, "GLINT_PREVIEW_MODULE", GLINT_HELPER_PATHS,
                       preview_http::kModuleIdentity, preview_http::kStartFunction, error);
  if (start == nullptr) throw PreviewError("cannot start the preview: " + error);
  return reinterpret_cast<preview_http::StartFunction>(start);
}

}  // namespace

struct PreviewServer::Impl {
  Impl(PreviewState& previewState, std::string boundAddress)
      : state(previewState), address(std::move(boundAddress)) {}

  PreviewState& state;
  std::string address;
  int port = 0;
  std::unique_ptr<preview_http::Server> server;
  std::atomic<int> streams{0};
  std::atomic<int> streamsFinal{0};  // open streams that have sent the render's outcome
  bool stopped = false;

  std::unique_ptr<preview_http::EventStream> openStream();
};

namespace {

// One page's event stream: what changed in the PreviewState since it last looked, as server-sent
// events, and a comment now and then to keep it open.
class StateStream final : public preview_http::EventStream {
 public:
  StateStream(PreviewState& state, std::atomic<int>& streams, std::atomic<int>& streamsFinal)
      : state_(state), streams_(streams), streamsFinal_(streamsFinal) {}
  ~StateStream() override {
    if (sentFinal_) streamsFinal_.fetch_sub(1);
    streams_.fetch_sub(1);
  }

  bool writeNext(const Write& sink) override {
    if (state_.isClosed()) return false;
    const PreviewChanges changes = state_.waitForChanges(version_, kStreamWait);
    const auto now = Clock::now();
    const auto write = [&](const std::string& text) {
      lastWrite_ = now;
      return sink(text);
    };
    if (!started_) {
      started_ = true;
      if (!write("retry: 1000\n\n")) return false;
    }
    // Pixels before the status: a page that reads "finished" already has the whole image.
    const std::span<const PreviewTile> tiles(changes.tiles);
    for (std::size_t i = 0; i < tiles.size(); i += kTilesPerEvent)
      if (!write(tilesEvent(tiles.subspan(i, std::min(kTilesPerEvent, tiles.size() - i)),
                            changes.status.width, changes.status.height)))
        return false;
    version_ = changes.version;
    std::string status = statusEvent(changes.status);
    const bool due =
        changes.status.phase != PreviewPhase::Rendering || now - statusSent_ >= kStatusInterval;
    if (status != lastStatus_ && due) {
      if (!write(status)) return false;
      lastStatus_ = std::move(status);
      statusSent_ = now;
      const PreviewPhase phase = changes.status.phase;
      if (!sentFinal_ && phase != PreviewPhase::Loading && phase != PreviewPhase::Rendering) {
        sentFinal_ = true;
        streamsFinal_.fetch_add(1);
      }
    }
    if (now - lastWrite_ >= kKeepAliveInterval && !write(": keep-alive\n\n")) return false;
    return true;
  }

 private:
  PreviewState& state_;
  std::atomic<int>& streams_;
  std::atomic<int>& streamsFinal_;
  bool sentFinal_ = false;
  std::uint64_t version_ = 0;
  std::string lastStatus_;
  Clock::time_point statusSent_{};
  Clock::time_point lastWrite_ = Clock::now();
  bool started_ = false;
};

}  // namespace

std::unique_ptr<preview_http::EventStream> PreviewServer::Impl::openStream() {
  if (streams.fetch_add(1) >= kMaxStreams) {
    streams.fetch_sub(1);
    return nullptr;
  }
  return std::make_unique<StateStream>(state, streams, streamsFinal);
}

PreviewServer::PreviewServer(PreviewState& state, const std::string& address, int port)
    : impl_(std::make_unique<Impl>(state, address)) {
  int family = AF_INET;
  if (!isIpLiteral(address, family))
    throw PreviewError(fmt::format(
        "cannot serve the preview on '{}': not an IP address (such as 127.0.0.1, 0.0.0.0 or ::1)",
        address));
  if (port < 0 || port > 65535)
    throw PreviewError(fmt::format("the preview port must be from 0 to 65535, got {}", port));
  const preview_http::StartFunction start = loadServerModule();
  preview_http::Settings settings;
  settings.address = address;
  settings.port = port;
  settings.page = std::string_view(kPreviewPage, sizeof kPreviewPage - 1);
  settings.contentSecurityPolicy = kContentSecurityPolicy;
  settings.threads = kServerThreads;
  settings.hostAllowed = [loopback = isLoopback(address)](std::string_view host) {
    return !loopback || isLoopbackHost(host);
  };
  settings.openStream = [impl = impl_.get()]() { return impl->openStream(); };
  impl_->server.reset(start(settings));
  if (!impl_->server)
    throw PreviewError(fmt::format("cannot serve the preview on {}:{}: {}", address, port,
                                   bindFailure(address, family, port)));
  impl_->port = impl_->server->port();
}

PreviewServer::~PreviewServer() { stop(); }

int PreviewServer::port() const { return impl_->port; }

std::string PreviewServer::url() const {
  const bool v6 = impl_->address.find(':') != std::string::npos;
  return v6 ? fmt::format("http://[{}]:{}/", impl_->address, impl_->port)
            : fmt::format("http://{}:{}/", impl_->address, impl_->port);
}

void PreviewServer::drain(std::chrono::milliseconds limit) {
  const auto deadline = Clock::now() + limit;
  while (impl_->streamsFinal.load() < impl_->streams.load() && Clock::now() < deadline)
    std::this_thread::sleep_for(5ms);
}

void PreviewServer::stop() {
  if (impl_->stopped) return;
  impl_->stopped = true;
  impl_->state.close();
  impl_->server->stop();
}

bool PreviewServer::isLoopback(const std::string& address) {
  in_addr v4{};
  if (inet_pton(AF_INET, address.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  in6_addr v6{};
  return inet_pton(AF_INET6, address.c_str(), &v6) == 1 && IN6_IS_ADDR_LOOPBACK(&v6);
}

}  // namespace glint

#include "glint/preview/preview_server.h"

#include <arpa/inet.h>
#include <fmt/format.h>
#include <httplib.h>
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
#include <thread>

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
// A comment line keeps idle streams open through proxies and finds closed ones.
constexpr auto kKeepAliveInterval = 5s;
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

void plainText(httplib::Response& res, int status, const std::string& text) {
  res.status = status;
  res.set_content(text + "\n", "text/plain; charset=utf-8");
}

}  // namespace

struct PreviewServer::Impl {
  Impl(PreviewState& previewState, std::string boundAddress)
      : state(previewState), address(std::move(boundAddress)) {}

  PreviewState& state;
  std::string address;
  int port = 0;
  httplib::Server server;
  std::thread listener;
  std::atomic<int> streams{0};
  std::atomic<bool> listenerDone{false};
  bool stopped = false;

  void route(bool loopback);
  void stream(httplib::Response& res);
};

void PreviewServer::Impl::route(bool loopback) {
  server.set_pre_routing_handler([loopback](const httplib::Request& req, httplib::Response& res) {
    if (req.method != "GET") {
      res.set_header("Allow", "GET");
      plainText(res, 405, "method not allowed: the glint preview answers GET only");
      return httplib::Server::HandlerResponse::Handled;
    }
    if (loopback && !isLoopbackHost(req.get_header_value("Host"))) {
      plainText(res, 403, "forbidden: this preview answers only to localhost addresses");
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  server.set_post_routing_handler([](const httplib::Request&, httplib::Response& res) {
    res.set_header("X-Content-Type-Options", "nosniff");
    res.set_header("Referrer-Policy", "no-referrer");
    res.set_header("Cache-Control", "no-store");
  });
  server.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
    if (res.status == 404)
      plainText(res, 404, fmt::format("not found: {} (the glint preview is at /)", req.path));
  });
  server.Get("/", [](const httplib::Request&, httplib::Response& res) {
    res.set_header("Content-Security-Policy", kContentSecurityPolicy);
    res.set_content(kPreviewPage, "text/html; charset=utf-8");
  });
  server.Get("/events", [this](const httplib::Request&, httplib::Response& res) { stream(res); });
}

void PreviewServer::Impl::stream(httplib::Response& res) {
  if (streams.fetch_add(1) >= kMaxStreams) {
    streams.fetch_sub(1);
    plainText(res, 503, "too many open preview pages; close one");
    return;
  }
  struct Cursor {
    std::uint64_t version = 0;
    std::string lastStatus;
    Clock::time_point statusSent{};
    Clock::time_point lastWrite = Clock::now();
    bool started = false;
  };
  res.set_chunked_content_provider(
      "text/event-stream",
      [this, cursor = Cursor{}](std::size_t, httplib::DataSink& sink) mutable {
        if (state.isClosed()) return false;
        const PreviewChanges changes = state.waitForChanges(cursor.version, kStreamWait);
        const auto now = Clock::now();
        const auto write = [&](const std::string& text) {
          cursor.lastWrite = now;
          return sink.write(text.data(), text.size());
        };
        if (!cursor.started) {
          cursor.started = true;
          if (!write("retry: 1000\n\n")) return false;
        }
        // Pixels before the status: a page that reads "finished" already has the whole image.
        const std::span<const PreviewTile> tiles(changes.tiles);
        for (std::size_t i = 0; i < tiles.size(); i += kTilesPerEvent)
          if (!write(tilesEvent(tiles.subspan(i, std::min(kTilesPerEvent, tiles.size() - i)),
                                changes.status.width, changes.status.height)))
            return false;
        cursor.version = changes.version;
        std::string status = statusEvent(changes.status);
        const bool due = changes.status.phase != PreviewPhase::Rendering ||
                         now - cursor.statusSent >= kStatusInterval;
        if (status != cursor.lastStatus && due) {
          if (!write(status)) return false;
          cursor.lastStatus = std::move(status);
          cursor.statusSent = now;
        }
        if (now - cursor.lastWrite >= kKeepAliveInterval && !write(": keep-alive\n\n"))
          return false;
        return true;
      },
      [this](bool) { streams.fetch_sub(1); });
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
  httplib::Server& server = impl_->server;
  // cpp-httplib's default sets SO_REUSEPORT, which would let a second glint listen on the same
  // port; SO_REUSEADDR only allows a quick restart after a previous one ended.
  server.set_socket_options([](int sock) {
    const int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  server.new_task_queue = []() { return new httplib::ThreadPool(kServerThreads); };
  server.set_keep_alive_max_count(20);
  server.set_keep_alive_timeout(1);
  server.set_read_timeout(5, 0);
  server.set_write_timeout(5, 0);
  server.set_payload_max_length(64 * 1024);
  impl_->route(isLoopback(address));

  const int bound = port == 0 ? server.bind_to_any_port(address)
                              : (server.bind_to_port(address, port) ? port : -1);
  if (bound < 0)
    throw PreviewError(fmt::format("cannot serve the preview on {}:{}: {}", address, port,
                                   bindFailure(address, family, port)));
  impl_->port = bound;
  impl_->listener = std::thread([this]() {
    impl_->server.listen_after_bind();
    impl_->listenerDone = true;
  });
}

PreviewServer::~PreviewServer() { stop(); }

int PreviewServer::port() const { return impl_->port; }

std::string PreviewServer::url() const {
  const bool v6 = impl_->address.find(':') != std::string::npos;
  return v6 ? fmt::format("http://[{}]:{}/", impl_->address, impl_->port)
            : fmt::format("http://{}:{}/", impl_->address, impl_->port);
}

void PreviewServer::stop() {
  if (impl_->stopped) return;
  impl_->stopped = true;
  impl_->state.close();
  // stop() does nothing until the listener thread has started listening.
  while (!impl_->server.is_running() && !impl_->listenerDone) std::this_thread::sleep_for(1ms);
  impl_->server.stop();
  impl_->listener.join();
}

bool PreviewServer::isLoopback(const std::string& address) {
  in_addr v4{};
  if (inet_pton(AF_INET, address.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  in6_addr v6{};
  return inet_pton(AF_INET6, address.c_str(), &v6) == 1 && IN6_IS_ADDR_LOOPBACK(&v6);
}

}  // namespace glint

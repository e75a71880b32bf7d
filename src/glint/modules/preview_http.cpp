// glint-preview-http.so: the preview server's HTTP side (preview/preview_http_module.h) on
// cpp-httplib — routing, headers, the thread pool and the event streams' chunked responses. What
// the page shows comes from PreviewServer, in the library, through the Settings' functions.
#include <fmt/format.h>
#include <httplib.h>
#include <sys/socket.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "glint/preview/preview_http_module.h"

namespace glint::preview_http {
namespace {

void plainText(httplib::Response& res, int status, const std::string& text) {
  res.status = status;
  res.set_content(text + "\n", "text/plain; charset=utf-8");
}

class HttpServer final : public Server {
 public:
  explicit HttpServer(const Settings& settings) : settings_(settings) {}
  ~HttpServer() override { stop(); }

  // Binds and starts listening; false when binding failed.
  bool start();
  int port() const override { return port_; }
  void stop() override;

 private:
  void route();

  Settings settings_;
  httplib::Server server_;
  std::thread listener_;
  std::atomic<bool> listenerDone_{false};
  int port_ = 0;
  bool stopped_ = false;
};

void HttpServer::route() {
  server_.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    if (req.method != "GET") {
      res.set_header("Allow", "GET");
      plainText(res, 405, "method not allowed: the glint preview answers GET only");
      return httplib::Server::HandlerResponse::Handled;
    }
    if (!settings_.hostAllowed(req.get_header_value("Host"))) {
      plainText(res, 403, "forbidden: this preview answers only to localhost addresses");
      return httplib::Server::HandlerResponse::Handled;
    }
    // The page and the stream are sent whole. cpp-httplib 0.11 serves any number of ranges of a
    // body, each with its own part headers: 4000 ranges in an 8 KB header made a 31 MB answer of
    // the page. No body here, so there is nothing for ranges to multiply.
    if (req.has_header("Range")) {
      res.status = 416;
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  server_.set_post_routing_handler([](const httplib::Request&, httplib::Response& res) {
    res.set_header("X-Content-Type-Options", "nosniff");
    res.set_header("Referrer-Policy", "no-referrer");
    res.set_header("Cache-Control", "no-store");
  });
  server_.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
    if (res.status == 404)
      plainText(res, 404, fmt::format("not found: {} (the glint preview is at /)", req.path));
  });
  server_.Get("/", [this](const httplib::Request&, httplib::Response& res) {
    res.set_header("Content-Security-Policy", std::string(settings_.contentSecurityPolicy));
    res.set_content(settings_.page.data(), settings_.page.size(), "text/html; charset=utf-8");
  });
  server_.Get("/events", [this](const httplib::Request&, httplib::Response& res) {
    std::shared_ptr<EventStream> stream = settings_.openStream();
    if (!stream) {
      plainText(res, 503, "too many open preview pages; close one");
      return;
    }
    // The stream (and with it the count of open ones) ends with this response, when the
    // connection's request is done.
    res.set_chunked_content_provider(
        "text/event-stream", [stream](std::size_t, httplib::DataSink& sink) {
          return stream->writeNext(
              [&sink](std::string_view text) { return sink.write(text.data(), text.size()); });
        });
  });
}

bool HttpServer::start() {
  // cpp-httplib's default sets SO_REUSEPORT, which would let a second glint listen on the same
  // port; SO_REUSEADDR only allows a quick restart after a previous one ended.
  server_.set_socket_options([](int sock) {
    const int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  const std::size_t threads = settings_.threads;
  server_.new_task_queue = [threads]() { return new httplib::ThreadPool(threads); };
  server_.set_keep_alive_max_count(20);
  server_.set_keep_alive_timeout(1);
  server_.set_read_timeout(5, 0);
  server_.set_write_timeout(5, 0);
  server_.set_payload_max_length(64 * 1024);
  route();
  const int bound =
      settings_.port == 0
          ? server_.bind_to_any_port(settings_.address)
          : (server_.bind_to_port(settings_.address, settings_.port) ? settings_.port : -1);
  if (bound < 0) {
    stopped_ = true;
    return false;
  }
  port_ = bound;
  listener_ = std::thread([this]() {
    server_.listen_after_bind();
    listenerDone_ = true;
  });
  return true;
}

void HttpServer::stop() {
  if (stopped_) return;
  stopped_ = true;
  using namespace std::chrono_literals;
  // stop() does nothing until the listener thread has started listening.
  while (!server_.is_running() && !listenerDone_) std::this_thread::sleep_for(1ms);
  server_.stop();
  listener_.join();
}

}  // namespace
}  // namespace glint::preview_http

GLINT_DEFINE_MODULE_IDENTITY(glint::preview_http::kModuleIdentity)

extern "C" {

[[gnu::visibility("default")]] glint::preview_http::Server* glint_preview_http_start(
    const glint::preview_http::Settings& settings) {
  auto server = std::make_unique<glint::preview_http::HttpServer>(settings);
  return server->start() ? server.release() : nullptr;
}

}  // extern "C"

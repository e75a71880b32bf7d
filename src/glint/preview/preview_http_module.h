// The preview's HTTP side as a module loaded only when a preview is asked for
// (glint-preview-http.so, src/glint/modules/preview_http.cpp): cpp-httplib, and OpenSSL through
// it, cost ~8 ms of dynamic linking and initialisation at every start of a program linked with
// them. The interface between PreviewServer and the module; both come from one build (checked by
// GLINT_MODULE_IDENTITY), so C++ types may cross it.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "glint/core/helper_files.h"

namespace glint::preview_http {

inline constexpr const char* kModuleFile = "glint-preview-http.so";
inline constexpr const char* kModuleIdentity = GLINT_MODULE_IDENTITY("preview-http", 1);
inline constexpr const char* kStartFunction = "glint_preview_http_start";

// One open event stream (GET /events): a server thread calls writeNext again and again; each call
// writes what changed through `write` (which returns false once the page went away) and returns
// whether the stream goes on. Destroyed once the connection ends.
class EventStream {
 public:
  using Write = std::function<bool(std::string_view)>;
  virtual ~EventStream() = default;
  virtual bool writeNext(const Write& write) = 0;
};

struct Settings {
  std::string address;                     // an IPv4 or IPv6 literal
  int port = 0;                            // 0: any free port
  std::string_view page;                   // GET /: the preview page's HTML
  std::string_view contentSecurityPolicy;  // sent with the page
  std::size_t threads = 8;                 // connection threads
  // Whether a request's Host header may be answered (DNS rebinding, preview_server.cpp).
  std::function<bool(std::string_view host)> hostAllowed;
  // GET /events: a new stream, or nullptr when too many are open (answered 503).
  std::function<std::unique_ptr<EventStream>()> openStream;
};

class Server {
 public:
  virtual ~Server() = default;
  virtual int port() const = 0;  // the bound port
  // Closes the listening socket and waits for the server's threads (streams end at their next
  // writeNext that returns false).
  virtual void stop() = 0;
};

// The module's entry point: the server bound and listening, or nullptr when binding failed (the
// caller finds out why).
using StartFunction = Server* (*)(const Settings& settings);

}  // namespace glint::preview_http

// PreviewServer: the preview page over HTTP on one address and port, on its own threads — GET /
// (preview_page.html) and GET /events (server-sent events from a PreviewState). Every other path
// is 404 and every method but GET is 405.
#pragma once

#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>

#include "glint/preview/preview_state.h"

namespace glint {

inline constexpr int kDefaultPreviewPort = 8642;

// The server cannot start (the address is no IP address of this machine, the port is in use);
// worded for the user.
class PreviewError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class PreviewServer {
 public:
  // Binds `address` (an IPv4 or IPv6 literal) and `port` (0: any free port) and starts serving
  // `state`, which must outlive the server. Throws PreviewError.
  PreviewServer(PreviewState& state, const std::string& address, int port);
  ~PreviewServer();  // stop()
  PreviewServer(const PreviewServer&) = delete;
  PreviewServer& operator=(const PreviewServer&) = delete;

  int port() const;         // the bound port (the chosen one when asked for 0)
  std::string url() const;  // "http://127.0.0.1:8642/", "http://[::1]:8642/"
  // Waits (at most `limit`) until every open page has been sent the render's outcome (the state's
  // ended() has been called): a stop right after ended() closed streams before they sent it.
  void drain(std::chrono::milliseconds limit);
  // Closes the state's streams and the listening socket and waits for the server's threads.
  void stop();

  // Whether only this machine can reach `address` (127.0.0.0/8, ::1).
  static bool isLoopback(const std::string& address);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace glint

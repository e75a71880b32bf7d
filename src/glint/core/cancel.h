// Cancellation of long work (parsing, mesh loading, BVH building, writing): a flag the caller sets
// (the CLI from SIGINT/SIGTERM/SIGHUP) and the worker polls, and the exception that unwinds the
// load or build when it is seen. Rendering itself stops without an exception (RenderStats).
#pragma once

#include <atomic>
#include <exception>

namespace glint {

// Thrown by a load or build step that saw its cancel flag set; carries nothing: the caller knows
// which signal set the flag.
class Cancelled : public std::exception {
 public:
  const char* what() const noexcept override { return "cancelled"; }
};

// A cancel flag that may be absent (nullptr: never cancelled).
inline bool isCancelled(const std::atomic<bool>* cancel) {
  return cancel != nullptr && cancel->load(std::memory_order_relaxed);
}

inline void throwIfCancelled(const std::atomic<bool>* cancel) {
  if (isCancelled(cancel)) throw Cancelled();
}

}  // namespace glint

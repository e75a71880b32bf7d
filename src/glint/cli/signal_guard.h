// SIGINT/SIGTERM/SIGHUP handling for a render: the first signal asks the render job to stop (a flag
// it polls); a second one ends the process at once, unless a file is being committed.
#pragma once

#include <atomic>

namespace glint::cli {

// Installs the handlers (sigaction) for its lifetime and restores the previous ones afterwards,
// unless a stop signal came (the handlers then stay until the process exits).
// SIGHUP (the terminal or the ssh session closed) stops a render like SIGTERM; SIGPIPE is ignored
// meanwhile, so that a vanished reader of stderr fails the progress writes instead of killing the
// process before the checkpoint is saved; so is SIGXFSZ, so that an image past the file-size limit
// (ulimit -f) fails its write (EFBIG: exit 1, the temporary file removed) instead of killing the
// process with the temporary file left behind. Only one may exist at a time: the handlers share
// process-wide state.
class SignalGuard {
 public:
  SignalGuard();
  ~SignalGuard();
  SignalGuard(const SignalGuard&) = delete;
  SignalGuard& operator=(const SignalGuard&) = delete;

  // Set by the first SIGINT/SIGTERM/SIGHUP; give it to RenderJobSpec::cancel.
  const std::atomic<bool>& cancelFlag() const;
  // The first signal received, or 0; give it to RenderJobSpec::cancelSignal.
  const std::atomic<int>& signalNumber() const;
  int receivedSignal() const { return signalNumber().load(); }
  // The exit status for a run stopped by `signal`: 128 + signal (130 for SIGINT, 143 for SIGTERM,
  // 129 for SIGHUP).
  static int exitCodeFor(int signal) { return 128 + signal; }

  // While committing (writing a checkpoint or the finished image: temporary file, then rename), a
  // second signal no longer ends the process, so no temporary file can be left behind.
  void setCommitting(bool committing);
};

}  // namespace glint::cli

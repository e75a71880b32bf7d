#include "glint/cli/signal_guard.h"

#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <array>

namespace glint::cli {
namespace {

// Process-wide state touched from the signal handler: lock-free atomics only (async-signal-safe).
std::atomic<bool> gCancel{false};
std::atomic<int> gSignal{0};
std::atomic<bool> gCommitting{false};
std::atomic<bool> gReported{false};  // the guard is gone after a stop: the interrupt is reported
std::atomic<long long> gFirstAt{0};  // CLOCK_MONOTONIC nanoseconds of the first stop signal
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free &&
              std::atomic<long long>::is_always_lock_free);

// A repeat of the first signal within this time is the same request, not a second one: GNU
// timeout sends its signal to the command and then to the whole process group, so the command
// gets it twice within microseconds (and an ended render's checkpoint must still be saved).
constexpr long long kSameRequestNanoseconds = 250'000'000;

long long monotonicNanoseconds() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);  // async-signal-safe
  return static_cast<long long>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

constexpr std::array<int, 3> kHandledSignals{SIGINT, SIGTERM, SIGHUP};
std::array<struct sigaction, kHandledSignals.size()> gPrevious{};
// Ignored while the guard lives: SIGPIPE and SIGXFSZ (their writes fail instead).
constexpr std::array<int, 2> kIgnoredSignals{SIGPIPE, SIGXFSZ};
std::array<struct sigaction, kIgnoredSignals.size()> gPreviousIgnored{};

extern "C" void onStopSignal(int signal) {
  // The time is read first: the repeat may run on another thread between the first's exchange and
  // its store, and then sees 0 — also "just now".
  const long long now = monotonicNanoseconds();
  int expected = 0;
  if (gSignal.compare_exchange_strong(expected, signal)) {
    gFirstAt.store(now);
    gCancel.store(true);
    return;
  }
  if (signal == expected) {
    const long long first = gFirstAt.load();
    if (first == 0 || now - first < kSameRequestNanoseconds) return;
  }
  // A second signal: the user insists. Only write(2) and _exit(2) here (async-signal-safe).
  if (gCommitting.load()) return;
  if (!gReported.load()) {
    static constexpr char kMessage[] = "\nglint: interrupted\n";
    [[maybe_unused]] const ssize_t written = write(STDERR_FILENO, kMessage, sizeof kMessage - 1);
  }
  _exit(SignalGuard::exitCodeFor(expected));
}

}  // namespace

SignalGuard::SignalGuard() {
  gCancel.store(false);
  gSignal.store(0);
  gFirstAt.store(0);
  gCommitting.store(false);
  gReported.store(false);
  struct sigaction action {};
  action.sa_handler = onStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;  // file I/O of other threads carries on; the flag is polled
  for (std::size_t i = 0; i < kHandledSignals.size(); ++i) {
    sigaction(kHandledSignals[i], &action, &gPrevious[i]);
  }
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  for (std::size_t i = 0; i < kIgnoredSignals.size(); ++i) {
    sigaction(kIgnoredSignals[i], &ignore, &gPreviousIgnored[i]);
  }
}

SignalGuard::~SignalGuard() {
  // After a stop signal the process is on its way out with 128 + n: a second signal that arrives
  // now (the user pressing Ctrl-C twice) must still end it with that status, not kill it by the
  // default action, so the handlers stay.
  if (gSignal.load() != 0) {
    gReported.store(true);
    return;
  }
  for (std::size_t i = 0; i < kHandledSignals.size(); ++i) {
    sigaction(kHandledSignals[i], &gPrevious[i], nullptr);
  }
  for (std::size_t i = 0; i < kIgnoredSignals.size(); ++i) {
    sigaction(kIgnoredSignals[i], &gPreviousIgnored[i], nullptr);
  }
}

const std::atomic<bool>& SignalGuard::cancelFlag() const { return gCancel; }

const std::atomic<int>& SignalGuard::signalNumber() const { return gSignal; }

void SignalGuard::setCommitting(bool committing) { gCommitting.store(committing); }

}  // namespace glint::cli

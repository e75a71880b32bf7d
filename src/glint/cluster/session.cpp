#include "glint/cluster/session.h"

#include <charconv>
#include <cstdlib>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "glint/cluster/mpi_transport.h"

namespace glint::cluster {
namespace {

// GLINT_MPI_TIMEOUT: seconds (a decimal number > 0) a rank may stay silent.
LinkTiming timingFromEnvironment() {
  LinkTiming timing;
  if (const char* text = std::getenv("GLINT_MPI_TIMEOUT")) {
    const std::string_view value(text);
    double seconds = 0;
    const auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), seconds);
    if (error != std::errc{} || end != value.data() + value.size() || !(seconds > 0) ||
        seconds > 1e6)
      throw std::invalid_argument("GLINT_MPI_TIMEOUT must be a number of seconds > 0, got '" +
                                  std::string(value) + "'");
    timing.timeout = std::chrono::milliseconds(static_cast<long long>(seconds * 1000));
    // Several heartbeats fit in any timeout, so one late heartbeat is no alarm.
    if (timing.heartbeat * 4 > timing.timeout) timing.heartbeat = timing.timeout / 4;
  }
  return timing;
}

}  // namespace

Session::Session() : mpi_(mpiTransport()), timing_(timingFromEnvironment()) {
  // MPI_THREAD_SERIALIZED: only the link's thread calls MPI while it runs.
  if (!mpi_.start())
    throw std::runtime_error("this MPI library does not allow MPI calls from a second thread");
  rank_ = mpi_.rank();
  size_ = mpi_.size();
  host_ = mpi_.host();
  std::vector<int> watched;
  if (rank_ == 0) {
    for (int peer = 1; peer < size_; ++peer) watched.push_back(peer);
  } else {
    watched.push_back(0);
  }
  link_ = std::make_unique<Link>(mpi_, std::move(watched), timing_);
}

Session::~Session() {
  if (!finished_) finish(0, false);
}

int Session::finish(int status, bool orderly) {
  if (finished_) return status;
  finished_ = true;
  link_->stop();
  if (orderly) mpi_.finalize();
  return status;
}

}  // namespace glint::cluster

#include "glint/cluster/session.h"

#include <mpi.h>

#include <charconv>
#include <cstdlib>
#include <stdexcept>
#include <string_view>
#include <vector>

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
      throw std::runtime_error("GLINT_MPI_TIMEOUT must be a number of seconds > 0, got '" +
                               std::string(value) + "'");
    timing.timeout = std::chrono::milliseconds(static_cast<long long>(seconds * 1000));
    // Several heartbeats fit in any timeout, so one late heartbeat is no alarm.
    if (timing.heartbeat * 4 > timing.timeout) timing.heartbeat = timing.timeout / 4;
  }
  return timing;
}

}  // namespace

Session::Session() : timing_(timingFromEnvironment()) {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
  if (provided < MPI_THREAD_SERIALIZED) {
    MPI_Finalize();
    throw std::runtime_error("this MPI library does not allow MPI calls from a second thread");
  }
  // A failed send to a rank that died is the link's to report (Tag::Silent), not a reason for
  // MPI to abort this process before rank 0 has saved its checkpoint.
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  char name[MPI_MAX_PROCESSOR_NAME] = {};
  int length = 0;
  MPI_Get_processor_name(name, &length);
  host_.assign(name, static_cast<std::size_t>(length));
  std::vector<int> watched;
  if (rank_ == 0) {
    for (int peer = 1; peer < size_; ++peer) watched.push_back(peer);
  } else {
    watched.push_back(0);
  }
  link_ = std::make_unique<Link>(std::move(watched), timing_);
}

Session::~Session() {
  if (!finished_) finish(0, false);
}

int Session::finish(int status, bool orderly) {
  if (finished_) return status;
  finished_ = true;
  link_->stop();
  if (orderly) MPI_Finalize();
  return status;
}

}  // namespace glint::cluster

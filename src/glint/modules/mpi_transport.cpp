// glint-mpi.so: cluster/mpi_transport.h on the MPI library's C API. The only file of glint that
// includes mpi.h.
#include <mpi.h>

#include <cstring>
#include <string>
#include <type_traits>

#include "glint/cluster/mpi_transport.h"

namespace glint::cluster {
namespace {

// MPI's handles travel as their bytes in a 64-bit word.
template <typename Handle>
std::uint64_t wordOf(Handle handle) {
  static_assert(sizeof(Handle) <= sizeof(std::uint64_t) && std::is_trivially_copyable_v<Handle>);
  std::uint64_t word = 0;
  std::memcpy(&word, &handle, sizeof handle);
  return word;
}

template <typename Handle>
Handle handleOf(std::uint64_t word) {
  Handle handle;
  std::memcpy(&handle, &word, sizeof handle);
  return handle;
}

void store(MPI_Request request, MpiRequest& out) {
  out.active = request != MPI_REQUEST_NULL;
  out.handle = out.active ? wordOf(request) : 0;
}

class MpiLibrary final : public MpiTransport {
 public:
  bool start() override {
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
    if (provided < MPI_THREAD_SERIALIZED) {
      MPI_Finalize();
      return false;
    }
    // A failed send to a rank that died is the link's to report, not a reason for MPI to abort
    // this process before rank 0 has saved its checkpoint.
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    return true;
  }

  int rank() const override { return rank_; }
  int size() const override { return size_; }

  std::string host() const override {
    char name[MPI_MAX_PROCESSOR_NAME] = {};
    int length = 0;
    MPI_Get_processor_name(name, &length);
    return std::string(name, static_cast<std::size_t>(length));
  }

  bool send(const void* data, int bytes, int peer, int tag, MpiRequest& request) override {
    MPI_Request handle = MPI_REQUEST_NULL;
    const bool sent =
        MPI_Isend(data, bytes, MPI_BYTE, peer, tag, MPI_COMM_WORLD, &handle) == MPI_SUCCESS;
    store(sent ? handle : MPI_REQUEST_NULL, request);
    return sent;
  }

  MpiTest test(MpiRequest& request) override {
    if (!request.active) return MpiTest::Done;
    MPI_Request handle = handleOf<MPI_Request>(request.handle);
    int done = 0;
    const bool failed = MPI_Test(&handle, &done, MPI_STATUS_IGNORE) != MPI_SUCCESS;
    store(handle, request);  // MPI_REQUEST_NULL once complete, and when MPI freed a failed one
    if (failed) return MpiTest::Failed;
    return done ? MpiTest::Done : MpiTest::Pending;
  }

  void release(MpiRequest& request) override {
    if (!request.active) return;
    MPI_Request handle = handleOf<MPI_Request>(request.handle);
    MPI_Request_free(&handle);
    store(MPI_REQUEST_NULL, request);
  }

  bool probe(MpiArrival& arrival) override {
    int flag = 0;
    MPI_Message message = MPI_MESSAGE_NULL;
    MPI_Status status;
    if (MPI_Improbe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &message, &status) !=
            MPI_SUCCESS ||
        !flag)
      return false;
    int count = 0;
    MPI_Get_count(&status, MPI_BYTE, &count);
    arrival = MpiArrival{status.MPI_SOURCE, status.MPI_TAG, count, wordOf(message)};
    return true;
  }

  bool receive(void* data, const MpiArrival& arrival, MpiRequest& request) override {
    MPI_Message message = handleOf<MPI_Message>(arrival.message);
    MPI_Request handle = MPI_REQUEST_NULL;
    const bool started =
        MPI_Imrecv(data, arrival.bytes, MPI_BYTE, &message, &handle) == MPI_SUCCESS;
    store(started ? handle : MPI_REQUEST_NULL, request);
    return started;
  }

  void finalize() override { MPI_Finalize(); }

 private:
  int rank_ = 0;
  int size_ = 1;
};

}  // namespace
}  // namespace glint::cluster

GLINT_DEFINE_MODULE_IDENTITY(glint::cluster::kMpiModuleIdentity)

extern "C" {

[[gnu::visibility("default")]] glint::cluster::MpiTransport* glint_mpi_transport() {
  static glint::cluster::MpiLibrary library;
  return &library;
}

}  // extern "C"

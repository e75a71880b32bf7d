// The few MPI calls a rank makes (Session, Link), behind an interface whose implementation is a
// module loaded only when an MPI launcher started glint (glint-mpi.so,
// src/glint/modules/mpi_transport.cpp): linking OpenMPI (libmpi and the runtime libraries it
// brings) costs ~3 ms at every start of a plain render. Both sides come from one build (checked
// by GLINT_MODULE_IDENTITY), so C++ types may cross; MPI's own types stay inside the module.
#pragma once

#include <cstdint>
#include <string>

#include "glint/core/helper_files.h"

namespace glint::cluster {

inline constexpr const char* kMpiModuleFile = "glint-mpi.so";
inline constexpr const char* kMpiModuleIdentity = GLINT_MODULE_IDENTITY("mpi", 1);
inline constexpr const char* kMpiTransportFunction = "glint_mpi_transport";

// A nonblocking operation's MPI_Request, opaque here (a pointer in OpenMPI, an int in MPICH).
struct MpiRequest {
  std::uint64_t handle = 0;  // the MPI_Request's bytes
  bool active = false;       // false: MPI_REQUEST_NULL (never started, completed or freed)
};

// A message that arrived and was matched (MPI_Improbe), not yet received.
struct MpiArrival {
  int source = 0;
  int tag = 0;
  int bytes = 0;
  std::uint64_t message = 0;  // the MPI_Message's bytes
};

enum class MpiTest { Pending, Done, Failed };

// Every call is MPI's on MPI_COMM_WORLD, with errors returned (MPI_ERRORS_RETURN), not fatal.
class MpiTransport {
 public:
  virtual ~MpiTransport() = default;
  // MPI_Init_thread asking for MPI_THREAD_SERIALIZED; false (and MPI finalized) when the library
  // does not give that level.
  virtual bool start() = 0;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  virtual std::string host() const = 0;  // MPI_Get_processor_name
  // MPI_Isend of `bytes` bytes to `peer` with `tag`; false when MPI refused it.
  virtual bool send(const void* data, int bytes, int peer, int tag, MpiRequest& request) = 0;
  // MPI_Test: Done and Failed leave the request inactive (MPI frees a failed one).
  virtual MpiTest test(MpiRequest& request) = 0;
  virtual void release(MpiRequest& request) = 0;  // MPI_Request_free
  // MPI_Improbe from any source with any tag: true when a message was matched.
  virtual bool probe(MpiArrival& arrival) = 0;
  // MPI_Imrecv of the matched message into `data` (arrival.bytes bytes); false when refused.
  virtual bool receive(void* data, const MpiArrival& arrival, MpiRequest& request) = 0;
  virtual void finalize() = 0;  // MPI_Finalize
};

// The module's entry point: its one transport.
using MpiTransportFunction = MpiTransport* (*)();

// The transport of this process, the module loaded on the first call. Throws std::runtime_error
// when the module cannot be found or loaded.
MpiTransport& mpiTransport();

}  // namespace glint::cluster

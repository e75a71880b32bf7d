// MPI for one glint process that an MPI launcher started: initialisation, this rank's place, the
// link that carries its messages, and the ending (MPI_Finalize only when every rank can reach it).
#pragma once

#include <memory>
#include <string>

#include "glint/cluster/link.h"
#include "glint/cluster/mpi_transport.h"

namespace glint::cluster {

class Session {
 public:
  // Loads the MPI module (mpi_transport.h), MPI_Init_thread asking for MPI_THREAD_SERIALIZED (only
  // the link's thread calls MPI meanwhile), then the link: rank 0 watches every other rank, the
  // others watch rank 0. The timeout is GLINT_MPI_TIMEOUT seconds when set (docs/distributed.md).
  // Throws std::runtime_error when MPI cannot give that thread level or the module cannot be
  // loaded.
  Session();
  // Without finish(): as finish(status, false).
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  const std::string& host() const { return host_; }
  Link& link() { return *link_; }
  const LinkTiming& timing() const { return timing_; }

  // Stops the link; with `orderly` (every other rank is alive and finishing too) MPI_Finalize,
  // which waits for all of them. Without, nothing more: a rank that is gone would never reach
  // MPI_Finalize, and the launcher ends the others once this one exits with a non-zero status.
  // Returns `status`.
  int finish(int status, bool orderly);

 private:
  MpiTransport& mpi_;
  int rank_ = 0;
  int size_ = 1;
  std::string host_;
  LinkTiming timing_;
  std::unique_ptr<Link> link_;
  bool finished_ = false;
};

}  // namespace glint::cluster

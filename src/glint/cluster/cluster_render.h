// `glint render` under an MPI launcher (docs/distributed.md): one object per process that joins
// the job's ranks; rank 0 runs the RenderJob with its render step spread over every rank, the
// others serve it.
#pragma once

#include <memory>

#include "glint/cluster/coordinator.h"
#include "glint/cluster/session.h"
#include "glint/job/render_job.h"

namespace glint::cluster {

class ClusterRender {
 public:
  // Starts MPI (Session). Throws std::invalid_argument for a bad GLINT_MPI_TIMEOUT,
  // std::runtime_error when it cannot start.
  ClusterRender();

  bool coordinates() const { return session_.rank() == 0; }
  int ranks() const { return session_.size(); }

  // Not rank 0: renders what rank 0 hands out (worker.h), ends MPI, returns the exit status.
  int serve(const RenderJobSpec& spec);
  // Rank 0: sets spec.renderStep to spread the render over the ranks.
  void distribute(RenderJobSpec& spec);
  // Rank 0, after the job: releases the other ranks, ends MPI and returns `status`.
  int finish(int status);

  // Rank 0: each rank's share, once the render ran.
  const ClusterFigures& figures() const;

 private:
  Session session_;
  std::unique_ptr<Coordinator> coordinator_;
  ClusterFigures none_;
};

}  // namespace glint::cluster

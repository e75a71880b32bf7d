// A rank other than 0 in an MPI render: loads the scene itself, introduces itself to rank 0
// (RankIdentity), renders the tiles rank 0 hands it and sends them back until rank 0 is done.
#pragma once

#include "glint/cluster/session.h"
#include "glint/job/render_job.h"

namespace glint::cluster {

// Serves rank 0 with the render `spec` describes (its output, checkpoint and resume are rank 0's
// business and ignored here). Prints nothing but a lost rank 0: rank 0 reports for every rank.
// Ends the session and returns the exit status: 0 when rank 0 finished the job or ended it in
// order (rank 0's status is the job's), its order's status otherwise, 128 + signal when stopped by
// one, 1 when rank 0 is lost or this rank's render failed.
int serveTiles(Session& session, const RenderJobSpec& spec);

}  // namespace glint::cluster

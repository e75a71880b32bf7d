// The --stats lines of a render across MPI ranks: each rank's tiles, rays and busy/idle time, and
// rank 0's coordination cost.
#pragma once

#include <string>

#include "glint/cluster/coordinator.h"

namespace glint::cli {

std::string clusterStatsText(const cluster::ClusterFigures& figures);

}  // namespace glint::cli

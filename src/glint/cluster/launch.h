// How glint learns that an MPI launcher started it (mpirun, srun), and the per-rank defaults that
// follow from it; read from the environment, without MPI.
#pragma once

#include <optional>

namespace glint::cluster {

// Whether this process was started by an MPI launcher: OpenMPI's mpirun (OMPI_COMM_WORLD_SIZE),
// a PMIx server such as srun --mpi=pmix (PMIX_RANK), or a PMI-1/2 launcher such as srun
// --mpi=pmi2 or MPICH's hydra (PMI_RANK with PMI_SIZE). Only then does glint start MPI: a plain
// run neither needs nor touches it.
bool launchedByMpi();

// The ranks this launcher started on this host (OMPI_COMM_WORLD_LOCAL_SIZE, SLURM_NTASKS_PER_NODE
// or MPI_LOCALNRANKS), when it says.
std::optional<int> ranksOnThisHost();

// Render threads for a rank when --threads is not given: the cores it may run on; when the launcher
// did not bind it (it may run on every core of the host), those cores shared among the ranks on
// this host, so that N ranks on one machine do not run N × cores threads.
int defaultThreadsPerRank();

}  // namespace glint::cluster

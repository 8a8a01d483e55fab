// codyna sweep under mpirun (docs/parameter-studies.md, "MPI"). MPI stays out of the core: each
// rank runs its slice of the study (the shard machinery, i % size == rank) into a journal in
// memory (SweepRequest::journal_in_memory), rank 0 gathers the journals and joins them through
// study_sweep_merge_journals, the path of codyna sweep-merge, so that the one result file is the
// single-process run's, bit for bit.
#pragma once

#include <functional>

#include "study/sweep.hpp"

namespace codyna::cli {

// The number of processes a launcher started this one among (OMPI_COMM_WORLD_SIZE of OpenMPI's
// mpirun, PMI_SIZE of MPICH's and Slurm's PMI); 1 when none did.
int launched_processes();

// True when this codyna was built with MPI (CMake found it: find_package(MPI)).
bool built_with_mpi();

// The sweep r shared among the MPI ranks; tell, progress and print (the summary and the files
// written) are used on rank 0 only. Every rank's errors are gathered and printed by rank 0 (a rank
// that fails does not leave the others waiting); returns the exit code, the same on every rank
// (0, 1 bad input, 2 a failure). Only with built_with_mpi().
int sweep_over_mpi(const SweepRequest& r, const StudyMessages& tell, const SweepProgress& progress,
                   const std::function<void(const SweepJob&)>& print);

}  // namespace codyna::cli

// SPDX-License-Identifier: MIT
/// @file The processes of this run as a Communicator (core/communicator.hpp): MPI_COMM_WORLD under
/// mpirun, one process otherwise. comm/ is the only folder besides solvers/hypre/ that includes
/// mpi.h; built without MPI (MLC_WITH_HYPRE=OFF, as the sanitizer tree is), world() is always the
/// one-process communicator.
#pragma once

#include "core/communicator.hpp"

namespace mlc::comm {

/// Whether this build has MPI (it comes with hypre: MLC_WITH_HYPRE).
bool have_mpi();

/// Whether an MPI launcher started this process: Open MPI's mpirun sets OMPI_COMM_WORLD_SIZE,
/// MPICH's hydra PMI_SIZE, PMIx launchers PMIX_RANK. Reads the environment only.
bool launched_by_mpirun();

/// The processes of the run, created on the first call and valid until exit.
///
/// With MPI built, and the process either started by an MPI launcher or with MPI already
/// initialised (hypre initialises it on first use as a single process): MPI_COMM_WORLD. The first
/// call initialises MPI if it is not yet (MPI_Init_thread, MPI_THREAD_FUNNELED: only the main
/// thread communicates) and finalises it at exit (after hypre's own finalisation, which it leaves
/// in place). MPI errors on it throw std::runtime_error naming the call.
/// Otherwise, and always without MPI: a SerialCommunicator, and MPI is not initialised, so one
/// process started without mpirun runs exactly as before this layer existed.
/// Must be called first from the main thread.
const Communicator& world();

/// The MPI communicator behind `c` as MPI's Fortran handle (MPI_Comm_c2f; convert back with
/// MPI_Comm_f2c), for the engines that take an MPI_Comm (hypre, in solvers/hypre/) without this
/// header naming MPI types: MPI_COMM_WORLD for world() under MPI, MPI_COMM_SELF for a
/// SerialCommunicator. Throws InvalidInput without MPI (no engine needs it then) and for a
/// communicator of another kind.
int mpi_handle(const Communicator& c);
/// The number of processes of this run on this machine (the launcher's OMPI_COMM_WORLD_LOCAL_SIZE,
/// MPI_LOCALNRANKS or MPI_LOCAL_NRANKS; world().size() when it says nothing; 1 without a launcher):
/// they share its memory.
int processes_on_this_machine();
/// Ends every process of the run with exit code `code` (MPI_Abort on MPI_COMM_WORLD when MPI is
/// initialised, std::exit otherwise): what a process does after an error the others cannot know
/// of, so that none waits forever in a collective call.
[[noreturn]] void abort_all(int code);

} // namespace mlc::comm

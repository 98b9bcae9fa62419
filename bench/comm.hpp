// SPDX-License-Identifier: MIT
/// @file `mlcontact bench comm`: what one V-cycle of the distributed mg, one
/// mat-vec and one Krylov iteration cost each process in messages, bytes and reductions, and in
/// seconds: the inputs of the scaling model (scripts/measure/scaling_model.py,
/// docs/parallel.md#cluster-communication).
///
/// On the elastic block of a scene's level L (its contact pairs dropped, distributed as a run
/// distributes it: bench/distributed.hpp), with the mg of a run (vertex-block Gauss-Seidel,
/// one pre- and one post-sweep, gathered LU on level p), each operation is repeated `ops` times
/// between barriers:
///   matvec        one product with the finest K (hypre's halo exchange);
///   vcycle L'     one V-cycle from level L' = p+1..L (so level L' alone costs vcycle L' minus
///                 vcycle L'-1, and vcycle p+1 holds the coarse solve);
///   coarse_lu     one solve with level p's LU (each process, no communication);
///   cgs           a CGS + mg solve from zero to --tol, per iteration (2 mat-vecs, 2 V-cycles
///                 and its reductions).
/// Times are per operation: the slowest process, median over 3 repetitions. Counts are per
/// operation and process (the largest and the mean over the processes), read from the PMPI library
/// comm/pmpi_counters.cpp, which must be preloaded on N > 1 processes:
///   mpirun -np N -x LD_PRELOAD=build/lib/libmlc_pmpi_counters.so mlcontact bench comm ...
/// On one process there is nothing to count and the bench measures the times only. The JSON
/// (out/bench/comm_<scene>_L<L>_np<N>.json unless --out) is written by rank 0.
#pragma once

#include "core/communicator.hpp"

#include <filesystem>
#include <ostream>
#include <string>

namespace mlc::apps {

/// Options of `mlcontact bench comm`: the scene, levels and repetitions of the measured operations.
struct BenchCommOptions {
    std::string scene = "square";
    int levels = 5;           ///< the finest level L (1..8)
    int partition_level = -1; ///< p; < 0: the run's rule
    int ops = 10;             ///< repetitions of each operation per timing
    double rel_tol = 1e-8;    ///< tolerance of the CGS solve
    std::filesystem::path out;
};

/// Collective. Throws InvalidInput for options out of range, a scene the loader refuses, and on
/// N > 1 processes without the PMPI library preloaded (naming the command that loads it).
/// Returns 0 (2 when the CGS solve did not converge).
int bench_comm(const BenchCommOptions& opt, const Communicator& comm, std::ostream& os);

} // namespace mlc::apps

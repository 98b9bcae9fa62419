// SPDX-License-Identifier: MIT
/// @file `mlcontact bench square` on several processes (mpirun -np N, N > 1): the
/// coarse-to-fine solve of the scene with Krylov + the distributed mg
/// (levels/distributed_solve.hpp), timed `repeat` times; per level the Krylov iterations per
/// Newton step (mean, max) and per process its unknowns and peak RSS. The JSON
/// (out/bench/<scene>_L<L>_np<N>.json unless --out) is written by rank 0.
///
/// `mlcontact bench elastic` on several processes: the elastic block of the finest level (the
/// scene without its contact pairs, so that every level's K is the elastic block on the free
/// displacements; right-hand side the full load), distributed as a run distributes it, solved
/// from zero to --tol by hypre's ParCSR PCG with BoomerAMG ("boomeramg-pcg", the one-process
/// bench's settings) and by the distributed V-cycle (levels/distributed_solve.hpp) inside GMRES,
/// CGS and CG ("mg-gmres", "mg-cgs", "mg-cg"). Per solver: setup and solve seconds (medians over
/// --repeat of the slowest process), iterations, the true relative residual ||b - K x|| / ||b|| and
/// the 2-norm and max-norm of x (all over the processes). The JSON
/// (out/bench/elastic_<scene>_L<L>_np<N>.json unless --out) is written by rank 0.
#pragma once

#include "bench/bench.hpp"
#include "core/communicator.hpp"
#include "levels/distributed.hpp"
#include "levels/level.hpp"
#include "levels/problem.hpp"

#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace mlc::apps {

/// Collective. Throws InvalidInput for a preconditioner other than mg (one --pc), --levels < 1,
/// or a scene with no distributed form (two-body pairs). Returns 0 when every run converged.
int bench_square_distributed(const BenchSquareOptions& opt, const Communicator& comm,
                             std::ostream& os);

/// Collective. Throws InvalidInput for --levels outside 1..8, --repeat < 1, --tol outside (0, 1)
/// or a scene with no load on the free unknowns. Returns 0 when every solve converged, 2 otherwise.
int bench_elastic_distributed(const BenchElasticOptions& opt, const Communicator& comm,
                              std::ostream& os);

/// The elastic block's distributed levels p..L of a scene (its contact pairs dropped), as a run
/// distributes them, and level p whole (the gathered coarse level). Built in place: the levels
/// refer to the problem.
struct ElasticHierarchy {
    levels::Problem problem;
    int partition_level = 0;
    levels::Level level_p;
    std::vector<levels::DistributedLevel> levels;       ///< levels[k]: level p + k, this part
    std::vector<levels::DistributedTransfer> transfers; ///< transfers[k - 1]: k - 1 -> k
    double seconds = 0;                                 ///< building time, slowest process
};

/// Collective. partition_level < 0: the run's rule (levels::partition_level). Throws
/// InvalidInput for a partition level outside 0..L-1 and what the scene loader refuses.
std::unique_ptr<ElasticHierarchy> build_elastic_hierarchy(const std::string& scene, int L,
                                                          int partition_level,
                                                          const Communicator& comm);

} // namespace mlc::apps

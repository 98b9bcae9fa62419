// SPDX-License-Identifier: MIT
/// @file The coarse-to-fine solve of a 3D contact problem on several processes, the 3D
/// counterpart of levels/distributed_solve.hpp: levels 0..p (p the partition level) are solved
/// on every process by levels::solve (solve3.hpp), as one process solves them; then every load
/// step is solved on the distributed levels p+1..L (levels/distributed3.hpp), coarse to fine,
/// each process its part: each level starts from the level below's converged state of the step
/// (displacements by the part's vertex prolongation, multipliers by the surface transfer of the
/// parts' own contact nodes) and runs Newton (ContactNewton3 with a NewtonDistribution: owned
/// rows, every norm, count and decision reduced over the processes), its systems solved by GMRES
/// preconditioned by the distributed multigrid (DistributedMultigrid3: rediscretized operators at
/// each level's converged statuses, vertex-block Gauss-Seidel on each process's diagonal block,
/// the gathered LU of level p at its converged statuses as the coarse solve).
///
/// Levels 0..p do not depend on the levels above, so all their load steps are solved first;
/// level p's converged state of each step is then the start of the distributed levels' step.
#pragma once

#include "core/communicator.hpp"
#include "core/timer.hpp"
#include "levels/distributed3.hpp"
#include "levels/solve3.hpp"

#include <string>
#include <vector>

namespace mlc::levels {

/// What one process holds after a distributed 3D run.
struct DistributedRunResult3 {
    int n_processes = 1;
    int partition_level = 0;
    /// Levels 0..p, solved on every process alike (their hierarchy, steps and final state).
    RunResult3 serial;
    /// Levels p..L, this process's part (levels[0] is level p), and their transfers.
    DistributedHierarchy3 parts;
    /// level_steps[k]: the load steps of level p + k (k >= 1), with status counts and the
    /// predicted-status confusion summed over the processes (the same on every process).
    std::vector<std::vector<LevelStep3>> level_steps;
    std::vector<StepReport> steps; ///< the finest level's, one per load step
    Vector x;      ///< the finest level's unknowns on this part (ghost entries from their owners)
    Vector u_full; ///< the finest level's nodal displacements on this part's vertices (3 each)
    std::vector<ContactNodeState3> nodes; ///< the finest level's contact nodes owned here
    /// The same after every completed load step (nodes is the last).
    std::vector<std::vector<ContactNodeState3>> step_nodes;
    std::string solver;               ///< e.g. "gmres + distributed mg(pre=2,post=2,omega=1)"
    Timings timings;                  ///< this process's
    double distributed_seconds = 0.0; ///< this process's time in the distributed levels
    double seconds = 0.0;             ///< wall time of the whole solve
    bool converged = false;
    std::string failure;
    int completed_steps = 0;

    const DistributedLevel3& finest() const { return parts.levels.back(); }
};

/// Collective: solves `problem` (problem.levels >= 1) on the processes of `comm` with the
/// partition level `partition_level` in [0, problem.levels - 1]. options: coarse_to_fine must be
/// on and `upper` must be Method3::mg (schur and lu need a whole level on one process);
/// `level0`, krylov_rel_tol, progress (called on rank 0 only, for every level and step) and
/// interrupt apply; extrapolate applies to levels 0..p (the distributed levels start from the
/// level below); solve_all_levels and wrap_system_solver must be left at their defaults. Throws
/// InvalidInput naming what is not distributed or out of range, on every process alike (a
/// loading path is refused by build_distributed_level3).
DistributedRunResult3 solve_distributed3(const ElasticProblem3& problem,
                                         const SolveOptions3& options, const Communicator& comm,
                                         int partition_level);

} // namespace mlc::levels

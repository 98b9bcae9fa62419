// SPDX-License-Identifier: MIT
/// @file The coarse-to-fine solve on several processes: levels 0..p (p the partition
/// level) are solved on every process by levels::solve, as one process solves them, and after
/// each load step of level p the distributed levels p+1..L solve the same step, each process its
/// part (levels/distributed.hpp), by Newton (levels::ContactNewton with a NewtonDistribution)
/// with a Krylov method (global reductions) preconditioned by the distributed multigrid below.
///
/// The distributed multigrid. One V-cycle over the distributed levels, on each the operator of its
/// converged statuses (rediscretized, as mg does on one process), its Newton system's on the
/// finest:
///   pre-smooth:  z = S_fwd r (vertex-block Gauss-Seidel on the process's diagonal block of A_k,
///                from z = 0; the unknowns of other processes enter through the residual: Jacobi
///                across the cuts),
///   coarse:      z += T_k B_{k-1} T_k^T (r - A_k z)   (T_k a ParCSR matrix, R = T^T),
///   post-smooth: z += S_bwd (r - A_k z),
/// and on level p the gathered coarse solve: the residual is gathered on every process, and the
/// Jacobian of level p at its converged statuses (factored by sparse LU on every process) solves
/// it. A fixed linear operator per Newton system: CGS, BiCGStab and GMRES apply.
#pragma once

#include "core/communicator.hpp"
#include "core/timer.hpp"
#include "levels/distributed.hpp"
#include "levels/distributed_multigrid.hpp"
#include "levels/solve.hpp"
#include "solvers/mg.hpp"

#include <memory>
#include <string>
#include <vector>

namespace mlc::levels {

/// What one process holds after a distributed run.
struct DistributedRunResult {
    int n_processes = 1;
    int partition_level = 0;
    /// Levels 0..p, solved on every process alike (their hierarchy, steps and final state).
    RunResult serial;
    /// Levels p..L, this process's part (levels[0] is level p).
    std::vector<DistributedLevel> levels;
    std::vector<DistributedTransfer> transfers; ///< transfers[k - 1]: levels[k - 1] -> levels[k]
    /// level_steps[k]: the load steps of level p + k (k >= 1), with reduced status counts,
    /// predicted-status confusion and agreement (the same on every process).
    std::vector<std::vector<LevelStep>> level_steps;
    std::vector<StepReport> steps; ///< the finest level's, one per load step
    Vector x;      ///< the finest level's unknowns on this part (ghost entries from their owners)
    Vector u_full; ///< the finest level's nodal displacements on this part's vertices
    std::vector<ContactNodeState> nodes; ///< the finest level's contact nodes owned here
    /// The same after every completed load step (nodes is the last).
    std::vector<std::vector<ContactNodeState>> step_nodes;
    solvers::MultigridParams mg;      ///< the distributed multigrid's cycle
    Timings timings;                  ///< this process's
    double distributed_seconds = 0.0; ///< this process's time in the distributed levels
    double seconds = 0.0;             ///< wall time of the whole solve
    bool converged = false;
    std::string failure;
    int completed_steps = 0;

    const DistributedLevel& finest() const { return levels.back(); }
};

/// Collective: the status counts summed over the processes of `comm` (2D and 3D statuses).
StatusCounts reduce_counts(const Communicator& comm, StatusCounts c);

/// Collective: solves `problem` on the processes of `comm` (at least one level above level p,
/// rigid or two-body pairs, supports that stay the same along the path) with the partition level
/// `partition_level` (< problem.levels). options.linear must be "krylov" with pc "mg" (its
/// pre/post/omega options apply); options.coarse_to_fine must be on. The observer (null: none)
/// sees the load steps of every level (level_step_done) on rank 0 only, is asked
/// interrupt_requested and wraps the solvers of levels 0..p on every process; its level_step
/// and stop_requested are not called (the distributed levels take level p's steps, and a run
/// stops on every process alike or not at all). Throws InvalidInput naming what is not
/// distributed or out of range, on every process alike.
DistributedRunResult solve_distributed(const Problem& problem, const SolveOptions& options,
                                       const Communicator& comm, int partition_level,
                                       SolveObserver* observer = nullptr);

} // namespace mlc::levels

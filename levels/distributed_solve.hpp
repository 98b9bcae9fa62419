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
#include "levels/solve.hpp"
#include "solvers/mg.hpp"

#include <memory>
#include <string>
#include <vector>

namespace mlc::levels {

/// The distributed multigrid over the levels of a distributed run and the Newton systems of its
/// levels 1..m (levels[k] is level p + k; levels[0], level p, is the gathered coarse level).
/// Collective calls throughout (every process calls them in the same order).
class DistributedMultigrid {
public:
    /// `levels`, `transfers` (transfers[k - 1]: levels[k - 1] -> levels[k]) and `comm` must outlive
    /// it. spec: the Krylov method, tolerance and iteration limit of solve().
    DistributedMultigrid(const std::vector<DistributedLevel>& levels,
                         const std::vector<DistributedTransfer>& transfers,
                         const Communicator& comm, LinearSolverSpec spec,
                         solvers::MultigridParams mg);
    ~DistributedMultigrid();
    /// The coarse solve: level p (the whole level, on every process) at the status matrices M
    /// (one per contact element of level_p; none without contact), factored by sparse LU.
    void set_coarse(const Level& level_p, const std::vector<Eigen::Matrix2d>& M);
    /// Level k's operator J_k = K_k + contact tangents at M (one per contact element of the
    /// part), assembled in place, and its smoother set up; nothing when M is the last call's on
    /// every process.
    void prepare(size_t k, const std::vector<Eigen::Matrix2d>& M);
    /// J_k(M) dx = b on the owned unknowns by the Krylov method preconditioned by one V-cycle
    /// from level k, to max(forcing, spec.rel_tol).
    SolveResult solve(size_t k, const std::vector<Eigen::Matrix2d>& M, const Vector& b, Vector& dx,
                      double forcing);
    /// J_k as prepared last (a ParCSR view of its blocks).
    const solvers::ParMatrix& matrix(size_t k) const;
    /// One V-cycle from level k as a Preconditioner of J_k (borrows this object).
    std::unique_ptr<Preconditioner> preconditioner(size_t k) const;
    /// e.g. "cgs + distributed mg(pre=1,post=1,omega=1)".
    std::string name() const;

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

/// The V-cycle parameters of spec.pc ("mg[:pre=N,post=N,omega=W]"). Throws InvalidInput when
/// spec is not a Krylov method with mg (naming what has no distributed form).
solvers::MultigridParams distributed_mg_params(const LinearSolverSpec& spec);

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

// SPDX-License-Identifier: MIT
/// @file The distributed multigrid: the V-cycle of solvers/vcycle.hpp (the one-process
/// multigrid's) over the distributed levels of a run on several processes
/// (levels/distributed.hpp). On each level the operator of its converged statuses (rediscretized,
/// as mg does on one process; its Newton system's on the finest) as a ParCSR matrix, whose halo
/// exchange gives the residuals; the smoother of each process's diagonal block, the other
/// processes' unknowns held at their values (Jacobi across the cuts): mg:smoother=lattice's sweep
/// where the level is numbered by lattices (the macro triangles a process owns whole), else
/// vertex-block Gauss-Seidel, in double or (mg:precision=single) single precision; T a ParCSR
/// matrix, R = T^T. On level p the gathered coarse solve: the residual gathered on every process
/// and solved by the sparse LU of level p's Jacobian at its converged statuses.
/// DistributedMultigrid3 is the same cycle on the distributed 3D levels (levels/distributed3.hpp):
/// GMRES, vertex-block Gauss-Seidel in double precision (the lattice sweep and single precision
/// are 2D), V- or W-cycles, T the displacements' (DistributedTransfer3).
#pragma once

#include "core/communicator.hpp"
#include "levels/distributed.hpp"
#include "levels/distributed3.hpp"
#include "levels/solve.hpp"
#include "solvers/hypre/par_matrix.hpp"
#include "solvers/krylov.hpp"
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

/// The distributed multigrid on 3D levels (levels/distributed3.hpp; levels[0] is level p, the
/// gathered coarse level, levels[k] level p + k): GMRES on J_k preconditioned by the cycle of
/// DistributedMultigrid with vertex-block Gauss-Seidel (the free components of a vertex and its
/// multipliers one block) on each process's diagonal block, V- or W-cycles (mg.cycles 1 or 2;
/// elastic3_mg_params is the 3D default), T the DistributedTransfer3's. Double precision and
/// block sweeps only: mg.smoother = lattice or mg.precision = float32 throw InvalidInput.
/// Collective calls throughout (every process calls them in the same order).
class DistributedMultigrid3 {
public:
    /// `levels`, `transfers` (transfers[k - 1]: levels[k - 1] -> levels[k]) and `comm` must
    /// outlive it. krylov: GMRES's parameters (rel_tol the floor of solve's tolerance, max_iter,
    /// restart, give_up_budget); its comm is set inside.
    DistributedMultigrid3(const std::vector<DistributedLevel3>& levels,
                          const std::vector<DistributedTransfer3>& transfers,
                          const Communicator& comm, solvers::KrylovParams krylov,
                          solvers::MultigridParams mg);
    /// spec's Krylov method with spec.pc: mg (the cycle above), or a preconditioner of the
    /// matrix alone (diag, ilu, sor, ssor, lu) on each process's diagonal block, Jacobi across
    /// the cuts; what has no distributed or no 3D form throws InvalidInput.
    DistributedMultigrid3(const std::vector<DistributedLevel3>& levels,
                          const std::vector<DistributedTransfer3>& transfers,
                          const Communicator& comm, const LinearSolverSpec& spec,
                          solvers::KrylovParams krylov, solvers::MultigridParams mg);
    ~DistributedMultigrid3();
    /// The coarse solve: level p (the whole level, on every process) at the status matrices M
    /// (one per contact element of level_p), its Jacobian (BasicJacobianAssembler<3>) factored
    /// by sparse LU.
    void set_coarse(const Level3& level_p, const std::vector<Eigen::Matrix3d>& M);
    /// Level k's operator J_k = K_k + contact tangents at M (one per element of local.contacts,
    /// then one per element of local.ghost_contacts), assembled in place, and its smoother set
    /// up; nothing when M is the last call's on every process.
    void prepare(size_t k, const std::vector<Eigen::Matrix3d>& M);
    /// J_k(M) dx = b on the owned unknowns by GMRES preconditioned by one cycle from level k, to
    /// the relative residual max(forcing, krylov.rel_tol). dx holds the initial guess.
    SolveResult solve(size_t k, const std::vector<Eigen::Matrix3d>& M, const Vector& b, Vector& dx,
                      double forcing);
    /// J_k as prepared last (a ParCSR view of its blocks).
    const solvers::ParMatrix& matrix(size_t k) const;
    /// One cycle from level k as a Preconditioner of J_k (borrows this object).
    std::unique_ptr<Preconditioner> preconditioner(size_t k) const;
    /// e.g. "gmres + distributed mg(pre=2,post=2,omega=1,cycles=2)".
    std::string name() const;

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

/// The V-cycle parameters of spec.pc ("mg[:pre=N,post=N,omega=W]"). Throws InvalidInput when
/// spec is not a Krylov method with mg (naming what has no distributed form).
solvers::MultigridParams distributed_mg_params(const LinearSolverSpec& spec);

/// The solver of levels 0..p of a distributed run (solved on every process by levels::solve):
/// `spec` itself, but without mg:smoother=lattice when p is below the first level the lattice
/// sweep applies to (those levels are swept by vertex blocks either way).
LinearSolverSpec serial_levels_spec(const LinearSolverSpec& spec, int partition_level);

} // namespace mlc::levels

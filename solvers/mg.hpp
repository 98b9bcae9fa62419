// SPDX-License-Identifier: MIT
/// @file Geometric multigrid V-cycle for the level hierarchy: one `MultigridCycle` per level,
/// each calling the level below through a `CoarseSolve` (the level below's own cycle, or a direct
/// solve on the coarsest level), smoothed by vertex-block Gauss–Seidel (smoothers::BlockSOR with
/// threaded parts and the unrolled kernel), which copes with the zero diagonals of the contact
/// multiplier rows: one block per vertex, its 2 displacements and, at a contact vertex, its 1 or 2
/// multipliers, so the zero multiplier diagonals of stick and slip rows sit inside a nonsingular
/// 3x3/4x4 block.
///
/// One cycle on A z = r (z = 0 on entry) is
///
///     pre-smooth:  z <- z + S_fwd (r - A z)          (nu1 forward block Gauss–Seidel sweeps)
///     coarse:      z <- z + T A_H^{-1}~ R (r - A z)  (A_H^{-1}~: the level below's cycle)
///     post-smooth: z <- z + S_bwd (r - A z)          (nu2 backward sweeps)
///
/// with T the prolongation (P on displacements, Q on multipliers: transfer::LevelTransfer::T) and
/// R = T^T. Every step is linear in r and nothing depends on the iteration, so the cycle is a
/// fixed linear operator: CGS, BiCGStab and (non-flexible) GMRES all apply. With forward pre-
/// and backward post-sweeps (nu1 = nu2) and a symmetric A and A_H, the cycle is symmetric too,
/// so it also preconditions CG (`pcg` below) on the elastic block.
#pragma once

#include "core/linear_operator.hpp"
#include "smoothers/block_sor.hpp"
#include "solvers/coarse_fine.hpp"

#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace mlc::solvers {

/// Parameters of `MultigridCycle`.
struct MultigridParams {
    int pre_sweeps = 1;  ///< forward smoothing sweeps before the coarse correction, >= 0
    int post_sweeps = 1; ///< backward sweeps after it, >= 0 (pre + post >= 1)
    double omega = 1.0;  ///< relaxation of the block Gauss–Seidel sweeps, in (0, 2)
    /// Throws mlc::InvalidInput naming the first field out of range.
    void validate() const;
};

/// Prints every field of `p` on one line.
std::ostream& operator<<(std::ostream& os, const MultigridParams& p);

/// One level of the V-cycle (see the file comment). Borrows T and R (they must outlive it) and
/// the coarse solve (what it refers to must outlive it; it must be linear and accept a zero
/// initial guess). `setup` stores a reference to A (A must outlive the next setup).
///
/// `apply` does not allocate (work vectors sized at `setup`) when the coarse solve does not;
/// not thread-safe (mutable work vectors).
class MultigridCycle final : public Preconditioner {
public:
    /// @param T  prolongation, fine x coarse
    /// @param R  restriction, coarse x fine (usually T^T)
    /// @param block_starts  smoother blocks of the fine level (smoothers::BlockSORParams::
    ///                      block_starts; empty: blocks of 2 rows)
    MultigridCycle(const SparseMatrix& T, const SparseMatrix& R, CoarseSolve coarse,
                   std::vector<Index> block_starts, MultigridParams params = {});
    void setup(const SparseMatrix& A) override;
    void update_values(const SparseMatrix& A) override;
    void apply(const Vector& r, Vector& z) const override;
    /// "mg(pre=1,post=1,omega=1)".
    std::string name() const override;
    /// Replaces the coarse solve (e.g. when the level below was set up anew).
    void set_coarse(CoarseSolve coarse) { coarse_ = std::move(coarse); }

private:
    const SparseMatrix& T_;
    const SparseMatrix& R_;
    CoarseSolve coarse_;
    smoothers::BlockSOR smoother_;
    MultigridParams params_;
    const SparseMatrix* A_ = nullptr;
    mutable Vector res_, rc_, ec_;
};

/// Preconditioned conjugate gradients for a symmetric positive definite A with a symmetric
/// positive definite preconditioner M: stops when ||b - A x|| <= rel_tol ||b|| (the recursive
/// residual; the true one is recomputed at exit) or after max_iter iterations. x holds the
/// initial guess on entry (resized to zero if empty).
SolveResult pcg(const SparseMatrix& A, const Preconditioner& M, const Vector& b, Vector& x,
                double rel_tol, int max_iter);

/// The vertex blocks of a dof numbering in which each vertex's unknowns are contiguous:
/// `vertex_of_dof[i]` is the owner of unknown i; returns the first unknown of each run.
std::vector<Index> vertex_block_starts(const std::vector<int>& vertex_of_dof);

} // namespace mlc::solvers

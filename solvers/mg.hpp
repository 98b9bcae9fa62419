// SPDX-License-Identifier: MIT
/// @file Geometric multigrid V-cycle for the level hierarchy: one `MultigridCycle` per level,
/// each calling the level below through a `CoarseSolve` (the level below's own cycle, or a direct
/// solve on the coarsest level), and a vertex-block Gauss–Seidel smoother that copes with the
/// zero diagonals of the contact multiplier rows.
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

#include "core/csr.hpp"
#include "core/linear_operator.hpp"
#include "solvers/coarse_fine.hpp"

#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace mlc::solvers {

/// Block Gauss–Seidel over variable diagonal blocks (one block per vertex: its 2 displacements
/// and, at a contact vertex, its 1 or 2 multipliers, so the zero multiplier diagonals of stick
/// and slip rows sit inside a nonsingular 3x3/4x4 block), with relaxation omega.
///
/// `setup` stores a reference to A (A must outlive it) and inverts the blocks; `update_values`
/// re-inverts them (same blocks): for the matrix of the last setup refreshed in place (same
/// object and nonzero count: the pattern is taken as unchanged) that is all it does, for another
/// matrix it also redoes the parts and diagonal positions. The sweeps do not allocate. A singular
/// block throws mlc::InvalidInput naming it.
///
/// Parts (hybrid Gauss–Seidel, as in hypre's threaded relaxation): the blocks are cut into P
/// contiguous runs of about equal nonzeros, one per OpenMP thread. Each part sweeps its own
/// blocks in order with the newest values of its own unknowns, and reads the unknowns of the
/// other parts as they were when the sweep began (Jacobi across the cuts). So every sweep is the
/// same linear map whatever the threads do, and with P = 1 it is plain block Gauss–Seidel. With
/// the unknowns numbered along a space-filling curve the parts are compact pieces of the domain
/// and only their few interface rows differ from a sequential sweep.
class BlockGaussSeidel final : public Smoother {
public:
    /// `block_starts`: first row of every block, strictly increasing from 0 (a trailing n is
    /// allowed); empty: blocks of 2 rows. omega in (0, 2). `parts`: 0 takes the number of OpenMP
    /// threads; at most one part per kMinRowsPerPart rows (small levels stay sequential).
    explicit BlockGaussSeidel(std::vector<Index> block_starts = {}, double omega = 1.0,
                              int parts = 0);
    /// Rows per part below which fewer parts are used.
    static constexpr Index kMinRowsPerPart = kMinRowsPerThread;
    /// Number of parts of the last setup.
    int parts() const { return static_cast<int>(part_block_.size()) - 1; }
    /// First row of every part, then the number of rows.
    std::vector<Index> part_rows() const {
        std::vector<Index> rows;
        for (const Index I : part_block_)
            rows.push_back(starts_[static_cast<size_t>(I)]);
        return rows;
    }
    void setup(const SparseMatrix& A) override;
    void update_values(const SparseMatrix& A) override;
    /// z = one forward sweep from z = 0.
    void apply(const Vector& r, Vector& z) const override;
    /// One forward sweep on A x = b, in place.
    void smooth(const Vector& b, Vector& x) const override { sweep(b, x, true); }
    /// One sweep, blocks in increasing (forward) or decreasing order.
    void sweep(const Vector& b, Vector& x, bool forward) const;
    /// x = one forward sweep from x = 0, and res = b - A x, in one pass over A (the lower part
    /// during the sweep, the block-diagonal and upper part after it). x and res are resized.
    void forward_from_zero(const Vector& b, Vector& x, Vector& res) const;
    std::string name() const override;

private:
    void invert_blocks();
    void find_diagonal_starts();
    void split_parts();
    // One part's sweep from x (other parts' unknowns read from snap_), blocks [b0, b1).
    void sweep_part(const double* bp, double* xp, Index b0, Index b1, bool forward) const;

    std::vector<Index> starts_; // block starts followed by n
    double omega_;
    int parts_requested_;
    const SparseMatrix* A_ = nullptr;
    Index nonzeros_ = 0;          // of A at the last setup (pattern check of update_values)
    std::vector<Index> offset_;   // offset of block I's inverse (row-major) in dinv_
    std::vector<int> diag_begin_; // per row: first stored entry in or right of its block
    std::vector<int> own_begin_, own_end_; // per row: its entries with columns in its own part
    std::vector<Index> part_block_;        // first block of each part, then the block count
    std::vector<int> interface_;           // columns read across a cut (copied into snap_)
    mutable Vector snap_;                  // other parts' unknowns at the start of a sweep
    std::vector<double> dinv_;             // omega * D_I^{-1}
};

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
    /// @param block_starts  smoother blocks of the fine level (see BlockGaussSeidel)
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
    BlockGaussSeidel smoother_;
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

// SPDX-License-Identifier: MIT
/// @file SSOR with the generalized diagonal D* of Alart & Lebon (1995, sect. 4.2, eqs. 26-33),
/// and the SOR coarse/fine preconditioner SORCF: CF with A_ff^{-1} replaced by that SSOR.
///
/// With A_ff = L + D + U (strict lower, diagonal, strict upper), the paper replaces A_ff by
///
///     P = (L + D*) D*^{-1} (U + D*)
///
/// where D* is a *generalized diagonal* that has no zero where D has (the stick and slip-normal
/// multiplier rows of the contact Jacobian). With relaxation 0 < omega < 2 we use the usual SSOR
/// normalization (the text of the paper breaks off where it introduces omega):
///
///     P_omega = 1 / (omega (2 - omega)) (D* + omega L) D*^{-1} (D* + omega U),
///     P_omega^{-1} = omega (2 - omega) (D* + omega U)^{-1} D* (D* + omega L)^{-1},
///
/// which is P at omega = 1 and the colleague's BlockSOR symmetric sweep when D* = D.
///
/// **Scalar D* (block = false), eqs. 26-33.** For an elastic node and its multiplier node, the
/// paper writes the 4x4 patterns of A_ff in slip ([[A11, A12, 0, -eps mu], [A21, A22, 0, 1],
/// [0, -eps mu, -1/r, -eps mu/r], [0, 1, 0, 0]]) and stick ([[A11, A12, 1, 0], [A21, A22, 0, 1],
/// [1, 0, 0, 0], [0, 1, 0, 0]]) and chooses the multiplier entries of D* so that P keeps the
/// zero diagonal of A_ff: alpha = 1/beta = -1/A22 in slip (eq. 29: alpha^2 beta + 1/A22 = 0) and
/// alpha = 1/beta = -1/A11, gamma = 1/delta = -1/A22 in stick (eq. 33), i.e. the effective pivot
/// of the lambda row is -1/A11 or -1/A22. The general rule behind both, which we implement: D*_ii
/// = A_ii where |A_ii| > zero_tol max_j |A_ij|, and otherwise
///
///     D*_ii = -omega^2 sum_{k < i} A_ik A_ki / D*_kk,
///
/// the value that makes (P_omega)_ii = 0 = A_ii (diagonal of the incomplete factorization on the
/// pattern of the diagonal). For node-on-rigid elements the sum runs over the multiplier's own
/// vertex (its only couplings), giving exactly eqs. 29 and 33 at omega = 1.
///
/// **Block D* (block = true).** D* is the block diagonal of A_ff with 2x2 vertex blocks and 4x4
/// (3x3 frictionless) vertex + multiplier blocks, given as block starts; L and U are the strict
/// block lower and upper parts. The blocks are nonsingular in every status (gap, stick, slip).
#pragma once

#include "core/linear_operator.hpp"
#include "solvers/coarse_fine.hpp"

#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace mlc::solvers {

/// Parameters of `GeneralizedSSOR` and `make_sorcf`.
struct SorcfParams {
    /// Relaxation factor omega in (0, 2). Default 1: the paper's P = (L + D*) D*^{-1} (U + D*).
    double omega = 1.0;
    /// false: scalar generalized diagonal (eqs. 26-33); true: vertex (+ multiplier) blocks.
    /// Default false: the paper's construction.
    bool block = false;
    /// A diagonal entry is treated as zero when |a_ii| <= zero_tol * max_j |a_ij|, in [0, 1).
    /// Default 1e-12: exact zeros and cancellation remnants of the multiplier rows only.
    double zero_tol = 1e-12;

    /// Throws mlc::InvalidInput naming the first field out of range.
    void validate() const;
};

/// Prints every field of `p` on one line.
std::ostream& operator<<(std::ostream& os, const SorcfParams& p);

/// z = P_omega^{-1} r, the SSOR preconditioner with the generalized diagonal D* (file comment).
///
/// `setup` stores a reference to A: A must outlive this object (or the next `setup`). It
/// computes D* (scalar) or inverts the diagonal blocks (block mode, dense LU with partial
/// pivoting); a zero D*_ii, or a singular block, throws mlc::SolverBreakdown naming the row.
/// `apply` does not allocate once sizes are set (one mutable work vector): not thread-safe.
class GeneralizedSSOR final : public Preconditioner {
public:
    /// `block_starts`: first row of every diagonal block (strictly increasing from 0), used when
    /// params.block is true (required then); ignored otherwise. Validates `params`.
    explicit GeneralizedSSOR(SorcfParams params = {}, std::vector<Index> block_starts = {});

    /// Computes D* (or the block inverses) for A (square, compressed, finite). Allocates.
    void setup(const SparseMatrix& A) override;
    /// z = omega (2 - omega) (D* + omega U)^{-1} D* (D* + omega L)^{-1} r. No allocation.
    void apply(const Vector& r, Vector& z) const override;
    /// "gssor(omega=W,block=B)".
    std::string name() const override;

    /// The scalar generalized diagonal D* (scalar mode), after `setup`.
    const Vector& generalized_diagonal() const { return dstar_; }
    /// Number of rows whose D* entry was generated (zero diagonal of A), scalar mode.
    Index n_generated() const { return n_generated_; }
    /// The parameters in effect.
    const SorcfParams& params() const { return params_; }

private:
    SorcfParams params_;
    std::vector<Index> starts_; // block starts followed by n (block mode)
    const SparseMatrix* A_ = nullptr;
    Index n_ = 0;
    Index n_generated_ = 0;
    Vector dstar_;              // scalar D*
    std::vector<Index> block_;  // block of every row (block mode)
    std::vector<Index> offset_; // offset of block I in dblk_/dinv_
    std::vector<double> dblk_;  // row-major diagonal blocks
    std::vector<double> dinv_;  // row-major inverses
    mutable Vector y_;
};

/// SORCF: CF (solvers/coarse_fine.hpp) with A_ff^{-1} replaced by P_omega^{-1} on A_ff. With
/// params.block the diagonal blocks of A_ff are split.fine_block_starts (required non-empty).
/// name() is "sorcf(gssor(omega=W,block=B))".
std::unique_ptr<CoarseFinePreconditioner>
make_sorcf(CoarseFineSplit split, CoarseSolve coarse_solve, const SorcfParams& params = {});

} // namespace mlc::solvers

// SPDX-License-Identifier: MIT
/// @file Level-of-fill incomplete LU factorization ILU(k) (1995 paper, sect. 3.2), with the
/// symbolic phase separate from the numeric phase so a Newton step with an unchanged pattern
/// refactors values only.
#pragma once

#include "core/csr.hpp"
#include "core/linear_operator.hpp"

#include <ostream>
#include <string>
#include <vector>

namespace mlc::smoothers {

/// Parameters of `ILUK`.
struct ILUKParams {
    /// Level of fill k >= 0. Fill entries are kept when their level, lev(i,j) = min over
    /// elimination steps m of lev(i,m) + lev(m,j) + 1 (original entries: 0), is <= k.
    /// Default 0: ILU(0) keeps A's pattern, the papers' cheapest variant; k >= the bandwidth
    /// gives the complete LU (without pivoting) of a banded matrix.
    int fill_level = 0;
    /// A pivot u_ii is treated as zero when |u_ii| <= pivot_tol * max_j |a_ij| (or is not
    /// finite), in [0, 1). Default 1e-14: catches exact zeros and pure round-off remnants only.
    double pivot_tol = 1e-14;

    /// Throws mlc::InvalidInput naming the first field out of range.
    void validate() const;
};

/// Prints every field of `p` on one line.
std::ostream& operator<<(std::ostream& os, const ILUKParams& p);

/// ILU(k) preconditioner: C = L U with L unit lower and U upper triangular, both restricted to
/// the level-k fill pattern of A (natural order, no pivoting).
///
/// - Symbolic phase (`setup`): row-wise IKJ elimination on the pattern of A with levels of fill;
///   a missing diagonal is added to the pattern. Stores the combined L\U pattern in CSR.
/// - Numeric phase (`setup` and `update_values`): IKJ elimination restricted to that pattern.
///   `update_values` reuses the symbolic phase when A's pattern (outer and inner index arrays)
///   is unchanged and redoes it otherwise.
/// - A zero pivot (|u_ii| <= pivot_tol * max_j |a_ij|) throws mlc::SolverBreakdown naming the
///   row. For the contact Jacobian, order each node's multipliers after its displacements
///   (formulation.md sect. 5) so that the pivots of multiplier rows are filled in first.
///
/// `apply` is two triangular solves in place in z; it does not allocate (once z has the right
/// size) and keeps no mutable state, so it is thread-safe. A need not outlive `setup`.
class ILUK final : public Preconditioner {
public:
    /// Validates `params`.
    explicit ILUK(ILUKParams params = {});

    /// Symbolic and numeric factorization of A (square, compressed, finite). Allocates.
    /// Throws mlc::SolverBreakdown on a zero pivot.
    void setup(const SparseMatrix& A) override;
    /// Numeric factorization only, reusing the symbolic pattern when A's pattern is unchanged.
    void update_values(const SparseMatrix& A) override;
    /// z = U^{-1} L^{-1} r (r and z may be the same object). No allocation.
    void apply(const Vector& r, Vector& z) const override;
    /// z = L^{-T} U^{-T} r (r and z may be the same object). No allocation.
    void apply_transpose(const Vector& r, Vector& z) const override;
    /// "ilu(k)".
    std::string name() const override;

    /// The factors as one CSR matrix: strict lower part = L (unit diagonal implied), upper part
    /// including the diagonal = U. Built on request (allocates); for tests and reports.
    SparseMatrix factors() const;
    /// Number of stored entries of L\U (compare with nnz(A) for the fill ratio).
    Index n_nonzeros() const { return static_cast<Index>(cols_.size()); }
    /// Number of symbolic factorizations done so far (update_values with an unchanged pattern
    /// does not increase it).
    int n_symbolic() const { return n_symbolic_; }
    /// The parameters in effect.
    const ILUKParams& params() const { return params_; }

private:
    void symbolic(const SparseMatrix& A);
    void numeric(const SparseMatrix& A);

    ILUKParams params_;
    Index n_ = 0;
    int n_symbolic_ = 0;
    SparsityPattern a_pattern_;          // pattern of A at the last symbolic phase
    std::vector<int> a_to_lu_;           // position in L\U of each stored entry of A
    std::vector<int> ptr_, cols_, diag_; // CSR of L\U; diag_[i] = position of (i, i)
    std::vector<double> vals_;
    std::vector<double> inv_pivot_; // 1 / u_ii
    std::vector<int> pos_;          // numeric work: column -> position in the current row
};

} // namespace mlc::smoothers

// SPDX-License-Identifier: MIT
/// @file Direct solve behind the Preconditioner interface: Eigen's SparseLU on a column-major copy,
/// with the symbolic analysis reused while the sparsity pattern is unchanged.
#pragma once

#include "core/linear_operator.hpp"

#include <memory>
#include <ostream>
#include <string>

namespace mlc::solvers {

/// Parameters of `SparseLUPreconditioner`.
struct SparseLUParams {
    /// Eigen's diagonal pivot threshold in (0, 1]: a diagonal entry is kept as pivot when it is
    /// at least this fraction of the column's largest entry. Default 1: partial pivoting, the
    /// safe choice for the zero diagonals of contact-multiplier rows; smaller values favour the
    /// diagonal and keep more sparsity.
    double pivot_threshold = 1.0;

    /// Throws mlc::InvalidInput naming the first field out of range.
    void validate() const;
};

/// Prints every field of `p` on one line.
std::ostream& operator<<(std::ostream& os, const SparseLUParams& p);

/// Exact preconditioner C = A, i.e. z = A^{-1} r by Eigen::SparseLU (COLAMD column ordering).
///
/// `setup` converts A to column-major once, runs `analyzePattern` and `factorize`;
/// `update_values` compares A's outer and inner index arrays with those of the last analysis and
/// then only refactorizes (a changed pattern triggers a full `setup`). A singular matrix throws
/// mlc::SolverBreakdown with Eigen's message. A need not outlive `setup`.
///
/// `apply` allocates (Eigen's SparseLU solve uses temporaries); it is meant for the coarsest level
/// and for reference solves, where that cost is negligible. Thread-safe for concurrent `apply`.
class SparseLUPreconditioner final : public Preconditioner {
public:
    /// Validates `params`.
    explicit SparseLUPreconditioner(SparseLUParams params = {});
    /// Frees the factors (defined in the .cpp, where Impl is complete).
    ~SparseLUPreconditioner() override;
    /// Movable, not copyable (the factors are owned through a unique_ptr).
    SparseLUPreconditioner(SparseLUPreconditioner&&) noexcept;
    /// Move assignment.
    SparseLUPreconditioner& operator=(SparseLUPreconditioner&&) noexcept;

    /// Analysis and factorization of A (square, compressed, finite). Allocates.
    void setup(const SparseMatrix& A) override;
    /// Refactorization reusing the analysis when A's pattern is unchanged.
    void update_values(const SparseMatrix& A) override;
    /// z = A^{-1} r. Allocates.
    void apply(const Vector& r, Vector& z) const override;
    /// z = A^{-T} r. Allocates.
    void apply_transpose(const Vector& r, Vector& z) const override;
    /// "lu".
    std::string name() const override { return "lu"; }

    /// Number of symbolic analyses done so far (an unchanged pattern does not increase it).
    int n_analyses() const;
    /// The parameters in effect.
    const SparseLUParams& params() const { return params_; }

private:
    struct Impl;
    SparseLUParams params_;
    std::unique_ptr<Impl> impl_;
};

} // namespace mlc::solvers

// SPDX-License-Identifier: MIT
/// @file Run-time interfaces at the boundaries between parts: LinearOperator, Preconditioner,
/// Smoother, and the SolveResult every iterative solver returns.
#pragma once

#include "core/types.hpp"

#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace mlc {

/// y = A x for some square operator A.
class LinearOperator {
public:
    virtual ~LinearOperator() = default;
    virtual Index rows() const = 0;
    virtual Index cols() const = 0;
    /// y = A x; y is resized and overwritten.
    virtual void apply(const Vector& x, Vector& y) const = 0;
    /// y = A^T x; y is resized and overwritten. Needed by BiCG only.
    /// Default: throws mlc::InvalidInput ("... does not provide a transpose").
    virtual void apply_transpose(const Vector& x, Vector& y) const;
};

/// How `MatrixOperator` sums each row of y = A x.
enum class MatVec {
    /// Eigen's product `A * x`: every row summed in storage order with one accumulator (rows
    /// over core/parallel's threads, `csr_multiply_in_order`, for a compressed A). The
    /// default, so that the iteration counts published for the papers' preconditioners (DIAG,
    /// ILU, CF, SORCF, EBE, SOR) stay bit-for-bit reproducible.
    in_order,
    /// `csr_multiply` (core/csr.hpp): four accumulators per row, rows over the OpenMP threads.
    /// Faster, different in the last bits; used with the multigrid preconditioner.
    unrolled
};

/// The CSR matrix as a LinearOperator: y = A x by the kernel `kind`, y = A^T x by a scatter over
/// the rows. The matrix must outlive this object. Neither product allocates once y has its size.
/// `apply` counts one mat-vec pass (core/traffic.hpp), whichever kernel runs it.
class MatrixOperator final : public LinearOperator {
public:
    explicit MatrixOperator(const SparseMatrix& A, MatVec kind = MatVec::in_order)
        : A_(A), kind_(kind) {}
    Index rows() const override { return A_.rows(); }
    Index cols() const override { return A_.cols(); }
    /// y = A x, summed as `kind` says.
    void apply(const Vector& x, Vector& y) const override;
    /// y = A^T x (Eigen's transposed product, whatever `kind`).
    void apply_transpose(const Vector& x, Vector& y) const override;
    const SparseMatrix& matrix() const { return A_; }
    /// The row summation in use.
    MatVec kind() const { return kind_; }

private:
    const SparseMatrix& A_;
    MatVec kind_;
};

/// z = C^{-1} r for an approximation C of A.
///
/// `setup` may allocate and is expensive; `update_values` is called when only the values of A
/// changed (same pattern) and defaults to `setup`. `apply` assumes a zero initial guess.
class Preconditioner {
public:
    virtual ~Preconditioner() = default;
    /// Builds the preconditioner for A. A must outlive the next `setup`/`update_values` call only
    /// if the implementation says so.
    virtual void setup(const SparseMatrix& A) = 0;
    /// Same sparsity pattern, new values. Default: full setup.
    virtual void update_values(const SparseMatrix& A) { setup(A); }
    /// z = C^{-1} r (z resized and overwritten).
    virtual void apply(const Vector& r, Vector& z) const = 0;
    /// z = C^{-T} r (z resized and overwritten); needed by BiCG only.
    /// Default: throws mlc::InvalidInput naming `name()` ("... does not provide a transpose").
    virtual void apply_transpose(const Vector& r, Vector& z) const;
    /// Short name for reports, e.g. "ilu(0)".
    virtual std::string name() const = 0;
    /// The product a Krylov method preconditioned by this should use for A (the matrix it was
    /// set up on): null for A's own in-order product (the default). The multigrid returns the
    /// unrolled product, or its finest level's lattice stencils. It refers to A and to this.
    virtual std::unique_ptr<LinearOperator> krylov_operator(const SparseMatrix& A) const {
        (void)A;
        return nullptr;
    }
};

/// Identity preconditioner (z = r).
class IdentityPreconditioner final : public Preconditioner {
public:
    void setup(const SparseMatrix&) override {}
    void apply(const Vector& r, Vector& z) const override { z = r; }
    /// z = r (the identity is its own transpose).
    void apply_transpose(const Vector& r, Vector& z) const override { z = r; }
    std::string name() const override { return "none"; }
};

/// A Preconditioner that can also smooth with a non-zero initial guess.
class Smoother : public Preconditioner {
public:
    /// x <- x + C^{-1} (b - A x) (one or more sweeps, in place).
    virtual void smooth(const Vector& b, Vector& x) const = 0;
};

/// Why an iterative solve stopped.
enum class StopReason { converged, max_iter, breakdown, diverged };

std::string_view to_string(StopReason reason);

/// Outcome of one iterative linear solve; returned by value.
struct SolveResult {
    int iterations = 0;
    bool converged = false;
    StopReason reason = StopReason::max_iter;
    std::string message;            ///< detail for breakdown/divergence, empty otherwise
    double initial_residual = 0.0;  ///< ||b - A x0||
    double final_residual = 0.0;    ///< true ||b - A x|| at exit (recomputed, not recursive)
    double relative_residual = 0.0; ///< final_residual / ||b|| (or / initial if b = 0)
    double average_rate = 0.0;      ///< (final/initial)^(1/iterations)
    double setup_seconds = 0.0;     ///< matrix assembly (if any) and preconditioner/factorization
    double assembly_seconds = 0.0;  ///< of setup_seconds: assembling the matrix (Newton systems)
    double solve_seconds = 0.0;
    std::vector<double> history; ///< residual norms per iteration when recording was asked for
};

/// One line: "converged in 12 it, rel. residual 3.1e-09, rate 0.21, setup 0.01 s, solve 0.03 s".
std::ostream& operator<<(std::ostream& os, const SolveResult& r);

} // namespace mlc

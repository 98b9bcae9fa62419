// SPDX-License-Identifier: MIT
/// @file Jacobi (DIAG) preconditioner and damped-Jacobi smoother, with a documented patch for
/// the zero diagonal entries of contact-multiplier rows.
#pragma once

#include "core/linear_operator.hpp"

#include <ostream>
#include <string>
#include <vector>

namespace mlc::smoothers {

/// Parameters of `Jacobi`.
struct JacobiParams {
    /// Damping factor omega of z <- z + omega D^{-1} (r - A z), in (0, 2). Default 1: the plain
    /// DIAG preconditioner of the papers (1995 sect. 3.1); use about 2/3 when smoothing in
    /// multigrid.
    double omega = 1.0;
    /// Sweeps per `apply`/`smooth`, >= 1. Default 1: one sweep is the classical DIAG, and more
    /// sweeps cost one mat-vec each.
    int n_sweeps = 1;
    /// A diagonal entry is treated as zero when |a_ii| <= zero_tol * max_j |a_ij|, in [0, 1).
    /// Default 1e-12: catches exact zeros and round-off remnants of cancelled entries (stick and
    /// slip-normal multiplier rows) without touching genuinely small but meaningful pivots.
    double zero_tol = 1e-12;

    /// Throws mlc::InvalidInput naming the first field out of range.
    void validate() const;
};

/// Prints every field of `p` on one line.
std::ostream& operator<<(std::ostream& os, const JacobiParams& p);

/// Jacobi preconditioner / smoother: C = D / omega, D = diag(A).
///
/// One sweep from a zero guess: z = omega D^{-1} r. With `n_sweeps = m`,
/// z_{k+1} = z_k + omega D^{-1} (r - A z_k), z_0 = 0, so C^{-1} = sum_{k<m} (I - omega D^{-1}A)^k
/// omega D^{-1}.
///
/// **Zero or missing diagonals.** The contact Jacobian has zero diagonal entries on stick and
/// slip-normal multiplier rows (formulation.md sect. 2), where the plain DIAG of the papers fails.
/// When |a_ii| <= zero_tol * max_j |a_ij| (or a_ii is not stored), `setup` replaces d_i by the
/// row's largest absolute entry max_j |a_ij|, which keeps the scaling of the row; a row that is
/// entirely zero gets d_i = 1. The number of patched rows is `n_patched_rows()`, their indices
/// `patched_rows()`. Patching is deliberate, not an error: the Krylov iteration then decides.
///
/// `setup` stores a reference to A when `n_sweeps > 1` (A must outlive the next `setup`) and
/// always for `smooth`; `apply` with one sweep does not touch A. Neither `apply` nor `smooth`
/// allocates once sizes are set; they use a mutable work vector, so one object must not be
/// applied from two threads at once. r and z (b and x) must be distinct objects.
class Jacobi final : public Smoother {
public:
    /// Validates `params`.
    explicit Jacobi(JacobiParams params = {});

    /// Computes D^{-1} (with the zero-diagonal patch). A square, compressed, finite; A must
    /// outlive this object for `smooth` and multi-sweep `apply`. Allocates.
    void setup(const SparseMatrix& A) override;
    /// z = C^{-1} r as above (z resized and overwritten). Allocation-free for one sweep.
    void apply(const Vector& r, Vector& z) const override;
    /// z = C^{-T} r: the same sweeps with A^T in place of A (D^{-1} is its own transpose).
    void apply_transpose(const Vector& r, Vector& z) const override;
    /// n_sweeps times: x <- x + omega D^{-1} (b - A x), in place.
    void smooth(const Vector& b, Vector& x) const override;
    /// "diag" for the plain preconditioner, "jacobi(omega=..,sweeps=..)" otherwise.
    std::string name() const override;

    /// Number of rows whose diagonal was zero or missing and was patched by the last `setup`.
    Index n_patched_rows() const { return static_cast<Index>(patched_.size()); }
    /// Indices of those rows, increasing.
    const std::vector<Index>& patched_rows() const { return patched_; }
    /// The vector 1/d_i actually used (after patching), without the omega factor.
    const Vector& inverse_diagonal() const { return inv_diag_; }
    /// The parameters in effect.
    const JacobiParams& params() const { return params_; }

private:
    void sweeps(const Vector& r, Vector& z, bool transpose) const;

    JacobiParams params_;
    const SparseMatrix* A_ = nullptr;
    Vector inv_diag_;
    std::vector<Index> patched_;
    mutable Vector work_;
};

} // namespace mlc::smoothers

// SPDX-License-Identifier: MIT
// Jacobi preconditioner and smoother with the zero-diagonal patch of contact-multiplier rows.
#include "smoothers/jacobi.hpp"

#include "core/check.hpp"
#include "smoothers/matrix_checks.hpp"

#include <cmath>
#include <sstream>

namespace mlc::smoothers {

void JacobiParams::validate() const {
    MLC_CHECK(omega > 0.0 && omega < 2.0, "JacobiParams::omega must be in (0, 2), found " << omega);
    MLC_CHECK(n_sweeps >= 1, "JacobiParams::n_sweeps must be >= 1, found " << n_sweeps);
    MLC_CHECK(zero_tol >= 0.0 && zero_tol < 1.0,
              "JacobiParams::zero_tol must be in [0, 1), found " << zero_tol);
}

std::ostream& operator<<(std::ostream& os, const JacobiParams& p) {
    return os << "JacobiParams{omega=" << p.omega << ", n_sweeps=" << p.n_sweeps
              << ", zero_tol=" << p.zero_tol << "}";
}

Jacobi::Jacobi(JacobiParams params) : params_(params) {
    params_.validate();
}

void Jacobi::setup(const SparseMatrix& A) {
    check_setup_matrix(A, "Jacobi::setup");
    const Index n = A.rows();
    A_ = &A;
    inv_diag_.resize(n);
    patched_.clear();
    work_.resize(n);
    for (Index i = 0; i < n; ++i) {
        double d = 0.0;
        double m = 0.0;
        for (int p = A.outerIndexPtr()[i]; p < A.outerIndexPtr()[i + 1]; ++p) {
            const double a = A.valuePtr()[p];
            if (A.innerIndexPtr()[p] == i) d = a;
            m = std::max(m, std::abs(a));
        }
        if (std::abs(d) <= params_.zero_tol * m || d == 0.0) {
            // Zero multiplier-row diagonal: use the row's scale (see the header).
            d = m > 0.0 ? m : 1.0;
            patched_.push_back(i);
        }
        inv_diag_[i] = 1.0 / d;
    }
}

void Jacobi::sweeps(const Vector& r, Vector& z, bool transpose) const {
    MLC_CHECK(A_ != nullptr, "Jacobi: apply/smooth called before setup");
    check_size(r, inv_diag_.size(), "Jacobi::apply", "r");
    const double w = params_.omega;
    z.resize(r.size());
    z.noalias() = w * inv_diag_.cwiseProduct(r);
    for (int s = 1; s < params_.n_sweeps; ++s) {
        if (transpose)
            work_.noalias() = A_->transpose() * z;
        else
            work_.noalias() = *A_ * z;
        z.noalias() += w * inv_diag_.cwiseProduct(r - work_);
    }
}

void Jacobi::apply(const Vector& r, Vector& z) const {
    sweeps(r, z, false);
}

void Jacobi::apply_transpose(const Vector& r, Vector& z) const {
    sweeps(r, z, true);
}

void Jacobi::smooth(const Vector& b, Vector& x) const {
    MLC_CHECK(A_ != nullptr, "Jacobi::smooth called before setup");
    check_size(b, inv_diag_.size(), "Jacobi::smooth", "b");
    check_size(x, inv_diag_.size(), "Jacobi::smooth", "x");
    for (int s = 0; s < params_.n_sweeps; ++s) {
        work_.noalias() = *A_ * x;
        x.noalias() += params_.omega * inv_diag_.cwiseProduct(b - work_);
    }
}

std::string Jacobi::name() const {
    if (params_.omega == 1.0 && params_.n_sweeps == 1) return "diag";
    std::ostringstream os;
    os << "jacobi(omega=" << params_.omega << ",sweeps=" << params_.n_sweeps << ")";
    return os.str();
}

} // namespace mlc::smoothers

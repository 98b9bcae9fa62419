// SPDX-License-Identifier: MIT
// MatrixOperator and SolveResult printing.
#include "core/linear_operator.hpp"

#include "core/check.hpp"
#include "core/csr.hpp"

#include <iomanip>

namespace mlc {

void MatrixOperator::apply(const Vector& x, Vector& y) const {
    if (kind_ == MatVec::unrolled) {
        csr_multiply(A_, x, y);
        return;
    }
    const traffic::Pass pass(traffic::Kind::matvec,
                             traffic::csr_bytes(A_.rows(), A_.cols(), A_.nonZeros(), false));
    if (A_.isCompressed())
        csr_multiply_in_order(A_, x, y); // Eigen's sums, bit for bit, rows over the threads
    else
        y.noalias() = A_ * x;
}

void MatrixOperator::apply_transpose(const Vector& x, Vector& y) const {
    y.noalias() = A_.transpose() * x;
}

void LinearOperator::apply_transpose(const Vector&, Vector&) const {
    throw InvalidInput("LinearOperator::apply_transpose: this operator does not provide a "
                       "transpose; use a Krylov method that needs only A x (cgs, bicgstab, gmres)");
}

void Preconditioner::apply_transpose(const Vector&, Vector&) const {
    throw InvalidInput("Preconditioner::apply_transpose: preconditioner '" + name() +
                       "' does not provide a transpose; use a Krylov method that needs only "
                       "C^{-1} r (cgs, bicgstab, gmres)");
}

std::string_view to_string(StopReason reason) {
    switch (reason) {
    case StopReason::converged:
        return "converged";
    case StopReason::max_iter:
        return "max_iter";
    case StopReason::breakdown:
        return "breakdown";
    case StopReason::diverged:
        return "diverged";
    }
    return "unknown";
}

std::ostream& operator<<(std::ostream& os, const SolveResult& r) {
    os << to_string(r.reason) << " in " << r.iterations << " it, rel. residual " << std::scientific
       << std::setprecision(2) << r.relative_residual << std::defaultfloat << ", rate "
       << std::setprecision(3) << r.average_rate << ", setup " << r.setup_seconds << " s, solve "
       << r.solve_seconds << " s";
    if (!r.message.empty()) os << " (" << r.message << ")";
    return os;
}

} // namespace mlc

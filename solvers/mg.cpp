// SPDX-License-Identifier: MIT
// Geometric multigrid V-cycle with a vertex-block Gauss–Seidel smoother, and PCG.
#include "solvers/mg.hpp"

#include "core/check.hpp"
#include "core/csr.hpp"
#include "core/timer.hpp"
#include "smoothers/matrix_checks.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace mlc::solvers {

// ---------------------------------------------------------------------------------------------
void MultigridParams::validate() const {
    MLC_CHECK(pre_sweeps >= 0, "mg: pre must be >= 0, found " << pre_sweeps);
    MLC_CHECK(post_sweeps >= 0, "mg: post must be >= 0, found " << post_sweeps);
    MLC_CHECK(pre_sweeps + post_sweeps >= 1, "mg: pre + post must be >= 1 (no smoothing at all)");
    MLC_CHECK(omega > 0.0 && omega < 2.0, "mg: omega must be in (0, 2), found " << omega);
}

std::ostream& operator<<(std::ostream& os, const MultigridParams& p) {
    return os << "MultigridParams{pre=" << p.pre_sweeps << ", post=" << p.post_sweeps
              << ", omega=" << p.omega << "}";
}

namespace {
// The cycle's smoother: vertex-block Gauss–Seidel in threaded parts with the unrolled kernel
// (params validated first, so that a bad omega is reported as the cycle's).
smoothers::BlockSORParams smoother_params(const MultigridParams& params,
                                          std::vector<Index> block_starts) {
    params.validate();
    return {.omega = params.omega,
            .block_size = 2,
            .block_starts = std::move(block_starts),
            .parts = 0,
            .kernel = smoothers::Kernel::unrolled};
}
} // namespace

MultigridCycle::MultigridCycle(const SparseMatrix& T, const SparseMatrix& R, CoarseSolve coarse,
                               std::vector<Index> block_starts, MultigridParams params)
    : T_(T), R_(R), coarse_(std::move(coarse)),
      smoother_(smoother_params(params, std::move(block_starts))), params_(params) {
    params_.validate();
    MLC_CHECK(R.rows() == T.cols() && R.cols() == T.rows(),
              "MultigridCycle: R is " << R.rows() << " x " << R.cols() << ", T is " << T.rows()
                                      << " x " << T.cols() << " (R must be coarse x fine)");
}

void MultigridCycle::setup(const SparseMatrix& A) {
    MLC_CHECK(A.rows() == T_.rows(), "MultigridCycle::setup: the matrix has "
                                         << A.rows() << " rows, the prolongation " << T_.rows());
    A_ = &A;
    smoother_.setup(A);
    res_.resize(A.rows());
    rc_.resize(R_.rows());
    ec_.resize(R_.rows());
}

void MultigridCycle::update_values(const SparseMatrix& A) {
    if (A_ == nullptr || res_.size() != A.rows()) {
        setup(A);
        return;
    }
    A_ = &A;
    smoother_.update_values(A);
}

void MultigridCycle::apply(const Vector& r, Vector& z) const {
    MLC_CHECK(A_ != nullptr, "MultigridCycle: call setup first");
    smoothers::check_size(r, A_->rows(), "MultigridCycle::apply", "r");
    MLC_CHECK(static_cast<bool>(coarse_), "MultigridCycle: no coarse solve set");
    if (params_.pre_sweeps == 0) {
        z.setZero(r.size());
        res_ = r;
    } else {
        smoother_.forward_from_zero(r, z, res_);
        for (int k = 1; k < params_.pre_sweeps; ++k)
            smoother_.sweep(r, z, smoothers::Sweep::forward);
        if (params_.pre_sweeps > 1) {
            res_ = r;
            res_.noalias() -= *A_ * z;
        }
    }
    csr_multiply(R_, res_, rc_);
    coarse_(rc_, ec_);
    csr_multiply(T_, ec_, z, true);
    for (int k = 0; k < params_.post_sweeps; ++k)
        smoother_.sweep(r, z, smoothers::Sweep::backward);
}

std::string MultigridCycle::name() const {
    std::ostringstream os;
    os << "mg(pre=" << params_.pre_sweeps << ",post=" << params_.post_sweeps
       << ",omega=" << params_.omega << ")";
    return os.str();
}

// ---------------------------------------------------------------------------------------------
// ---------------------------------------------------------------------------------------------
SolveResult pcg(const SparseMatrix& A, const Preconditioner& M, const Vector& b, Vector& x,
                double rel_tol, int max_iter) {
    MLC_CHECK(rel_tol > 0.0 && rel_tol < 1.0, "pcg: rel_tol must be in (0, 1), found " << rel_tol);
    MLC_CHECK(max_iter >= 1, "pcg: max_iter must be >= 1, found " << max_iter);
    MLC_CHECK(A.rows() == A.cols() && b.size() == A.rows(),
              "pcg: A is " << A.rows() << " x " << A.cols() << ", b has " << b.size());
    const double t0 = wall_seconds();
    if (x.size() != b.size()) x = Vector::Zero(b.size());
    SolveResult res;
    Vector r = b;
    r.noalias() -= A * x;
    Vector z(b.size()), p(b.size()), q(b.size());
    const MatrixOperator Aop(A, MatVec::unrolled);
    const double bnorm = b.norm();
    const double target = rel_tol * (bnorm > 0 ? bnorm : r.norm());
    res.initial_residual = r.norm();
    double rnorm = res.initial_residual;
    double rz = 0.0;
    int it = 0;
    while (rnorm > target && it < max_iter) {
        M.apply(r, z);
        const double rz_new = r.dot(z);
        if (it == 0)
            p = z;
        else
            p = z + (rz_new / rz) * p;
        rz = rz_new;
        Aop.apply(p, q);
        const double pq = p.dot(q);
        if (!(pq > 0.0) || !std::isfinite(pq)) {
            res.reason = StopReason::breakdown;
            res.message = "p^T A p is not positive";
            break;
        }
        const double alpha = rz / pq;
        x += alpha * p;
        r -= alpha * q;
        rnorm = r.norm();
        ++it;
    }
    r = b;
    r.noalias() -= A * x;
    res.iterations = it;
    res.final_residual = r.norm();
    res.relative_residual = res.final_residual / (bnorm > 0 ? bnorm : res.initial_residual);
    res.converged = res.reason != StopReason::breakdown && rnorm <= target;
    if (res.converged) res.reason = StopReason::converged;
    if (it > 0 && res.initial_residual > 0)
        res.average_rate = std::pow(res.final_residual / res.initial_residual, 1.0 / it);
    res.solve_seconds = wall_seconds() - t0;
    return res;
}

std::vector<Index> vertex_block_starts(const std::vector<int>& vertex_of_dof) {
    std::vector<Index> starts;
    for (size_t i = 0; i < vertex_of_dof.size(); ++i)
        if (i == 0 || vertex_of_dof[i] != vertex_of_dof[i - 1])
            starts.push_back(static_cast<Index>(i));
    return starts;
}

} // namespace mlc::solvers

// SPDX-License-Identifier: MIT
// Eigen::SparseLU wrapped as a Preconditioner, with pattern-checked reuse of the analysis.
#include "solvers/direct.hpp"

#include "core/check.hpp"
#include "core/csr.hpp"
#include "smoothers/matrix_checks.hpp"

#include <Eigen/SparseLU>

#include <algorithm>
#include <vector>

namespace mlc::solvers {

void SparseLUParams::validate() const {
    MLC_CHECK(pivot_threshold > 0.0 && pivot_threshold <= 1.0,
              "SparseLUParams::pivot_threshold must be in (0, 1], found " << pivot_threshold);
}

std::ostream& operator<<(std::ostream& os, const SparseLUParams& p) {
    return os << "SparseLUParams{pivot_threshold=" << p.pivot_threshold << "}";
}

struct SparseLUPreconditioner::Impl {
    SparseMatrixCol Acol;
    Eigen::SparseLU<SparseMatrixCol, Eigen::COLAMDOrdering<int>> lu;
    SparsityPattern pattern; // of the analysed A (empty before the first analysis)
    bool factorized = false;
    int n_analyses = 0;
};

SparseLUPreconditioner::SparseLUPreconditioner(SparseLUParams params)
    : params_(params), impl_(std::make_unique<Impl>()) {
    params_.validate();
}
SparseLUPreconditioner::~SparseLUPreconditioner() = default;
SparseLUPreconditioner::SparseLUPreconditioner(SparseLUPreconditioner&&) noexcept = default;
SparseLUPreconditioner&
SparseLUPreconditioner::operator=(SparseLUPreconditioner&&) noexcept = default;

void SparseLUPreconditioner::setup(const SparseMatrix& A) {
    smoothers::check_setup_matrix(A, "SparseLUPreconditioner::setup");
    Impl& m = *impl_;
    m.pattern = SparsityPattern();
    m.Acol = A;
    m.Acol.makeCompressed();
    m.lu.setPivotThreshold(params_.pivot_threshold);
    m.lu.analyzePattern(m.Acol);
    ++m.n_analyses;
    m.pattern = SparsityPattern(A);
    m.factorized = false;
    m.lu.factorize(m.Acol);
    if (m.lu.info() != Eigen::Success)
        throw SolverBreakdown("SparseLUPreconditioner: factorization failed (" +
                              m.lu.lastErrorMessage() +
                              "); the matrix is singular: check the Dirichlet conditions and "
                              "the gap contact rows");
    m.factorized = true;
}

void SparseLUPreconditioner::update_values(const SparseMatrix& A) {
    Impl& m = *impl_;
    if (!m.pattern.matches(A)) {
        setup(A);
        return;
    }
    smoothers::check_setup_matrix(A, "SparseLUPreconditioner::update_values");
    m.Acol = A; // same pattern, so the column-major pattern is the analysed one
    m.Acol.makeCompressed();
    m.factorized = false;
    m.lu.factorize(m.Acol);
    if (m.lu.info() != Eigen::Success)
        throw SolverBreakdown("SparseLUPreconditioner: refactorization failed (" +
                              m.lu.lastErrorMessage() + "); the matrix is singular");
    m.factorized = true;
}

void SparseLUPreconditioner::apply(const Vector& r, Vector& z) const {
    MLC_CHECK(impl_ && impl_->factorized,
              "SparseLUPreconditioner::apply called before a successful setup");
    smoothers::check_size(r, impl_->Acol.rows(), "SparseLUPreconditioner::apply", "r");
    z = impl_->lu.solve(r);
}

void SparseLUPreconditioner::apply_transpose(const Vector& r, Vector& z) const {
    MLC_CHECK(impl_ && impl_->factorized,
              "SparseLUPreconditioner::apply_transpose called before a successful setup");
    smoothers::check_size(r, impl_->Acol.rows(), "SparseLUPreconditioner::apply_transpose", "r");
    z = impl_->lu.transpose().solve(r);
}

int SparseLUPreconditioner::n_analyses() const {
    return impl_ ? impl_->n_analyses : 0;
}

} // namespace mlc::solvers

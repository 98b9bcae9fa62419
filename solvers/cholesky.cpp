// SPDX-License-Identifier: MIT
// CHOLMOD supernodal Cholesky with a given order (the only place that includes CHOLMOD).
#include "solvers/cholesky.hpp"

#include "core/check.hpp"

#include <algorithm>
#include <cholmod.h>
#include <cstring>

namespace mlc::solvers {

namespace {

/// A CHOLMOD view (no copy) of the lower triangle of a compressed column-major matrix.
cholmod_sparse lower_view(SparseMatrixCol& A, int xtype) {
    cholmod_sparse S;
    std::memset(&S, 0, sizeof(S));
    S.nrow = S.ncol = static_cast<size_t>(A.rows());
    S.nzmax = static_cast<size_t>(A.nonZeros());
    S.p = A.outerIndexPtr();
    S.i = A.innerIndexPtr();
    S.x = A.valuePtr();
    S.stype = -1; // lower triangle stored
    S.itype = CHOLMOD_INT;
    S.xtype = xtype;
    S.dtype = CHOLMOD_DOUBLE;
    S.sorted = 1;
    S.packed = 1;
    return S;
}

} // namespace

struct SparseCholesky::Impl {
    cholmod_common c;
    cholmod_factor* L = nullptr;
    Index n = 0;
    Impl() {
        cholmod_start(&c);
        c.nmethods = 1;
        c.method[0].ordering = CHOLMOD_NATURAL; // the caller's order
        c.postorder = 0;                         // keep it: the trailing set must stay last
        c.supernodal = CHOLMOD_SUPERNODAL;
        c.print = 0;
    }
    ~Impl() {
        if (L) cholmod_free_factor(&L, &c);
        cholmod_finish(&c);
    }
};

SparseCholesky::SparseCholesky() : impl_(std::make_unique<Impl>()) {}
SparseCholesky::~SparseCholesky() = default;

void SparseCholesky::factor(const SparseMatrixCol& A_in) {
    MLC_CHECK(A_in.rows() == A_in.cols(), "SparseCholesky: matrix is not square");
    // A compressed lower triangle is viewed as it is (CHOLMOD reads it only); anything else is
    // copied to one first.
    bool lower = A_in.isCompressed();
    for (Index j = 0; lower && j < A_in.outerSize(); ++j) {
        const int begin = A_in.outerIndexPtr()[j], end = A_in.outerIndexPtr()[j + 1];
        lower = begin == end || A_in.innerIndexPtr()[begin] >= j;
    }
    SparseMatrixCol copy;
    if (!lower) {
        copy = A_in.triangularView<Eigen::Lower>();
        copy.makeCompressed();
    }
    SparseMatrixCol& A = lower ? const_cast<SparseMatrixCol&>(A_in) : copy;
    auto& c = impl_->c;
    if (impl_->L) cholmod_free_factor(&impl_->L, &c);
    cholmod_sparse S = lower_view(A, CHOLMOD_REAL);
    impl_->L = cholmod_analyze(&S, &c);
    MLC_CHECK(impl_->L != nullptr, "CHOLMOD analysis failed (status " << c.status << ")");
    cholmod_factorize(&S, impl_->L, &c);
    MLC_CHECK(c.status == CHOLMOD_OK && impl_->L->minor == impl_->L->n,
              "the matrix is not positive definite (Cholesky breaks down at column "
                  << impl_->L->minor << " of " << impl_->L->n << ")");
    impl_->n = A.rows();
}

void SparseCholesky::solve(const Vector& b, Vector& x) const {
    MLC_CHECK(impl_->L && b.size() == impl_->n, "SparseCholesky::solve before factor or size mismatch");
    cholmod_dense B;
    std::memset(&B, 0, sizeof(B));
    B.nrow = static_cast<size_t>(b.size());
    B.ncol = 1;
    B.nzmax = B.nrow;
    B.d = B.nrow;
    B.x = const_cast<double*>(b.data());
    B.xtype = CHOLMOD_REAL;
    B.dtype = CHOLMOD_DOUBLE;
    cholmod_dense* X = cholmod_solve(CHOLMOD_A, impl_->L, &B, &impl_->c);
    MLC_CHECK(X != nullptr, "CHOLMOD solve failed");
    x = Eigen::Map<const Vector>(static_cast<const double*>(X->x), b.size());
    cholmod_free_dense(&X, &impl_->c);
}

Eigen::MatrixXd SparseCholesky::trailing_block(Index nb) const {
    MLC_CHECK(impl_->L && nb <= impl_->n, "SparseCholesky::trailing_block: bad size");
    const Index n = impl_->n, first = n - nb;
    const cholmod_factor* L = impl_->L;
    if (L->is_super) {
        // Read the supernodes in place (no copy of the factor): supernode k holds columns
        // super[k] .. super[k+1]-1, its rows s[pi[k]] .. s[pi[k+1]-1] (the first of them its own
        // columns), values column by column from px[k]; entries above the diagonal are unused.
        Eigen::MatrixXd out = Eigen::MatrixXd::Zero(nb, nb);
        const int* super = static_cast<const int*>(L->super);
        const int* pi = static_cast<const int*>(L->pi);
        const int* px = static_cast<const int*>(L->px);
        const int* rows = static_cast<const int*>(L->s);
        const double* x = static_cast<const double*>(L->x);
        for (size_t k = 0; k < L->nsuper; ++k) {
            const int j0 = super[k], j1 = super[k + 1];
            if (j1 <= first) continue;
            const int nr = pi[k + 1] - pi[k];
            for (int j = std::max<int>(j0, static_cast<int>(first)); j < j1; ++j) {
                const double* col = x + px[k] + static_cast<size_t>(j - j0) * nr;
                for (int q = 0; q < nr; ++q) {
                    const int i = rows[pi[k] + q];
                    if (i >= j) out(i - first, j - first) = col[q];
                }
            }
        }
        return out;
    }
    auto& c = impl_->c;
    cholmod_factor* F = cholmod_copy_factor(impl_->L, &c);
    cholmod_sparse* S = cholmod_factor_to_sparse(F, &c);
    cholmod_free_factor(&F, &c);
    MLC_CHECK(S != nullptr, "CHOLMOD could not convert the factor");
    Eigen::MatrixXd out = Eigen::MatrixXd::Zero(nb, nb);
    const int* p = static_cast<const int*>(S->p);
    const int* i = static_cast<const int*>(S->i);
    const double* x = static_cast<const double*>(S->x);
    for (Index j = first; j < n; ++j)
        for (int k = p[j]; k < p[j + 1]; ++k)
            if (i[k] >= first) out(i[k] - first, j - first) = x[k];
    cholmod_free_sparse(&S, &c);
    return out;
}

std::vector<int> SparseCholesky::fill_reducing_order(const SparseMatrixCol& A_in) {
    SparseMatrixCol A = A_in.triangularView<Eigen::Lower>();
    A.makeCompressed();
    cholmod_common c;
    cholmod_start(&c);
    c.print = 0;
    c.nmethods = 1;
    c.method[0].ordering = CHOLMOD_NESDIS; // nested dissection (METIS-based): least fill on 2D meshes
    cholmod_sparse S = lower_view(A, CHOLMOD_PATTERN);
    cholmod_factor* L = cholmod_analyze(&S, &c);
    if (!L) {
        // No METIS in this CHOLMOD build: fall back to its default choice.
        cholmod_finish(&c);
        cholmod_start(&c);
        c.print = 0;
        L = cholmod_analyze(&S, &c);
    }
    MLC_CHECK(L != nullptr, "CHOLMOD ordering failed (status " << c.status << ")");
    const int* perm = static_cast<const int*>(L->Perm);
    std::vector<int> order(perm, perm + A.rows());
    cholmod_free_factor(&L, &c);
    cholmod_finish(&c);
    return order;
}

double SparseCholesky::factor_nonzeros() const {
    return impl_ ? impl_->c.lnz : 0.0;
}

} // namespace mlc::solvers

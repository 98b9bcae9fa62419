// SPDX-License-Identifier: MIT
// CSR kernels: row-parallel mat-vec and the sparsity-pattern comparison.
#include "core/csr.hpp"

#include "core/check.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mlc {

namespace {

int max_threads() {
#ifdef _OPENMP
    return omp_get_max_threads();
#else
    return 1;
#endif
}

// The one comparison behind same_pattern and SparsityPattern::matches.
bool equal_pattern(Index rows, Index cols, const int* outer, const int* inner, Index nonzeros,
                   const SparseMatrix& B) {
    if (!B.isCompressed() || rows != B.rows() || cols != B.cols() || nonzeros != B.nonZeros())
        return false;
    const int* bo = B.outerIndexPtr();
    if (!std::equal(outer, outer + rows + 1, bo)) return false;
    return std::equal(inner, inner + nonzeros, B.innerIndexPtr());
}

} // namespace

int threads_for_rows(Index n) {
    return static_cast<int>(std::clamp<Index>(n / kMinRowsPerThread, 1, max_threads()));
}

void csr_multiply(const SparseMatrix& A, const Vector& x, Vector& y, bool add) {
    MLC_CHECK(x.size() == A.cols() && (!add || y.size() == A.rows()),
              "csr_multiply: A is " << A.rows() << " x " << A.cols() << ", x has " << x.size()
                                    << ", y has " << y.size());
    MLC_CHECK(A.isCompressed(), "csr_multiply: A must be compressed");
    const Index n = A.rows();
    if (!add) y.resize(n);
    const int* outer = A.outerIndexPtr();
    const int* inner = A.innerIndexPtr();
    const double* val = A.valuePtr();
    const double* xp = x.data();
    double* yp = y.data();
    const int threads = threads_for_rows(n);
    if (add) {
#pragma omp parallel for num_threads(threads) schedule(static) if (threads > 1)
        for (Index i = 0; i < n; ++i)
            yp[i] += row_dot(inner, val, xp, outer[i], outer[i + 1]);
    } else {
#pragma omp parallel for num_threads(threads) schedule(static) if (threads > 1)
        for (Index i = 0; i < n; ++i)
            yp[i] = row_dot(inner, val, xp, outer[i], outer[i + 1]);
    }
}

bool same_pattern(const SparseMatrix& A, const SparseMatrix& B) {
    if (!A.isCompressed()) return false;
    return equal_pattern(A.rows(), A.cols(), A.outerIndexPtr(), A.innerIndexPtr(), A.nonZeros(), B);
}

SparsityPattern::SparsityPattern(const SparseMatrix& A)
    : rows_(A.rows()), cols_(A.cols()),
      outer_(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1) {
    MLC_CHECK(A.isCompressed(), "SparsityPattern: the matrix must be compressed");
    inner_.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
}

bool SparsityPattern::matches(const SparseMatrix& A) const {
    if (outer_.empty()) return false;
    return equal_pattern(rows_, cols_, outer_.data(), inner_.data(),
                         static_cast<Index>(inner_.size()), A);
}

} // namespace mlc

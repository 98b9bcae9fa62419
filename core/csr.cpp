// SPDX-License-Identifier: MIT
// CSR kernels: row-parallel mat-vec and the sparsity-pattern comparison.
#include "core/csr.hpp"

#include "core/check.hpp"
#include "core/parallel.hpp"

namespace mlc {

namespace {

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

void csr_multiply(const SparseMatrix& A, const Vector& x, Vector& y, bool add, traffic::Kind kind) {
    MLC_CHECK(x.size() == A.cols() && (!add || y.size() == A.rows()),
              "csr_multiply: A is " << A.rows() << " x " << A.cols() << ", x has " << x.size()
                                    << ", y has " << y.size());
    MLC_CHECK(A.isCompressed(), "csr_multiply: A must be compressed");
    const Index n = A.rows();
    if (!add) y.resize(n);
    const traffic::Pass pass(kind, traffic::csr_bytes(n, A.cols(), A.nonZeros(), add));
    const int* outer = A.outerIndexPtr();
    const int* inner = A.innerIndexPtr();
    const double* val = A.valuePtr();
    const double* xp = x.data();
    double* yp = y.data();
    // Chunks of at least kMinRowsPerThread rows claimed by the pool's threads (core/parallel):
    // every row is summed the same way whoever runs it, and a loaded core only does fewer chunks.
    parallel::for_rows(static_cast<size_t>(n), static_cast<size_t>(kMinRowsPerThread),
                       [&](size_t b, size_t e) {
                           if (add)
                               for (size_t i = b; i < e; ++i)
                                   yp[i] += row_dot(inner, val, xp, outer[i], outer[i + 1]);
                           else
                               for (size_t i = b; i < e; ++i)
                                   yp[i] = row_dot(inner, val, xp, outer[i], outer[i + 1]);
                       });
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

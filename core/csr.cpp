// SPDX-License-Identifier: MIT
// CSR kernels: row-parallel mat-vec and the sparsity-pattern comparison.
#include "core/csr.hpp"

#include "core/first_touch.hpp"

#include "core/check.hpp"
#include "core/parallel.hpp"

#include <cmath>

namespace mlc {

namespace {

// The one comparison behind same_pattern and SparsityPattern::matches.
bool equal_pattern(Index rows, Index cols, const int* outer, const int* inner, Index nonzeros,
                   const SparseMatrix& B) {
    if (!B.isCompressed() || rows != B.rows() || cols != B.cols() || nonzeros != B.nonZeros())
        return false;
    const int* bo = B.outerIndexPtr();
    const int* bi = B.innerIndexPtr();
    // The rows over the threads (a refresh of a Newton Jacobian compares 120 MB of column
    // indices at level 6 of the square): equal when every chunk is.
    const parallel::RowChunks rc =
        parallel::row_chunks(static_cast<size_t>(rows), static_cast<size_t>(kMinRowsPerThread));
    std::vector<char> same(rc.count, 0);
    parallel::for_chunks(rc.count, [&](size_t c) {
        const size_t r0 = rc.begin(c), r1 = rc.end(c);
        // Chunk c compares its rows' offsets (the last chunk also the final one) and, when they
        // agree, the column indices they delimit.
        const size_t o1 = c + 1 == rc.count ? r1 + 1 : r1;
        if (!std::equal(outer + r0, outer + o1, bo + r0)) return;
        same[c] = std::equal(inner + outer[r0], inner + outer[r1], bi + outer[r0]);
    });
    return std::all_of(same.begin(), same.end(), [](char c) { return c != 0; });
}

} // namespace

template <class Value>
void csr_multiply(const CsrArrays<Value>& A, const Vector& x, Vector& y, bool add,
                  traffic::Kind kind) {
    MLC_CHECK(x.size() == A.cols && (!add || y.size() == A.rows),
              "csr_multiply: A is " << A.rows << " x " << A.cols << ", x has " << x.size()
                                    << ", y has " << y.size());
    const Index n = A.rows;
    if (!add) y.resize(n);
    const traffic::Pass pass(
        kind, traffic::csr_bytes(n, A.cols, A.nonzeros(), add, static_cast<int>(sizeof(Value))));
    const int* outer = A.outer;
    const int* inner = A.inner;
    const Value* val = A.values;
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

template void csr_multiply(const CsrArrays<double>&, const Vector&, Vector&, bool, traffic::Kind);
template void csr_multiply(const CsrArrays<float>&, const Vector&, Vector&, bool, traffic::Kind);

void csr_multiply(const SparseMatrix& A, const Vector& x, Vector& y, bool add, traffic::Kind kind) {
    MLC_CHECK(A.isCompressed(), "csr_multiply: A must be compressed");
    csr_multiply(csr_arrays(A, A.valuePtr()), x, y, add, kind);
}

namespace {

/// Row i of A x summed in storage order with one accumulator (Eigen's serial order).
inline double row_sum_in_order(const int* outer, const int* inner, const double* val,
                               const double* x, size_t i) {
    double s = 0.0;
    for (int k = outer[i]; k < outer[i + 1]; ++k)
        s += val[k] * x[inner[k]];
    return s;
}

} // namespace

void csr_multiply_in_order(const SparseMatrix& A, const Vector& x, Vector& y) {
    MLC_CHECK(A.isCompressed(), "csr_multiply_in_order: A must be compressed");
    MLC_CHECK(x.size() == A.cols(), "csr_multiply_in_order: A is " << A.rows() << " x " << A.cols()
                                                                   << ", x has " << x.size());
    y.resize(A.rows());
    const int* outer = A.outerIndexPtr();
    const int* inner = A.innerIndexPtr();
    const double* val = A.valuePtr();
    const double* xp = x.data();
    double* yp = y.data();
    parallel::for_rows(static_cast<size_t>(A.rows()), static_cast<size_t>(kMinRowsPerThread),
                       [&](size_t i0, size_t i1) {
                           for (size_t i = i0; i < i1; ++i)
                               yp[i] = row_sum_in_order(outer, inner, val, xp, i);
                       });
}

void csr_residual_in_order(const SparseMatrix& A, const Vector& b, const Vector& x, Vector& res) {
    MLC_CHECK(A.isCompressed(), "csr_residual_in_order: A must be compressed");
    MLC_CHECK(x.size() == A.cols() && b.size() == A.rows(),
              "csr_residual_in_order: A is " << A.rows() << " x " << A.cols() << ", x has "
                                             << x.size() << ", b has " << b.size());
    res.resize(A.rows());
    const int* outer = A.outerIndexPtr();
    const int* inner = A.innerIndexPtr();
    const double* val = A.valuePtr();
    const double* xp = x.data();
    const double* bp = b.data();
    double* rp = res.data();
    parallel::for_rows(static_cast<size_t>(A.rows()), static_cast<size_t>(kMinRowsPerThread),
                       [&](size_t i0, size_t i1) {
                           for (size_t i = i0; i < i1; ++i)
                               rp[i] = bp[i] - row_sum_in_order(outer, inner, val, xp, i);
                       });
}

template <class Value>
void csr_residual(const CsrArrays<Value>& A, const Vector& b, const Vector& x, Vector& res,
                  traffic::Kind kind) {
    MLC_CHECK(x.size() == A.cols && b.size() == A.rows,
              "csr_residual: A is " << A.rows << " x " << A.cols << ", x has " << x.size()
                                    << ", b has " << b.size());
    const Index n = A.rows;
    res.resize(n);
    const traffic::Pass pass(
        kind, traffic::csr_bytes(n, A.cols, A.nonzeros(), true, static_cast<int>(sizeof(Value))));
    const int* outer = A.outer;
    const int* inner = A.inner;
    const Value* val = A.values;
    const double* xp = x.data();
    const double* bp = b.data();
    double* rp = res.data();
    parallel::for_rows(static_cast<size_t>(n), static_cast<size_t>(kMinRowsPerThread),
                       [&](size_t i0, size_t i1) {
                           for (size_t i = i0; i < i1; ++i)
                               rp[i] = bp[i] - row_dot(inner, val, xp, outer[i], outer[i + 1]);
                       });
}

template void csr_residual(const CsrArrays<double>&, const Vector&, const Vector&, Vector&,
                           traffic::Kind);
template void csr_residual(const CsrArrays<float>&, const Vector&, const Vector&, Vector&,
                           traffic::Kind);

Index row_of_entry(const SparseMatrix& A, Index k) {
    const int* outer = A.outerIndexPtr();
    return std::upper_bound(outer, outer + A.outerSize() + 1, k) - outer - 1;
}

void round_values(const SparseMatrix& A, parallel::UninitializedVector<float>& out,
                  const char* who) {
    MLC_CHECK(A.isCompressed(), who << ": the matrix must be compressed");
    const auto nnz = static_cast<size_t>(A.nonZeros());
    out.resize(nnz);
    const double* v = A.valuePtr();
    float* o = out.data();
    // The entries over the threads (a Newton Jacobian is rounded at every refresh: 29 million
    // values at level 6 of the square); the first entry without a float value is named.
    const size_t bad =
        parallel::first_flagged(nnz, parallel::kTouchRowsPerChunk, [&](size_t b, size_t e) {
            bool finite = true;
            for (size_t k = b; k < e; ++k) {
                o[k] = static_cast<float>(v[k]);
                finite &= std::isfinite(o[k]);
            }
            if (finite) return e;
            return static_cast<size_t>(
                std::find_if(o + b, o + e, [](float f) { return !std::isfinite(f); }) - o);
        });
    MLC_CHECK(bad == nnz, who << ": entry (" << row_of_entry(A, static_cast<Index>(bad)) << ", "
                              << A.innerIndexPtr()[bad] << ") = " << v[bad]
                              << " has no single-precision value (beyond +-3.4e38, or not "
                                 "finite); use precision=double");
}

bool same_pattern(const SparseMatrix& A, const SparseMatrix& B) {
    if (!A.isCompressed()) return false;
    return equal_pattern(A.rows(), A.cols(), A.outerIndexPtr(), A.innerIndexPtr(), A.nonZeros(), B);
}

SparsityPattern::SparsityPattern(const SparseMatrix& A)
    : rows_(A.rows()), cols_(A.cols()), n_outer_(static_cast<size_t>(A.outerSize()) + 1),
      n_inner_(static_cast<size_t>(A.nonZeros())) {
    MLC_CHECK(A.isCompressed(), "SparsityPattern: the matrix must be compressed");
    // Copied with the rows over the threads (core/first_touch): at level 7 of the square the
    // Jacobian's column indices are 470 MB of fresh memory.
    outer_ = parallel::uninitialized_array<int>(n_outer_);
    inner_ = parallel::uninitialized_array<int>(n_inner_);
    parallel::copy(A.outerIndexPtr(), n_outer_, outer_.get());
    parallel::copy(A.innerIndexPtr(), n_inner_, inner_.get());
}

SparsityPattern::SparsityPattern(const SparsityPattern& o)
    : rows_(o.rows_), cols_(o.cols_), n_outer_(o.n_outer_), n_inner_(o.n_inner_) {
    if (!o.outer_) return;
    outer_ = parallel::uninitialized_array<int>(n_outer_);
    inner_ = parallel::uninitialized_array<int>(n_inner_);
    parallel::copy(o.outer_.get(), n_outer_, outer_.get());
    parallel::copy(o.inner_.get(), n_inner_, inner_.get());
}

SparsityPattern& SparsityPattern::operator=(const SparsityPattern& o) {
    if (this != &o) *this = SparsityPattern(o);
    return *this;
}

bool SparsityPattern::matches(const SparseMatrix& A) const {
    if (!outer_) return false;
    return equal_pattern(rows_, cols_, outer_.get(), inner_.get(), static_cast<Index>(n_inner_), A);
}

} // namespace mlc

// SPDX-License-Identifier: MIT
/// @file Kernels on compressed CSR matrices shared by every folder: the row dot product with four
/// accumulators, the row-parallel mat-vec `csr_multiply`, and the sparsity-pattern check that
/// decides whether a preconditioner may only refresh its values.
#pragma once

#include "core/first_touch.hpp"
#include "core/traffic.hpp"
#include "core/types.hpp"

#include <algorithm>
#include <memory>
#include <vector>

namespace mlc {

/// Rows per chunk of a row-parallel kernel (csr_multiply, the parts of the hybrid block
/// Gauss–Seidel) at least: small levels stay sequential, where handing rows to another thread
/// would cost more than the rows.
inline constexpr Index kMinRowsPerThread = 4096;

/// sum_k val[k] x[inner[k]] for k in [k0, k1) with four independent accumulators, returned as
/// (a0 + a1) + (a2 + a3): accumulator j takes the entries k0 + j, k0 + j + 4, ... of the full
/// groups of four, and a0 also the (k1 - k0) mod 4 remaining ones.
///
/// Why four: a single accumulator chains every multiply-add on the previous one, and the
/// sweeps and mat-vecs (about 18 entries per row) were bound by that latency rather than by
/// memory bandwidth. The summation order differs from a one-accumulator loop, so results differ
/// from Eigen's product in the last bits.
/// Templated over the stored value type: with float values (the multigrid's single-precision
/// data) every product is formed and summed in double, only the stored entry is rounded.
template <class Value>
inline double row_dot(const int* inner, const Value* val, const double* x, int k0, int k1) {
    double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0;
    int k = k0;
    for (; k + 3 < k1; k += 4) {
        a0 += val[k] * x[inner[k]];
        a1 += val[k + 1] * x[inner[k + 1]];
        a2 += val[k + 2] * x[inner[k + 2]];
        a3 += val[k + 3] * x[inner[k + 3]];
    }
    for (; k < k1; ++k)
        a0 += val[k] * x[inner[k]];
    return (a0 + a1) + (a2 + a3);
}

/// row_dot of two rows with the same columns at once (a vertex's twin rows: BlockSOR's sweeps): r0
/// over entries [k0, k1) of the first row, r1 over the same positions of the second, whose values
/// are `len` entries on. Each row has row_dot's four accumulators and order, so r0 and r1 are its
/// values bit for bit; a change of row_dot's order must be made here too (tests/smoothers: the twin
/// test compares them).
template <class Value>
inline void twin_row_dot(const int* inner, const Value* val, int len, const double* x, int k0,
                         int k1, double& r0, double& r1) {
    const Value* w = val + len;
    double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0;
    double b0 = 0.0, b1 = 0.0, b2 = 0.0, b3 = 0.0;
    int k = k0;
    for (; k + 3 < k1; k += 4) {
        const double x0 = x[inner[k]], x1 = x[inner[k + 1]];
        const double x2 = x[inner[k + 2]], x3 = x[inner[k + 3]];
        a0 += val[k] * x0;
        a1 += val[k + 1] * x1;
        a2 += val[k + 2] * x2;
        a3 += val[k + 3] * x3;
        b0 += w[k] * x0;
        b1 += w[k + 1] * x1;
        b2 += w[k + 2] * x2;
        b3 += w[k + 3] * x3;
    }
    for (; k < k1; ++k) {
        const double xk = x[inner[k]];
        a0 += val[k] * xk;
        b0 += w[k] * xk;
    }
    r0 = (a0 + a1) + (a2 + a3);
    r1 = (b0 + b1) + (b2 + b3);
}

/// y = A x (or y += A x with `add`) for a compressed CSR matrix, each row by `row_dot`, rows
/// split into chunks of at least kMinRowsPerThread rows run by core/parallel's threads (every
/// row is summed the same way
/// whatever the thread count, so the result does not depend on it). Without `add`, y is
/// resized; with it, y must have A.rows() entries. Throws mlc::InvalidInput on a size mismatch
/// or an uncompressed A. Does not allocate once y has its size. Counts one pass of `kind`
/// (core/traffic.hpp: traffic::csr_bytes(A.rows(), A.cols(), A.nonZeros(), add) bytes).
void csr_multiply(const SparseMatrix& A, const Vector& x, Vector& y, bool add = false,
                  traffic::Kind kind = traffic::Kind::matvec);

/// y = A x for a compressed CSR matrix, each row summed in storage order with one accumulator:
/// bit for bit Eigen's serial `y = A * x`, but with the rows split as in csr_multiply over
/// core/parallel's threads. Counts no traffic (MatrixOperator's `in_order` kernel counts its own
/// pass; the Newton residual is outside the linear solves the bandwidth account covers).
void csr_multiply_in_order(const SparseMatrix& A, const Vector& x, Vector& y);

/// res = b - A x for a compressed CSR matrix, each row's product summed in storage order with one
/// accumulator: bit for bit Eigen's serial `res = b; res.noalias() -= A * x`, with the rows split
/// over core/parallel's threads (Eigen's own product would start OpenMP threads that spin against
/// them). res is resized; counts no traffic (callers count their own pass).
void csr_residual_in_order(const SparseMatrix& A, const Vector& b, const Vector& x, Vector& res);

/// Precision in which a preconditioner stores its matrix data (values, block inverses, transfers);
/// its vectors and the Krylov method stay double either way.
enum class Precision {
    float64, ///< double: the values as assembled (the default)
    float32  ///< float: every stored value rounded once, products and sums still in double
};

/// "double" or "single".
inline const char* to_string(Precision p) {
    return p == Precision::float32 ? "single" : "double";
}

/// Bytes of one stored value in `p`: 8 or 4.
inline int value_bytes(Precision p) {
    return p == Precision::float32 ? 4 : 8;
}

/// A compressed CSR matrix by its arrays: `outer` (rows + 1 offsets), `inner` (column indices)
/// and `values` of type Value, all borrowed. The pattern is usually an Eigen matrix's and the
/// values either its own (double) or a rounded copy (float, `round_values`).
template <class Value> struct CsrArrays {
    Index rows = 0, cols = 0;
    const int* outer = nullptr;
    const int* inner = nullptr;
    const Value* values = nullptr;
    Index nonzeros() const { return rows > 0 ? outer[rows] : 0; }
};

/// The arrays of a compressed A with `values` in place of its own (values.size() == nnz).
template <class Value> CsrArrays<Value> csr_arrays(const SparseMatrix& A, const Value* values) {
    return {A.rows(), A.cols(), A.outerIndexPtr(), A.innerIndexPtr(), values};
}

/// The row of a compressed A's stored entry k (0 <= k < nnz), for messages naming an entry.
Index row_of_entry(const SparseMatrix& A, Index k);

/// A's stored values rounded to float into `out` (resized to A.nonZeros(); no allocation when it
/// has that size). A must be compressed. Throws mlc::InvalidInput, naming `who`, if a finite
/// value overflows float (|a| > 3.4e38) or A holds NaN or Inf.
void round_values(const SparseMatrix& A, parallel::UninitializedVector<float>& out,
                  const char* who);

/// y = A x (or y += A x with `add`) on CSR arrays with values of type Value (double or float),
/// each row by `row_dot`, rows split as in the SparseMatrix overload below (so with Value =
/// double the result is the same, bit for bit). Counts one pass of `kind` with
/// traffic::csr_bytes(rows, cols, nnz, add, sizeof(Value)).
template <class Value>
void csr_multiply(const CsrArrays<Value>& A, const Vector& x, Vector& y, bool add,
                  traffic::Kind kind);

/// res = b - A x on CSR arrays (res resized), each row by `row_dot`: one pass over A, counted as
/// traffic::csr_bytes(rows, cols, nnz, true, sizeof(Value)) of `kind` (b read in place of y).
template <class Value>
void csr_residual(const CsrArrays<Value>& A, const Vector& b, const Vector& x, Vector& res,
                  traffic::Kind kind);

/// True when A and B have identical sizes and identical compressed patterns (outer and inner
/// index arrays compared entry by entry); values are ignored. False if either is uncompressed.
bool same_pattern(const SparseMatrix& A, const SparseMatrix& B);

/// A copy of the sparsity pattern of a compressed CSR matrix (its sizes and outer and inner
/// index arrays), kept by preconditioners whose symbolic phase (analysis, fill pattern, parts)
/// depends only on the pattern, so that `update_values` can tell a refreshed matrix from a
/// different one. Memory: rows + 1 + nonzeros ints.
class SparsityPattern {
public:
    /// The empty pattern: matches no matrix.
    SparsityPattern() = default;
    /// The pattern of A (A must be compressed; throws mlc::InvalidInput otherwise).
    explicit SparsityPattern(const SparseMatrix& A);
    SparsityPattern(const SparsityPattern& o);
    SparsityPattern& operator=(const SparsityPattern& o);
    SparsityPattern(SparsityPattern&&) noexcept = default;
    SparsityPattern& operator=(SparsityPattern&&) noexcept = default;
    ~SparsityPattern() = default;
    /// True when A is compressed and has exactly this pattern (the same test as `same_pattern`).
    bool matches(const SparseMatrix& A) const;
    /// False for a default-constructed pattern.
    bool empty() const { return !outer_; }

private:
    Index rows_ = 0, cols_ = 0;
    size_t n_outer_ = 0, n_inner_ = 0;
    std::unique_ptr<int[]> outer_, inner_; // filled over the threads (core/first_touch)
};

} // namespace mlc

// SPDX-License-Identifier: MIT
// CSR kernels of core/: the unrolled mat-vec, MatrixOperator's two summations, the pattern check.
#include "core/check.hpp"
#include "core/csr.hpp"
#include "core/linear_operator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace mlc {
namespace {

// A random n x n CSR matrix with about `per_row` entries per row (at least the diagonal).
SparseMatrix random_matrix(Index n, int per_row, unsigned seed) {
    std::mt19937 gen(seed);
    std::uniform_int_distribution<Index> col(0, n - 1);
    std::uniform_real_distribution<double> val(-1.0, 1.0);
    std::vector<Triplet> t;
    for (Index i = 0; i < n; ++i) {
        t.emplace_back(static_cast<int>(i), static_cast<int>(i), 4.0);
        for (int k = 0; k < per_row; ++k)
            t.emplace_back(static_cast<int>(i), static_cast<int>(col(gen)), val(gen));
    }
    SparseMatrix A(n, n);
    A.setFromTriplets(t.begin(), t.end());
    A.makeCompressed();
    return A;
}

TEST(CsrMultiply, AgreesWithEigenToRoundOffAndAdds) {
    // Large enough for several threads when OpenMP offers them.
    for (const Index n : {Index{7}, Index{3 * kMinRowsPerThread + 5}}) {
        const SparseMatrix A = random_matrix(n, 17, 3);
        const Vector x = Vector::Random(n);
        const Vector ref = A * x;
        Vector y;
        csr_multiply(A, x, y);
        ASSERT_EQ(y.size(), n);
        EXPECT_LT((y - ref).lpNorm<Eigen::Infinity>(), 1e-13 * ref.lpNorm<Eigen::Infinity>());
        Vector z = Vector::Ones(n);
        csr_multiply(A, x, z, true);
        EXPECT_LT((z - ref - Vector::Ones(n)).lpNorm<Eigen::Infinity>(),
                  1e-13 * ref.lpNorm<Eigen::Infinity>());
    }
    const SparseMatrix A = random_matrix(5, 2, 1);
    Vector y;
    EXPECT_THROW(csr_multiply(A, Vector::Ones(4), y), InvalidInput);
    Vector short_y = Vector::Zero(3);
    EXPECT_THROW(csr_multiply(A, Vector::Ones(5), short_y, true), InvalidInput);
}

TEST(RowDot, UsesFourAccumulatorsInAFixedOrder) {
    const int inner[6] = {0, 1, 2, 3, 4, 5};
    const double val[6] = {1e16, 1.0, -1e16, 1.0, 1.0, 1.0};
    const double x[6] = {1, 1, 1, 1, 1, 1};
    // Entries 0..3 go to a0..a3, the remainder (4, 5) to a0: a0 = (1e16 + 1) + 1 = 1e16 (each 1
    // rounds away), a1 = 1, a2 = -1e16, a3 = 1, and (a0 + a1) + (a2 + a3) = 1e16 - 1e16 = 0,
    // where the sum in storage order gives 3 (only the 1 next to 1e16 is lost).
    EXPECT_EQ(row_dot(inner, val, x, 0, 6), 0.0);
    double in_order = 0.0;
    for (int k = 0; k < 6; ++k)
        in_order += val[k] * x[inner[k]];
    EXPECT_EQ(in_order, 3.0);
    EXPECT_EQ(row_dot(inner, val, x, 2, 2), 0.0);
}

TEST(TwinRowDot, IsRowDotOfEachRowBitForBit) {
    // Two rows with the same columns, their values stored one after the other (len apart):
    // every sub-range [k0, k1) of the first row's entries (the remainder loop included) gives
    // row_dot of each row. Values of mixed magnitudes make any other grouping show; the first
    // row's case is RowDot's, whose grouped sum 0 differs from the in-order 3.
    const int len = 9;
    const int inner[2 * len] = {0, 2, 3, 5, 6, 7, 9, 10, 12, 0, 2, 3, 5, 6, 7, 9, 10, 12};
    const double val[2 * len] = {1e16,  1.0, -1e16, 1.0, 1.0, 1.0, 3.5,   -2.25, 7.0,
                                 -1e16, 2.0, 1e16,  1.0, 0.5, 1.0, -1e16, 1.0,   1e16};
    double x[13];
    for (int j = 0; j < 13; ++j)
        x[j] = 1.0 + 0.125 * j;
    x[0] = x[2] = x[3] = x[5] = x[6] = x[7] = 1.0; // the first six entries: RowDot's case
    for (int k0 = 0; k0 <= len; ++k0)
        for (int k1 = k0; k1 <= len; ++k1) {
            double r0 = -1.0, r1 = -1.0;
            twin_row_dot(inner, val, len, x, k0, k1, r0, r1);
            EXPECT_EQ(r0, row_dot(inner, val, x, k0, k1)) << k0 << " " << k1;
            EXPECT_EQ(r1, row_dot(inner, val, x, k0 + len, k1 + len)) << k0 << " " << k1;
        }
    double r0 = 0.0, r1 = 0.0;
    twin_row_dot(inner, val, len, x, 0, 6, r0, r1);
    EXPECT_EQ(r0, 0.0); // RowDot's grouping: (1e16 + 1 + 1) + 1 + (-1e16 + 1)
    const float val32[2 * len] = {1.5f,  2.0f, -3.0f, 0.25f, 1.0f, 1.0f, 3.5f,  -2.25f, 7.0f,
                                  -1.0f, 2.0f, 1.0f,  1.0f,  0.5f, 1.0f, -1.0f, 1.0f,   1e3f};
    twin_row_dot(inner, val32, len, x, 1, 8, r0, r1);
    EXPECT_EQ(r0, row_dot(inner, val32, x, 1, 8));
    EXPECT_EQ(r1, row_dot(inner, val32, x, 1 + len, 8 + len));
}

TEST(CsrMultiplyInOrder, IsEigensSerialProductBitForBitOnEveryChunk) {
    // Rows over several chunks (and threads): each row still summed as Eigen sums it. Values
    // spread over 12 orders of magnitude, so that another summation order shows in the last bits.
    const Index n = 3 * kMinRowsPerThread + 11;
    SparseMatrix A = random_matrix(n, 17, 9);
    std::mt19937 gen(4);
    std::uniform_int_distribution<int> e(-6, 6);
    for (Index k = 0; k < A.nonZeros(); ++k)
        A.valuePtr()[k] *= std::pow(10.0, e(gen));
    const Vector x = Vector::Random(n);
    Vector y;
    csr_multiply_in_order(A, x, y);
    const Vector ref = A * x;
    ASSERT_EQ(y.size(), n);
    EXPECT_EQ((y - ref).cwiseAbs().maxCoeff(), 0.0);
    Vector u;
    csr_multiply(A, x, u); // four accumulators: not the same sums
    EXPECT_GT((u - ref).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_THROW(csr_multiply_in_order(A, Vector::Ones(n - 1), y), InvalidInput);
}

TEST(MatrixOperator, InOrderIsEigensProductBitForBitAndUnrolledIsCsrMultiply) {
    const Index n = 2 * kMinRowsPerThread + 3;
    const SparseMatrix A = random_matrix(n, 17, 5);
    const Vector x = Vector::Random(n);
    Vector y, u;
    MatrixOperator(A).apply(x, y);
    const Vector ref = A * x;
    EXPECT_EQ((y - ref).norm(), 0.0);
    MatrixOperator(A, MatVec::unrolled).apply(x, u);
    Vector c;
    csr_multiply(A, x, c);
    EXPECT_EQ((u - c).norm(), 0.0);
    Vector t;
    MatrixOperator(A, MatVec::unrolled).apply_transpose(x, t);
    const Vector tref = A.transpose() * x;
    EXPECT_EQ((t - tref).norm(), 0.0);
}

TEST(MovableSparseMatrix, MovesTheArraysAndCopiesOnlyOnCopy) {
    SparseMatrix A = random_matrix(50, 3, 2);
    MovableSparseMatrix a(A); // a copy
    EXPECT_NE(a.valuePtr(), A.valuePtr());
    const double* values = a.valuePtr();
    const int* inner = a.innerIndexPtr();
    MovableSparseMatrix b(std::move(a)); // the same arrays, not a copy
    EXPECT_EQ(b.valuePtr(), values);
    EXPECT_EQ(b.innerIndexPtr(), inner);
    MovableSparseMatrix c;
    c = std::move(b);
    EXPECT_EQ(c.valuePtr(), values);
    EXPECT_EQ(SparseMatrix(c - A).norm(), 0.0);
    // A plain SparseMatrix moved in is taken over too; expressions and copies assign as usual.
    SparseMatrix tmp = A;
    const double* tv = tmp.valuePtr();
    MovableSparseMatrix d(std::move(tmp));
    EXPECT_EQ(d.valuePtr(), tv);
    MovableSparseMatrix e;
    e = A.transpose();
    EXPECT_EQ(SparseMatrix(e - SparseMatrix(A.transpose())).norm(), 0.0);
    MovableSparseMatrix f;
    f = c;
    EXPECT_NE(f.valuePtr(), c.valuePtr());
    EXPECT_EQ(SparseMatrix(f - A).norm(), 0.0);
}

TEST(SparsityPattern, MatchesTheSamePatternWhateverTheValues) {
    const SparseMatrix A = random_matrix(50, 4, 7);
    SparseMatrix B = 3.0 * A;
    B.makeCompressed();
    EXPECT_TRUE(same_pattern(A, B));
    const SparsityPattern p(A);
    EXPECT_TRUE(p.matches(B));
    EXPECT_FALSE(SparsityPattern().matches(A));
    // One entry moved within a row: same counts, different inner indices.
    SparseMatrix C = A;
    const int row = 10;
    std::vector<Triplet> t;
    for (int i = 0; i < C.outerSize(); ++i)
        for (SparseMatrix::InnerIterator it(C, i); it; ++it)
            t.emplace_back(i, static_cast<int>(it.col()), it.value());
    SparseMatrix D(50, 50);
    for (auto& e : t)
        if (e.row() == row && e.col() != row) {
            int c = e.col();
            while (C.coeff(row, c) != 0.0 || c == row)
                c = (c + 1) % 50;
            e = Triplet(e.row(), c, e.value());
            break;
        }
    D.setFromTriplets(t.begin(), t.end());
    D.makeCompressed();
    ASSERT_EQ(D.nonZeros(), A.nonZeros());
    EXPECT_FALSE(same_pattern(A, D));
    EXPECT_FALSE(p.matches(D));
    // Different sizes, and an uncompressed matrix.
    EXPECT_FALSE(p.matches(random_matrix(51, 4, 7)));
    SparseMatrix U = A;
    U.uncompress();
    EXPECT_FALSE(p.matches(U));
    EXPECT_FALSE(same_pattern(U, A));
}

TEST(SparsityPattern, AChangeInAnyRowChunkIsSeen) {
    // Five chunks of kMinRowsPerThread rows (the comparison runs over the threads by chunk): a
    // column moved in the last row, and an entry moved to the next row across a chunk boundary
    // (same count, so only the row offsets differ there), are both found.
    const Index n = 5 * kMinRowsPerThread;
    const SparseMatrix A = random_matrix(n, 4, 11);
    const SparsityPattern p(A);
    SparseMatrix B = 2.0 * A;
    B.makeCompressed();
    EXPECT_TRUE(p.matches(B));
    EXPECT_TRUE(same_pattern(A, B));
    auto moved = [&](Index from_row, Index to_row) {
        std::vector<Triplet> t;
        bool done = false;
        for (int i = 0; i < A.outerSize(); ++i)
            for (SparseMatrix::InnerIterator it(A, i); it; ++it) {
                Index r = i, c = it.col();
                if (!done && r == from_row && c != r) {
                    r = to_row;
                    while (A.coeff(r, c) != 0.0 || c == r)
                        c = (c + 1) % n;
                    done = true;
                }
                t.emplace_back(static_cast<int>(r), static_cast<int>(c), it.value());
            }
        SparseMatrix M(n, n);
        M.setFromTriplets(t.begin(), t.end());
        M.makeCompressed();
        return M;
    };
    const SparseMatrix last = moved(n - 1, n - 1);
    ASSERT_EQ(last.nonZeros(), A.nonZeros());
    EXPECT_FALSE(p.matches(last));
    EXPECT_FALSE(same_pattern(A, last));
    const Index edge = 3 * kMinRowsPerThread - 1; // the last row of chunk 2
    const SparseMatrix across = moved(edge, edge + 1);
    ASSERT_EQ(across.nonZeros(), A.nonZeros());
    EXPECT_FALSE(p.matches(across));
    EXPECT_FALSE(same_pattern(A, across));
}

} // namespace
} // namespace mlc

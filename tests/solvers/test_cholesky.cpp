// SPDX-License-Identifier: MIT
// solvers::SparseCholesky: the factor of the caller's order, its trailing dense block (read in
// place from CHOLMOD's supernodes) and the solve, against Eigen's dense LLT of the same matrix.
#include "core/parallel.hpp"
#include "solvers/cholesky.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <string>

using namespace mlc;

namespace {

// 2D Laplacian on an n x n grid plus the identity, with a few long-range couplings so that the
// trailing rows fill in: symmetric positive definite, large enough for supernodes.
SparseMatrixCol test_matrix(int n) {
    const int N = n * n;
    std::vector<Eigen::Triplet<double>> t;
    auto add = [&](int i, int j, double v) {
        t.emplace_back(i, j, v);
        if (i != j) t.emplace_back(j, i, v);
    };
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const int i = y * n + x;
            add(i, i, 5.0 + 0.01 * (i % 7));
            if (x + 1 < n) add(i, i + 1, -1.0);
            if (y + 1 < n) add(i, i + n, -1.0);
        }
    for (int k = 0; k < n; ++k)
        add(N - 1 - k, k * n, -0.1); // ties the last rows to the first column of the grid
    SparseMatrixCol A(N, N);
    A.setFromTriplets(t.begin(), t.end());
    A.makeCompressed();
    return A;
}

} // namespace

TEST(SparseCholesky, TrailingBlockEqualsTheDenseFactor) {
    const SparseMatrixCol A = test_matrix(24); // 576 unknowns
    const Index nb = 40;
    for (const bool lower_only : {false, true}) {
        solvers::SparseCholesky chol;
        if (lower_only) {
            SparseMatrixCol lower = A.triangularView<Eigen::Lower>();
            lower.makeCompressed();
            chol.factor(lower); // viewed in place
        } else {
            chol.factor(A); // copied to its lower triangle first
        }
        const Eigen::MatrixXd Ld = Eigen::MatrixXd(A).llt().matrixL();
        const Eigen::MatrixXd expect = Ld.bottomRightCorner(nb, nb);
        const Eigen::MatrixXd got = chol.trailing_block(nb);
        EXPECT_LT((got - expect).norm(), 1e-12 * expect.norm()) << "lower_only " << lower_only;
        // Strictly upper part of the block is zero, the diagonal positive.
        EXPECT_EQ(got.triangularView<Eigen::StrictlyUpper>().toDenseMatrix().norm(), 0.0);
        EXPECT_GT(got.diagonal().minCoeff(), 0.0);
        const Vector b = Vector::LinSpaced(A.rows(), -1.0, 2.0);
        Vector x;
        chol.solve(b, x);
        EXPECT_LT((A * x - b).norm(), 1e-12 * b.norm());
    }
}

// The BLAS behind CHOLMOD's supernodes is OpenBLAS (scripts/deps.sh installs libopenblas0-serial,
// which Debian's alternatives make libblas.so.3): with the reference BLAS the set-up of `schur`
// is 1.9-2.5x slower. An environment check: it fails on a machine whose libblas.so.3 is another
// library, naming it.
TEST(SparseCholesky, RunsOnOpenBlas) {
    solvers::SparseCholesky chol;
    chol.factor(test_matrix(24)); // CHOLMOD (and its BLAS) loaded and used
    const std::string blas = parallel::blas_library();
    EXPECT_NE(blas.find("OpenBLAS"), std::string::npos)
        << "libblas.so.3 is " << blas << ": install libopenblas0-serial (scripts/deps.sh)";
    EXPECT_EQ(blas.find("libblas.so.3.11"), std::string::npos) << blas; // the reference BLAS
    EXPECT_EQ(parallel::blas_library(), blas);                          // computed once
}

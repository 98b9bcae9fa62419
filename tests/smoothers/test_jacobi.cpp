// SPDX-License-Identifier: MIT
// Jacobi: equals its explicit diagonal matrix, patches zero/missing diagonals as documented.
#include "core/check.hpp"
#include "smoothers/jacobi.hpp"
#include "tests/smoothers/matrices.hpp"

#include "core/csr.hpp"
#include "smoothers/matrix_checks.hpp"

#include <gtest/gtest.h>

#include <sstream>

using namespace mlc;
using namespace mlc::smoothers;

TEST(Jacobi, ApplyEqualsExplicitInverseDiagonal) {
    const SparseMatrix A = testmat::convection_diffusion();
    Jacobi J;
    J.setup(A);
    EXPECT_EQ(J.n_patched_rows(), 0);
    EXPECT_EQ(J.name(), "diag");
    const Vector r = testmat::pseudo_random(A.rows());
    Vector z;
    J.apply(r, z);
    const Vector expected = A.diagonal().cwiseInverse().cwiseProduct(r);
    EXPECT_LE((z - expected).norm(), 1e-15 * expected.norm());
    Vector zt;
    J.apply_transpose(r, zt);
    EXPECT_LE((zt - expected).norm(), 1e-15 * expected.norm());
}

TEST(Jacobi, PatchesZeroDiagonalsWithRowMaxAbs) {
    std::vector<Index> starts;
    const SparseMatrix A = testmat::contact_saddle(8, &starts);
    const Eigen::MatrixXd D = testmat::dense(A);
    Jacobi J;
    J.setup(A);
    std::vector<Index> zero_rows;
    for (Index i = 0; i < A.rows(); ++i)
        if (D(i, i) == 0.0) zero_rows.push_back(i);
    ASSERT_FALSE(zero_rows.empty());
    EXPECT_EQ(J.n_patched_rows(), static_cast<Index>(zero_rows.size()));
    EXPECT_EQ(J.patched_rows(), zero_rows);
    for (Index i = 0; i < A.rows(); ++i) {
        const double d = D(i, i) != 0.0 ? D(i, i) : D.row(i).cwiseAbs().maxCoeff();
        EXPECT_DOUBLE_EQ(J.inverse_diagonal()[i], 1.0 / d) << "row " << i;
    }
}

TEST(Jacobi, MissingDiagonalAndEmptyRow) {
    // Row 0: no diagonal stored, max |a| = 3; row 1: regular; row 2: empty.
    const SparseMatrix A = testmat::from_triplets(3, {{0, 1, -3.0}, {1, 1, 4.0}, {1, 0, 1.0}});
    Jacobi J;
    J.setup(A);
    EXPECT_EQ(J.n_patched_rows(), 2);
    EXPECT_DOUBLE_EQ(J.inverse_diagonal()[0], 1.0 / 3.0);
    EXPECT_DOUBLE_EQ(J.inverse_diagonal()[1], 0.25);
    EXPECT_DOUBLE_EQ(J.inverse_diagonal()[2], 1.0);
}

TEST(Jacobi, DampedSweepsEqualExplicitPolynomial) {
    const SparseMatrix A = testmat::convection_diffusion();
    const Eigen::MatrixXd Ad = testmat::dense(A);
    const double w = 0.7;
    Jacobi J(JacobiParams{.omega = w, .n_sweeps = 3});
    J.setup(A);
    const Eigen::MatrixXd Dinv = Ad.diagonal().cwiseInverse().asDiagonal();
    const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(A.rows(), A.rows());
    const Eigen::MatrixXd E = I - w * Dinv * Ad;
    const Eigen::MatrixXd Cinv = (I + E + E * E) * (w * Dinv);
    const Vector r = testmat::pseudo_random(A.rows(), 3);
    Vector z, zt;
    J.apply(r, z);
    J.apply_transpose(r, zt);
    EXPECT_LE((z - Cinv * r).norm(), 1e-13 * z.norm());
    EXPECT_LE((zt - Cinv.transpose() * r).norm(), 1e-13 * zt.norm());

    // smooth: x <- x + C1^{-1} (b - A x), three times.
    Vector x = testmat::pseudo_random(A.rows(), 4), xe = x;
    const Vector b = testmat::pseudo_random(A.rows(), 5);
    J.smooth(b, x);
    for (int k = 0; k < 3; ++k)
        xe += w * Dinv * (b - Ad * xe);
    EXPECT_LE((x - xe).norm(), 1e-13 * xe.norm());
}

TEST(Jacobi, RejectsBadInput) {
    EXPECT_THROW(Jacobi(JacobiParams{.omega = 2.0}), InvalidInput);
    EXPECT_THROW(Jacobi(JacobiParams{.n_sweeps = 0}), InvalidInput);
    Jacobi J;
    SparseMatrix R(2, 3);
    EXPECT_THROW(J.setup(R), InvalidInput);
    SparseMatrix A = testmat::laplace_1d(3);
    A.coeffRef(0, 0) = std::nan("");
    EXPECT_THROW(J.setup(A), InvalidInput);
    J.setup(testmat::laplace_1d(3));
    Vector z;
    EXPECT_THROW(J.apply(Vector::Ones(4), z), InvalidInput);
    std::ostringstream os;
    os << JacobiParams{};
    EXPECT_NE(os.str().find("zero_tol"), std::string::npos);
}

TEST(MatrixChecks, NameTheFirstNonFiniteEntryWhateverChunkHoldsIt) {
    // check_setup_matrix scans the entries in chunks over the threads: with non-finite ones in
    // several chunks, the message names the first one in row order, as a serial scan would.
    const Index n = 4 * kMinRowsPerThread;
    SparseMatrix A = testmat::laplace_1d(n);
    check_setup_matrix(A, "test");
    A.coeffRef(3 * kMinRowsPerThread + 5, 3 * kMinRowsPerThread + 4) = std::nan("");
    A.coeffRef(kMinRowsPerThread + 7, kMinRowsPerThread + 8) = INFINITY;
    A.coeffRef(kMinRowsPerThread + 9, kMinRowsPerThread + 9) = std::nan("");
    try {
        check_setup_matrix(A, "test");
        FAIL() << "no throw";
    } catch (const InvalidInput& e) {
        const std::string want = "non-finite entry inf at (" +
                                 std::to_string(kMinRowsPerThread + 7) + ", " +
                                 std::to_string(kMinRowsPerThread + 8) + ")";
        EXPECT_NE(std::string(e.what()).find(want), std::string::npos) << e.what();
    }
}

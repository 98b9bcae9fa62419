// SPDX-License-Identifier: MIT
// ILU(k): exactness for k >= bandwidth and on tridiagonals, L U = A on A's pattern, fill
// pattern against a dense level-of-fill reference, pattern reuse, zero pivots.
#include "core/check.hpp"
#include "smoothers/iluk.hpp"
#include "tests/smoothers/matrices.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>

using namespace mlc;
using namespace mlc::smoothers;

namespace {

// Splits the combined factors into unit-lower L and upper U (dense).
void split(const SparseMatrix& F, Eigen::MatrixXd& L, Eigen::MatrixXd& U) {
    const Eigen::MatrixXd D = testmat::dense(F);
    L = D.triangularView<Eigen::StrictlyLower>();
    L.diagonal().setOnes();
    U = D.triangularView<Eigen::Upper>();
}

// Dense reference of the ILU(k) fill pattern (row-wise levels, as in Saad sect. 10.3.3).
Eigen::MatrixXi reference_levels(const SparseMatrix& A, int K) {
    const Index n = A.rows();
    const int inf = 1 << 20;
    Eigen::MatrixXi lev = Eigen::MatrixXi::Constant(n, n, inf);
    for (Index i = 0; i < n; ++i) {
        lev(i, i) = 0;
        for (SparseMatrix::InnerIterator it(A, i); it; ++it)
            lev(i, it.col()) = 0;
    }
    for (Index i = 0; i < n; ++i)
        for (Index k = 0; k < i; ++k) {
            if (lev(i, k) > K) continue;
            for (Index j = k + 1; j < n; ++j)
                if (lev(k, j) <= K) lev(i, j) = std::min(lev(i, j), lev(i, k) + lev(k, j) + 1);
        }
    return lev;
}

struct IlukCase {
    const char* name;
    SparseMatrix A;
};

std::vector<IlukCase> iluk_cases() {
    return {{"laplace_2d", testmat::laplace_2d(6)},
            {"convection_diffusion", testmat::convection_diffusion()},
            {"contact_saddle", testmat::contact_saddle(9)}};
}

} // namespace

TEST(ILUK, FillAtLeastBandwidthEqualsLU) {
    for (const auto& c : iluk_cases()) {
        const Index w = testmat::bandwidth(c.A);
        ILUK ilu(ILUKParams{.fill_level = static_cast<int>(w)});
        ilu.setup(c.A);
        const Eigen::MatrixXd Ad = testmat::dense(c.A);
        for (unsigned s = 1; s <= 3; ++s) {
            const Vector r = testmat::pseudo_random(c.A.rows(), s);
            const Vector exact = Ad.fullPivLu().solve(r);
            Vector z;
            ilu.apply(r, z);
            EXPECT_LE((z - exact).norm(), 1e-12 * exact.norm()) << c.name;
            ilu.apply_transpose(r, z);
            const Vector exact_t = Ad.transpose().fullPivLu().solve(r);
            EXPECT_LE((z - exact_t).norm(), 1e-12 * exact_t.norm()) << c.name;
        }
    }
}

TEST(ILUK, ZeroFillIsExactOnTridiagonal) {
    const SparseMatrix A = testmat::laplace_1d(30);
    ILUK ilu;
    ilu.setup(A);
    EXPECT_EQ(ilu.n_nonzeros(), A.nonZeros());
    EXPECT_EQ(ilu.name(), "ilu(0)");
    const Vector r = testmat::pseudo_random(A.rows());
    Vector z;
    ilu.apply(r, z);
    EXPECT_LE((A * z - r).norm(), 1e-13 * r.norm());
}

TEST(ILUK, ZeroFillProductMatchesAOnItsPattern) {
    for (const auto& c : iluk_cases()) {
        ILUK ilu;
        ilu.setup(c.A);
        EXPECT_EQ(ilu.n_nonzeros(), c.A.nonZeros()) << c.name;
        Eigen::MatrixXd L, U;
        split(ilu.factors(), L, U);
        const Eigen::MatrixXd LU = L * U;
        const double scale = testmat::dense(c.A).cwiseAbs().maxCoeff();
        for (Index i = 0; i < c.A.outerSize(); ++i)
            for (SparseMatrix::InnerIterator it(c.A, i); it; ++it)
                EXPECT_NEAR(LU(it.row(), it.col()), it.value(), 1e-13 * scale)
                    << c.name << " entry (" << it.row() << ", " << it.col() << ")";
    }
}

TEST(ILUK, FillPatternMatchesDenseLevelReference) {
    for (const auto& c : iluk_cases())
        for (int K : {0, 1, 2, 3}) {
            ILUK ilu(ILUKParams{.fill_level = K});
            ilu.setup(c.A);
            const Eigen::MatrixXi lev = reference_levels(c.A, K);
            const SparseMatrix F = ilu.factors();
            Index expected_nnz = 0;
            for (Index i = 0; i < lev.rows(); ++i)
                for (Index j = 0; j < lev.cols(); ++j)
                    expected_nnz += lev(i, j) <= K;
            EXPECT_EQ(F.nonZeros(), expected_nnz) << c.name << " k=" << K;
            for (Index i = 0; i < F.outerSize(); ++i)
                for (SparseMatrix::InnerIterator it(F, i); it; ++it)
                    EXPECT_LE(lev(it.row(), it.col()), K) << c.name << " k=" << K;
            // L U matches A on the kept pattern's original entries too.
            Eigen::MatrixXd L, U;
            split(F, L, U);
            const Eigen::MatrixXd R = L * U - testmat::dense(c.A);
            for (Index i = 0; i < F.outerSize(); ++i)
                for (SparseMatrix::InnerIterator it(F, i); it; ++it)
                    EXPECT_NEAR(R(it.row(), it.col()), 0.0, 1e-12) << c.name << " k=" << K;
        }
}

TEST(ILUK, UpdateValuesReusesSymbolicPhase) {
    const SparseMatrix A = testmat::convection_diffusion();
    SparseMatrix B = A;
    for (Index p = 0; p < B.nonZeros(); ++p)
        B.valuePtr()[p] *= 1.0 + 0.01 * (p % 7);
    ILUK ilu(ILUKParams{.fill_level = 1}), fresh(ILUKParams{.fill_level = 1});
    ilu.setup(A);
    ilu.update_values(B);
    EXPECT_EQ(ilu.n_symbolic(), 1);
    fresh.setup(B);
    const Vector r = testmat::pseudo_random(A.rows());
    Vector z1, z2;
    ilu.apply(r, z1);
    fresh.apply(r, z2);
    EXPECT_EQ(z1, z2);
    // A different pattern triggers a new symbolic phase.
    ilu.update_values(testmat::laplace_1d(10));
    EXPECT_EQ(ilu.n_symbolic(), 2);
}

TEST(ILUK, ApplyInPlaceAndTransposeByProbing) {
    const SparseMatrix A = testmat::contact_saddle(7);
    ILUK ilu(ILUKParams{.fill_level = 1});
    ilu.setup(A);
    const Index n = A.rows();
    Eigen::MatrixXd C(n, n), Ct(n, n);
    for (Index j = 0; j < n; ++j) {
        Vector e = Vector::Unit(n, j), z;
        ilu.apply(e, z);
        C.col(j) = z;
        ilu.apply_transpose(e, z);
        Ct.col(j) = z;
    }
    EXPECT_LE((Ct - C.transpose()).norm(), 1e-13 * C.norm());
    Vector r = testmat::pseudo_random(n), z;
    ilu.apply(r, z);
    ilu.apply(r, r); // r and z may be the same object
    EXPECT_EQ(r, z);
}

TEST(ILUK, ZeroPivotThrowsNamingTheRow) {
    // [[0, 1], [1, 0]]: the first pivot is zero (a multiplier ordered before its displacement).
    const SparseMatrix A = testmat::from_triplets(2, {{0, 1, 1.0}, {1, 0, 1.0}});
    ILUK ilu;
    try {
        ilu.setup(A);
        FAIL() << "expected SolverBreakdown";
    } catch (const SolverBreakdown& e) {
        EXPECT_NE(std::string(e.what()).find("row 0"), std::string::npos) << e.what();
    }
}

TEST(ILUK, RejectsBadParams) {
    EXPECT_THROW(ILUK(ILUKParams{.fill_level = -1}), InvalidInput);
    EXPECT_THROW(ILUK(ILUKParams{.pivot_tol = 1.0}), InvalidInput);
}

// SPDX-License-Identifier: MIT
// SparseLUPreconditioner: exact solves, transpose, reuse of the analysis, singular matrices.
#include "core/check.hpp"
#include "solvers/direct.hpp"
#include "tests/smoothers/matrices.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>

using namespace mlc;
using namespace mlc::solvers;

TEST(SparseLU, SolvesAndTransposeSolves) {
    const SparseMatrix A = testmat::contact_saddle(10);
    SparseLUPreconditioner lu;
    lu.setup(A);
    EXPECT_EQ(lu.name(), "lu");
    const Eigen::MatrixXd Ad = testmat::dense(A);
    const Vector r = testmat::pseudo_random(A.rows());
    Vector z;
    lu.apply(r, z);
    EXPECT_LE((Ad * z - r).norm(), 1e-12 * r.norm());
    lu.apply_transpose(r, z);
    EXPECT_LE((Ad.transpose() * z - r).norm(), 1e-12 * r.norm());
}

TEST(SparseLU, UpdateValuesReusesAnalysisWhenPatternUnchanged) {
    const SparseMatrix A = testmat::convection_diffusion();
    SparseMatrix B = A;
    for (Index p = 0; p < B.nonZeros(); ++p)
        B.valuePtr()[p] *= 1.0 + 0.02 * (p % 5);
    SparseLUPreconditioner lu;
    lu.setup(A);
    lu.update_values(B);
    EXPECT_EQ(lu.n_analyses(), 1);
    const Vector r = testmat::pseudo_random(B.rows());
    Vector z;
    lu.apply(r, z);
    EXPECT_LE((B * z - r).norm(), 1e-12 * r.norm());
    // Same size, one more entry: a new analysis.
    SparseMatrix C = A;
    C.coeffRef(0, 35) = 0.5;
    C.makeCompressed();
    lu.update_values(C);
    EXPECT_EQ(lu.n_analyses(), 2);
    lu.apply(r, z);
    EXPECT_LE((C * z - r).norm(), 1e-12 * r.norm());
    // Another size: a new analysis too.
    const SparseMatrix E = testmat::laplace_2d(7);
    const Vector re = testmat::pseudo_random(E.rows());
    lu.update_values(E);
    EXPECT_EQ(lu.n_analyses(), 3);
    lu.apply(re, z);
    EXPECT_LE((E * z - re).norm(), 1e-12 * re.norm());
}

TEST(SparseLU, SingularMatrixThrowsBreakdown) {
    const SparseMatrix S = testmat::from_triplets(
        3, {{0, 0, 1.0}, {0, 1, 2.0}, {1, 0, 2.0}, {1, 1, 4.0}, {2, 2, 1.0}});
    SparseLUPreconditioner lu;
    EXPECT_THROW(lu.setup(S), SolverBreakdown);
    Vector z;
    EXPECT_THROW(lu.apply(Vector::Ones(3), z), InvalidInput);
    EXPECT_THROW(SparseLUPreconditioner(SparseLUParams{.pivot_threshold = 0.0}), InvalidInput);
}

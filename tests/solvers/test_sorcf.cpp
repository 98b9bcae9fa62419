// SPDX-License-Identifier: MIT
// SSOR with the generalized diagonal D* (1995 paper, eqs. 26-33) and SORCF against their
// explicit matrices.
#include "core/check.hpp"
#include "solvers/sorcf.hpp"
#include "tests/smoothers/matrices.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>

using namespace mlc;
using testmat::probe;
using namespace mlc::solvers;

namespace {

const double kR = 2.0, kMu = 0.3;

// The paper's 4x4 patterns of an elastic node with its multiplier node, flat floor:
// slip (eq. 26) [[A11, A12, 0, -eps mu], [A21, A22, 0, 1], [0, -eps mu, -1/r, -eps mu/r],
// [0, 1, 0, 0]] and stick (eq. 30) [[A11, A12, 1, 0], [A21, A22, 0, 1], [1, 0, 0, 0],
// [0, 1, 0, 0]], with the elastic block A of the node (plus r M).
SparseMatrix paper_pattern(bool stick, double eps = 1.0) {
    Eigen::Matrix2d M;
    if (stick)
        M.setIdentity();
    else
        M << 0.0, -eps * kMu, 0.0, 1.0;
    Eigen::Matrix2d K;
    K << 3.0, 0.7, 0.4, 2.5; // non-symmetric on purpose
    Eigen::Matrix4d A;
    A << K + kR * M, M, M, (M - Eigen::Matrix2d::Identity()) / kR;
    std::vector<Triplet> t;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            t.emplace_back(i, j, A(i, j)); // keep the zeros stored, as an assembled Jacobian does
    return testmat::from_triplets(4, t);
}


// P_omega = (D* + w L) D*^{-1} (D* + w U) / (w (2 - w)) with the splitting by `block_of`.
Eigen::MatrixXd explicit_p(const SparseMatrix& A, const Eigen::MatrixXd& Dstar,
                           const std::vector<Index>& block_of, double w) {
    const Eigen::MatrixXd Ad = testmat::dense(A);
    const Index n = A.rows();
    Eigen::MatrixXd L = Eigen::MatrixXd::Zero(n, n), U = L;
    for (Index i = 0; i < n; ++i)
        for (Index j = 0; j < n; ++j) {
            if (block_of[i] > block_of[j]) L(i, j) = Ad(i, j);
            if (block_of[i] < block_of[j]) U(i, j) = Ad(i, j);
        }
    return (Dstar + w * L) * Dstar.inverse() * (Dstar + w * U) / (w * (2.0 - w));
}

} // namespace

TEST(GeneralizedSSOR, GeneralizedDiagonalFollowsEqs29And33) {
    for (const bool stick : {true, false}) {
        const SparseMatrix A = paper_pattern(stick);
        GeneralizedSSOR P;
        P.setup(A);
        const Vector& d = P.generalized_diagonal();
        const double A11 = A.coeff(0, 0), A22 = A.coeff(1, 1);
        EXPECT_DOUBLE_EQ(d[0], A11);
        EXPECT_DOUBLE_EQ(d[1], A22);
        if (stick) {
            // Eq. 33: alpha = 1/beta = -1/A11, gamma = 1/delta = -1/A22.
            EXPECT_EQ(P.n_generated(), 2);
            EXPECT_NEAR(d[2], -1.0 / A11, 1e-15);
            EXPECT_NEAR(d[3], -1.0 / A22, 1e-15);
        } else {
            // Eq. 29: lambda_t keeps its diagonal -1/r, lambda_n gets alpha = -1/A22.
            EXPECT_EQ(P.n_generated(), 1);
            EXPECT_DOUBLE_EQ(d[2], -1.0 / kR);
            EXPECT_NEAR(d[3], -1.0 / A22, 1e-15);
        }
        // P keeps the zero diagonal of the multiplier rows, for any omega.
        for (const double w : {1.0, 1.4}) {
            GeneralizedSSOR Pw({.omega = w});
            Pw.setup(A);
            std::vector<Index> blocks = {0, 1, 2, 3};
            const Eigen::MatrixXd Pm =
                explicit_p(A, Pw.generalized_diagonal().asDiagonal().toDenseMatrix(), blocks, w);
            EXPECT_NEAR(Pm(3, 3), 0.0, 1e-14) << "omega " << w;
            if (stick) {
                EXPECT_NEAR(Pm(2, 2), 0.0, 1e-14) << "omega " << w;
            }
            EXPECT_LT((probe(Pw, 4) - Pm.inverse()).norm(), 1e-12 * Pm.inverse().norm());
        }
    }
}

TEST(GeneralizedSSOR, EqualsItsExplicitMatrix) {
    std::vector<Index> starts;
    const SparseMatrix A = testmat::contact_saddle(7, &starts);
    const Index n = A.rows();
    for (const double w : {1.0, 0.7, 1.5}) {
        // Scalar D*.
        GeneralizedSSOR S({.omega = w});
        S.setup(A);
        EXPECT_EQ(S.n_generated(), 4); // stick: 2 rows, each slip: 1 row (7 vertices: 3 contacts)
        std::vector<Index> points(n);
        for (Index i = 0; i < n; ++i)
            points[i] = i;
        const Eigen::MatrixXd Ps =
            explicit_p(A, S.generalized_diagonal().asDiagonal().toDenseMatrix(), points, w);
        EXPECT_LT((probe(S, n) - Ps.inverse()).norm(), 1e-11 * Ps.inverse().norm()) << w;
        // Vertex blocks: 2x2, and 4x4 with the multipliers.
        GeneralizedSSOR B({.omega = w, .block = true}, starts);
        B.setup(A);
        std::vector<Index> block_of(n);
        std::vector<Index> s = starts;
        s.push_back(n);
        for (size_t b = 0; b + 1 < s.size(); ++b)
            for (Index i = s[b]; i < s[b + 1]; ++i)
                block_of[i] = static_cast<Index>(b);
        Eigen::MatrixXd D = Eigen::MatrixXd::Zero(n, n);
        const Eigen::MatrixXd Ad = testmat::dense(A);
        for (Index i = 0; i < n; ++i)
            for (Index j = 0; j < n; ++j)
                if (block_of[i] == block_of[j]) D(i, j) = Ad(i, j);
        const Eigen::MatrixXd Pb = explicit_p(A, D, block_of, w);
        EXPECT_LT((probe(B, n) - Pb.inverse()).norm(), 1e-11 * Pb.inverse().norm()) << w;
        EXPECT_EQ(B.name(),
                  "gssor(omega=" + std::to_string(w).substr(0, w == 1.0 ? 1 : 3) + ",block=1)");
    }
}

TEST(Sorcf, EqualsTheExplicitBlockFormula) {
    // The CF fixture of test_coarse_fine with A_ff replaced by P_omega.
    std::vector<Index> starts;
    const SparseMatrix A = testmat::contact_saddle(8, &starts);
    starts.push_back(A.rows());
    CoarseFineSplit split;
    for (int v = 0; v < 8; ++v) {
        if (v % 3 != 0)
            split.fine_block_starts.push_back(static_cast<Index>(split.fine_set.size()));
        for (Index i = starts[v]; i < starts[v + 1]; ++i)
            (v % 3 == 0 ? split.coarse_set : split.fine_set).push_back(static_cast<int>(i));
    }
    const auto nc = static_cast<Index>(split.coarse_set.size());
    const auto nf = static_cast<Index>(split.fine_set.size());
    split.n_coarse = nc;
    for (Index k = 0; k < nc; ++k)
        split.coarse_dof.push_back(static_cast<int>(nc - 1 - k));
    const Eigen::MatrixXd Ad = testmat::dense(A);
    auto blk = [&](const std::vector<int>& r, const std::vector<int>& c) {
        Eigen::MatrixXd B(r.size(), c.size());
        for (size_t i = 0; i < r.size(); ++i)
            for (size_t j = 0; j < c.size(); ++j)
                B(i, j) = Ad(r[i], c[j]);
        return B;
    };
    const Eigen::MatrixXd S =
        blk(split.coarse_set, split.coarse_set) + 2.0 * Eigen::MatrixXd::Identity(nc, nc);
    Eigen::MatrixXd AH(nc, nc);
    for (Index k = 0; k < nc; ++k)
        for (Index l = 0; l < nc; ++l)
            AH(split.coarse_dof[k], split.coarse_dof[l]) = S(k, l);
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(AH);
    const CoarseSolve coarse = [&lu](const Vector& r, Vector& z) { z = lu.solve(r); };
    for (const bool block : {false, true}) {
        auto pc = make_sorcf(split, coarse, {.omega = 1.2, .block = block});
        pc->setup(A);
        // P from the inner solver's own D* (scalar) or the blocks of A_ff (block).
        const Eigen::MatrixXd Aff = blk(split.fine_set, split.fine_set);
        std::vector<Index> block_of(nf);
        Eigen::MatrixXd D = Eigen::MatrixXd::Zero(nf, nf);
        if (block) {
            std::vector<Index> s = split.fine_block_starts;
            s.push_back(nf);
            for (size_t b = 0; b + 1 < s.size(); ++b)
                for (Index i = s[b]; i < s[b + 1]; ++i)
                    block_of[i] = static_cast<Index>(b);
            for (Index i = 0; i < nf; ++i)
                for (Index j = 0; j < nf; ++j)
                    if (block_of[i] == block_of[j]) D(i, j) = Aff(i, j);
        } else {
            for (Index i = 0; i < nf; ++i)
                block_of[i] = i;
            D = dynamic_cast<const GeneralizedSSOR&>(pc->inner())
                    .generalized_diagonal()
                    .asDiagonal();
        }
        const Eigen::MatrixXd P = explicit_p(pc->A_ff(), D, block_of, 1.2);
        // C = [[P, 0], [A_cf, S]] [[I, P^{-1} A_fc], [0, I]] in (fine, coarse) order.
        const Index n = nf + nc;
        Eigen::MatrixXd Lo = Eigen::MatrixXd::Zero(n, n), Up = Eigen::MatrixXd::Identity(n, n);
        Lo.topLeftCorner(nf, nf) = P;
        Lo.bottomLeftCorner(nc, nf) = blk(split.coarse_set, split.fine_set);
        Lo.bottomRightCorner(nc, nc) = S;
        Up.topRightCorner(nf, nc) = P.inverse() * blk(split.fine_set, split.coarse_set);
        const Eigen::MatrixXd Cb = (Lo * Up).inverse();
        std::vector<int> order(split.fine_set);
        order.insert(order.end(), split.coarse_set.begin(), split.coarse_set.end());
        Eigen::MatrixXd Cinv(n, n);
        for (Index i = 0; i < n; ++i)
            for (Index j = 0; j < n; ++j)
                Cinv(order[i], order[j]) = Cb(i, j);
        EXPECT_LT((probe(*pc, n) - Cinv).norm(), 1e-11 * Cinv.norm()) << "block " << block;
        EXPECT_EQ(pc->name(),
                  std::string("sorcf(gssor(omega=1.2,block=") + (block ? "1" : "0") + "))");
    }
}

TEST(GeneralizedSSOR, RejectsBadInput) {
    EXPECT_THROW(GeneralizedSSOR({.omega = 2.0}), InvalidInput);
    EXPECT_THROW(GeneralizedSSOR({.block = true}), InvalidInput); // no block starts
    // A zero diagonal with no earlier coupling to generate D* from: row 0.
    const SparseMatrix A = testmat::from_triplets(2, {{0, 1, 1.0}, {1, 0, 1.0}, {1, 1, 2.0}});
    GeneralizedSSOR P;
    EXPECT_THROW(P.setup(A), SolverBreakdown);
    // A singular diagonal block.
    GeneralizedSSOR B({.block = true}, {0});
    const SparseMatrix Z =
        testmat::from_triplets(2, {{0, 0, 1.0}, {0, 1, 1.0}, {1, 0, 1.0}, {1, 1, 1.0}});
    EXPECT_THROW(B.setup(Z), SolverBreakdown);
    EXPECT_THROW(
        make_sorcf(CoarseFineSplit{}, [](const Vector& r, Vector& z) { z = r; }, {.block = true}),
        InvalidInput);
}

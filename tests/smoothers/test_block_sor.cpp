// SPDX-License-Identifier: MIT
// Point and block SOR / SSOR against their explicit matrices (D/omega + L etc.).
#include "core/check.hpp"
#include "smoothers/block_sor.hpp"
#include "tests/smoothers/matrices.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>

#include <sstream>

using namespace mlc;
using testmat::probe;
using namespace mlc::smoothers;

namespace {

// Explicit block splitting A = L + D + U for the given block starts (followed by n).
void splitting(const SparseMatrix& A, std::vector<Index> starts, Eigen::MatrixXd& L,
               Eigen::MatrixXd& D, Eigen::MatrixXd& U) {
    const Eigen::MatrixXd Ad = testmat::dense(A);
    const Index n = A.rows();
    if (starts.empty())
        for (Index i = 0; i < n; ++i)
            starts.push_back(i);
    starts.push_back(n);
    std::vector<Index> block_of(n);
    for (size_t b = 0; b + 1 < starts.size(); ++b)
        for (Index i = starts[b]; i < starts[b + 1]; ++i)
            block_of[i] = static_cast<Index>(b);
    L.setZero(n, n);
    D.setZero(n, n);
    U.setZero(n, n);
    for (Index i = 0; i < n; ++i)
        for (Index j = 0; j < n; ++j) {
            if (block_of[i] > block_of[j]) L(i, j) = Ad(i, j);
            if (block_of[i] == block_of[j]) D(i, j) = Ad(i, j);
            if (block_of[i] < block_of[j]) U(i, j) = Ad(i, j);
        }
}

// Dense C^{-1} of one sweep for the given direction.
Eigen::MatrixXd explicit_inverse(const SparseMatrix& A, const std::vector<Index>& starts, double w,
                                 Sweep sweep) {
    Eigen::MatrixXd L, D, U;
    splitting(A, starts, L, D, U);
    const Eigen::MatrixXd Mf = D / w + L, Mb = D / w + U;
    if (sweep == Sweep::forward) return Mf.inverse();
    if (sweep == Sweep::backward) return Mb.inverse();
    const Eigen::MatrixXd C = w / (2.0 - w) * Mf * D.inverse() * Mb;
    return C.inverse();
}


struct Case {
    const char* name;
    SparseMatrix A;
    std::vector<Index> starts;
};

std::vector<Case> cases() {
    std::vector<Case> c;
    c.push_back({"point convdiff", testmat::convection_diffusion(), {}});
    c.push_back({"2x2 convdiff", testmat::convection_diffusion(), uniform_block_starts(36, 2)});
    std::vector<Index> vs;
    SparseMatrix S = testmat::contact_saddle(8, &vs);
    c.push_back({"vertex+multiplier saddle", S, vs});
    return c;
}

} // namespace

TEST(BlockSOR, ApplyEqualsExplicitFormula) {
    for (const auto& c : cases())
        for (Sweep sweep : {Sweep::forward, Sweep::backward, Sweep::symmetric})
            for (double w : {1.0, 1.3, 0.6}) {
                BlockSOR S(BlockSORParams{.omega = w, .sweep = sweep, .block_starts = c.starts});
                S.setup(c.A);
                const Eigen::MatrixXd Cinv = explicit_inverse(c.A, c.starts, w, sweep);
                for (unsigned s = 1; s <= 3; ++s) {
                    const Vector r = testmat::pseudo_random(c.A.rows(), s);
                    Vector z;
                    S.apply(r, z);
                    const Vector ze = Cinv * r;
                    EXPECT_LE((z - ze).norm(), 1e-12 * ze.norm())
                        << c.name << " " << sweep << " omega " << w;
                }
            }
}

TEST(BlockSOR, TransposeEqualsProbedTranspose) {
    for (const auto& c : cases())
        for (Sweep sweep : {Sweep::forward, Sweep::backward, Sweep::symmetric})
            for (int sweeps : {1, 2}) {
                BlockSOR S(BlockSORParams{
                    .omega = 1.2, .sweep = sweep, .n_sweeps = sweeps, .block_starts = c.starts});
                S.setup(c.A);
                const Eigen::MatrixXd C = probe(S, c.A.rows(), false);
                const Eigen::MatrixXd Ct = probe(S, c.A.rows(), true);
                EXPECT_LE((Ct - C.transpose()).norm(), 1e-12 * C.norm())
                    << c.name << " " << sweep << " sweeps " << sweeps;
            }
}

TEST(BlockSOR, SmoothAndRepeatedSweepsFollowTheIteration) {
    for (const auto& c : cases())
        for (Sweep sweep : {Sweep::forward, Sweep::symmetric}) {
            const double w = 1.1;
            BlockSOR S(BlockSORParams{
                .omega = w, .sweep = sweep, .n_sweeps = 2, .block_starts = c.starts});
            S.setup(c.A);
            const Eigen::MatrixXd Ad = testmat::dense(c.A);
            const Eigen::MatrixXd C1 = explicit_inverse(c.A, c.starts, w, sweep);
            const Vector b = testmat::pseudo_random(c.A.rows(), 7);
            Vector x = testmat::pseudo_random(c.A.rows(), 8), xe = x;
            S.smooth(b, x);
            for (int k = 0; k < 2; ++k)
                xe += C1 * (b - Ad * xe);
            EXPECT_LE((x - xe).norm(), 1e-12 * xe.norm()) << c.name << " " << sweep;
            // apply = smooth from zero.
            Vector z, z0 = Vector::Zero(c.A.rows());
            S.apply(b, z);
            S.smooth(b, z0);
            EXPECT_LE((z - z0).norm(), 1e-13 * z.norm()) << c.name << " " << sweep;
        }
}

TEST(BlockSOR, ZeroScalarDiagonalInsideABlockIsFine) {
    std::vector<Index> vs;
    const SparseMatrix A = testmat::contact_saddle(8, &vs);
    BlockSOR point;
    try {
        point.setup(A);
        FAIL() << "expected InvalidInput for a zero diagonal with point blocks";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("zero or missing diagonal in row"), std::string::npos)
            << e.what();
    }
    BlockSOR block(BlockSORParams{.block_starts = vs});
    EXPECT_NO_THROW(block.setup(A));
    EXPECT_EQ(block.n_blocks(), 8);
    EXPECT_EQ(block.max_block_size(), 4);
}

TEST(BlockSOR, RejectsBadParamsAndBlocking) {
    EXPECT_THROW(BlockSOR(BlockSORParams{.omega = 0.0}), InvalidInput);
    EXPECT_THROW(BlockSOR(BlockSORParams{.omega = 2.0}), InvalidInput);
    EXPECT_THROW(BlockSOR(BlockSORParams{.n_sweeps = 0}), InvalidInput);
    EXPECT_THROW(BlockSOR(BlockSORParams{.block_size = 0}), InvalidInput);
    EXPECT_THROW(BlockSOR(BlockSORParams{.block_starts = {1, 3}}), InvalidInput);
    EXPECT_THROW(BlockSOR(BlockSORParams{.block_starts = {0, 3, 3}}), InvalidInput);
    BlockSOR S(BlockSORParams{.block_starts = {0, 2, 40}});
    EXPECT_THROW(S.setup(testmat::laplace_1d(10)), InvalidInput);
    std::ostringstream os;
    os << BlockSORParams{};
    EXPECT_NE(os.str().find("omega=1"), std::string::npos);
    EXPECT_EQ(BlockSOR(BlockSORParams{.omega = 1.5, .sweep = Sweep::symmetric}).name(),
              "ssor(omega=1.5)");
}

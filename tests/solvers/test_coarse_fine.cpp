// SPDX-License-Identifier: MIT
// Coarse/fine preconditioner: equal to the explicit block formula, exact with the exact Schur
// complement, inner CGS close to exact, and bad splits rejected.
#include "core/check.hpp"
#include "solvers/coarse_fine.hpp"
#include "solvers/factory.hpp"
#include "solvers/krylov.hpp"
#include "tests/smoothers/matrices.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>

using namespace mlc;
using testmat::probe;
using namespace mlc::solvers;

namespace {

// The contact saddle-point test matrix (8 vertices, contacts on the odd ones: stick, slip+,
// slip-, gap) split with vertices 0, 3, 6 coarse (vertex 3 carries multipliers), and the coarse
// unknowns numbered in a shuffled order.
struct Fixture {
    SparseMatrix A;
    CoarseFineSplit split;
    Fixture() {
        std::vector<Index> starts;
        A = testmat::contact_saddle(8, &starts);
        starts.push_back(A.rows());
        for (int v = 0; v < 8; ++v)
            for (Index i = starts[v]; i < starts[v + 1]; ++i)
                (v % 3 == 0 ? split.coarse_set : split.fine_set).push_back(static_cast<int>(i));
        const auto nc = static_cast<int>(split.coarse_set.size());
        split.n_coarse = nc;
        for (int k = 0; k < nc; ++k)
            split.coarse_dof.push_back((3 * k + 1) % nc); // a permutation (nc = 8)
    }
    // Dense blocks in set order.
    Eigen::MatrixXd block(const std::vector<int>& rows, const std::vector<int>& cols) const {
        const Eigen::MatrixXd Ad = testmat::dense(A);
        Eigen::MatrixXd B(rows.size(), cols.size());
        for (size_t i = 0; i < rows.size(); ++i)
            for (size_t j = 0; j < cols.size(); ++j)
                B(i, j) = Ad(rows[i], cols[j]);
        return B;
    }
};

// A_H in the coarse numbering from S_H given in coarse_set order (A_H[cd[k], cd[l]] = S_H(k, l)).
Eigen::MatrixXd to_coarse_numbering(const Eigen::MatrixXd& S, const std::vector<int>& cd) {
    Eigen::MatrixXd AH(S.rows(), S.cols());
    for (Index k = 0; k < S.rows(); ++k)
        for (Index l = 0; l < S.cols(); ++l)
            AH(cd[k], cd[l]) = S(k, l);
    return AH;
}

// C = P^T [[A_ff, 0], [A_cf, S]] [[I, A_ff^{-1} A_fc], [0, I]] P in the fine numbering.
Eigen::MatrixXd explicit_cf(const Fixture& f, const Eigen::MatrixXd& Aff,
                            const Eigen::MatrixXd& S) {
    const auto& fs = f.split.fine_set;
    const auto& cs = f.split.coarse_set;
    const Eigen::MatrixXd Afc = f.block(fs, cs), Acf = f.block(cs, fs);
    const Index nf = Aff.rows(), nc = S.rows(), n = nf + nc;
    Eigen::MatrixXd Lo = Eigen::MatrixXd::Zero(n, n), Up = Eigen::MatrixXd::Identity(n, n);
    Lo.topLeftCorner(nf, nf) = Aff;
    Lo.bottomLeftCorner(nc, nf) = Acf;
    Lo.bottomRightCorner(nc, nc) = S;
    Up.topRightCorner(nf, nc) = Aff.inverse() * Afc;
    const Eigen::MatrixXd Cb = Lo * Up;
    std::vector<int> order(fs);
    order.insert(order.end(), cs.begin(), cs.end());
    Eigen::MatrixXd C(n, n);
    for (Index i = 0; i < n; ++i)
        for (Index j = 0; j < n; ++j)
            C(order[i], order[j]) = Cb(i, j);
    return C;
}


CoarseSolve dense_solver(const Eigen::MatrixXd& AH) {
    auto lu = std::make_shared<Eigen::PartialPivLU<Eigen::MatrixXd>>(AH);
    return [lu](const Vector& r, Vector& z) { z = lu->solve(r); };
}

} // namespace

TEST(CoarseFine, EqualsTheExplicitBlockFormula) {
    const Fixture f;
    const auto nc = static_cast<Index>(f.split.coarse_set.size());
    // Some coarse operator (not the Schur complement): A_cc plus a shift.
    const Eigen::MatrixXd S =
        f.block(f.split.coarse_set, f.split.coarse_set) + 3.0 * Eigen::MatrixXd::Identity(nc, nc);
    const Eigen::MatrixXd AH = to_coarse_numbering(S, f.split.coarse_dof);
    auto cf = make_coarse_fine(f.split, dense_solver(AH));
    cf->setup(f.A);
    EXPECT_EQ(cf->name(), "cf(lu)");
    const Eigen::MatrixXd Aff = f.block(f.split.fine_set, f.split.fine_set);
    EXPECT_LT((testmat::dense(cf->A_ff()) - Aff).norm(), 1e-15);
    const Eigen::MatrixXd Cinv = explicit_cf(f, Aff, S).inverse();
    EXPECT_LT((probe(*cf, f.A.rows()) - Cinv).norm(), 1e-12 * Cinv.norm());
}

TEST(CoarseFine, ScalesMapTheCoarseOperator) {
    // With factors, the effective S_H is diag(1/restrict) A_H diag(1/prolong) (coarse_set order).
    Fixture f;
    const auto nc = static_cast<Index>(f.split.coarse_set.size());
    for (Index k = 0; k < nc; ++k) {
        f.split.prolong_scale.push_back(0.5 + 0.1 * k);
        f.split.restrict_scale.push_back(2.0 - 0.2 * k);
    }
    const Eigen::MatrixXd S0 =
        f.block(f.split.coarse_set, f.split.coarse_set) + 3.0 * Eigen::MatrixXd::Identity(nc, nc);
    const Eigen::MatrixXd AH = to_coarse_numbering(S0, f.split.coarse_dof);
    auto cf = make_coarse_fine(f.split, dense_solver(AH));
    cf->setup(f.A);
    const Eigen::VectorXd p = Eigen::Map<const Eigen::VectorXd>(f.split.prolong_scale.data(), nc);
    const Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(f.split.restrict_scale.data(), nc);
    const Eigen::MatrixXd S = q.cwiseInverse().asDiagonal() * S0 * p.cwiseInverse().asDiagonal();
    const Eigen::MatrixXd Cinv =
        explicit_cf(f, f.block(f.split.fine_set, f.split.fine_set), S).inverse();
    EXPECT_LT((probe(*cf, f.A.rows()) - Cinv).norm(), 1e-12 * Cinv.norm());
}

TEST(CoarseFine, ExactSchurComplementGivesTheInverse) {
    const Fixture f;
    const auto& fs = f.split.fine_set;
    const auto& cs = f.split.coarse_set;
    const Eigen::MatrixXd Aff = f.block(fs, fs);
    const Eigen::MatrixXd S = f.block(cs, cs) - f.block(cs, fs) * Aff.inverse() * f.block(fs, cs);
    auto cf = make_coarse_fine(f.split, dense_solver(to_coarse_numbering(S, f.split.coarse_dof)));
    cf->setup(f.A);
    const Eigen::MatrixXd Ainv = testmat::dense(f.A).inverse();
    EXPECT_LT((probe(*cf, f.A.rows()) - Ainv).norm(), 1e-10 * Ainv.norm());
    // One Krylov iteration solves A x = b.
    const Vector b = testmat::pseudo_random(f.A.rows(), 7);
    for (Krylov method : {Krylov::cgs, Krylov::bicgstab, Krylov::gmres}) {
        Vector x;
        const SolveResult res = solve(method, f.A, *cf, b, x, {.rel_tol = 1e-10});
        EXPECT_TRUE(res.converged) << to_string(method);
        EXPECT_EQ(res.iterations, 1) << to_string(method);
        EXPECT_LT((f.A * x - b).norm(), 1e-10 * b.norm());
    }
}

TEST(CoarseFine, InnerCGSApproachesTheExactInnerSolve) {
    const Fixture f;
    const auto nc = static_cast<Index>(f.split.coarse_set.size());
    const Eigen::MatrixXd AH = to_coarse_numbering(f.block(f.split.coarse_set, f.split.coarse_set) +
                                                       3.0 * Eigen::MatrixXd::Identity(nc, nc),
                                                   f.split.coarse_dof);
    auto exact = make_coarse_fine(f.split, dense_solver(AH));
    exact->setup(f.A);
    auto tight =
        make_coarse_fine(f.split, dense_solver(AH), {.inner = InnerSolve::cgs, .inner_tol = 1e-13});
    tight->setup(f.A);
    auto loose =
        make_coarse_fine(f.split, dense_solver(AH), {.inner = InnerSolve::cgs, .inner_tol = 1e-1});
    loose->setup(f.A);
    EXPECT_EQ(tight->name(), "cf(cgs(tol=1e-13))");
    const Vector r = testmat::pseudo_random(f.A.rows(), 2);
    Vector z0, z1, z2;
    exact->apply(r, z0);
    tight->apply(r, z1);
    loose->apply(r, z2);
    EXPECT_LT((z1 - z0).norm(), 1e-8 * z0.norm());
    EXPECT_GT((z2 - z0).norm(), 1e-12 * z0.norm()); // a loose inner solve is inexact...
    EXPECT_LT((z2 - z0).norm(), 1.0 * z0.norm());   // ...but in the right direction
    const auto& inner = dynamic_cast<const InnerCGS&>(tight->inner());
    EXPECT_EQ(inner.n_applies(), 2);
    EXPECT_GT(inner.n_iterations(), 2);
}

TEST(CoarseFine, RejectsBadSplits) {
    const Fixture f;
    const CoarseSolve id = [](const Vector& r, Vector& z) { z = r; };
    {
        CoarseFineSplit s = f.split;
        s.fine_set.pop_back(); // not a partition
        auto cf = make_coarse_fine(s, id);
        EXPECT_THROW(cf->setup(f.A), InvalidInput);
    }
    {
        CoarseFineSplit s = f.split;
        s.coarse_dof[1] = s.coarse_dof[0]; // not distinct
        auto cf = make_coarse_fine(s, id);
        EXPECT_THROW(cf->setup(f.A), InvalidInput);
    }
    {
        CoarseFineSplit s = f.split;
        s.prolong_scale = {1.0}; // wrong size
        auto cf = make_coarse_fine(s, id);
        EXPECT_THROW(cf->setup(f.A), InvalidInput);
    }
    EXPECT_THROW(make_coarse_fine(f.split, id, {.inner_tol = 0.0}), InvalidInput);
    EXPECT_THROW(make_coarse_fine(f.split, CoarseSolve{}), InvalidInput);
    EXPECT_THROW(parse_inner_solve("ilu"), InvalidInput);
}

TEST(CoarseFine, TheFactoryNamesTheLevelAwarePreconditioners) {
    // cf, sorcf and ebe are listed by the registry but built from the levels.
    for (const std::string name : {"cf", "sorcf", "ebe"}) {
        try {
            make_preconditioner(name);
            ADD_FAILURE() << name << " must not build from a matrix alone";
        } catch (const InvalidInput& e) {
            EXPECT_NE(std::string(e.what()).find("level hierarchy"), std::string::npos) << e.what();
        }
    }
}

// SPDX-License-Identifier: MIT
// The geometric V-cycle (solvers/mg.hpp) and hypre BoomerAMG on the elastic block of the square:
// the cycle as a stationary iteration contracts the residual by a fixed factor per cycle, and
// mg-CG and BoomerAMG-PCG both reach the tolerance and agree with a sparse direct solve.
#include "apps/scene.hpp"
#include "core/check.hpp"
#include "levels/elastic_block.hpp"
#include "levels/hierarchy.hpp"
#include "solvers/direct.hpp"
#include "solvers/factory.hpp"
#include "solvers/hypre/boomeramg.hpp"
#include "solvers/mg.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

using namespace mlc;

namespace {

// Levels 0..2 of the square's elastic block with a V-cycle on top (LU on level 0).
struct ElasticHierarchy {
    levels::Hierarchy h;
    std::vector<levels::ElasticBlock> blocks;
    std::vector<SparseMatrix> P, R;
    std::unique_ptr<solvers::SparseLUPreconditioner> lu;
    std::vector<std::unique_ptr<solvers::MultigridCycle>> cycle;
    Vector b;

    explicit ElasticHierarchy(int levels) {
        auto problem = apps::load_scene("square");
        problem.levels = levels;
        h = levels::build_hierarchy(problem);
        for (const auto& L : h.levels)
            blocks.push_back(levels::elastic_block(L));
        const size_t n = blocks.size();
        P.resize(n);
        R.resize(n);
        cycle.resize(n);
        lu = std::make_unique<solvers::SparseLUPreconditioner>();
        lu->setup(blocks[0].K);
        for (size_t l = 1; l < n; ++l) {
            P[l] =
                levels::displacement_prolongation(h.transfers[l - 1].T, blocks[l], blocks[l - 1]);
            R[l] = P[l].transpose();
            const Preconditioner* below =
                l == 1 ? static_cast<const Preconditioner*>(lu.get()) : cycle[l - 1].get();
            cycle[l] = std::make_unique<solvers::MultigridCycle>(
                P[l], R[l], [below](const Vector& r, Vector& z) { below->apply(r, z); },
                solvers::vertex_block_starts(blocks[l].vertex));
            cycle[l]->setup(blocks[l].K);
        }
        b = blocks.back().restrict(h.finest().elastic.f);
    }
    const SparseMatrix& K() const { return blocks.back().K; }
};

Vector direct_solve(const SparseMatrix& K, const Vector& b) {
    solvers::SparseLUPreconditioner lu;
    lu.setup(K);
    Vector x;
    lu.apply(b, x);
    return x;
}

} // namespace

TEST(Multigrid, TwoLevelCycleContractsTheElasticError) {
    // With forward pre- and backward post-smoothing the two-grid cycle is symmetric and its
    // error propagator contracts in the energy norm ||e||_K: measure the factor per cycle.
    ElasticHierarchy e(1);
    const SparseMatrix& K = e.K();
    const Vector xd = direct_solve(K, e.b);
    auto energy = [&](const Vector& err) { return std::sqrt(err.dot(K * err)); };
    Vector x = Vector::Zero(K.rows()), z;
    double prev = energy(xd - x);
    const double first = prev;
    for (int k = 0; k < 10; ++k) {
        const Vector r = e.b - K * x;
        e.cycle.back()->apply(r, z);
        x += z;
        const double now = energy(xd - x);
        EXPECT_LT(now, 0.5 * prev) << "cycle " << k; // measured 0.16, then 0.40 .. 0.46
        prev = now;
    }
    EXPECT_LT(prev, 1e-3 * first);
}

TEST(Multigrid, VCycleIsLevelIndependentAsCGPreconditioner) {
    for (int levels : {1, 2, 3}) {
        ElasticHierarchy e(levels);
        Vector x;
        const SolveResult r = solvers::pcg(e.K(), *e.cycle.back(), e.b, x, 1e-8, 100);
        ASSERT_TRUE(r.converged) << "levels " << levels << ": " << r;
        EXPECT_LE(r.iterations, 16) << "levels " << levels;
        EXPECT_LE(r.relative_residual, 1e-8);
        const Vector xd = direct_solve(e.K(), e.b);
        EXPECT_LT((x - xd).norm(), 1e-6 * xd.norm());
    }
}

TEST(Multigrid, BadInputIsRejected) {
    EXPECT_THROW(solvers::BlockGaussSeidel({}, 2.0), InvalidInput);
    solvers::MultigridParams p;
    p.pre_sweeps = 0;
    p.post_sweeps = 0;
    EXPECT_THROW(p.validate(), InvalidInput);
    // A singular vertex block.
    SparseMatrix A(2, 2);
    A.insert(0, 1) = 1.0;
    A.insert(1, 0) = 1.0;
    A.makeCompressed();
    solvers::BlockGaussSeidel point({0, 1});
    EXPECT_THROW(point.setup(A), InvalidInput);
    solvers::BlockGaussSeidel pair; // one 2x2 block: [[0, 1], [1, 0]] is fine
    EXPECT_NO_THROW(pair.setup(A));
}

TEST(BoomerAMG, PCGSolvesTheElasticBlockLikeADirectSolve) {
    if (!solvers::have_hypre()) GTEST_SKIP() << "built without hypre";
    ElasticHierarchy e(2);
    Vector x;
    const SolveResult r =
        solvers::boomeramg_pcg(e.K(), e.b, x, 1e-8, 200, {}, e.blocks.back().component);
    ASSERT_TRUE(r.converged) << r;
    EXPECT_LE(r.relative_residual, 1e-8 * 1.01);
    EXPECT_LE(r.iterations, 30);
    const Vector xd = direct_solve(e.K(), e.b);
    EXPECT_LT((x - xd).norm(), 1e-6 * xd.norm());
}

TEST(BoomerAMG, AsPreconditionerFromTheFactory) {
    if (!solvers::have_hypre()) GTEST_SKIP() << "built without hypre";
    ElasticHierarchy e(1);
    solvers::BoomerAMGPreconditioner amg;
    amg.set_dof_func(e.blocks.back().component);
    amg.setup(e.K());
    Vector x;
    const SolveResult r = solvers::pcg(e.K(), amg, e.b, x, 1e-8, 200);
    ASSERT_TRUE(r.converged) << r;
    EXPECT_LE(r.iterations, 30);
    EXPECT_THROW(solvers::make_preconditioner("amg:theta=1.5"), InvalidInput);
}

// SPDX-License-Identifier: MIT
// The geometric V-cycle (solvers/mg.hpp) and hypre BoomerAMG on the elastic block of the square:
// the cycle as a stationary iteration contracts the residual by a fixed factor per cycle, and
// mg-CG and BoomerAMG-PCG both reach the tolerance and agree with a sparse direct solve.
#include "core/check.hpp"
#include "core/traffic.hpp"
#include "levels/elastic_block.hpp"
#include "levels/hierarchy.hpp"
#include "scene/scene.hpp"
#include "smoothers/block_sor.hpp"
#include "solvers/direct.hpp"
#include "solvers/factory.hpp"
#include "solvers/hypre/boomeramg.hpp"
#include "solvers/krylov.hpp"
#include "solvers/mg.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <sstream>

using namespace mlc;

namespace {

// Levels 0..2 of the square's elastic block with a V-cycle on top (LU on level 0).
struct ElasticHierarchy {
    levels::Hierarchy h;
    std::vector<levels::ElasticBlock> blocks;
    std::unique_ptr<levels::ElasticMultigrid> mg;
    Vector b;

    explicit ElasticHierarchy(int levels, solvers::MultigridParams params = {}) {
        auto problem = scene::load_scene("square");
        problem.levels = levels;
        h = levels::build_hierarchy(problem);
        for (const auto& L : h.levels)
            blocks.push_back(levels::elastic_block(L));
        mg = std::make_unique<levels::ElasticMultigrid>(h, blocks, params);
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

// The multigrid cycle's smoother (vertex blocks, unrolled kernel) with `parts` parts.
smoothers::BlockSOR mg_smoother(std::vector<Index> starts, int parts) {
    return smoothers::BlockSOR(smoothers::BlockSORParams{.block_size = 2,
                                                         .block_starts = std::move(starts),
                                                         .parts = parts,
                                                         .kernel = smoothers::Kernel::unrolled});
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
        e.mg->finest().apply(r, z);
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
        const SolveResult r = solvers::cg(MatrixOperator(e.K()), e.mg->finest(), e.b, x,
                                          solvers::KrylovParams{.rel_tol = 1e-8, .max_iter = 100});
        ASSERT_TRUE(r.converged) << "levels " << levels << ": " << r;
        EXPECT_LE(r.iterations, 16) << "levels " << levels;
        EXPECT_LE(r.relative_residual, 1e-8);
        const Vector xd = direct_solve(e.K(), e.b);
        EXPECT_LT((x - xd).norm(), 1e-6 * xd.norm());
    }
}

TEST(Multigrid, BadInputIsRejected) {
    EXPECT_THROW(smoothers::BlockSOR(smoothers::BlockSORParams{.omega = 2.0}), InvalidInput);
    solvers::MultigridParams p;
    p.pre_sweeps = 0;
    p.post_sweeps = 0;
    EXPECT_THROW(p.validate(), InvalidInput);
    // A singular vertex block.
    SparseMatrix A(2, 2);
    A.insert(0, 1) = 1.0;
    A.insert(1, 0) = 1.0;
    A.makeCompressed();
    auto point = mg_smoother({0, 1}, 1);
    EXPECT_THROW(point.setup(A), InvalidInput);
    auto pair = mg_smoother({}, 1); // one 2x2 block: [[0, 1], [1, 0]] is fine
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
    const SolveResult r = solvers::cg(MatrixOperator(e.K()), amg, e.b, x,
                                      solvers::KrylovParams{.rel_tol = 1e-8, .max_iter = 200});
    ASSERT_TRUE(r.converged) << r;
    EXPECT_LE(r.iterations, 30);
    EXPECT_THROW(solvers::make_preconditioner("amg:theta=1.5"), InvalidInput);
}

namespace {

// Which part each row belongs to, from the block starts and the parts' first rows.
std::vector<int> part_of_rows(Index n, const std::vector<Index>& part_first_row) {
    std::vector<int> part(static_cast<size_t>(n), 0);
    for (size_t p = 0; p < part_first_row.size(); ++p)
        for (Index i = part_first_row[p]; i < n; ++i)
            part[static_cast<size_t>(i)] = static_cast<int>(p);
    return part;
}

} // namespace

TEST(BlockSORParts, TwoPartsSweepTheirOwnRowsAndReadTheOtherPartAsItWas) {
    // The elastic block of level 3 (33152 unknowns, 2x2 vertex blocks): two parts. Every row i
    // of part p must satisfy, after a forward sweep from x_old,
    //   sum_{j in p, block(j) <= block(i)} a_ij x_new_j + sum_{other j} a_ij x_old_j = b_i,
    // which is the hybrid Gauss–Seidel definition (and from zero, x_old = 0 everywhere).
    const ElasticHierarchy eh(3);
    const SparseMatrix& K = eh.K();
    const Index n = K.rows();
    const auto starts = solvers::vertex_block_starts(eh.blocks.back().vertex);
    auto two = mg_smoother(starts, 2);
    auto one = mg_smoother(starts, 1);
    two.setup(K);
    one.setup(K);
    ASSERT_EQ(two.parts(), 2);
    ASSERT_EQ(one.parts(), 1);
    std::vector<int> block(static_cast<size_t>(n));
    for (size_t I = 0; I < starts.size(); ++I)
        for (Index i = starts[I]; i < (I + 1 < starts.size() ? starts[I + 1] : n); ++i)
            block[static_cast<size_t>(i)] = static_cast<int>(I);
    Vector x0, res;
    two.forward_from_zero(eh.b, x0, res);
    Vector check = eh.b;
    check.noalias() -= K * x0;
    EXPECT_LT((res - check).norm(), 1e-12 * eh.b.norm()); // the residual it returns is exact
    // The cut: at a block start, with about half the nonzeros on each side.
    const auto rows = two.part_rows();
    ASSERT_EQ(rows.size(), 3u);
    EXPECT_EQ(rows[0], 0);
    EXPECT_EQ(rows[2], n);
    const Index cut = rows[1];
    EXPECT_TRUE(std::binary_search(starts.begin(), starts.end(), cut));
    const double half = K.outerIndexPtr()[cut] / static_cast<double>(K.nonZeros());
    EXPECT_NEAR(half, 0.5, 0.01);
    const auto part = part_of_rows(n, {0, cut});
    auto hybrid_defect = [&](const Vector& x_old, const Vector& x_new, bool forward) {
        double worst = 0.0;
        for (Index i = 0; i < n; ++i) {
            double s = 0.0;
            for (SparseMatrix::InnerIterator it(K, i); it; ++it) {
                const auto j = static_cast<size_t>(it.col());
                const bool same = part[j] == part[static_cast<size_t>(i)];
                const bool done = forward ? block[j] <= block[static_cast<size_t>(i)]
                                          : block[j] >= block[static_cast<size_t>(i)];
                s += it.value() * (same && done ? x_new[it.col()] : x_old[it.col()]);
            }
            worst = std::max(worst, std::abs(s - eh.b[i]));
        }
        return worst / eh.b.lpNorm<Eigen::Infinity>();
    };
    EXPECT_LT(hybrid_defect(Vector::Zero(n), x0, true), 1e-10);
    for (bool forward : {true, false}) {
        Vector x_old = Vector::Random(n) * x0.lpNorm<Eigen::Infinity>();
        Vector x = x_old;
        two.sweep(eh.b, x, forward ? smoothers::Sweep::forward : smoothers::Sweep::backward);
        EXPECT_LT(hybrid_defect(x_old, x, forward), 1e-10) << (forward ? "forward" : "backward");
        // The same linear map every time, and not the sequential sweep (the cut is real).
        Vector x2 = x_old;
        two.sweep(eh.b, x2, forward ? smoothers::Sweep::forward : smoothers::Sweep::backward);
        EXPECT_EQ((x2 - x).norm(), 0.0);
        Vector xs = x_old;
        one.sweep(eh.b, xs, forward ? smoothers::Sweep::forward : smoothers::Sweep::backward);
        EXPECT_GT((xs - x).norm(), 1e-12 * x.norm());
    }
    // update_values: values refreshed in place (K doubled: the sweep from zero halves), and
    // another matrix (the same as a fresh setup on it).
    SparseMatrix K2 = K;
    auto mine = mg_smoother(starts, 2);
    mine.setup(K2);
    Vector xa, ra, xb, rb;
    mine.forward_from_zero(eh.b, xa, ra);
    K2 *= 2.0;
    mine.update_values(K2);
    mine.forward_from_zero(eh.b, xb, rb);
    EXPECT_LT((2.0 * xb - xa).norm(), 1e-12 * xa.norm());
    SparseMatrix K3 = K;
    K3.coeffRef(0, 0) *= 3.0;
    mine.update_values(K3);
    auto fresh = mg_smoother(starts, 2);
    fresh.setup(K3);
    mine.forward_from_zero(eh.b, xa, ra);
    fresh.forward_from_zero(eh.b, xb, rb);
    EXPECT_EQ((xa - xb).norm(), 0.0);
    // Smaller than two parts' worth of rows: one part whatever is asked.
    auto small = mg_smoother(solvers::vertex_block_starts(eh.blocks[1].vertex), 2);
    small.setup(eh.blocks[1].K);
    EXPECT_EQ(small.parts(), 1);
}

TEST(Multigrid, GalerkinElasticOperatorIsTheRediscretizedOne) {
    // Nested P1 spaces and P the exact interpolation: P^T K_l P = K_{l-1} (the same bilinear form
    // on the coarse space), so for the elastic block the Galerkin and rediscretized coarse
    // operators coincide; only the contact rows can differ.
    const ElasticHierarchy eh(2);
    for (size_t l = 1; l < eh.blocks.size(); ++l) {
        const SparseMatrix RKP = SparseMatrix(eh.mg->R[l] * eh.blocks[l].K) * eh.mg->P[l];
        const SparseMatrix diff = RKP - eh.blocks[l - 1].K;
        double dmax = 0.0, kmax = 0.0;
        for (int k = 0; k < diff.nonZeros(); ++k)
            dmax = std::max(dmax, std::abs(diff.valuePtr()[k]));
        for (int k = 0; k < eh.blocks[l - 1].K.nonZeros(); ++k)
            kmax = std::max(kmax, std::abs(eh.blocks[l - 1].K.valuePtr()[k]));
        EXPECT_LT(dmax, 1e-12 * kmax) << "level " << l;
    }
}

TEST(Multigrid, OwnsItsLevelsAndReportsThem) {
    ElasticHierarchy e(2);
    const solvers::MultigridReport r = e.mg->finest().report();
    ASSERT_EQ(r.levels.size(), 3u);
    double nnz = 0, rows = 0;
    for (size_t l = 0; l < 3; ++l) {
        EXPECT_EQ(r.levels[l].level, static_cast<int>(l));
        EXPECT_EQ(r.levels[l].rows, e.blocks[l].K.rows());
        EXPECT_EQ(r.levels[l].nonzeros, e.blocks[l].K.nonZeros());
        nnz += static_cast<double>(e.blocks[l].K.nonZeros());
        rows += static_cast<double>(e.blocks[l].K.rows());
    }
    EXPECT_DOUBLE_EQ(r.operator_complexity, nnz / static_cast<double>(e.K().nonZeros()));
    EXPECT_DOUBLE_EQ(r.grid_complexity, rows / static_cast<double>(e.K().rows()));
    // Refinement by four: both complexities lie between 1 and 4/3.
    EXPECT_GT(r.operator_complexity, 1.0);
    EXPECT_LT(r.operator_complexity, 4.0 / 3.0 + 0.02);
    EXPECT_EQ(r.levels[0].solve, "lu");
    EXPECT_EQ(r.levels[2].solve, "smoother");
    EXPECT_EQ(r.coarse_operators, "rediscretized");
    std::ostringstream table;
    table << r;
    EXPECT_NE(table.str().find("operator complexity"), std::string::npos) << table.str();
}

TEST(Multigrid, TheLevelAboveSharesTheLevelsBelowAndAppliesTheSameCycle) {
    // Levels 0..2 built at once, and level 2 built above a multigrid of levels 0..1: the same
    // linear map, bit for bit (the levels below are shared, not copied).
    ElasticHierarchy e(2);
    const auto& P = e.mg->P;
    const auto& R = e.mg->R;
    auto data = [&](size_t l) {
        solvers::MultigridLevelData d;
        if (l > 0) {
            d.T = &P[l];
            d.R = &R[l];
        }
        d.block_starts = solvers::vertex_block_starts(e.blocks[l].vertex);
        return d;
    };
    solvers::Multigrid below({data(0), data(1)}, {});
    below.set_operator(0, e.blocks[0].K);
    below.setup(e.blocks[1].K);
    auto above = solvers::Multigrid::above(below, data(2), {});
    EXPECT_EQ(above->n_levels(), 3);
    above->setup(e.K());
    Vector z1, z2;
    const Vector r = Vector::LinSpaced(e.K().rows(), -1.0, 2.0);
    above->apply(r, z1);
    e.mg->finest().apply(r, z2);
    EXPECT_EQ((z1 - z2).lpNorm<Eigen::Infinity>(), 0.0);
    // Galerkin: the operators are R A T products, which for the elastic block equal the
    // rediscretized stiffness up to round-off (GalerkinElasticOperatorIsTheRediscretizedOne),
    // so one cycle agrees to round-off.
    solvers::Multigrid gal({data(0), data(1), data(2)}, {}, solvers::CoarseOperators::galerkin);
    gal.setup(e.K());
    Vector z3;
    gal.apply(r, z3);
    EXPECT_LT((z3 - z2).norm(), 1e-8 * z2.norm());
    EXPECT_EQ(gal.report().coarse_operators, "Galerkin (R A T)");
    EXPECT_THROW(gal.set_operator(0, e.blocks[0].K), InvalidInput);
    EXPECT_THROW(solvers::Multigrid({data(1)}, {}), InvalidInput);          // one level
    EXPECT_THROW(solvers::Multigrid({data(1), data(2)}, {}), InvalidInput); // coarsest with T
}

TEST(Multigrid, OneVCycleCountsItsPasses) {
    // Levels 0..2: per level above 0 a forward sweep from zero with its residual (two smoother
    // passes), a backward sweep (one), a restriction and a prolongation (two transfer passes);
    // one coarse solve; nothing else (no mat-vec, no Krylov vector operation).
    ElasticHierarchy e(2);
    const Vector r = e.b;
    Vector z;
    const traffic::Account a0 = traffic::snapshot();
    e.mg->finest().apply(r, z);
    const traffic::Account d = traffic::snapshot() - a0;
    EXPECT_EQ(d.p(traffic::Kind::smoother), 6.0);
    EXPECT_EQ(d.p(traffic::Kind::transfer), 4.0);
    EXPECT_EQ(d.p(traffic::Kind::coarse), 1.0);
    EXPECT_EQ(d.p(traffic::Kind::matvec), 0.0);
    EXPECT_EQ(d.p(traffic::Kind::vector), 0.0);
    EXPECT_EQ(d.b(traffic::Kind::coarse), 0.0);
    // The transfers read at least the nonzeros of T and R once each (12 bytes an entry).
    const solvers::MultigridReport rep = e.mg->finest().report();
    ASSERT_EQ(rep.levels.size(), 3u);
    EXPECT_GT(d.b(traffic::Kind::transfer), 0.0);
    // The smoother reads each level's operator twice (12 bytes an entry: once over the two
    // passes of the sweep from zero, once in the backward sweep), plus the row offsets, block
    // inverses and vectors (about 18 entries a row: less than the matrix again).
    const double ops = 12.0 * static_cast<double>(rep.levels[1].nonzeros + rep.levels[2].nonzeros);
    EXPECT_GT(d.b(traffic::Kind::smoother), 2 * ops);
    EXPECT_LT(d.b(traffic::Kind::smoother), 4 * ops);
}

TEST(Multigrid, OneWCycleVisitsEachLevelTwiceAsOftenAsTheOneAbove) {
    // Levels 0..3, W(1,1): level 3 once, level 2 twice, level 1 four times (level 1 solves its
    // coarse problem once: level 0's LU is exact), four coarse solves; per visit three smoother
    // and two transfer passes; one residual of the level below per second coarse cycle (at
    // level 3 and at each visit of level 2).
    solvers::MultigridParams w;
    w.cycles = 2;
    ElasticHierarchy e(3, w);
    Vector z;
    const traffic::Account a0 = traffic::snapshot();
    e.mg->finest().apply(e.b, z);
    const traffic::Account d = traffic::snapshot() - a0;
    EXPECT_EQ(d.p(traffic::Kind::smoother), 3.0 * (1 + 2 + 4));
    EXPECT_EQ(d.p(traffic::Kind::transfer), 2.0 * (1 + 2 + 4));
    EXPECT_EQ(d.p(traffic::Kind::coarse), 4.0);
    EXPECT_EQ(d.p(traffic::Kind::matvec), 3.0);
    EXPECT_EQ(e.mg->finest().report().cycle.substr(0, 6), "W(1,1)");
    EXPECT_NE(e.mg->finest().name().find("cycle=W"), std::string::npos);
}

TEST(Multigrid, OnTwoLevelsTheWCycleIsTheVCycleBitForBit) {
    solvers::MultigridParams w;
    w.cycles = 2;
    ElasticHierarchy v1(1), w1(1, w);
    Vector zv, zw;
    v1.mg->finest().apply(v1.b, zv);
    w1.mg->finest().apply(w1.b, zw);
    EXPECT_EQ(zv, zw);
}

TEST(Multigrid, WCycleIsSymmetricAndNeedsNoMoreCGIterationsThanTheVCycle) {
    solvers::MultigridParams w;
    w.cycles = 2;
    ElasticHierarchy v(3), e(3, w);
    // Symmetric: (B r1, r2) = (r1, B r2).
    const Index n = e.K().rows();
    Vector r1(n), r2(n), z1, z2;
    for (Index i = 0; i < n; ++i) {
        r1[i] = std::sin(0.7 * static_cast<double>(i));
        r2[i] = std::cos(1.3 * static_cast<double>(i));
    }
    e.mg->finest().apply(r1, z1);
    e.mg->finest().apply(r2, z2);
    EXPECT_NEAR(z1.dot(r2), r1.dot(z2), 1e-12 * z1.norm() * r2.norm());
    const solvers::KrylovParams kp{.rel_tol = 1e-8, .max_iter = 100};
    Vector xv, xw;
    const SolveResult rv = solvers::cg(MatrixOperator(v.K()), v.mg->finest(), v.b, xv, kp);
    const SolveResult rw = solvers::cg(MatrixOperator(e.K()), e.mg->finest(), e.b, xw, kp);
    ASSERT_TRUE(rv.converged && rw.converged);
    EXPECT_LE(rw.iterations, rv.iterations);
    EXPECT_LT((xw - xv).norm(), 1e-6 * xv.norm());
    // Cycles other than 1 and 2 are refused.
    w.cycles = 3;
    EXPECT_THROW(w.validate(), InvalidInput);
}

TEST(Multigrid, OneVCycleCountsItsBytesInBothPrecisions) {
    // Every pass of a V-cycle on levels 0..2 in closed form (core/traffic.hpp): per level above
    // 0 the sweep from zero with its residual and the backward sweep on K_l (vertex blocks), the
    // restriction R_l r and the prolongation z += P_l e; with precision=single the same passes
    // with 4-byte values and block-inverse entries. The single cycle is the double one up to
    // float rounding of the data (about 1e-7 relative), not bit for bit.
    solvers::MultigridParams single;
    single.precision = Precision::float32;
    ElasticHierarchy d(2), s(2, single);
    EXPECT_EQ(s.mg->finest().name(), "mg(pre=1,post=1,omega=1,precision=single)");
    EXPECT_EQ(d.mg->finest().name(), "mg(pre=1,post=1,omega=1)");
    for (const auto& [e, vb] : {std::pair<ElasticHierarchy*, int>{&d, 8}, {&s, 4}}) {
        double smoother = 0.0, transfer = 0.0;
        for (size_t l = 1; l < 3; ++l) {
            const SparseMatrix& K = e->blocks[l].K;
            const std::vector<Index> starts = solvers::vertex_block_starts(e->blocks[l].vertex);
            Index inverse = 0;
            for (size_t b = 0; b < starts.size(); ++b) {
                const Index size = (b + 1 < starts.size() ? starts[b + 1] : K.rows()) - starts[b];
                inverse += size * size;
            }
            const auto nb = static_cast<Index>(starts.size());
            smoother += traffic::sweep_from_zero_bytes(K.rows(), K.nonZeros(), nb, inverse, vb) +
                        traffic::sweep_bytes(K.rows(), K.nonZeros(), nb, inverse, vb);
            const SparseMatrix& R = e->mg->R[l];
            const SparseMatrix& P = e->mg->P[l];
            transfer += traffic::csr_bytes(R.rows(), R.cols(), R.nonZeros(), false, vb) +
                        traffic::csr_bytes(P.rows(), P.cols(), P.nonZeros(), true, vb);
        }
        Vector z;
        const traffic::Account a0 = traffic::snapshot();
        e->mg->finest().apply(e->b, z);
        const traffic::Account a = traffic::snapshot() - a0;
        EXPECT_EQ(a.b(traffic::Kind::smoother), smoother) << vb;
        EXPECT_EQ(a.b(traffic::Kind::transfer), transfer) << vb;
        EXPECT_EQ(a.p(traffic::Kind::smoother), 6.0);
        EXPECT_EQ(a.p(traffic::Kind::transfer), 4.0);
    }
    Vector zd, zs;
    d.mg->finest().apply(d.b, zd);
    s.mg->finest().apply(s.b, zs);
    EXPECT_LT((zs - zd).norm(), 1e-5 * zd.norm());
    EXPECT_GT((zs - zd).norm(), 0.0);
}

// SPDX-License-Identifier: MIT
// `--pc mg` on the square (mu = 1, five load steps, coarse-to-fine): the V-cycle over all
// levels preconditions the non-symmetric contact Jacobian inside CGS, BiCGStab and GMRES with a
// small iteration count that does not grow from level 1 to level 3.
#include "core/check.hpp"
#include "levels/krylov_system.hpp"
#include "levels/resources.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>

using namespace mlc;
using namespace mlc::levels;

namespace {

// Largest Krylov iteration count of any Newton system on each level >= 1.
std::vector<int> max_iterations(const RunResult& r) {
    std::vector<int> out;
    for (size_t l = 1; l < r.level_steps.size(); ++l) {
        int m = 0;
        for (const auto& st : r.level_steps[l])
            for (int i : st.report.linear_iterations_per_newton)
                m = std::max(m, i);
        out.push_back(m);
    }
    return out;
}

RunResult run_square(int levels, const std::string& krylov, const std::string& pc,
                     int load_steps = 0) {
    auto p = scene::load_scene("square");
    p.levels = levels;
    if (load_steps > 0) p.load_steps = load_steps;
    SolveOptions so;
    so.linear = {.method = "krylov", .krylov = krylov, .pc = pc, .rel_tol = 1e-8, .max_iter = 200};
    return solve(p, so);
}

RunResult run_square_problem(const Problem& p) {
    SolveOptions so;
    so.linear = {.method = "krylov", .krylov = "cgs", .pc = "mg", .rel_tol = 1e-8, .max_iter = 200};
    return solve(p, so);
}

} // namespace

TEST(MultilevelPreconditioner, WorksInsideCgsBicgstabAndGmres) {
    // Measured on level 2: CGS 8-9, BiCGStab 7-8, GMRES 13 iterations per Newton step.
    auto p = scene::load_scene("square");
    p.levels = 2;
    const RunResult ref = solve(p, {}); // the exact condensed solver
    ASSERT_TRUE(ref.converged);
    for (const auto& [krylov, bound] :
         {std::pair<std::string, int>{"cgs", 12}, {"bicgstab", 12}, {"gmres", 18}}) {
        const RunResult r = run_square(2, krylov, "mg");
        ASSERT_TRUE(r.converged) << krylov << ": " << r.failure;
        for (int m : max_iterations(r))
            EXPECT_LE(m, bound) << krylov;
        EXPECT_LT((r.x - ref.x).norm(), 1e-7 * ref.x.norm()) << krylov;
    }
}

TEST(MultilevelPreconditioner, TheRunReportsTheMultigridOfTheFinestLevel) {
    const RunResult r = run_square(2, "cgs", "mg", 1);
    ASSERT_TRUE(r.converged) << r.failure;
    ASSERT_TRUE(r.multigrid.has_value());
    ASSERT_EQ(r.multigrid->levels.size(), 3u);
    for (size_t l = 0; l < 3; ++l)
        EXPECT_EQ(r.multigrid->levels[l].rows, r.hierarchy.levels[l].n_unknowns()) << l;
    EXPECT_GT(r.multigrid->operator_complexity, 1.0);
    // Without mg, no multigrid.
    auto p = scene::load_scene("square");
    p.levels = 1;
    EXPECT_FALSE(solve(p, {}).multigrid.has_value());
}

TEST(MultilevelPreconditioner, IterationsDoNotGrowWithTheLevel) {
    const RunResult r = run_square(3, "cgs", "mg", 2); // two load steps keep the test short
    ASSERT_TRUE(r.converged) << r.failure;
    const auto m = max_iterations(r); // levels 1, 2, 3
    ASSERT_EQ(m.size(), 3u);
    EXPECT_LE(m[2], 12);
    EXPECT_LE(m[2], m[0] + 2);
}

TEST(MultilevelPreconditioner, NeedsTheLevelBelowAndValidOptions) {
    auto p = scene::load_scene("square");
    p.levels = 0;
    SolveOptions so;
    so.linear = {.method = "krylov", .krylov = "cgs", .pc = "mg"};
    EXPECT_THROW(solve(p, so), InvalidInput);
    p.levels = 1;
    so.linear.pc = "mg:pre=0,post=0";
    EXPECT_THROW(solve(p, so), InvalidInput);
    so.linear.pc = "mg:sweeps=2";
    EXPECT_THROW(solve(p, so), InvalidInput);
}

TEST(InexactNewton, ForcingTermsSaveKrylovIterationsAndGiveTheSameSolution) {
    // The first Newton iteration of each load step solves to 1e-3 (its statuses are a coarse
    // prediction, corrected by that step), the later ones just to what reaches the Newton
    // tolerance: measured on levels 1..2, 105 instead of 156 CGS iterations in all.
    auto p = scene::load_scene("square");
    p.levels = 2;
    const RunResult ref = solve(p, {}); // the exact condensed solver
    ASSERT_TRUE(ref.converged);
    auto total_krylov = [](const RunResult& r) {
        int n = 0;
        for (const auto& steps : r.level_steps)
            for (const auto& st : steps)
                n += st.report.linear_iterations;
        return n;
    };
    p.newton.forcing = 0.0;
    const RunResult exact = run_square_problem(p);
    p.newton.forcing = 1e-3;
    const RunResult inexact = run_square_problem(p);
    ASSERT_TRUE(exact.converged) << exact.failure;
    ASSERT_TRUE(inexact.converged) << inexact.failure;
    EXPECT_LT(total_krylov(inexact), 0.8 * total_krylov(exact));
    // Same Newton tolerance (1e-10), so the same solution to far below discretization error.
    EXPECT_LT((inexact.x - ref.x).norm(), 1e-8 * ref.x.norm());
    EXPECT_LT((exact.x - ref.x).norm(), 1e-8 * ref.x.norm());
    // Out of range.
    p.newton.forcing = 1.0;
    EXPECT_THROW(p.newton.validate(), InvalidInput);
    p.newton.forcing = -0.1;
    EXPECT_THROW(p.newton.validate(), InvalidInput);
}

TEST(MultilevelPreconditioner, GalerkinCoarseOperatorsConvergeLikeRediscretization) {
    // mg:coarse=galerkin builds R J T down to level 0 from each Newton system (statuses of the
    // fine level carried down by the products); the default rediscretizes (the level below's
    // Jacobian at its converged statuses). Same solution, similar iterations on levels 1..2.
    auto p = scene::load_scene("square");
    p.levels = 2;
    p.load_steps = 2;
    const RunResult ref = solve(p, {});
    ASSERT_TRUE(ref.converged);
    SolveOptions so;
    so.linear = {.method = "krylov",
                 .krylov = "cgs",
                 .pc = "mg:coarse=galerkin",
                 .rel_tol = 1e-8,
                 .max_iter = 200};
    const RunResult gal = solve(p, so);
    ASSERT_TRUE(gal.converged) << gal.failure;
    EXPECT_LT((gal.x - ref.x).norm(), 1e-8 * ref.x.norm());
    for (int m : max_iterations(gal))
        EXPECT_LE(m, 12);
    so.linear.pc = "mg:coarse=algebraic";
    EXPECT_THROW(solve(p, so), InvalidInput);
}

TEST(MultilevelPreconditioner, StiffContactBlocksOfLargeRAreSmoothed_Slow) {
    // r = 1e4 E (1.3e9): the 4x4 vertex + multiplier block of a gap vertex is
    // [[K, 0], [0, -I/r]] with pivots 1e5 and 7.7e-10, which the smoother's full-pivot LU test
    // (threshold 1e-14 relative to the largest pivot) used to call singular. Equilibrated, the
    // blocks are inverted and mg gives the exact solver's solution with few iterations.
    auto p = scene::load_scene("square");
    p.levels = 3;
    p.load_steps = 2;
    for (auto& c : p.contacts)
        c.r = 1e4 * p.bodies[0].material.E;
    const RunResult ref = solve(p, {});
    ASSERT_TRUE(ref.converged) << ref.failure;
    const RunResult r = run_square_problem(p);
    ASSERT_TRUE(r.converged) << r.failure;
    EXPECT_LT((r.x - ref.x).norm(), 1e-6 * ref.x.norm());
    for (int m : max_iterations(r))
        EXPECT_LE(m, 30);
}

TEST(MultilevelPreconditioner, TheExactFallbackSolvesWhatTheMultigridCannot) {
    // Near-incompressible square (nu = 0.4999): the vertex-block smoother degrades and CGS + mg
    // needs thousands of iterations per Newton system on level 1. Without a fallback the
    // Krylov budget is the only limit; with it, a slow solve is given up and the level's systems
    // are solved exactly, with the answer of the exact solver.
    auto p = scene::load_scene("square");
    p.levels = 1;
    p.load_steps = 1;
    for (auto& b : p.bodies)
        b.material.nu = 0.4999;
    SolveOptions exact;
    const RunResult ref = solve(p, exact);
    ASSERT_TRUE(ref.converged) << ref.failure;
    SolveOptions so;
    so.linear = {.method = "krylov", .krylov = "cgs", .pc = "mg", .max_iter = 100};
    const RunResult fails = solve(p, so);
    EXPECT_FALSE(fails.converged);
    EXPECT_NE(fails.failure.find("linear solve failed"), std::string::npos) << fails.failure;
    so.exact_fallback = true;
    const RunResult r = solve(p, so);
    ASSERT_TRUE(r.converged) << r.failure;
    int fallbacks = 0;
    for (const auto& st : r.level_steps[1])
        fallbacks += st.report.fallback_solves;
    EXPECT_GT(fallbacks, 0);
    EXPECT_NE(r.level_steps[1][0].report.fallback_reason.find("solved by schur"), std::string::npos)
        << r.level_steps[1][0].report.fallback_reason;
    EXPECT_LT((r.x - ref.x).norm(), 1e-8 * ref.x.norm());
    // On the ordinary square the fallback never fires and changes nothing.
    auto q = scene::load_scene("square");
    q.levels = 2;
    SolveOptions plain;
    plain.linear = {.method = "krylov", .krylov = "cgs", .pc = "mg"};
    SolveOptions with = plain;
    with.exact_fallback = true;
    const RunResult a = solve(q, plain), b = solve(q, with);
    ASSERT_TRUE(a.converged && b.converged);
    EXPECT_EQ((a.x - b.x).norm(), 0.0);
    for (size_t l = 0; l < a.level_steps.size(); ++l)
        for (size_t s = 0; s < a.level_steps[l].size(); ++s) {
            EXPECT_EQ(a.level_steps[l][s].report.linear_iterations,
                      b.level_steps[l][s].report.linear_iterations);
            EXPECT_EQ(b.level_steps[l][s].report.fallback_solves, 0);
        }
}

TEST(MultilevelPreconditioner, TheDampedTwoBodyDefaultSolvesTheDovetail) {
    // The default's Krylov + mg with a two-body pair (BiCGStab + mg:omega=0.8, levels/
    // resources.hpp): the same solution as the exact schur on dovetail level 2 (56 181
    // unknowns), with few BiCGStab iterations per Newton step (27 per load step on
    // level 4 against 55 undamped, README "Choosing the Newton-system solver").
    auto p = scene::load_scene("dovetail");
    p.levels = 2;
    p.load_steps = 2;
    const RunResult ref = solve(p, {});
    ASSERT_TRUE(ref.converged) << ref.failure;
    SolveOptions so;
    so.linear = {.method = "krylov", .krylov = "bicgstab", .pc = levels::kMgDefaultTwoBody,
                 .rel_tol = 1e-10, .max_iter = 200};
    const RunResult r = solve(p, so);
    ASSERT_TRUE(r.converged) << r.failure;
    ASSERT_TRUE(r.multigrid.has_value());
    EXPECT_EQ(r.multigrid->cycle, "V(1,1), omega = 0.8");
    const auto m = max_iterations(r);
    ASSERT_EQ(m.size(), 2u);
    EXPECT_LE(m.back(), 20); // measured 17 (two load steps of 0.5)
    EXPECT_LT((r.x - ref.x).norm(), 1e-8 * ref.x.norm());
}

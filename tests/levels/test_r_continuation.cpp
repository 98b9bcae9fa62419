// SPDX-License-Identifier: MIT
// SolveOptions::r_continuation: at a very large augmentation parameter the generalized Newton
// method cycles over statuses (it is only locally convergent); the step is solved at a reduced r
// and finished at the scene's r. The discrete contact solution does not depend on r, so the
// answer must be the one of the default r = 0.1 E.
#include "levels/solve.hpp"
#include "scene/scene.hpp"

#include <gtest/gtest.h>

#include <string>

using namespace mlc;
using namespace mlc::levels;

namespace {

Problem square_with_r(double r_over_E, int levels) {
    auto p = scene::load_scene("square");
    p.levels = levels;
    for (auto& c : p.contacts)
        c.r = r_over_E * p.bodies[0].material.E;
    return p;
}

double max_lambda_difference(const RunResult& a, const RunResult& b) {
    double d = 0.0, m = 0.0;
    for (size_t i = 0; i < a.nodes.size(); ++i) {
        d = std::max({d, std::abs(a.nodes[i].lambda_n - b.nodes[i].lambda_n),
                      std::abs(a.nodes[i].lambda_t - b.nodes[i].lambda_t)});
        m = std::max(m, std::abs(b.nodes[i].lambda_n));
    }
    return d / m;
}

} // namespace

TEST(RContinuation, RecoversTheStepThatCyclesAtHugeR) {
    // Level 0 of the square at r = 1e5 E: Newton cycles in load step 2 or 3 (measured: the
    // relative residual stalls near 1e-2 after 50 iterations; which step first cycles depends on
    // the rounding of the factorization of K + r B^T B at this r: step 2 with the reference BLAS,
    // step 3 with OpenBLAS).
    const Problem p = square_with_r(1e5, 0);
    const RunResult fails = solve(p, {});
    ASSERT_FALSE(fails.converged);
    const int k = fails.completed_steps; // the step that cycled (0-based)
    ASSERT_GE(k, 1);
    ASSERT_LE(k, 2);
    EXPECT_NE(fails.failure.find("load step " + std::to_string(k + 1)), std::string::npos)
        << fails.failure;

    SolveOptions so;
    so.r_continuation = true;
    const RunResult r = solve(p, so);
    ASSERT_TRUE(r.converged) << r.failure;
    // The steps before it converge at r as before, untouched; the step that cycled needs the
    // continuation, and the later steps go straight to it at the factor that worked.
    for (int j = 0; j < k; ++j) {
        EXPECT_EQ(r.steps[j].continuation_factor, 0.0);
        EXPECT_EQ(r.steps[j].iterations, fails.steps[j].iterations);
    }
    ASSERT_GT(r.steps[k].continuation_factor, 0.0);
    EXPECT_LE(r.steps[k].continuation_factor, 1e-2);
    EXPECT_NE(r.steps[k].continuation_note.find("Newton at r failed"), std::string::npos)
        << r.steps[k].continuation_note;
    for (size_t j = k + 1; j < r.steps.size(); ++j)
        EXPECT_EQ(r.steps[j].continuation_factor, r.steps[k].continuation_factor);
    // Every step passed the Newton test at the scene's r.
    for (const auto& st : r.steps)
        EXPECT_LE(st.residuals.back(), p.newton.rel_tol);

    // The same answer as the default r = 0.1 E, where Newton converges directly.
    const RunResult ref = solve(square_with_r(0.1, 0), {});
    ASSERT_TRUE(ref.converged) << ref.failure;
    EXPECT_LT((r.u_full - ref.u_full).norm(), 1e-8 * ref.u_full.norm());
    EXPECT_LT(max_lambda_difference(r, ref), 1e-8);
    for (size_t i = 0; i < r.nodes.size(); ++i)
        EXPECT_EQ(r.nodes[i].status, ref.nodes[i].status) << "contact node " << i;
}

TEST(RContinuation, CoarseToFineWithTheMultigridAtHugeR) {
    // Coarse-to-fine to level 1 with CGS + mg: the continuation runs on level 0 (exact solves)
    // and leaves the Krylov solves of level 1 at the scene's r.
    const Problem p = square_with_r(1e5, 1);
    SolveOptions so;
    so.linear = {.method = solvers::Method::krylov,
                 .krylov = solvers::Krylov::cgs,
                 .pc = solvers::parse_pc("mg")};
    so.exact_fallback = true;
    so.r_continuation = true;
    const RunResult r = solve(p, so);
    ASSERT_TRUE(r.converged) << r.failure;
    int continued = 0;
    for (const auto& ls : r.level_steps)
        for (const auto& st : ls)
            continued += st.report.continuation_factor > 0;
    EXPECT_GT(continued, 0);
    SolveOptions ref_options;
    ref_options.linear = so.linear;
    const RunResult ref = solve(square_with_r(0.1, 1), ref_options);
    ASSERT_TRUE(ref.converged) << ref.failure;
    EXPECT_LT((r.u_full - ref.u_full).norm(), 1e-8 * ref.u_full.norm());
    EXPECT_LT(max_lambda_difference(r, ref), 1e-8);
}

TEST(RContinuation, ChangesNothingWhereNewtonConverges) {
    // The ordinary square: bit for bit the run without the option.
    auto p = scene::load_scene("square");
    p.levels = 2;
    SolveOptions plain;
    plain.linear = {.method = solvers::Method::krylov,
                    .krylov = solvers::Krylov::cgs,
                    .pc = solvers::parse_pc("mg")};
    SolveOptions with = plain;
    with.r_continuation = true;
    const RunResult a = solve(p, plain), b = solve(p, with);
    ASSERT_TRUE(a.converged && b.converged);
    EXPECT_EQ(a.x, b.x);
    for (size_t l = 0; l < a.level_steps.size(); ++l)
        for (size_t k = 0; k < a.level_steps[l].size(); ++k) {
            EXPECT_EQ(a.level_steps[l][k].report.iterations, b.level_steps[l][k].report.iterations);
            EXPECT_EQ(b.level_steps[l][k].report.continuation_factor, 0.0);
        }
}

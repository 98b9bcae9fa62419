// SPDX-License-Identifier: MIT
// Coarse-to-fine Newton: same discrete solution as the cold start, far fewer Newton iterations,
// and statuses predicted by the interpolated state.
#include "levels/solve.hpp"
#include "scene/scene.hpp"

#include <gtest/gtest.h>

#include <iostream>

using namespace mlc;

namespace {

double mean_newton(const levels::RunResult& r, int level) {
    const auto& s = r.level_steps[static_cast<size_t>(level)];
    double sum = 0;
    for (const auto& x : s)
        sum += x.report.iterations;
    return sum / static_cast<double>(s.size());
}

} // namespace

TEST(CoarseToFine, SquareMatchesColdStartWithHalfTheNewtonIterations) {
    auto p = scene::load_scene("square");
    p.levels = 3;
    levels::SolveOptions warm_opt, cold_opt;
    cold_opt.coarse_to_fine = false;
    cold_opt.solve_all_levels = true;
    const auto warm = levels::solve(p, warm_opt);
    const auto cold = levels::solve(p, cold_opt);
    ASSERT_TRUE(warm.converged) << warm.failure;
    ASSERT_TRUE(cold.converged) << cold.failure;
    // The same discrete problem: identical solutions up to round-off.
    EXPECT_LT((warm.u_full - cold.u_full).norm(), 1e-9 * cold.u_full.norm());
    EXPECT_LT((warm.x - cold.x).norm(), 1e-9 * cold.x.norm());
    double w = 0, c = 0;
    for (int l = 2; l <= 3; ++l) {
        w += mean_newton(warm, l);
        c += mean_newton(cold, l);
        for (const auto& st : warm.level_steps[static_cast<size_t>(l)]) {
            EXPECT_TRUE(st.predicted);
            EXPECT_GE(st.agreement(), 0.95) << "level " << l << " step " << st.report.step;
            int total = 0;
            for (const auto& row : st.confusion)
                for (int n : row)
                    total += n;
            EXPECT_EQ(total, static_cast<int>(st.final_statuses.size()));
        }
    }
    EXPECT_LE(w, 0.5 * c);
}

TEST(CoarseToFine, ConservativeQGivesTheSameSolution) {
    auto p = scene::load_scene("square");
    p.levels = 2;
    levels::SolveOptions a, b;
    b.q_rule = transfer::QRule::conservative;
    const auto ra = levels::solve(p, a);
    const auto rb = levels::solve(p, b);
    ASSERT_TRUE(ra.converged && rb.converged);
    EXPECT_LT((ra.x - rb.x).norm(), 1e-9 * ra.x.norm());
}

TEST(CoarseToFine, HertzConvergesOnEveryLevelWithPredictedStatuses) {
    auto p = scene::load_scene("hertz");
    p.levels = 2;
    const auto r = levels::solve(p);
    ASSERT_TRUE(r.converged) << r.failure;
    for (int l = 1; l <= 2; ++l)
        for (const auto& st : r.level_steps[static_cast<size_t>(l)]) {
            EXPECT_GE(st.agreement(), 0.95);
            EXPECT_LE(st.report.iterations, 3);
        }
}

TEST(CoarseToFine, FailureNamesTheLevelAndStep) {
    auto p = scene::load_scene("square");
    p.levels = 1;
    p.newton.max_iter = 1;
    const auto r = levels::solve(p);
    EXPECT_FALSE(r.converged);
    EXPECT_NE(r.failure.find("load step 1"), std::string::npos) << r.failure;
    EXPECT_NE(r.failure.find("on level 0"), std::string::npos) << r.failure;
    EXPECT_NE(r.failure.find("residual history"), std::string::npos) << r.failure;
}

TEST(Newton, SolutionDoesNotDependOnTheAugmentationParameter) {
    // The discrete solution of the Alart-Curnier equations is independent of r; a very large r
    // makes the generalized Newton cycle between status sets, which must be detected and damped.
    auto p = scene::load_scene("square");
    p.levels = 2;
    const auto ref = levels::solve(p);
    ASSERT_TRUE(ref.converged) << ref.failure;
    for (double rf : {1e-4, 1e4}) {
        auto q = p;
        q.contacts[0].r = rf * q.bodies[0].material.E;
        const auto r = levels::solve(q);
        ASSERT_TRUE(r.converged) << "r = " << rf << " E: " << r.failure;
        EXPECT_LT((r.u_full - ref.u_full).norm(), 1e-8 * ref.u_full.norm()) << "r = " << rf << " E";
    }
}

TEST(CoarseToFine, IncrementTransferGivesTheSameSolutionAndPredictsAtLeastAsWell) {
    auto p = scene::load_scene("square");
    p.levels = 3;
    levels::SolveOptions a, b;
    b.transfer_increment = true;
    const auto ra = levels::solve(p, a);
    const auto rb = levels::solve(p, b);
    ASSERT_TRUE(ra.converged && rb.converged);
    EXPECT_LT((ra.x - rb.x).norm(), 1e-9 * ra.x.norm());
    double total_a = 0, total_b = 0;
    for (int l = 1; l <= 3; ++l) {
        const auto& sa = ra.level_steps[static_cast<size_t>(l)];
        const auto& sb = rb.level_steps[static_cast<size_t>(l)];
        ASSERT_EQ(sa.size(), sb.size());
        // Step 1 starts from zero in both modes: the same guess, the same prediction.
        EXPECT_EQ(sa[0].predicted_statuses, sb[0].predicted_statuses);
        double agree_a = 0, agree_b = 0;
        for (size_t k = 1; k < sa.size(); ++k) {
            agree_a += sa[k].agreement();
            agree_b += sb[k].agreement();
        }
        EXPECT_GE(agree_b, agree_a - 1e-12) << "level " << l;
        std::cout << "[ increment ] level " << l << ": agreement over steps 2.. " << agree_a
                  << " (state) vs " << agree_b << " (increment)\n";
        total_a += agree_a;
        total_b += agree_b;
    }
    // Measured: 11.72 vs 11.89 (levels 1..3, steps 2..5): the increment start predicts strictly
    // better; a start that ignored the option would give the same sum.
    EXPECT_GT(total_b, total_a + 0.1);
}

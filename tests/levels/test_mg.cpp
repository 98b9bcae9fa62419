// SPDX-License-Identifier: MIT
// `--pc mg` on the square (mu = 1, five load steps, coarse-to-fine): the V-cycle over all
// levels preconditions the non-symmetric contact Jacobian inside CGS, BiCGStab and GMRES with a
// small iteration count that does not grow from level 1 to level 3.
#include "apps/scene.hpp"
#include "core/check.hpp"
#include "levels/krylov_system.hpp"
#include "levels/solve.hpp"

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
            for (int i : st.report.linear_iterations_per_newton) m = std::max(m, i);
        out.push_back(m);
    }
    return out;
}

RunResult run_square(int levels, const std::string& krylov, const std::string& pc,
                     int load_steps = 0) {
    auto p = apps::load_scene("square");
    p.levels = levels;
    if (load_steps > 0) p.load_steps = load_steps;
    SolveOptions so;
    so.linear = {.method = "krylov", .krylov = krylov, .pc = pc, .rel_tol = 1e-8, .max_iter = 200};
    return solve(p, so);
}

} // namespace

TEST(MultilevelPreconditioner, WorksInsideCgsBicgstabAndGmres) {
    // Measured on level 2: CGS 8-9, BiCGStab 7-8, GMRES 13 iterations per Newton step.
    auto p = apps::load_scene("square");
    p.levels = 2;
    const RunResult ref = solve(p, {}); // the exact condensed solver
    ASSERT_TRUE(ref.converged);
    for (const auto& [krylov, bound] :
         {std::pair<std::string, int>{"cgs", 12}, {"bicgstab", 12}, {"gmres", 18}}) {
        const RunResult r = run_square(2, krylov, "mg");
        ASSERT_TRUE(r.converged) << krylov << ": " << r.failure;
        for (int m : max_iterations(r)) EXPECT_LE(m, bound) << krylov;
        EXPECT_LT((r.x - ref.x).norm(), 1e-7 * ref.x.norm()) << krylov;
    }
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
    auto p = apps::load_scene("square");
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

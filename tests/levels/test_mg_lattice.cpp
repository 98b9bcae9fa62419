// SPDX-License-Identifier: MIT
// `mg:smoother=lattice` with `--numbering lattice`: on levels 4 and finer the smoother sweeps the
// macro triangles' interiors by their stencils, visiting each macro's rows in serpentine order.
// Against the block smoother on the same numbering (the same blocks, visited row by row): the
// same Newton history, Krylov iterations within one on every Newton system and the same
// solution to 1e-8 relative, on the dyadic square (stencils equal bit for bit) and on hertz
// (curved, stencils equal to round-off). (tests/smoothers/test_lattice_gs.cpp checks the sweep
// itself: against a dense reference, and against BlockSOR in BlockSOR's order.)
#include "core/check.hpp"
#include "levels/resources.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"

#include <gtest/gtest.h>

#include <string>

using namespace mlc;
using namespace mlc::levels;

namespace {

RunResult run(const std::string& scene, int levels, const std::string& pc, int load_steps) {
    auto p = scene::load_scene(scene);
    p.levels = levels;
    if (load_steps > 0) p.load_steps = load_steps;
    p.numbering = Problem::Numbering::lattice;
    SolveOptions so;
    so.linear = {.method = solvers::Method::krylov,
                 .krylov = solvers::Krylov::bicgstab,
                 .pc = solvers::parse_pc(pc),
                 .rel_tol = 1e-8,
                 .max_iter = 200};
    return solve(p, so);
}

// load_steps > 0 overrides the scene's (one step keeps the fast test fast under the sanitizers).
void expect_like_block(const std::string& scene, int levels, int load_steps) {
    const RunResult b = run(scene, levels, "mg:pre=0,post=2", load_steps);
    const RunResult l = run(scene, levels, "mg:pre=0,post=2,smoother=lattice", load_steps);
    ASSERT_TRUE(b.converged) << b.failure;
    ASSERT_TRUE(l.converged) << l.failure;
    EXPECT_LT((l.x - b.x).norm(), 1e-8 * b.x.norm()) << scene;
    ASSERT_EQ(l.level_steps.size(), b.level_steps.size());
    int systems = 0;
    for (size_t lv = 0; lv < b.level_steps.size(); ++lv) {
        ASSERT_EQ(l.level_steps[lv].size(), b.level_steps[lv].size()) << lv;
        for (size_t k = 0; k < b.level_steps[lv].size(); ++k) {
            const auto& its_b = b.level_steps[lv][k].report.linear_iterations_per_newton;
            const auto& its_l = l.level_steps[lv][k].report.linear_iterations_per_newton;
            ASSERT_EQ(its_l.size(), its_b.size()) << scene << " level " << lv << " step " << k;
            for (size_t i = 0; i < its_b.size(); ++i) {
                EXPECT_LE(std::abs(its_l[i] - its_b[i]), 1)
                    << scene << " level " << lv << " step " << k << " Newton " << i;
                ++systems;
            }
        }
    }
    EXPECT_GT(systems, 0);
    // The finest level's smoother is the lattice one, with deep points; the block run's is not.
    ASSERT_TRUE(l.multigrid.has_value());
    EXPECT_NE(l.multigrid->levels.back().solve.find("lattice"), std::string::npos);
    EXPECT_EQ(l.multigrid->levels.back().solve.find(" 0 deep"), std::string::npos);
    EXPECT_EQ(b.multigrid->levels.back().solve.find("lattice"), std::string::npos);
}

} // namespace

TEST(LatticeMultigrid, SquareLevel4LikeTheBlockSmoother) {
    expect_like_block("square", 4, 1);
}

TEST(LatticeMultigrid, HertzLevel4LikeTheBlockSmoother_Slow) {
    expect_like_block("hertz", 4, 0);
}

// What cannot take effect is refused, naming the fix.
TEST(LatticeMultigrid, RefusesWhatCannotTakeEffect) {
    auto p = scene::load_scene("square");
    p.levels = 4;
    const SolverRequest req{.pc = solvers::parse_pc("mg:pre=0,post=2,smoother=lattice")};
    // Named without a numbering, the option numbers the levels for itself; named beside
    // numbering hilbert it is refused.
    EXPECT_TRUE(plan_solver(p, req).lattice_numbering());
    SolverRequest hilbert = req;
    hilbert.numbering = Problem::Numbering::hilbert;
    try {
        (void)plan_solver(p, hilbert);
        ADD_FAILURE() << "no error with the Hilbert numbering";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("drop --numbering hilbert"), std::string::npos)
            << e.what();
    }
    // The library's solve numbers the levels from the spec itself (levels::hierarchy_numbering):
    // lattice without a numbering given, refused beside numbering hilbert.
    LinearSolverSpec direct{.method = solvers::Method::krylov,
                            .krylov = solvers::Krylov::bicgstab,
                            .pc = *req.pc,
                            .rel_tol = 1e-8};
    EXPECT_EQ(p.numbering, Problem::Numbering::hilbert);
    EXPECT_EQ(hierarchy_numbering(p, direct), Problem::Numbering::lattice);
    direct.numbering = Problem::Numbering::hilbert;
    EXPECT_THROW((void)hierarchy_numbering(p, direct), InvalidInput);
    EXPECT_NO_THROW((void)plan_solver(p, req));
    p.levels = 3;
    try {
        (void)plan_solver(p, req);
        ADD_FAILURE() << "no error on level 3";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("--levels >= 4"), std::string::npos) << e.what();
    }
    p.levels = 4;
    SolveOptions so;
    so.linear = {.method = solvers::Method::krylov,
                 .krylov = solvers::Krylov::bicgstab,
                 .pc = solvers::parse_pc("mg:smoother=lattice,precision=single"),
                 .rel_tol = 1e-8};
    EXPECT_THROW((void)solve(p, so), InvalidInput);
}

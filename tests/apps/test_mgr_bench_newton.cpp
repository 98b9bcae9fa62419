// SPDX-License-Identifier: MIT
// --pc mgr (hypre MGR) in a run gives the exact solver's contact answer, and `bench newton`
// writes one record per Newton system of the finest level with finite values.
#include "bench/bench.hpp"
#include "core/check.hpp"
#include "levels/checks.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"
#include "solvers/hypre/boomeramg.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

using namespace mlc;

TEST(MGRRun, SquareLevel2GivesTheSchurAnswer) {
    if (!solvers::have_hypre()) GTEST_SKIP() << "built without hypre";
    auto p = scene::load_scene("square");
    p.levels = 2;
    levels::SolveOptions exact;
    exact.linear.method = solvers::Method::schur;
    levels::SolveOptions mgr;
    mgr.linear = {.method = solvers::Method::krylov,
                  .krylov = solvers::Krylov::cgs,
                  .pc = solvers::parse_pc("mgr")};
    const auto a = levels::solve(p, exact);
    const auto b = levels::solve(p, mgr);
    ASSERT_TRUE(a.converged) << a.failure;
    ASSERT_TRUE(b.converged) << b.failure;
    for (const auto& st : b.steps) {
        EXPECT_EQ(st.fallback_solves, 0);
        EXPECT_GT(st.linear_iterations, 0);
    }
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    double lmax = 0, umax = 0;
    for (const auto& n : a.nodes) {
        lmax = std::max({lmax, std::abs(n.lambda_n), std::abs(n.lambda_t)});
        umax = std::max(umax, n.u.norm());
    }
    for (size_t i = 0; i < a.nodes.size(); ++i) {
        EXPECT_EQ(a.nodes[i].status, b.nodes[i].status) << "node " << i;
        EXPECT_NEAR(a.nodes[i].lambda_n, b.nodes[i].lambda_n, 1e-8 * lmax) << "node " << i;
        EXPECT_NEAR(a.nodes[i].lambda_t, b.nodes[i].lambda_t, 1e-8 * lmax) << "node " << i;
        EXPECT_LE((a.nodes[i].u - b.nodes[i].u).norm(), 1e-8 * umax) << "node " << i;
    }
    const Vec2 ra = levels::contact_resultant(a, 0), rb = levels::contact_resultant(b, 0);
    EXPECT_LE((ra - rb).norm(), 1e-8 * ra.norm());
}

TEST(BenchNewton, OneRecordPerNewtonSystemWithFiniteValues) {
    if (!solvers::have_hypre()) GTEST_SKIP() << "built without hypre";
    // The run's own Newton systems on the finest level.
    auto p = scene::load_scene("square");
    p.levels = 1;
    levels::SolveOptions so;
    so.linear = {.method = solvers::Method::krylov,
                 .krylov = solvers::Krylov::cgs,
                 .pc = solvers::parse_pc("mg"),
                 .rel_tol = 1e-8};
    const auto r = levels::solve(p, so);
    ASSERT_TRUE(r.converged) << r.failure;
    int systems = 0;
    for (const auto& st : r.steps)
        systems += st.iterations;

    apps::BenchNewtonOptions opt;
    opt.levels = 1;
    opt.threads = {1, 2};
    opt.out = std::filesystem::path(::testing::TempDir()) / "bench_newton_L1.json";
    std::ostringstream table;
    EXPECT_EQ(apps::bench_newton(opt, table), 0) << table.str();
    std::ifstream f(opt.out);
    ASSERT_TRUE(f.good());
    std::stringstream ss;
    ss << f.rdbuf();
    const std::string json = ss.str();
    const auto count = [&](const std::string& what) {
        const std::regex re(what);
        return static_cast<int>(
            std::distance(std::sregex_iterator(json.begin(), json.end(), re), {}));
    };
    EXPECT_EQ(count("\"newton_iteration\": "), systems) << json;
    // Every record has our mg at 1 and 2 threads, MGR and AMG, and no value is missing.
    EXPECT_EQ(count("\"mg@1\": \\{\"iterations\""), systems);
    EXPECT_EQ(count("\"mg@2\": \\{\"iterations\""), systems);
    EXPECT_EQ(count("\"mgr\": \\{\"iterations\""), systems);
    EXPECT_EQ(count("\"amg\": \\{\"iterations\""), systems);
    EXPECT_EQ(count("\"mgr\\+fgmres\": \\{\"iterations\""), systems);
    EXPECT_EQ(count("\\bnull\\b|\\bnan\\b|\\binf\\b"), 0) << json;
    // mg and MGR reach the tolerance on every system (AMG on the whole Jacobian may not).
    EXPECT_EQ(count("\"mg@1\": \\{[^}]*\"converged\": true"), systems);
    EXPECT_EQ(count("\"mgr\": \\{[^}]*\"converged\": true"), systems);
    EXPECT_EQ(count("\"mgr\\+fgmres\": \\{[^}]*\"converged\": true"), systems);
    EXPECT_NE(table.str().find("totals over"), std::string::npos) << table.str();
}

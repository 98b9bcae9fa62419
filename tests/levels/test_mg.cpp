// SPDX-License-Identifier: MIT
// `--pc mg` on the square (mu = 1, five load steps, coarse-to-fine): the V-cycle over all
// levels preconditions the non-symmetric contact Jacobian inside CGS, BiCGStab and GMRES with a
// small iteration count that does not grow from level 1 to level 3.
#include "core/check.hpp"
#include "levels/krylov_system.hpp"
#include "levels/resources.hpp"
#include "levels/solve.hpp"
#include "mesh/io/gmsh.hpp"
#include "scene/scene.hpp"
#include "tests/common/scene_text.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <utility>

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
    so.linear = {.method = solvers::Method::krylov,
                 .krylov = solvers::parse_krylov(krylov),
                 .pc = solvers::parse_pc(pc),
                 .rel_tol = 1e-8,
                 .max_iter = 200};
    return solve(p, so);
}

RunResult run_square_problem(const Problem& p) {
    SolveOptions so;
    so.linear = {.method = solvers::Method::krylov,
                 .krylov = solvers::Krylov::cgs,
                 .pc = solvers::parse_pc("mg"),
                 .rel_tol = 1e-8,
                 .max_iter = 200};
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
    // On a single level mg builds its aggregation hierarchy; the geometric coarse operators
    // need the level below.
    so.linear = {.method = solvers::Method::krylov,
                 .krylov = solvers::Krylov::cgs,
                 .pc = solvers::parse_pc("mg:coarse=galerkin")};
    EXPECT_THROW(solve(p, so), InvalidInput);
    so.linear.pc = solvers::parse_pc("mg:coarse=rediscretize");
    EXPECT_THROW(solve(p, so), InvalidInput);
    so.linear.pc = solvers::parse_pc("mg:smooth=2");
    EXPECT_THROW(solve(p, so), InvalidInput);
    p.levels = 1;
    so.linear.pc = solvers::parse_pc("mg:pre=0,post=0");
    EXPECT_THROW(solve(p, so), InvalidInput);
    // Refused where the spec is read, before anything is built.
    EXPECT_THROW((void)solvers::parse_pc("mg:sweeps=2"), InvalidInput);
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
    so.linear = {.method = solvers::Method::krylov,
                 .krylov = solvers::Krylov::cgs,
                 .pc = solvers::parse_pc("mg:coarse=galerkin"),
                 .rel_tol = 1e-8,
                 .max_iter = 200};
    const RunResult gal = solve(p, so);
    ASSERT_TRUE(gal.converged) << gal.failure;
    EXPECT_LT((gal.x - ref.x).norm(), 1e-8 * ref.x.norm());
    for (int m : max_iterations(gal))
        EXPECT_LE(m, 12);
    // Refused where the spec is read, before anything is built.
    EXPECT_THROW((void)solvers::parse_pc("mg:coarse=algebraic"), InvalidInput);
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
    so.linear = {.method = solvers::Method::krylov,
                 .krylov = solvers::Krylov::cgs,
                 .pc = solvers::parse_pc("mg"),
                 .max_iter = 100};
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
    plain.linear = {.method = solvers::Method::krylov,
                    .krylov = solvers::Krylov::cgs,
                    .pc = solvers::parse_pc("mg")};
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
    // The default's Krylov + mg with a two-body pair (BiCGStab + mg:omega=0.8,pre=0,post=2, levels/
    // resources.hpp): the same solution as the exact schur on dovetail level 2 (56 181
    // unknowns), with few BiCGStab iterations per Newton step (docs/results/default-cycle.md).
    auto p = scene::load_scene("dovetail");
    p.levels = 2;
    p.load_steps = 2;
    const RunResult ref = solve(p, {});
    ASSERT_TRUE(ref.converged) << ref.failure;
    SolveOptions so;
    so.linear = {.method = solvers::Method::krylov,
                 .krylov = solvers::Krylov::bicgstab,
                 .pc = solvers::parse_pc(levels::kMgDefaultTwoBody),
                 .rel_tol = 1e-10,
                 .max_iter = 200};
    const RunResult r = solve(p, so);
    ASSERT_TRUE(r.converged) << r.failure;
    ASSERT_TRUE(r.multigrid.has_value());
    EXPECT_EQ(r.multigrid->cycle, "V(0,2), omega = 0.8");
    const auto m = max_iterations(r);
    ASSERT_EQ(m.size(), 2u);
    EXPECT_LE(m.back(), 20); // measured 17 (two load steps of 0.5)
    EXPECT_LT((r.x - ref.x).norm(), 1e-8 * ref.x.norm());
}

namespace {

// A level-0 scene whose mesh is level `level` of the square written as a Gmsh file and read
// back. With `recover` false ([scene].recover_levels = false) it has no levels: a fine mesh
// brought from Gmsh that is no refinement; with true the scene recovers the levels.
Problem exported_square(int level, bool recover = false) {
    const std::string built_in = scene::builtin_scene_text("square");
    auto p = scene::load_scene("square");
    mesh::Mesh m = p.mesh0;
    for (int l = 0; l < level; ++l)
        m = mesh::refine(m);
    const auto dir = std::filesystem::temp_directory_path() /
                     ("mlc_test_exported_square_" + std::to_string(level));
    std::filesystem::create_directories(dir);
    {
        std::ofstream msh(dir / "square.msh");
        mesh::write_gmsh(m, msh);
    }
    const std::string from = "mesh = { type = \"rectangle\"";
    const auto at = built_in.find(from);
    EXPECT_NE(at, std::string::npos);
    std::string text = built_in.substr(0, at) +
                       "mesh = { type = \"gmsh\", file = " + "\"square.msh\" }" +
                       built_in.substr(built_in.find('\n', at));
    if (!recover) text = test::replace(text, "[scene]\n", "[scene]\nrecover_levels = false\n");
    return scene::parse_scene(text, (dir / "square.toml").string(), dir);
}

// The exact schur solve of a single-level problem: the reference of the algebraic mg below.
RunResult schur_reference(const Problem& p) {
    EXPECT_EQ(p.levels, 0);
    RunResult ref = solve(p, {});
    EXPECT_TRUE(ref.converged) << ref.failure;
    return ref;
}

// Krylov + mg on a single level (its aggregation hierarchy) against the exact schur solve.
void expect_algebraic_mg_solves_like_schur(const Problem& p, const RunResult& ref,
                                           const std::string& pc, int bound,
                                           const std::string& krylov = "cgs") {
    ASSERT_EQ(p.levels, 0);
    ASSERT_TRUE(ref.converged);
    SolveOptions so;
    so.linear = {.method = solvers::Method::krylov,
                 .krylov = solvers::parse_krylov(krylov),
                 .pc = solvers::parse_pc(pc),
                 .rel_tol = 1e-10,
                 .max_iter = 200};
    const RunResult r = solve(p, so);
    ASSERT_TRUE(r.converged) << r.failure;
    int worst = 0;
    for (const auto& st : r.steps)
        for (int i : st.linear_iterations_per_newton)
            worst = std::max(worst, i);
    EXPECT_LE(worst, bound) << pc;
    EXPECT_LT((r.x - ref.x).norm(), 1e-8 * ref.x.norm()) << pc;
    ASSERT_TRUE(r.multigrid.has_value());
    EXPECT_GE(r.multigrid->levels.size(), 2u);
    EXPECT_NE(r.multigrid->coarse_operators.find("aggregates"), std::string::npos);
}

} // namespace

TEST(AlgebraicMultigrid, SolvesTheSquareExportedFromLevel2LikeSchur) {
    Problem p = exported_square(2);
    EXPECT_EQ(p.mesh0.n_vertices(), 65 * 65);
    p.load_steps = 2; // keeps the test short; measured 11.4 CGS iterations per Newton step
    const RunResult ref = schur_reference(p);
    expect_algebraic_mg_solves_like_schur(p, ref, "mg", 20);
    // Three levels and more (coarsened to 300 unknowns) solve it too.
    expect_algebraic_mg_solves_like_schur(p, ref, "mg:csize=300", 25);
    // What --linear krylov takes on a single level: BiCGStab + the V(0,2) cycle (measured: at
    // most 12 BiCGStab iterations per Newton step).
    SolverRequest krylov;
    krylov.linear = solvers::Method::krylov;
    const LinearSolverSpec pair = plan_solver(p, krylov).spec;
    expect_algebraic_mg_solves_like_schur(p, ref, pair.pc.text(), 15,
                                          std::string(solvers::to_string(pair.krylov)));
}

TEST(AlgebraicMultigrid, SolvesHertzGmshAtLevel0LikeSchur) {
    auto p = scene::load_scene("hertz_gmsh");
    p.levels = 0;
    expect_algebraic_mg_solves_like_schur(p, schur_reference(p), "mg:csize=100", 20);
}

TEST(AlgebraicMultigrid, IsAskedForOnASingleLevelAndEstimated) {
    // The square exported from level 2: 8 512 unknowns on level 0, rigid obstacle only. The
    // default stays the exact schur on a single level (faster there:
    // docs/results/solver-choice.md); --pc mg builds the aggregation hierarchy.
    const Problem p = exported_square(2);
    EXPECT_EQ(plan_solver(p, {}).spec.method, solvers::Method::schur);
    SolverRequest asked;
    asked.pc = solvers::parse_pc("mg");
    const SolverPlan c = plan_solver(p, asked);
    EXPECT_EQ(c.spec.method, solvers::Method::krylov);
    EXPECT_EQ(c.spec.pc.text(), "mg");
    EXPECT_EQ(c.spec.krylov, solvers::Krylov::cgs);
    // Its memory estimate counts the aggregation hierarchy (prolongations, Galerkin operators:
    // about as much again as the Krylov solve's own), which ILU(0) does not have.
    const auto sizes = predict_level_sizes(p);
    const double with_mg = estimate_memory(sizes, c.spec, false).solver_bytes;
    LinearSolverSpec ilu = c.spec;
    ilu.pc = solvers::parse_pc("ilu:0");
    EXPECT_GT(with_mg, 2.0 * estimate_memory(sizes, ilu, false).solver_bytes);
    // --linear krylov alone takes the default pair over the aggregation hierarchy (since
    // 2026-11-26; it was ILU(0), which falls back to schur from the level-3 export on).
    SolverRequest krylov;
    krylov.linear = solvers::Method::krylov;
    EXPECT_EQ(plan_solver(p, krylov).spec.pc.text(), "mg:pre=0,post=2");
    EXPECT_EQ(plan_solver(p, krylov).spec.krylov, solvers::Krylov::bicgstab);
}

// The levels of a Gmsh mesh that is a uniform refinement (scene/scene.cpp, mesh::unrefine).
TEST(RecoveredLevels, TheExportedSquareSolvesAsTheRefinedSquareDoes) {
    // The built-in square's 16 x 16 level-0 mesh is itself four refinements of one square cut
    // in two, so its level-3 export recovers 7 levels down to 2 triangles.
    const Problem p = exported_square(3, true);
    EXPECT_EQ(p.recovered_levels, 7);
    EXPECT_EQ(p.levels, 7);
    EXPECT_EQ(p.mesh0.n_cells(), 2);
    auto q = scene::load_scene("square");
    q.levels = 3;
    const RunResult a = solve(p, {});
    const RunResult b = solve(q, {});
    ASSERT_TRUE(a.converged) << a.failure;
    ASSERT_TRUE(b.converged) << b.failure;
    // The same finest mesh in another numbering: the displacement of every vertex, found by its
    // coordinates, agrees to the Newton tolerance's scale.
    const auto& La = a.finest();
    const auto& Lb = b.finest();
    ASSERT_EQ(La.mesh.n_vertices(), Lb.mesh.n_vertices());
    std::map<std::pair<double, double>, Vec2> ub;
    auto u_of = [](const auto& L, const Vector& x, int v) {
        Vec2 u = Vec2::Zero();
        for (int c = 0; c < 2; ++c)
            if (const int i = L.dofs.u_dof(v, c); i >= 0) u[c] = x[i];
        return u;
    };
    double umax = 0.0;
    for (int v = 0; v < Lb.mesh.n_vertices(); ++v) {
        const Vec2& xv = Lb.mesh.vertices[static_cast<size_t>(v)];
        ub[{xv.x(), xv.y()}] = u_of(Lb, b.x, v);
        umax = std::max(umax, ub[{xv.x(), xv.y()}].norm());
    }
    double worst = 0.0;
    for (int v = 0; v < La.mesh.n_vertices(); ++v) {
        const Vec2& xv = La.mesh.vertices[static_cast<size_t>(v)];
        const auto it = ub.find({xv.x(), xv.y()});
        ASSERT_NE(it, ub.end()) << "vertex (" << xv.x() << ", " << xv.y() << ")";
        worst = std::max(worst, (u_of(La, a.x, v) - it->second).norm());
    }
    EXPECT_LT(worst, 1e-8 * umax);
    // Above the crossover the default is the multigrid over the recovered levels, swept by
    // lattices on levels 4 to 7 (2 triangles refined 4 to 7 times).
    const auto c = plan_solver(p, {});
    EXPECT_EQ(c.spec.pc.text(), "mg:pre=0,post=2,smoother=lattice");
    EXPECT_TRUE(c.lattice_numbering());
}

TEST(RecoveredLevels, AnUnstructuredGmshMeshHasNoneAndTheKeyNeedsGmshMeshes) {
    EXPECT_EQ(scene::load_scene("hertz_gmsh").recovered_levels, 0);
    const std::string text = test::replace(scene::builtin_scene_text("square"), "[scene]\n",
                                           "[scene]\nrecover_levels = true\n");
    EXPECT_NE(test::error_of(text).find("recover_levels applies to meshes read from Gmsh files"),
              std::string::npos)
        << test::error_of(text);
    // Stated false on the built-in square's rectangle: nothing to recover, no error.
    EXPECT_EQ(scene::parse_scene(test::replace(scene::builtin_scene_text("square"), "[scene]\n",
                                               "[scene]\nrecover_levels = false\n"),
                                 "square")
                  .levels,
              0);
}

TEST(RecoveredLevels, StopAtTheCoarsestMeshWhoseLevel0TheSceneCanBuild) {
    // A support point at x = 5 on the 40 mm square is a vertex from 8 x 8 squares on (spacing
    // 5): of the level-3 export's 7 ancestors only the 4 finest can be level 0.
    const std::string built_in = scene::builtin_scene_text("square");
    const auto dir = std::filesystem::temp_directory_path() / "mlc_test_recovered_support";
    std::filesystem::create_directories(dir);
    {
        mesh::Mesh m = scene::load_scene("square").mesh0;
        for (int l = 0; l < 3; ++l)
            m = mesh::refine(m);
        std::ofstream msh(dir / "square.msh");
        mesh::write_gmsh(m, msh);
    }
    const std::string from = "mesh = { type = \"rectangle\"";
    const auto at = built_in.find(from);
    ASSERT_NE(at, std::string::npos);
    const std::string text =
        built_in.substr(0, at) + "mesh = { type = \"gmsh\", file = \"square.msh\" }" +
        built_in.substr(built_in.find('\n', at)) + "\n[[support]]\npoint = [5.0, 40.0]\nux = 0.0\n";
    const Problem p = scene::parse_scene(text, (dir / "square.toml").string(), dir);
    EXPECT_EQ(p.recovered_levels, 4);
    EXPECT_EQ(p.mesh0.n_cells(), 2 * 8 * 8);
    EXPECT_NO_THROW(build_level(p, p.mesh0));
}

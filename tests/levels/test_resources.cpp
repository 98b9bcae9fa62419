// SPDX-License-Identifier: MIT
// What a run needs before it is built: predicted level sizes against the built hierarchy, the
// driver's solver choice, the memory estimate and the refusal of a run that cannot fit.
#include "core/check.hpp"
#include "levels/hierarchy.hpp"
#include "levels/resources.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"

#include <gtest/gtest.h>

#include <iostream>

#include <cmath>
#include <limits>

using namespace mlc;

namespace {

// A request as the command line gives it: --linear, --krylov, --pc, --linear-tol, --numbering.
levels::SolverRequest request(std::optional<std::string> linear, std::optional<std::string> krylov,
                              std::optional<std::string> pc, std::optional<double> rel_tol,
                              std::optional<std::string> numbering) {
    levels::SolverRequest r;
    if (linear) r.linear = solvers::parse_method(*linear);
    if (krylov) r.krylov = solvers::parse_krylov(*krylov);
    if (pc) r.pc = solvers::parse_pc(*pc);
    r.rel_tol = rel_tol;
    if (numbering) r.numbering = levels::parse_numbering(*numbering, "--numbering");
    return r;
}

} // namespace

TEST(PredictLevelSizes, RefinementCountsAreExactAndUnknownsClose) {
    for (const char* name : {"square", "hertz", "dovetail", "mindlin"}) {
        SCOPED_TRACE(name);
        auto p = scene::load_scene(name);
        p.levels = 3;
        const auto sizes = levels::predict_level_sizes(p);
        const auto h = levels::build_hierarchy(p);
        ASSERT_EQ(sizes.size(), h.levels.size());
        for (size_t l = 0; l < sizes.size(); ++l) {
            SCOPED_TRACE(l);
            const auto& L = h.levels[l];
            EXPECT_EQ(sizes[l].vertices, L.mesh.n_vertices());
            EXPECT_EQ(sizes[l].triangles, L.mesh.n_cells());
            // Boundary terms are doubled per level, so the finer counts are estimates: within
            // 3 % for the unknowns and nonzeros, within a factor for the contact nodes.
            EXPECT_NEAR(sizes[l].unknowns / L.n_unknowns(), 1.0, 0.03);
            EXPECT_NEAR(sizes[l].k_nonzeros / L.elastic.K.nonZeros(), 1.0, 0.03);
            EXPECT_GE(sizes[l].contact_nodes, 0.9 * L.n_contact_nodes());
            EXPECT_LE(sizes[l].contact_nodes, 1.6 * L.n_contact_nodes() + 4);
        }
        // Level 0 is counted, not predicted.
        EXPECT_EQ(sizes[0].unknowns, h.levels[0].n_unknowns());
        EXPECT_EQ(sizes[0].contact_nodes, h.levels[0].n_contact_nodes());
    }
}

TEST(ChooseSolver, APreconditionerAloneMeansAKrylovSolve) {
    auto p = scene::load_scene("square");
    p.levels = 2;
    const auto c = levels::plan_solver(p, request({}, {}, std::string("mg"), {}, {}));
    EXPECT_EQ(c.spec.method, solvers::Method::krylov);
    EXPECT_EQ(c.spec.pc.text(), "mg");
    EXPECT_EQ(c.spec.krylov, solvers::Krylov::cgs);
    EXPECT_FALSE(c.automatic);
    // A Krylov method or tolerance alone too, with mg where there is a level below.
    const auto k = levels::plan_solver(p, request({}, std::string("gmres"), {}, {}, {}));
    EXPECT_EQ(k.spec.method, solvers::Method::krylov);
    EXPECT_EQ(k.spec.krylov, solvers::Krylov::gmres);
    EXPECT_EQ(k.spec.pc.text(), "mg:pre=0,post=2");
    // The tolerance alone: the driver's own mg pair, BiCGStab + V(0,2).
    const auto t = levels::plan_solver(p, request({}, {}, {}, 1e-6, {}));
    EXPECT_EQ(t.spec.method, solvers::Method::krylov);
    EXPECT_EQ(t.spec.rel_tol, 1e-6);
    EXPECT_EQ(t.spec.krylov, solvers::Krylov::bicgstab);
    EXPECT_EQ(t.spec.pc.text(), "mg:pre=0,post=2");
}

TEST(ChooseSolver, LinearKrylovUsesTheDefaultMgOnEveryMesh) {
    auto p = scene::load_scene("square");
    p.levels = 1;
    const auto mg = levels::plan_solver(p, request(std::string("krylov"), {}, {}, {}, {}));
    EXPECT_EQ(mg.spec.pc.text(), "mg:pre=0,post=2");
    EXPECT_EQ(mg.spec.krylov, solvers::Krylov::bicgstab);
    // A Krylov method named beside it is kept.
    EXPECT_EQ(levels::plan_solver(p, request(std::string("krylov"), std::string("cgs"), {}, {}, {}))
                  .spec.krylov,
              solvers::Krylov::cgs);
    // On a single level the same pair over an aggregation hierarchy (not ILU(0)), damped with a
    // two-body pair.
    p.levels = 0;
    const auto one = levels::plan_solver(p, request(std::string("krylov"), {}, {}, {}, {}));
    EXPECT_EQ(one.spec.pc.text(), "mg:pre=0,post=2");
    EXPECT_EQ(one.spec.krylov, solvers::Krylov::bicgstab);
    EXPECT_NE(one.reason.find("aggregation hierarchy"), std::string::npos) << one.reason;
    auto dt = scene::load_scene("dovetail");
    dt.levels = 0;
    EXPECT_EQ(
        levels::plan_solver(dt, request(std::string("krylov"), {}, {}, {}, {})).spec.pc.text(),
        "mg:omega=0.8,pre=0,post=2");
}

TEST(ChooseSolver, AKrylovOptionBesideADirectSolverIsAnError) {
    auto p = scene::load_scene("square");
    p.levels = 2;
    for (const char* direct : {"schur", "lu"}) {
        try {
            levels::plan_solver(p, request(std::string(direct), {}, std::string("mg"), {}, {}));
            ADD_FAILURE() << "no error for --linear " << direct << " --pc mg";
        } catch (const InvalidInput& e) {
            EXPECT_NE(std::string(e.what()).find("--pc mg applies to Krylov solves only"),
                      std::string::npos)
                << e.what();
        }
        EXPECT_THROW(
            levels::plan_solver(p, request(std::string(direct), std::string("cgs"), {}, {}, {})),
            InvalidInput);
        EXPECT_THROW(levels::plan_solver(p, request(std::string(direct), {}, {}, 1e-8, {})),
                     InvalidInput);
        EXPECT_EQ(levels::plan_solver(p, request(std::string(direct), {}, {}, {}, {})).spec.method,
                  solvers::parse_method(direct));
    }
}

TEST(ChooseSolver, TheDefaultPicksBySizeAtTheCrossover) {
    for (const char* name : {"square", "hertz", "dovetail"}) {
        SCOPED_TRACE(name);
        auto p = scene::load_scene(name);
        const double crossover = levels::mg_crossover_unknowns(p);
        for (int L = 0; L <= 6; ++L) {
            SCOPED_TRACE(L);
            p.levels = L;
            const double n = levels::predict_level_sizes(p).back().unknowns;
            const auto c = levels::plan_solver(p, {});
            EXPECT_TRUE(c.automatic);
            EXPECT_FALSE(c.reason.empty());
            if (L >= 1 && n > crossover) {
                EXPECT_EQ(c.spec.method, solvers::Method::krylov);
                // From level 4 on with the lattice sweep (the test below).
                EXPECT_EQ(c.spec.pc.text(), std::string(crossover == levels::kMgCrossoverTwoBody
                                                            ? "mg:omega=0.8,pre=0,post=2"
                                                            : "mg:pre=0,post=2") +
                                                (L >= 4 ? ",smoother=lattice" : ""));
                EXPECT_EQ(c.lattice_numbering(), L >= 4);
                EXPECT_EQ(c.spec.krylov, solvers::Krylov::bicgstab);
            } else {
                EXPECT_EQ(c.spec.method, solvers::Method::schur);
            }
        }
    }
    // Rigid obstacles: mg from square level 1 (2 208 unknowns; 592 on level 0) and hertz level 1
    // (5 459); two bodies: dovetail from level 1 (14 341).
    auto sq = scene::load_scene("square");
    EXPECT_EQ(levels::mg_crossover_unknowns(sq), levels::kMgCrossoverOneBody);
    sq.levels = 0;
    EXPECT_EQ(levels::plan_solver(sq, {}).spec.method, solvers::Method::schur);
    sq.levels = 1;
    EXPECT_EQ(levels::plan_solver(sq, {}).spec.pc.text(), "mg:pre=0,post=2");
    auto hz = scene::load_scene("hertz");
    hz.levels = 1;
    EXPECT_EQ(levels::plan_solver(hz, {}).spec.pc.text(), "mg:pre=0,post=2");
    auto cl = scene::load_scene("calumet"); // 796 unknowns on level 1, 2 844 on level 2
    cl.levels = 1;
    EXPECT_EQ(levels::plan_solver(cl, {}).spec.method, solvers::Method::schur);
    cl.levels = 2;
    EXPECT_EQ(levels::plan_solver(cl, {}).spec.pc.text(), "mg:pre=0,post=2");
    auto dt = scene::load_scene("dovetail");
    EXPECT_EQ(levels::mg_crossover_unknowns(dt), levels::kMgCrossoverTwoBody);
    EXPECT_TRUE(levels::has_two_body_pair(dt));
    EXPECT_FALSE(levels::has_two_body_pair(sq));
    EXPECT_EQ(levels::default_mg(true).text(), "mg:omega=0.8,pre=0,post=2");
    EXPECT_EQ(levels::default_mg(false).text(), "mg:pre=0,post=2");
    EXPECT_EQ(levels::default_mg(true).text(), levels::kMgDefaultTwoBody);
    EXPECT_EQ(levels::default_mg(false, true).text(), "mg:pre=0,post=2,smoother=lattice");
    dt.levels = 0;
    EXPECT_EQ(levels::plan_solver(dt, {}).spec.method, solvers::Method::schur);
    auto pt = scene::load_scene("patch"); // two bodies, 1 405 unknowns on level 2
    pt.levels = 2;
    EXPECT_TRUE(levels::has_two_body_pair(pt));
    EXPECT_EQ(levels::plan_solver(pt, {}).spec.method, solvers::Method::schur);
    dt.levels = 1;
    // BiCGStab with a V(0,2) cycle, and with a two-body pair damped sweeps (fewer V-cycles
    // there); --linear krylov alone takes the same pair.
    EXPECT_EQ(levels::plan_solver(dt, {}).spec.pc.text(), "mg:omega=0.8,pre=0,post=2");
    EXPECT_EQ(levels::plan_solver(dt, {}).spec.krylov, solvers::Krylov::bicgstab);
    EXPECT_NE(levels::plan_solver(dt, {}).reason.find("BiCGStab + mg:omega=0.8,pre=0,post=2"),
              std::string::npos);
    EXPECT_EQ(
        levels::plan_solver(dt, request(std::string("krylov"), {}, {}, {}, {})).spec.pc.text(),
        "mg:omega=0.8,pre=0,post=2");
    EXPECT_EQ(levels::plan_solver(dt, request(std::string("krylov"), {}, {}, {}, {})).spec.krylov,
              solvers::Krylov::bicgstab);
    // A named preconditioner is taken as given, with CGS unless a method is named.
    EXPECT_EQ(levels::plan_solver(dt, request({}, {}, std::string("mg"), {}, {})).spec.pc.text(),
              "mg");
    EXPECT_EQ(levels::plan_solver(dt, request({}, {}, std::string("mg"), {}, {})).spec.krylov,
              solvers::Krylov::cgs);
    sq.levels = 3;
    EXPECT_EQ(levels::plan_solver(sq, {}).spec.krylov, solvers::Krylov::bicgstab);
    EXPECT_NE(levels::plan_solver(sq, {}).reason.find("BiCGStab + mg:pre=0,post=2"),
              std::string::npos);
}

TEST(MemoryEstimate, GrowsWithTheLevelsAndSchurNeedsMoreThanMgOnFineLevels) {
    auto p = scene::load_scene("square");
    p.levels = 5;
    const auto sizes = levels::predict_level_sizes(p);
    levels::LinearSolverSpec mg;
    mg.method = solvers::Method::krylov;
    mg.pc = solvers::parse_pc("mg");
    levels::LinearSolverSpec schur;
    const auto e5 = levels::estimate_memory(sizes, mg, true);
    const auto e4 = levels::estimate_memory({sizes.begin(), sizes.end() - 1}, mg, true);
    EXPECT_GT(e5.bytes, 3.0 * (e4.bytes - 12 * 1048576.0));
    EXPECT_LT(e5.bytes, 5.0 * e4.bytes);
    EXPECT_EQ(e5.largest_level, 5);
    EXPECT_GT(levels::estimate_memory(sizes, schur, true).bytes, e5.bytes);
    EXPECT_DOUBLE_EQ(e5.bytes,
                     e5.hierarchy_bytes + e5.solver_bytes + e5.steps_bytes + 12 * 1048576.0);
}

TEST(MemoryEstimate, CountsWhatEveryLoadStepKeepsAndTheFiles) {
    // A 15-vertex block in a million load steps: its reports, contact states and summary, kept
    // until the files are written, are gigabytes; the hierarchy and solver are kilobytes.
    auto p = scene::load_scene(std::string(MLC_TEST_DATA_DIR) + "/many_steps.toml");
    const auto sizes = levels::predict_level_sizes(p);
    ASSERT_EQ(sizes.size(), 1u);
    EXPECT_EQ(sizes[0].vertices, 15);
    EXPECT_EQ(sizes[0].contact_nodes, 5);
    const levels::LinearSolverSpec schur;
    const auto one = levels::estimate_memory(sizes, schur, false, {1, false});
    const auto many = levels::estimate_memory(sizes, schur, false, {1000000, false});
    const double per_step = levels::kStepBytesPerLevel + 5 * levels::kStepBytesPerContactNode;
    EXPECT_DOUBLE_EQ(one.steps_bytes, per_step);
    EXPECT_DOUBLE_EQ(many.steps_bytes, 1e6 * per_step);
    EXPECT_DOUBLE_EQ(many.bytes - one.bytes, (1e6 - 1) * per_step);
    EXPECT_DOUBLE_EQ(many.output_bytes,
                     1e6 * (levels::kOutputBytesPerLevel + 5 * levels::kOutputBytesPerContactNode));
    // Kept step states: two doubles per vertex and step more; coarse-to-fine on two levels: the
    // reports of both.
    const auto kept = levels::estimate_memory(sizes, schur, false, {1000000, true});
    EXPECT_DOUBLE_EQ(kept.steps_bytes - many.steps_bytes, 1e6 * 15 * 16);
    p.levels = 1;
    const auto two = levels::predict_level_sizes(p);
    const auto c2f = levels::estimate_memory(two, schur, true, {1000, false});
    EXPECT_DOUBLE_EQ(c2f.steps_bytes,
                     1000 * (2 * levels::kStepBytesPerLevel +
                             two.back().contact_nodes * levels::kStepBytesPerContactNode));
    // Refused when it does not fit, saying it is the load steps.
    try {
        levels::check_memory_fits(many, {0.5 * many.bytes, "a test limit"}, sizes);
        ADD_FAILURE() << "not refused";
    } catch (const InvalidInput& ex) {
        const std::string m = ex.what();
        EXPECT_NE(m.find("for what every load step keeps until the files are written"),
                  std::string::npos)
            << m;
        EXPECT_NE(m.find("use fewer load steps"), std::string::npos) << m;
    }
}

TEST(MemoryEstimate, MeshingATriangleCountThatCannotFitIsRefused) {
    EXPECT_DOUBLE_EQ(levels::level_size_from_triangles(1000).vertices, 500);
    EXPECT_DOUBLE_EQ(levels::level_size_from_triangles(1000).edges, 1500);
    EXPECT_GT(levels::meshing_memory(1e6), levels::kMeshingBytesPerTriangle * 1e6);
    EXPECT_NO_THROW(levels::check_meshing_fits(1e6, "m", "f", {1e15, "test"}));
    try {
        levels::check_meshing_fits(1e9, "the mesh", "raise max_size", {1e9, "a test limit"});
        ADD_FAILURE() << "not refused";
    } catch (const InvalidInput& ex) {
        EXPECT_EQ(std::string(ex.what()).rfind("the mesh needs an estimated ", 0), 0u) << ex.what();
        EXPECT_NE(std::string(ex.what()).find("but this process may use 954 MiB (a test limit): "
                                              "raise max_size"),
                  std::string::npos)
            << ex.what();
    }
}

TEST(MemoryEstimate, ARunThatCannotFitIsRefusedBeforeAllocatingNamingLevelAndLimit) {
    auto p = scene::load_scene("square");
    p.levels = 3;
    const auto sizes = levels::predict_level_sizes(p);
    const auto e = levels::estimate_memory(sizes, levels::LinearSolverSpec{}, true);
    EXPECT_NO_THROW(levels::check_memory_fits(e, {1e15, "test"}, sizes));
    try {
        levels::check_memory_fits(e, {0.5 * e.bytes, "a test limit"}, sizes);
        ADD_FAILURE() << "not refused";
    } catch (const InvalidInput& ex) {
        const std::string m = ex.what();
        EXPECT_NE(m.find("finest level 3"), std::string::npos) << m;
        EXPECT_NE(m.find("a test limit"), std::string::npos) << m;
        EXPECT_NE(m.find(levels::format_bytes(e.bytes)), std::string::npos) << m;
    }
    // levels::solve refuses too: level 12 of the square (1.1e9 unknowns) fits nowhere here.
    p.levels = 12;
    EXPECT_THROW(levels::solve(p), InvalidInput);
}

TEST(MemoryLimit, IsPositiveAndNamesItsSource) {
    const auto m = levels::process_memory_limit();
    EXPECT_GT(m.bytes, 0.0);
    EXPECT_FALSE(m.source.empty());
    EXPECT_EQ(levels::format_bytes(3.0 * 1024 * 1024 * 1024), "3.0 GiB");
    EXPECT_EQ(levels::format_bytes(5.0 * 1024 * 1024), "5 MiB");
}

TEST(MemoryEstimate, SquareLevel7WithMgFitsIn24GiB) {
    // `bench square --levels 7` (8.4 million unknowns, mg coarse-to-fine) must not be refused on
    // a 24 GiB machine: the estimate for level 7 scales about 4x from level 6, far below 24 GiB.
    auto p = scene::load_scene("square");
    p.levels = 7;
    const auto sizes = levels::predict_level_sizes(p);
    EXPECT_NEAR(sizes.back().unknowns, 8.4e6, 0.1e6);
    levels::LinearSolverSpec mg;
    mg.method = solvers::Method::krylov;
    mg.pc = solvers::parse_pc("mg");
    const auto e = levels::estimate_memory(sizes, mg, true);
    EXPECT_LT(e.bytes, 16.0 * 1024 * 1024 * 1024) << levels::format_bytes(e.bytes);
    EXPECT_GT(e.bytes, 4.0 * 2487 * 1048576.0 * 0.7) << levels::format_bytes(e.bytes);
    EXPECT_NO_THROW(levels::check_memory_fits(e, {24.0 * 1024 * 1024 * 1024, "24 GiB"}, sizes));
    std::cout << "square level 7, mg: estimated " << levels::format_bytes(e.bytes) << "\n";
}

TEST(ChooseSolver, TheDefaultSweepsByLatticesFromLevel4UnlessNumberingHilbertIsAsked) {
    // Above the crossover from level 4 on, the default mg sweeps the levels by lattices and
    // asks for the lattice numbering; below level 4 (no lattice levels), with numbering hilbert
    // asked, or with any solver option named, the block sweep on the Hilbert numbering.
    auto p = scene::load_scene("square");
    p.levels = 4;
    const auto d = levels::plan_solver(p, {});
    EXPECT_TRUE(d.automatic);
    EXPECT_TRUE(d.lattice_numbering());
    EXPECT_EQ(d.spec.pc.text(), "mg:pre=0,post=2,smoother=lattice");
    EXPECT_EQ(d.spec.krylov, solvers::Krylov::bicgstab);
    EXPECT_NE(d.reason.find("macro triangle by macro triangle"), std::string::npos) << d.reason;
    const auto l = levels::plan_solver(p, request({}, {}, {}, {}, std::string("lattice")));
    EXPECT_TRUE(l.lattice_numbering());
    EXPECT_EQ(l.spec.pc, d.spec.pc);
    const auto h = levels::plan_solver(p, request({}, {}, {}, {}, std::string("hilbert")));
    EXPECT_TRUE(h.automatic);
    EXPECT_FALSE(h.lattice_numbering());
    EXPECT_EQ(h.spec.pc.text(), "mg:pre=0,post=2");
    const auto named =
        levels::plan_solver(p, request({}, {}, std::string("mg:pre=0,post=2"), {}, {}));
    EXPECT_FALSE(named.lattice_numbering());
    const auto krylov = levels::plan_solver(p, request(std::string("krylov"), {}, {}, {}, {}));
    EXPECT_FALSE(krylov.lattice_numbering());
    EXPECT_EQ(krylov.spec.pc.text(), "mg:pre=0,post=2");
    // A two-body pair keeps its damping, with the lattice sweep.
    auto dt = scene::load_scene("dovetail");
    dt.levels = 4;
    const auto t = levels::plan_solver(dt, {});
    EXPECT_TRUE(t.lattice_numbering());
    EXPECT_EQ(t.spec.pc.text(), "mg:omega=0.8,pre=0,post=2,smoother=lattice");
    p.levels = 3;
    const auto three = levels::plan_solver(p, {});
    EXPECT_TRUE(three.automatic);
    EXPECT_FALSE(three.lattice_numbering());
    EXPECT_EQ(three.spec.pc.text(), "mg:pre=0,post=2");
}

TEST(PlanSolver, SeveralProcessesSweepByLatticesFromLevel5UnlessNumberingHilbertIsAsked) {
    // On several processes the default is BiCGStab + the V(0,2) mg at any size (never schur):
    // the block sweep on the Hilbert numbering up to level 4, the lattice sweep on each part
    // numbered for it from level 5 on; numbering hilbert keeps the block sweep. A named
    // preconditioner takes CGS, BiCGStab with a two-body pair; a direct method is refused.
    auto p = scene::load_scene("square");
    for (const int level : {2, 4, 5, 6}) {
        p.levels = level;
        const auto d = levels::plan_solver(p, {}, 2);
        EXPECT_FALSE(d.automatic) << level;
        EXPECT_EQ(d.spec.method, solvers::Method::krylov) << level;
        EXPECT_EQ(d.spec.krylov, solvers::Krylov::bicgstab) << level;
        EXPECT_EQ(d.lattice_numbering(), level >= levels::kMgDistributedLatticeLevel) << level;
        EXPECT_EQ(d.spec.pc.text(),
                  level >= 5 ? "mg:pre=0,post=2,smoother=lattice" : "mg:pre=0,post=2")
            << level;
        const auto h = levels::plan_solver(p, request({}, {}, {}, {}, std::string("hilbert")), 2);
        EXPECT_FALSE(h.lattice_numbering()) << level;
        EXPECT_EQ(h.spec.pc.text(), "mg:pre=0,post=2") << level;
    }
    EXPECT_EQ(levels::plan_solver(p, request({}, {}, std::string("ilu:1"), {}, {}), 3).spec.krylov,
              solvers::Krylov::cgs);
    EXPECT_THROW(levels::plan_solver(p, request(std::string("schur"), {}, {}, {}, {}), 2),
                 InvalidInput);
    EXPECT_THROW(levels::plan_solver(p, request({}, {}, std::string("cf"), {}, {}), 2),
                 InvalidInput);
    auto dt = scene::load_scene("dovetail");
    dt.levels = 5;
    const auto t = levels::plan_solver(dt, request({}, {}, std::string("mg"), {}, {}), 2);
    EXPECT_EQ(t.spec.krylov, solvers::Krylov::bicgstab);
    EXPECT_EQ(levels::plan_solver(dt, {}, 2).spec.pc.text(),
              "mg:omega=0.8,pre=0,post=2,smoother=lattice");
}

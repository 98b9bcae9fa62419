// SPDX-License-Identifier: MIT
// The preconditioner registry is the one list of names: the CLI help, `mlcontact
// preconditioners`, the study's and the bench's lists and the driver's choice all agree with it.
#include "bench/bench.hpp"
#include "core/check.hpp"
#include "levels/resources.hpp"
#include "run/preconditioners.hpp"
#include "scene/scene.hpp"
#include "solvers/factory.hpp"
#include "solvers/hypre/boomeramg.hpp"
#include "studies/preconditioners.hpp"

#include <gtest/gtest.h>

#include <set>
#include <sstream>

using namespace mlc;

namespace {

// Level data whose callables return empty inputs: enough for a builder to read its options.
solvers::LevelData stub_level_data() {
    solvers::LevelData d;
    d.has_level_below = true;
    d.coarse_fine_split = [](solvers::MultiplierScale) { return solvers::CoarseFineSplit{}; };
    d.coarse_lu = []() -> solvers::CoarseSolve { return [](const Vector&, Vector&) {}; };
    d.coarse_solver = [](const Vector&, Vector&) {};
    return d;
}

} // namespace

TEST(Registry, NamesAreUniqueAndEveryEntryIsComplete) {
    std::set<std::string> names;
    for (const auto& e : solvers::preconditioner_registry()) {
        EXPECT_TRUE(names.insert(e.name).second) << e.name << " registered twice";
        EXPECT_EQ(e.usage().rfind(e.name, 0), 0u) << "usage of " << e.name << ": " << e.usage();
        EXPECT_TRUE(e.build) << e.name;
        EXPECT_TRUE(!e.needs_level_below || e.level_aware) << e.name;
        for (const auto& key : e.keys())
            EXPECT_NE(e.usage().find(key.name), std::string::npos)
                << e.name << "'s usage does not mention its option " << key.name;
    }
    // The level-aware ones of the papers and ours.
    for (const char* n : {"cf", "sorcf", "mg"})
        EXPECT_TRUE(solvers::parse_pc(n).entry->needs_level_below) << n;
    EXPECT_TRUE(solvers::parse_pc("ebe").entry->level_aware);
    EXPECT_FALSE(solvers::parse_pc("ebe").entry->needs_level_below);
    // hypre MGR: the C/F split comes from the level (which unknowns are multipliers); it needs
    // no level below, so it serves meshes without levels too.
    EXPECT_TRUE(solvers::parse_pc("mgr").entry->level_aware);
    EXPECT_FALSE(solvers::parse_pc("mgr").entry->needs_level_below);
    EXPECT_EQ(solvers::parse_pc("MG:pre=2").name(), "mg");
    // mg also builds on a single level (its aggregation hierarchy); cf and sorcf do not.
    EXPECT_TRUE(solvers::parse_pc("mg").entry->single_level_too);
    EXPECT_FALSE(solvers::parse_pc("cf").entry->single_level_too);
    EXPECT_FALSE(solvers::parse_pc("sorcf").entry->single_level_too);
    EXPECT_THROW(solvers::parse_pc("amgx"), InvalidInput);
}

TEST(Registry, DeclaredOptionsAreExactlyTheOnesTheBuilderReads) {
    // An unknown key is reported with the list of the keys the builder read: that list must be
    // the entry's declared options, for every entry.
    const solvers::LevelData data = stub_level_data();
    for (const auto& e : solvers::preconditioner_registry()) {
        const std::string spec = e.name + ":bogus_key=1";
        try {
            solvers::make_preconditioner(spec, &data);
            ADD_FAILURE() << spec << " was accepted";
        } catch (const InvalidInput& err) {
            const std::string msg = err.what();
            std::ostringstream expected;
            const auto keys = e.keys();
            for (size_t i = 0; i < keys.size(); ++i)
                expected << (i ? ", " : "") << keys[i].name;
            EXPECT_NE(msg.find("unknown option 'bogus_key'"), std::string::npos) << msg;
            EXPECT_NE(
                msg.find("valid options: " + (keys.empty() ? std::string("none") : expected.str())),
                std::string::npos)
                << e.name << ": " << msg;
        }
    }
}

TEST(Registry, LevelAwareEntriesRefuseToBeBuiltFromAMatrixAlone) {
    for (const auto& e : solvers::preconditioner_registry()) {
        if (!e.level_aware) {
            if (e.name != "amg" || solvers::have_hypre()) {
                EXPECT_NO_THROW(solvers::make_preconditioner(e.name)) << e.name;
            }
            continue;
        }
        try {
            solvers::make_preconditioner(e.name);
            ADD_FAILURE() << e.name << " built without level data";
        } catch (const InvalidInput& err) {
            EXPECT_NE(std::string(err.what()).find("level hierarchy"), std::string::npos)
                << err.what();
        }
        if (!e.needs_level_below) continue;
        solvers::LevelData alone; // a level without the level below
        try {
            solvers::make_preconditioner(e.name, &alone);
            ADD_FAILURE() << e.name << " built without the level below";
        } catch (const InvalidInput& err) {
            EXPECT_NE(std::string(err.what()).find(e.name + " needs the level below"),
                      std::string::npos)
                << err.what();
        }
    }
}

TEST(Registry, HelpStudyBenchAndDriverAgreeWithIt) {
    const auto& reg = solvers::preconditioner_registry();
    // CLI help and `mlcontact preconditioners`.
    const std::string help = apps::pc_option_help("preconditioner");
    std::ostringstream listing;
    apps::print_preconditioners(listing);
    for (const auto& e : reg) {
        EXPECT_NE(help.find(e.name), std::string::npos) << e.name << " missing from: " << help;
        EXPECT_NE(listing.str().find(e.usage()), std::string::npos) << e.name;
    }
    // The study's and the bench's default lists name registered preconditioners, and both
    // accept every registered name and refuse others.
    for (const auto& spec : apps::PreconditionerStudyOptions{}.pcs)
        EXPECT_NO_THROW(solvers::parse_pc(spec)) << spec;
    // The bench's default is the run's default pair, whose mg spec is registered too.
    const apps::BenchSquareOptions bench_defaults;
    EXPECT_EQ(bench_defaults.pcs, std::vector<std::string>{"default"});
    // "default" is the run's default above the crossover whatever the size, planned by
    // plan_default_mg: on square level 2 (below the crossover) and on dovetail (two bodies).
    for (const char* scene_name : {"square", "dovetail"}) {
        levels::Problem p = scene::load_scene(scene_name);
        p.levels = 2;
        const bool two_body = levels::has_two_body_pair(p);
        const levels::SolverPlan d = apps::bench_plan(bench_defaults, "default", p);
        EXPECT_EQ(d.spec.method, solvers::Method::krylov) << scene_name;
        EXPECT_EQ(d.spec.krylov, levels::kMgDefaultKrylov) << scene_name;
        EXPECT_EQ(d.spec.pc.text(),
                  two_body ? levels::kMgDefaultTwoBody : levels::kMgDefaultOneBody)
            << scene_name;
        EXPECT_EQ(apps::bench_label(d), "bicgstab + " + d.spec.pc.text());
    }
    levels::Problem sq = scene::load_scene("square");
    sq.levels = 2;
    // A named preconditioner without --krylov keeps CGS; --krylov applies to both.
    EXPECT_EQ(apps::bench_plan(bench_defaults, "mg", sq).spec.krylov, solvers::Krylov::cgs);
    apps::BenchSquareOptions gmres;
    gmres.krylov = "gmres";
    EXPECT_EQ(apps::bench_plan(gmres, "mg", sq).spec.krylov, solvers::Krylov::gmres);
    EXPECT_EQ(apps::bench_plan(gmres, "default", sq).spec.krylov, solvers::Krylov::gmres);
    EXPECT_EQ(apps::bench_plan(gmres, "schur", sq).spec.method, solvers::Method::schur);
    EXPECT_EQ(apps::bench_label(apps::bench_plan(gmres, "lu", sq)), "lu");
    // From level 4 on the default sweeps by lattices on levels numbered for it.
    sq.levels = 4;
    sq.numbering = levels::Problem::Numbering::lattice;
    const levels::SolverPlan d4 = apps::bench_plan(bench_defaults, "default", sq);
    EXPECT_TRUE(d4.lattice_numbering());
    EXPECT_EQ(d4.spec.pc.text(), "mg:pre=0,post=2,smoother=lattice");
    std::vector<std::string> all;
    for (const auto& e : reg)
        all.push_back(e.name);
    EXPECT_NO_THROW(apps::check_preconditioner_names(all));
    all.push_back("schur");
    EXPECT_NO_THROW(apps::check_preconditioner_names(all, true));
    EXPECT_THROW(apps::check_preconditioner_names(all), InvalidInput);
    EXPECT_THROW(apps::check_preconditioner_names({"amgx"}, true), InvalidInput);
    apps::BenchSquareOptions bench;
    bench.pcs = {"amgx"};
    std::ostringstream sink;
    EXPECT_THROW(apps::bench_square(bench, sink), InvalidInput);
    // The driver: the preconditioner it chooses is registered, and needs the level below only
    // where there is one (mg, which builds its aggregation hierarchy on a single level).
    for (int L : {0, 1, 3}) {
        auto p = scene::load_scene("square");
        p.levels = L;
        for (const levels::SolverRequest& req :
             {levels::SolverRequest{.linear = solvers::Method::krylov}, levels::SolverRequest{}}) {
            const levels::SolverPlan c = levels::plan_solver(p, req);
            if (c.spec.method != solvers::Method::krylov) continue;
            const solvers::PreconditionerEntry* e = c.spec.pc.entry;
            ASSERT_NE(e, nullptr) << c.spec.pc;
            EXPECT_TRUE(!e->needs_level_below || L >= 1 || e->single_level_too)
                << c.spec.pc << " at levels " << L;
            EXPECT_EQ(e->name, "mg") << c.spec.pc << " at levels " << L;
        }
        // A name that needs the level below, asked for without one: refused before building,
        // unless it builds on a single level too (mg: its aggregation hierarchy).
        for (const auto& e : reg) {
            if (!e.needs_level_below) continue;
            levels::SolverRequest req;
            req.pc = solvers::parse_pc(e.name);
            if (L == 0 && !e.single_level_too)
                EXPECT_THROW(levels::plan_solver(p, req), InvalidInput) << e.name;
            else
                EXPECT_EQ(levels::plan_solver(p, req).spec.pc.text(), e.name);
        }
    }
    EXPECT_THROW(solvers::parse_pc("amgx"), InvalidInput);
}

// SPDX-License-Identifier: MIT
// `bench square` on a 3D scene: the per-level counts are those `mlcontact run` reports for the
// same scene (Newton steps and Krylov iterations are deterministic), the JSON holds every field
// and the sizes of the hierarchy, --scaling compares the finest level with the level below, and
// the options that apply to 2D scenes only are refused by name.
#include "bench/bench.hpp"
#include "core/check.hpp"
#include "levels/elastic3d_levels.hpp"
#include "run/run3.hpp"
#include "scene/scene3.hpp"
#include "tests/common/files.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

using namespace mlc;

namespace {

/// The per-level figures of one run in a bench JSON (or in `run`'s files).
struct Bsq3Level {
    long unknowns = 0;
    int contact_nodes = 0;
    int newton = 0;
    std::vector<int> newton_per_step, krylov;
};

std::vector<int> bsq3_ints(const std::string& list) {
    std::vector<int> v;
    std::stringstream ss(list);
    std::string item;
    while (std::getline(ss, item, ','))
        if (item.find_first_not_of(' ') != std::string::npos) v.push_back(std::stoi(item));
    return v;
}

/// The levels of the run with finest level `finest` in `js` (bench_square3's JSON).
std::vector<Bsq3Level> bsq3_levels(const std::string& js, int finest) {
    const std::string head = "\"finest\": " + std::to_string(finest) + ",";
    const size_t at = js.find(head);
    EXPECT_NE(at, std::string::npos) << head << "\n" << js;
    if (at == std::string::npos) return {};
    const size_t end = js.find("\n     ]}", at);
    const std::string run = js.substr(at, end - at);
    const std::regex level(
        "\\{\"level\": ([0-9]+), \"unknowns\": ([0-9]+), \"contact_nodes\": ([0-9]+), "
        "\"nonzeros\": [0-9]+, \"newton_steps\": ([0-9]+), \"newton_steps_per_load_step\": "
        "\\[([0-9, ]*)\\], \"krylov_per_newton\": \\[([0-9, ]*)\\]");
    std::vector<Bsq3Level> out;
    for (auto it = std::sregex_iterator(run.begin(), run.end(), level);
         it != std::sregex_iterator(); ++it) {
        EXPECT_EQ(std::stoi((*it)[1]), static_cast<int>(out.size()));
        Bsq3Level l;
        l.unknowns = std::stol((*it)[2]);
        l.contact_nodes = std::stoi((*it)[3]);
        l.newton = std::stoi((*it)[4]);
        l.newton_per_step = bsq3_ints((*it)[5]);
        l.krylov = bsq3_ints((*it)[6]);
        out.push_back(l);
    }
    return out;
}

/// What `mlcontact run` reports per level: iterations.csv (one row per Newton system: level,
/// unknowns, distributed, step, newton, krylov) and summary.json's Newton iterations per step.
std::vector<Bsq3Level> bsq3_run_levels(const std::filesystem::path& dir, int levels) {
    std::vector<Bsq3Level> out(static_cast<size_t>(levels) + 1);
    std::stringstream csv(testutil::slurp(dir / "iterations.csv"));
    std::string line;
    std::getline(csv, line);
    EXPECT_EQ(line, "level,unknowns,distributed,step,newton,krylov");
    while (std::getline(csv, line)) {
        const std::vector<int> f = bsq3_ints(line);
        EXPECT_EQ(f.size(), 6u) << line;
        if (f.size() != 6) continue;
        Bsq3Level& l = out.at(static_cast<size_t>(f[0]));
        l.unknowns = f[1];
        ++l.newton;
        l.krylov.push_back(f[5]);
    }
    const std::string summary = testutil::slurp(dir / "summary.json");
    const std::regex per_level("\"level\"\\s*:\\s*([0-9]+)\\s*,\\s*\"newton_iterations\"\\s*:"
                               "\\s*\\[([0-9,\\s]*)\\]");
    int found = 0;
    for (auto it = std::sregex_iterator(summary.begin(), summary.end(), per_level);
         it != std::sregex_iterator(); ++it, ++found)
        out.at(static_cast<size_t>(std::stoi((*it)[1]))).newton_per_step = bsq3_ints((*it)[2]);
    EXPECT_EQ(found, levels + 1) << summary;
    return out;
}

apps::BenchSquareOptions bsq3_options(const std::filesystem::path& dir, int levels) {
    apps::BenchSquareOptions o;
    o.scene = "block3d";
    o.levels = levels;
    o.stream_doubles = 100000;
    o.stream_repeats = 1;
    o.out = dir / "bench.json";
    return o;
}

/// The message of the InvalidInput `f` throws ("" when it throws none).
template <class F> std::string bsq3_refusal(F&& f) {
    try {
        f();
    } catch (const InvalidInput& e) {
        return e.what();
    }
    return "";
}

} // namespace

TEST(BenchSquare3, Block3dLevel1CountsAreTheRunsAndTheJsonHasEveryField) {
    const auto dir = testutil::scratch_dir("mlc_bsq3");
    // What `mlcontact run block3d --levels 1` reports.
    apps::RunOptions ro;
    ro.scene = "block3d";
    ro.levels = 1;
    ro.quiet = true;
    ro.out = (dir / "run").string();
    std::ostringstream run_os;
    ASSERT_EQ(apps::run_scene3(ro, run_os), 0) << run_os.str();
    const std::vector<Bsq3Level> run = bsq3_run_levels(dir / "run", 1);

    std::ostringstream os;
    ASSERT_EQ(apps::bench_square(bsq3_options(dir, 1), os), 0) << os.str();
    const std::string js = testutil::slurp(dir / "bench.json");
    const std::vector<Bsq3Level> bench = bsq3_levels(js, 1);
    ASSERT_EQ(bench.size(), 2u) << js;
    // The hierarchy's sizes: each level's unknowns are its free displacements and three
    // multipliers per (frictional) contact node.
    const levels::ElasticProblem3 p = scene::load_scene3("block3d");
    const levels::Hierarchy3 h = levels::build_hierarchy(p, 1);
    for (size_t l = 0; l < 2; ++l) {
        SCOPED_TRACE("level " + std::to_string(l));
        const levels::Level3& L = h.levels[l];
        EXPECT_EQ(bench[l].unknowns, static_cast<long>(L.n_unknowns()));
        EXPECT_EQ(bench[l].contact_nodes, L.n_contact_nodes());
        EXPECT_EQ(bench[l].unknowns, L.dofs.n_displacement_dofs() + 3 * L.n_contact_nodes());
        EXPECT_EQ(bench[l].unknowns, run[l].unknowns);
        // Newton steps per load step and Krylov iterations of every Newton system: the run's.
        EXPECT_EQ(bench[l].newton_per_step, run[l].newton_per_step);
        EXPECT_EQ(bench[l].newton, run[l].newton);
        EXPECT_EQ(bench[l].krylov, run[l].krylov);
        int sum = 0;
        for (int k : bench[l].newton_per_step)
            sum += k;
        EXPECT_EQ(bench[l].newton, sum);
        EXPECT_EQ(bench[l].newton_per_step.size(), static_cast<size_t>(p.load_steps));
    }
    // status-transfer's figures of the same level (tests/CMakeLists.txt, status_transfer3d), and
    // bench elastic's 1152 free displacements (bench_elastic3d_contact_scene) with 3 x 72.
    EXPECT_EQ(bench[1].unknowns, 1152 + 3 * 72);
    EXPECT_EQ(bench[1].contact_nodes, 72);
    // Level 1 is solved by GMRES + mg: Krylov iterations in every Newton system.
    for (int k : bench[1].krylov)
        EXPECT_GE(k, 1);
    for (const char* key : {"\"dimension\": 3",
                            "\"solver\": \"default\"",
                            "\"level0\": \"schur\"",
                            "\"upper\": \"gmres + mg\"",
                            "\"converged\": true",
                            "\"wall_seconds\"",
                            "\"peak_rss_mib\"",
                            "\"memory_estimate_mib\"",
                            "\"fine_newton_step_in_matvecs\"",
                            "\"krylov_per_newton_median\"",
                            "\"krylov_per_newton_max\"",
                            "\"seconds_per_newton_per_unknown\"",
                            "\"newton_step_in_matvecs\"",
                            "\"bytes_per_newton_per_unknown\"",
                            "\"bytes_per_newton_in_matvecs\"",
                            "\"kinds\": {\"matvec\"",
                            "\"smoother\"",
                            "\"transfer\"",
                            "\"solver_rss_growth_bytes\"",
                            "\"jacobian_bytes\"",
                            "\"stream\""})
        EXPECT_NE(js.find(key), std::string::npos) << key;
    EXPECT_NE(js.find("\"load_steps\": " + std::to_string(p.load_steps) + ","), std::string::npos);
    EXPECT_EQ(js.find("\"scaling\""), std::string::npos);
    EXPECT_EQ(js.find("nan"), std::string::npos) << js;
    EXPECT_EQ(js.find("inf"), std::string::npos) << js;
    // Level 1's multigrid passes were counted: GMRES's mat-vecs, at least one per iteration.
    std::smatch m;
    const std::string fine = js.substr(js.find("{\"level\": 1,"));
    ASSERT_TRUE(std::regex_search(
        fine, m,
        std::regex("\"newton_solves\": ([0-9]+), .*\"matvec\": \\{\"bytes\": ([0-9]+), "
                   "\"passes\": ([0-9]+)")))
        << fine;
    EXPECT_EQ(std::stoi(m[1]), bench[1].newton);
    int its = 0;
    for (int k : bench[1].krylov)
        its += k;
    EXPECT_GE(std::stol(m[3]), its);
    EXPECT_GT(std::stod(m[2]), 0.0);
    EXPECT_NE(os.str().find("plan (default, finest 1): "), std::string::npos) << os.str();
    std::filesystem::remove_all(dir);
}

TEST(BenchSquare3, Block3dLevel0IsTheExactSolveAlone) {
    const auto dir = testutil::scratch_dir("mlc_bsq3");
    std::ostringstream os;
    apps::BenchSquareOptions o = bsq3_options(dir, 0);
    o.pcs = {"lu"};
    ASSERT_EQ(apps::bench_square(o, os), 0) << os.str();
    const std::string js = testutil::slurp(dir / "bench.json");
    const std::vector<Bsq3Level> bench = bsq3_levels(js, 0);
    ASSERT_EQ(bench.size(), 1u) << js;
    const levels::ElasticProblem3 p = scene::load_scene3("block3d");
    const levels::Hierarchy3 h = levels::build_hierarchy(p, 0);
    EXPECT_EQ(bench[0].unknowns, static_cast<long>(h.finest().n_unknowns()));
    EXPECT_EQ(bench[0].newton_per_step.size(), static_cast<size_t>(p.load_steps));
    // An exact solve: no Krylov iteration, no counted pass.
    for (int k : bench[0].krylov)
        EXPECT_EQ(k, 0);
    EXPECT_NE(js.find("\"bandwidth\": {\"newton_solves\": " + std::to_string(bench[0].newton) +
                      ", \"krylov_seconds\": "),
              std::string::npos);
    EXPECT_NE(js.find("\"bytes\": 0, \"bytes_per_newton\": 0,"), std::string::npos) << js;
    EXPECT_EQ(static_cast<int>(bench[0].krylov.size()), bench[0].newton);
    EXPECT_NE(js.find("\"level0\": \"lu\""), std::string::npos) << js;
    std::filesystem::remove_all(dir);
}

TEST(BenchSquare3, ScalingComparesTheFinestLevelWithTheLevelBelow) {
    const auto dir = testutil::scratch_dir("mlc_bsq3");
    std::ostringstream os;
    apps::BenchSquareOptions o = bsq3_options(dir, 1);
    o.scaling = true;
    ASSERT_EQ(apps::bench_square(o, os), 0) << os.str();
    const std::string js = testutil::slurp(dir / "bench.json");
    const std::vector<Bsq3Level> below = bsq3_levels(js, 0);
    const std::vector<Bsq3Level> fine = bsq3_levels(js, 1);
    ASSERT_EQ(below.size(), 1u);
    ASSERT_EQ(fine.size(), 2u);
    // The level-0 run is the level-1 run's level 0 (the same solver, the same steps).
    EXPECT_EQ(below[0].unknowns, fine[0].unknowns);
    EXPECT_EQ(below[0].newton_per_step, fine[0].newton_per_step);
    EXPECT_EQ(below[0].krylov, fine[0].krylov);
    std::smatch m;
    ASSERT_TRUE(std::regex_search(js, m,
                                  std::regex("\"scaling\": \\{\"below\": 0, \"finest\": 1, "
                                             "\"runs_each\": 1, .*\"unknowns\": \\[([0-9]+), "
                                             "([0-9]+)\\], \"unknowns_ratio\": ([0-9.e+-]+)")))
        << js;
    EXPECT_EQ(std::stol(m[1]), below[0].unknowns);
    EXPECT_EQ(std::stol(m[2]), 1368);
    EXPECT_NEAR(std::stod(m[3]), 1368.0 / static_cast<double>(below[0].unknowns), 1e-5);
    // The Krylov medians of the two finest levels: level 0's exact solve (0) and level 1's GMRES.
    ASSERT_TRUE(std::regex_search(
        js, m, std::regex("\"fine_krylov_per_newton_median\": \\[([0-9.]+), ([0-9.]+)\\]")))
        << js;
    EXPECT_EQ(std::stod(m[1]), 0.0);
    std::vector<int> its = fine[1].krylov;
    std::sort(its.begin(), its.end());
    ASSERT_FALSE(its.empty());
    const size_t h = its.size() / 2;
    EXPECT_DOUBLE_EQ(std::stod(m[2]), its.size() % 2 ? its[h] : 0.5 * (its[h - 1] + its[h]));
    for (const char* key :
         {"\"matvecs_growth_bound\": 0.1", "\"time_ratio_bound\": 10",
          "\"matvecs_met\": ", "\"time_met\": ", "\"fine_newton_step_in_matvecs\": [",
          "\"time_ratio\": ", "\"bytes_growth\": "})
        EXPECT_NE(js.find(key), std::string::npos) << key;
    EXPECT_NE(os.str().find("scaling, finest 0 -> 1 (1 runs each, alternated; medians)"),
              std::string::npos)
        << os.str();
    std::filesystem::remove_all(dir);
}

TEST(BenchSquare3, RefusesTheOptionsOf2dScenesByName) {
    const auto dir = testutil::scratch_dir("mlc_bsq3");
    std::ostringstream os;
    auto refusal = [&](apps::BenchSquareOptions o) {
        return bsq3_refusal([&] { apps::bench_square(o, os); });
    };
    apps::BenchSquareOptions o = bsq3_options(dir, 1);
    o.pcs = {"mg:pre=0,post=2"};
    EXPECT_NE(refusal(o).find("bench square --pc 'mg:pre=0,post=2' does not apply to a 3D scene"),
              std::string::npos)
        << refusal(o);
    o = bsq3_options(dir, 1);
    o.pcs = {"schur", "ilu"};
    EXPECT_NE(refusal(o).find("--pc 'ilu'"), std::string::npos);
    o = bsq3_options(dir, 1);
    o.krylov = "gmres";
    EXPECT_NE(refusal(o).find("bench square --krylov does not apply to a 3D scene"),
              std::string::npos);
    for (const char* name : {"--tol", "--max-iter", "--numbering", "--extrapolate"}) {
        o = bsq3_options(dir, 1);
        o.given = {"--levels", name};
        EXPECT_NE(
            refusal(o).find(std::string("bench square ") + name + " does not apply to a 3D scene"),
            std::string::npos)
            << name << ": " << refusal(o);
    }
    o = bsq3_options(dir, 0);
    o.scaling = true;
    EXPECT_NE(refusal(o).find("--levels must be >= 1, found 0"), std::string::npos);
    o = bsq3_options(dir, 1);
    o.scaling = true;
    o.pcs = {"default", "lu"};
    EXPECT_NE(refusal(o).find("--scaling runs one solver, found 2"), std::string::npos);
    o = bsq3_options(dir, 13);
    EXPECT_NE(refusal(o).find("--levels must lie in 0..12 for a 3D scene, found 13"),
              std::string::npos);
    // The 2D square has no --scaling; nothing was written by a refusal.
    o = bsq3_options(dir, 1);
    o.scene = "square";
    o.scaling = true;
    EXPECT_NE(refusal(o).find("--scaling is for 3D scenes"), std::string::npos);
    EXPECT_FALSE(std::filesystem::exists(dir / "bench.json"));
    std::filesystem::remove_all(dir);
}

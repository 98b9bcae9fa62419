// SPDX-License-Identifier: MIT
// `study error-vs-time`: the multilevel rows exist (coarse-to-fine and cold
// mg from level 1, mgr where hypre is built in), converge, and their error against the level-3
// reference falls with the level; the other configurations are left out by --only.
#include "core/check.hpp"
#include "levels/resources.hpp"
#include "scene/scene.hpp"
#include "solvers/hypre/boomeramg.hpp"
#include "studies/error_vs_time.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

using namespace mlc;

namespace {

// The rows of error_vs_time.csv: configuration -> level -> (converged, energy error).
std::map<std::string, std::map<int, std::pair<bool, double>>>
read_rows(const std::filesystem::path& csv) {
    std::ifstream in(csv);
    std::string line;
    std::getline(in, line); // header
    std::map<std::string, std::map<int, std::pair<bool, double>>> rows;
    while (std::getline(in, line)) {
        // "name",level,unknowns,seconds,converged,energy_error,...
        const auto q = line.find('"', 1);
        const std::string name = line.substr(1, q - 1);
        std::stringstream rest(line.substr(q + 2));
        std::vector<std::string> f;
        for (std::string cell; std::getline(rest, cell, ',');)
            f.push_back(cell);
        rows[name][std::stoi(f.at(0))] = {f.at(3) == "1", std::stod(f.at(4))};
    }
    return rows;
}

} // namespace

TEST(ErrorVsTime, MultilevelRowsConvergeAndTheirErrorFallsWithTheLevel) {
    const auto dir = std::filesystem::temp_directory_path() / "mlc_test_error_vs_time";
    std::filesystem::remove_all(dir);
    apps::ErrorVsTimeOptions opt;
    opt.max_level = 2;
    opt.only = "mg"; // c2f default bicgstab+mg, c2f cgs+mg, cold cgs+mg, c2f cgs+mgr
    opt.plot = false;
    opt.out = dir;
    std::ostringstream log;
    ASSERT_EQ(apps::study_error_vs_time(scene::load_scene("square"), opt, log), 0) << log.str();
    const auto rows = read_rows(dir / "error_vs_time.csv");
    std::vector<std::string> expected{"c2f default bicgstab+mg", "c2f cgs+mg", "cold cgs+mg"};
    if (solvers::have_hypre()) expected.push_back("c2f cgs+mgr");
    EXPECT_EQ(rows.size(), expected.size()) << log.str();
    for (const auto& name : expected) {
        ASSERT_TRUE(rows.count(name)) << name << "\n" << log.str();
        const auto& r = rows.at(name);
        // mg needs a level below: from level 1 (mgr runs on level 0 too).
        EXPECT_EQ(r.count(0), name == "c2f cgs+mgr" ? 1u : 0u) << name;
        ASSERT_TRUE(r.count(1) && r.count(2)) << name;
        for (const auto& [level, row] : r)
            EXPECT_TRUE(row.first) << name << " level " << level;
        // Square, reference on level 3: energy errors 0.0167 (level 1) and 0.00757 (level 2),
        // the same for every solver that reaches the tolerance.
        EXPECT_NEAR(r.at(1).second, 0.0167, 0.0005) << name;
        EXPECT_NEAR(r.at(2).second, 0.00757, 0.0002) << name;
        EXPECT_LT(r.at(2).second, 0.6 * r.at(1).second) << name;
        if (r.count(0)) {
            EXPECT_LT(r.at(1).second, 0.6 * r.at(0).second) << name;
        }
    }
    std::filesystem::remove_all(dir);
}

// The grid's default row is the run's default above the crossover on every level: the block
// sweep up to level 3, the lattice sweep from level 4 (what plan_solver picks with no solver
// flag), with a one-body and a two-body scene.
TEST(ErrorVsTime, TheDefaultRowRunsTheRunsDefaultOnEveryLevel) {
    // patch (two bodies, crossover 10 000 unknowns) is below it up to level 3.
    for (const char* name : {"square", "patch"}) {
        const auto scene = scene::load_scene(name);
        for (int level : {3, 4, 5}) {
            if (std::string(name) == "patch" && level == 3) continue;
            levels::Problem p = scene;
            p.levels = level;
            const levels::SolverPlan choice = levels::plan_solver(p, {});
            ASSERT_TRUE(choice.spec.method == solvers::Method::krylov)
                << name << " level " << level << ": " << choice.reason;
            EXPECT_EQ(apps::error_vs_time_pc(scene, "c2f default bicgstab+mg", level),
                      choice.spec.pc.text())
                << name << " level " << level;
            EXPECT_EQ(choice.lattice_numbering(), level >= 4) << name << " level " << level;
        }
    }
    EXPECT_EQ(apps::error_vs_time_pc(scene::load_scene("square"), "c2f cgs+mg", 5), "mg");
    EXPECT_THROW(apps::error_vs_time_pc(scene::load_scene("square"), "no such row", 1),
                 InvalidInput);
}

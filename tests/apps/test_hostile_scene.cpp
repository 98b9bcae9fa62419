// SPDX-License-Identifier: MIT
// Hostile input: scenes that once crashed, hung or invoked undefined behaviour in the
// parser (found while fuzzing it with tests/fuzz, or by review). Each is a data file in
// tests/data/hostile/ (the Python tests read the same files, python/tests/test_hostile.py) whose
// comment line "# expect: invalid[: text]" or "# expect: valid: N triangles" says what parsing it
// must give: an InvalidInput (whose message contains the text), or a scene with N triangles,
// parsed in under 10 s. Scenes that parse but whose solve must name a cause say
// "# expect: not converged: text" (the run fails, exit 2, and its diagnosis contains the text) or
// "# expect: solves: text" (the run converges and its report contains the text: a warning or a
// check said not applicable); they are solved as `mlcontact run` solves them.
#include "core/check.hpp"
#include "run/output.hpp"
#include "run/run.hpp"
#include "scene/scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace mlc;

namespace {

struct Hostile {
    std::filesystem::path path;
    std::string text;
    bool valid = false;
    /// Parses, then the solve does not converge ("not converged") or converges ("solves").
    std::string solve;
    std::string message; ///< invalid, solve: a part of the expected message (may be empty)
    int triangles = -1;  ///< valid: the expected number of triangles
};

std::vector<Hostile> hostile_scenes() {
    std::vector<Hostile> out;
    for (const auto& e : std::filesystem::directory_iterator(
             std::filesystem::path(MLC_TEST_DATA_DIR) / "hostile")) {
        if (e.path().extension() != ".toml") continue;
        Hostile h;
        h.path = e.path();
        std::ifstream f(h.path);
        std::ostringstream text;
        text << f.rdbuf();
        h.text = text.str();
        std::istringstream lines(h.text);
        std::string line;
        bool found = false;
        while (std::getline(lines, line)) {
            const std::string tag = "# expect: ";
            if (line.rfind(tag, 0) != 0) continue;
            const std::string what = line.substr(tag.size());
            if (what.rfind("valid: ", 0) == 0) {
                h.valid = true;
                h.triangles = std::stoi(what.substr(7));
            } else if (what.rfind("not converged: ", 0) == 0 || what.rfind("solves: ", 0) == 0) {
                const size_t colon = what.find(": ");
                h.solve = what.substr(0, colon);
                h.message = what.substr(colon + 2);
            } else if (what.rfind("invalid", 0) == 0) {
                h.message = what.size() > 9 ? what.substr(9) : "";
            } else {
                ADD_FAILURE() << h.path << ": cannot read '" << line << "'";
            }
            found = true;
        }
        EXPECT_TRUE(found) << h.path << " has no '# expect:' line";
        out.push_back(h);
    }
    std::sort(out.begin(), out.end(), [](auto& a, auto& b) { return a.path < b.path; });
    return out;
}

} // namespace

TEST(HostileScene, EveryDataFileGivesItsExpectedOutcome) {
    const auto scenes = hostile_scenes();
    // rectangle_too_large, gmsh_from_a_device, thin_strip at least.
    ASSERT_GE(scenes.size(), 3u);
    for (const auto& h : scenes) {
        SCOPED_TRACE(h.path.string());
        const auto t0 = std::chrono::steady_clock::now();
        if (h.valid) {
            const auto p = scene::parse_scene(h.text, h.path.string());
            EXPECT_EQ(p.mesh0.n_cells(), h.triangles);
        } else if (!h.solve.empty()) {
            // As `mlcontact run` solves it, with its report.
            auto p = scene::parse_scene(h.text, h.path.string());
            const apps::RunOptions opt;
            apps::apply_overrides(p, opt);
            levels::SolverPlan choice;
            const levels::SolveOptions so = apps::run_solve_options(p, opt, choice);
            const levels::RunResult r = levels::solve(p, so);
            std::ostringstream report;
            apps::print_summary(report, p, r);
            if (h.solve == "not converged") {
                EXPECT_FALSE(r.converged);
                EXPECT_NE(r.failure.find(h.message), std::string::npos) << r.failure;
            } else {
                EXPECT_TRUE(r.converged) << r.failure;
                EXPECT_NE(report.str().find(h.message), std::string::npos) << report.str();
                // A warning is in RunResult::warnings too (summary.json's "warnings").
                if (h.message.rfind("warning: ", 0) == 0) {
                    const std::string w = h.message.substr(9);
                    EXPECT_TRUE(std::any_of(r.warnings.begin(), r.warnings.end(), [&](auto& x) {
                        return x.find(w) != std::string::npos;
                    })) << w;
                }
            }
        } else {
            try {
                scene::parse_scene(h.text, h.path.string());
                ADD_FAILURE() << "no exception";
            } catch (const InvalidInput& e) {
                EXPECT_NE(std::string(e.what()).find(h.message), std::string::npos) << e.what();
                EXPECT_NE(std::string(e.what()).find(h.path.string()), std::string::npos)
                    << e.what();
            }
        }
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        EXPECT_LT(seconds, 10.0);
    }
}

// The three files the first version of this test inlined are still there.
TEST(HostileScene, KnownCasesArePresent) {
    const auto dir = std::filesystem::path(MLC_TEST_DATA_DIR) / "hostile";
    for (const char* n : {"rectangle_too_large.toml", "gmsh_from_a_device.toml", "thin_strip.toml"})
        EXPECT_TRUE(std::filesystem::exists(dir / n)) << n;
}

// SPDX-License-Identifier: MIT
// `study extremes --dimension 3` (studies/extremes3.cpp) on level 0: every case of both tables
// converges or names why not, with finite numbers; the lift-off case opens every node, the
// frictionless one has no stick, the soft block on the stiff one converges; the 2D-only solver
// options and bad levels are refused.
#include "core/check.hpp"
#include "studies/extremes.hpp"
#include "tests/common/files.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

using namespace mlc;

namespace {

/// The cells of one CSV line (double quotes group a cell; no escaped quotes inside).
std::vector<std::string> extremes3_cells(const std::string& line) {
    std::vector<std::string> out(1);
    bool quoted = false;
    for (char c : line) {
        if (c == '"')
            quoted = !quoted;
        else if (c == ',' && !quoted)
            out.emplace_back();
        else
            out.back() += c;
    }
    return out;
}

/// extremes.csv as maps from its header's names to the cells.
std::vector<std::map<std::string, std::string>> extremes3_rows(const std::filesystem::path& csv) {
    std::istringstream in(testutil::slurp(csv));
    std::string line;
    std::getline(in, line);
    const auto header = extremes3_cells(line);
    std::vector<std::map<std::string, std::string>> rows;
    while (std::getline(in, line)) {
        const auto cells = extremes3_cells(line);
        EXPECT_EQ(cells.size(), header.size()) << line;
        std::map<std::string, std::string> row;
        for (size_t k = 0; k < header.size() && k < cells.size(); ++k)
            row[header[k]] = cells[k];
        rows.push_back(row);
    }
    return rows;
}

} // namespace

TEST(Extremes3, EveryCaseConvergesOrIsDiagnosedWithFiniteNumbers) {
    apps::ExtremesOptions opt;
    opt.dimension = 3;
    opt.levels = 0;
    opt.seconds_per_case = 120;
    opt.out = testutil::scratch_dir("extremes3");
    std::ostringstream log;
    ASSERT_EQ(apps::study_extremes3(opt, log), 0) << log.str();
    const auto rows = extremes3_rows(opt.out / "extremes.csv");
    // 17 cases, each with the run's plan (schur on level 0) and with lu.
    ASSERT_EQ(rows.size(), 34u) << log.str();
    std::map<std::string, int> per_solver;
    for (const auto& r : rows) {
        ++per_solver[r.at("solver")];
        const std::string what = r.at("solver") + " / " + r.at("case");
        const std::string& result = r.at("result");
        ASSERT_TRUE(result == "converged" || result == "no conv") << what << ": " << result;
        if (result == "no conv") {
            EXPECT_FALSE(r.at("notes").empty()) << what;
            EXPECT_EQ(r.at("exit"), "2") << what;
            continue;
        }
        EXPECT_EQ(r.at("exit"), "0") << what;
        EXPECT_GE(std::stoi(r.at("newton")), 1) << what;
        for (const char* k : {"residual", "penetration", "coulomb", "seconds"}) {
            const double v = std::stod(r.at(k));
            EXPECT_TRUE(std::isfinite(v) && v >= 0) << what << ": " << k << " = " << v;
        }
        // Converged: a residual below the Newton tolerance (1e-10), or at a round-off floor
        // Newton accepts within 1e3 times it once the statuses hold (the stiffness contrast),
        // no penetration and no Coulomb violation beyond round-off of the largest multiplier.
        EXPECT_LE(std::stod(r.at("residual")), 1e-7) << what;
        EXPECT_LE(std::stod(r.at("penetration")), 1e-6) << what;
        EXPECT_LE(std::stod(r.at("coulomb")), 1e-6) << what;
    }
    EXPECT_EQ(per_solver.size(), 2u);
    // Level 0 of block3d has 25 bottom vertices, 5 of them on the held edge: 20 contact nodes.
    for (const auto& r : rows) {
        if (r.at("case") == "lift-off") {
            EXPECT_EQ(r.at("result"), "converged") << r.at("solver");
            EXPECT_NE(r.at("notes").find("gap/stick/slip 20/0/0"), std::string::npos)
                << r.at("notes");
        }
        if (r.at("case") == "mu=0" && r.at("result") == "converged") {
            EXPECT_NE(r.at("notes").find("/0/"), std::string::npos) << r.at("notes");
        }
        // The soft block on the stiff one converges (with status cycling, damped); the stiff
        // block on the soft one is where the 3D Newton may fail (no r continuation in 3D): then
        // its notes name the level, the load step and the cycling.
        if (r.at("case") == "contrast 1e6 soft/stiff") {
            EXPECT_EQ(r.at("result"), "converged") << r.at("solver");
        }
        if (r.at("case") == "contrast 1e6 stiff/soft" && r.at("result") == "no conv") {
            EXPECT_NE(r.at("notes").find("load step 1 on level 0"), std::string::npos)
                << r.at("notes");
        }
    }
}

TEST(Extremes3, TwoDimensionalSolverOptionsAndBadLevelsAreRefused) {
    auto refused = [](const apps::ExtremesOptions& o) {
        std::ostringstream log;
        try {
            apps::study_extremes3(o, log);
        } catch (const InvalidInput& e) {
            return std::string(e.what());
        }
        return std::string("not refused");
    };
    apps::ExtremesOptions o;
    o.dimension = 3;
    o.out = testutil::scratch_dir("extremes3_refused");
    o.levels = 5;
    EXPECT_NE(refused(o).find("--levels between 0 and 4, found 5"), std::string::npos)
        << refused(o);
    o.levels = 0;
    o.pc = "mg";
    EXPECT_NE(refused(o).find("--pc does not apply to the 3D extremes study"), std::string::npos)
        << refused(o);
    o.pc.reset();
    o.linear = "krylov";
    EXPECT_NE(refused(o).find("--linear krylov does not apply"), std::string::npos) << refused(o);
    o.linear.reset();
    o.seconds_per_case = 0;
    EXPECT_NE(refused(o).find("--seconds must be positive"), std::string::npos) << refused(o);
}

// SPDX-License-Identifier: MIT
// `study error-vs-time` on a 3D scene (studies/error_vs_time3.cpp), block3d: with the reference
// on the grid's finest level the reference row measures 0 against itself and the other exact
// rows agree with it to the Newton tolerance; the errors fall with the level; bad options are
// refused.
#include "core/check.hpp"
#include "scene/scene3.hpp"
#include "studies/error_vs_time.hpp"
#include "tests/common/files.hpp"

#include <gtest/gtest.h>

#include <map>
#include <sstream>
#include <string>
#include <utility>

using namespace mlc;

namespace {

struct Evt3Row {
    bool converged = false;
    double energy = -1.0, traction = -1.0;
    int newton = 0;
};

/// error_vs_time.csv: configuration -> level -> row.
std::map<std::string, std::map<int, Evt3Row>> evt3_rows(const std::filesystem::path& csv) {
    std::istringstream in(testutil::slurp(csv));
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line, "configuration,level,unknowns,seconds,converged,energy_error,traction_error,"
                    "closed_form_error,primary_error,newton,krylov,pareto");
    std::map<std::string, std::map<int, Evt3Row>> rows;
    while (std::getline(in, line)) {
        const auto q = line.find('"', 1);
        const std::string name = line.substr(1, q - 1);
        std::stringstream rest(line.substr(q + 2));
        std::vector<std::string> f;
        for (std::string cell; std::getline(rest, cell, ',');)
            f.push_back(cell);
        Evt3Row r{f.at(3) == "1", std::stod(f.at(4)), std::stod(f.at(5)), std::stoi(f.at(8))};
        EXPECT_EQ(f.at(6), "-1") << line; // no closed form in 3D
        EXPECT_EQ(std::stod(f.at(7)), r.energy) << line;
        rows[name][std::stoi(f.at(0))] = r;
    }
    return rows;
}

} // namespace

TEST(ErrorVsTime3, ReferenceRowIsExactAgainstItselfAndErrorsFallWithTheLevel) {
    apps::ErrorVsTimeOptions opt;
    opt.max_level = 1;
    opt.reference_offset = 0; // reference: c2f lu on level 1
    opt.plot = false;
    opt.out = testutil::scratch_dir("evt3");
    std::ostringstream log;
    ASSERT_EQ(apps::study_error_vs_time3(scene::load_scene3("block3d"), opt, log), 0) << log.str();
    const auto rows = evt3_rows(opt.out / "error_vs_time.csv");
    ASSERT_EQ(rows.size(), 6u) << log.str();
    for (const auto& [name, levels] : rows) {
        const bool mg = name.find("mg") != std::string::npos;
        ASSERT_EQ(levels.size(), mg ? 1u : 2u) << name; // mg from level 1
        for (const auto& [l, r] : levels)
            ASSERT_TRUE(r.converged) << name << " level " << l << "\n" << log.str();
        // Level 1 is the reference's level: every solver reaches the same discrete solution
        // (Newton tolerance 1e-10), the reference configuration exactly (the same solve).
        const Evt3Row& top = levels.at(1);
        if (name == "c2f lu") {
            EXPECT_EQ(top.energy, 0.0) << log.str();
            EXPECT_EQ(top.traction, 0.0) << log.str();
        } else {
            EXPECT_LE(top.energy, 1e-7) << name;
            EXPECT_LE(top.traction, 1e-6) << name;
        }
        if (!mg) {
            // Level 0 against level 1, the same for every exact solver (measured 0.1441
            // energy, 0.2643 traction).
            EXPECT_NEAR(levels.at(0).energy, 0.1441, 0.001) << name;
            EXPECT_NEAR(levels.at(0).traction, 0.2643, 0.001) << name;
        }
    }
}

TEST(ErrorVsTime3, ErrorsAgainstAFinerReferenceFallWithTheLevel) {
    apps::ErrorVsTimeOptions opt;
    opt.max_level = 1;
    opt.reference_offset = 1; // reference: c2f lu on level 2
    opt.only = "c2f";
    opt.plot = false;
    opt.out = testutil::scratch_dir("evt3_finer");
    std::ostringstream log;
    ASSERT_EQ(apps::study_error_vs_time3(scene::load_scene3("block3d"), opt, log), 0) << log.str();
    const auto rows = evt3_rows(opt.out / "error_vs_time.csv");
    ASSERT_EQ(rows.size(), 3u) << log.str();
    for (const auto& [name, levels] : rows) {
        ASSERT_TRUE(levels.count(1)) << name;
        ASSERT_TRUE(levels.at(1).converged) << name;
        EXPECT_GT(levels.at(1).energy, 1e-3) << name;
        if (levels.count(0)) {
            EXPECT_LT(levels.at(1).energy, 0.7 * levels.at(0).energy) << name;
            EXPECT_LT(levels.at(1).traction, levels.at(0).traction) << name;
        }
    }
}

// The reference: the sparse LU where it fits, else the multigrid. On block3d with 24 GiB the LU
// fits on level 3 (about 3.6 GiB) and not on level 4 (about 200 GiB); 10 MiB fits neither.
TEST(ErrorVsTime3, TheReferenceIsTheSparseLuWhereItFits) {
    const auto block = scene::load_scene3("block3d");
    const double gib = 1024.0 * 1024.0 * 1024.0;
    const levels::MemoryLimit big{24 * gib, "test"}, small{10.0 * 1024 * 1024, "test"};
    EXPECT_TRUE(apps::lu_reference_fits3(block, 2, big));
    EXPECT_TRUE(apps::lu_reference_fits3(block, 3, big));
    EXPECT_FALSE(apps::lu_reference_fits3(block, 4, big));
    EXPECT_FALSE(apps::lu_reference_fits3(block, 2, small));
}

TEST(ErrorVsTime3, BadOptionsAndScenesWithoutContactAreRefused) {
    auto refused = [](const levels::ElasticProblem3& p, const apps::ErrorVsTimeOptions& o) {
        std::ostringstream log;
        try {
            apps::study_error_vs_time3(p, o, log);
        } catch (const InvalidInput& e) {
            return std::string(e.what());
        }
        return std::string("not refused");
    };
    const auto block = scene::load_scene3("block3d");
    apps::ErrorVsTimeOptions o;
    o.plot = false;
    o.out = testutil::scratch_dir("evt3_refused");
    o.max_level = 4;
    EXPECT_NE(refused(block, o).find("--levels between 0 and 3, found 4"), std::string::npos)
        << refused(block, o);
    o.max_level = 0;
    o.reference_offset = 3;
    EXPECT_NE(refused(block, o).find("reference offset must be 0, 1 or 2, found 3"),
              std::string::npos)
        << refused(block, o);
    o.reference_offset = 0;
    EXPECT_NE(refused(scene::load_scene3("box3d"), o).find("'box3d' has no contact"),
              std::string::npos)
        << refused(scene::load_scene3("box3d"), o);
}

// SPDX-License-Identifier: MIT
// `bench elastic` on a 3D scene: both solvers converge to the same solution and the JSON holds
// finite numbers, the unknowns the hierarchy has and the predicted memory.
#include "bench/bench.hpp"
#include "levels/elastic3d_levels.hpp"
#include "scene/scene3.hpp"
#include "solvers/hypre/boomeramg.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <unistd.h>

using namespace mlc;

TEST(BenchElastic3d, Box3dLevel2WritesFiniteFigures) {
    if (!solvers::have_hypre()) GTEST_SKIP() << "built without hypre";
    apps::BenchElasticOptions o;
    o.scene = "box3d";
    o.levels = 2;
    o.out = std::filesystem::path(::testing::TempDir()) /
            ("mlc_bench3d_" + std::to_string(::getpid()) + ".json");
    std::ostringstream os;
    EXPECT_EQ(apps::bench_elastic(o, os), 0) << os.str();
    std::ifstream in(o.out);
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string js = ss.str();
    std::filesystem::remove(o.out);
    // 17 x 17 x 9 vertices less the 17 x 17 held on zmin, 3 components each.
    const long n = 3 * (17 * 17 * 9 - 17 * 17);
    EXPECT_NE(js.find("\"unknowns\": " + std::to_string(n)), std::string::npos) << js;
    EXPECT_NE(js.find("\"dimension\": 3"), std::string::npos);
    for (const char* key :
         {"\"solver\": \"mg-cg\"", "\"solver\": \"boomeramg-pcg\"", "\"time_ratio_mg_over_amg\"",
          "\"memory_estimate_mib\"", "\"peak_rss_mib\""})
        EXPECT_NE(js.find(key), std::string::npos) << key;
    // Every number finite (no nan or inf written), both solvers converged.
    EXPECT_EQ(js.find("nan"), std::string::npos) << js;
    EXPECT_EQ(js.find("inf"), std::string::npos) << js;
    EXPECT_EQ(js.find("\"converged\": false"), std::string::npos) << js;
    const std::regex diff("\"solution_difference\": ([0-9.e+-]+)");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(js, m, diff)) << js;
    EXPECT_LT(std::stod(m[1]), 1e-6);
    const std::regex its("\"iterations\": ([0-9]+)");
    int count = 0;
    for (auto it = std::sregex_iterator(js.begin(), js.end(), its); it != std::sregex_iterator();
         ++it, ++count) {
        EXPECT_GE(std::stoi((*it)[1]), 1);
        EXPECT_LE(std::stoi((*it)[1]), 30);
    }
    EXPECT_EQ(count, 2);
}

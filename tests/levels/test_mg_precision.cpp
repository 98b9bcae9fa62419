// SPDX-License-Identifier: MIT
// `mg:precision=single` (smoother matrices, block inverses and transfers stored as float,
// vectors and Krylov double): the same converged solution as the double-precision mg to 1e-8
// relative on the square (level 3) and hertz (level 2), with every Newton system's Krylov
// iteration count within one of double's, and fewer smoother and transfer bytes.
#include "core/check.hpp"
#include "core/traffic.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"

#include <gtest/gtest.h>

#include <string>

using namespace mlc;
using namespace mlc::levels;

namespace {

struct Run {
    RunResult result;
    traffic::Account bytes; // of the whole run
};

Run run(const std::string& scene, int levels, const std::string& pc) {
    auto p = scene::load_scene(scene);
    p.levels = levels;
    SolveOptions so;
    so.linear = {.method = solvers::Method::krylov,
                 .krylov = solvers::Krylov::cgs,
                 .pc = solvers::parse_pc(pc),
                 .rel_tol = 1e-8,
                 .max_iter = 200};
    const traffic::Account a0 = traffic::snapshot();
    Run r{solve(p, so), {}};
    r.bytes = traffic::snapshot() - a0;
    return r;
}

// Same Newton history level by level, Krylov iterations per Newton system within +1, and the
// same solution to 1e-8 relative.
void expect_like_double(const std::string& scene, int levels) {
    const Run d = run(scene, levels, "mg");
    const Run s = run(scene, levels, "mg:precision=single");
    ASSERT_TRUE(d.result.converged) << d.result.failure;
    ASSERT_TRUE(s.result.converged) << s.result.failure;
    EXPECT_LT((s.result.x - d.result.x).norm(), 1e-8 * d.result.x.norm()) << scene;
    ASSERT_EQ(s.result.level_steps.size(), d.result.level_steps.size());
    int systems = 0;
    for (size_t l = 0; l < d.result.level_steps.size(); ++l) {
        ASSERT_EQ(s.result.level_steps[l].size(), d.result.level_steps[l].size()) << l;
        for (size_t k = 0; k < d.result.level_steps[l].size(); ++k) {
            const auto& its_d = d.result.level_steps[l][k].report.linear_iterations_per_newton;
            const auto& its_s = s.result.level_steps[l][k].report.linear_iterations_per_newton;
            ASSERT_EQ(its_s.size(), its_d.size()) << scene << " level " << l << " step " << k;
            for (size_t i = 0; i < its_d.size(); ++i) {
                EXPECT_LE(its_s[i], its_d[i] + 1)
                    << scene << " level " << l << " step " << k << " Newton " << i;
                ++systems;
            }
        }
    }
    EXPECT_GT(systems, 0);
    // The smoother and the transfers moved fewer bytes per pass (values 4 bytes instead of 8).
    for (const auto kind : {traffic::Kind::smoother, traffic::Kind::transfer}) {
        ASSERT_GT(d.bytes.p(kind), 0.0);
        ASSERT_GT(s.bytes.p(kind), 0.0);
        EXPECT_LT(s.bytes.b(kind) / s.bytes.p(kind), 0.9 * d.bytes.b(kind) / d.bytes.p(kind))
            << traffic::to_string(kind);
    }
    ASSERT_TRUE(s.result.multigrid.has_value());
    EXPECT_NE(s.result.multigrid->smoother.find("single-precision"), std::string::npos);
    EXPECT_EQ(d.result.multigrid->smoother.find("single-precision"), std::string::npos);
}

} // namespace

TEST(SinglePrecisionMultigrid, SquareLevel3LikeDouble) {
    expect_like_double("square", 3);
}

TEST(SinglePrecisionMultigrid, HertzLevel2LikeDouble) {
    expect_like_double("hertz", 2);
}

TEST(SinglePrecisionMultigrid, RefusesAnUnknownPrecision) {
    // Refused where the text is read, before any level is built, naming the valid ones.
    try {
        (void)solvers::parse_pc("mg:precision=half");
        ADD_FAILURE() << "precision=half accepted";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("valid double, single"), std::string::npos)
            << e.what();
    }
}

// SPDX-License-Identifier: MIT
// Hertz contact (benchmarks.md `hertz`): half-width and pressure against the closed form.
#include "run/closed_form.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"

#include <gtest/gtest.h>

using namespace mlc;

TEST(Hertz, ClosedFormValuesOfTheScene) {
    const apps::Hertz h{.P = 8.6307e-3, .R = 1.0, .E_star = 1.0 / (1.0 - 0.09)};
    EXPECT_NEAR(h.half_width(), 0.1, 1e-5);
    EXPECT_NEAR(h.peak_pressure(), 0.054945, 1e-5);
    // The scene's top traction carries P / 2 on the half model.
    const auto p = scene::load_scene("hertz");
    const auto L = levels::build_level(p, p.mesh0);
    double fy = 0;
    for (int v = 0; v < L.mesh.n_vertices(); ++v)
        fy += L.elastic.f_nodal_full[2 * v + 1];
    EXPECT_NEAR(fy, -h.P / 2, 1e-9);
}

TEST(Hertz, HalfWidthAndPeakPressureConvergeToTheClosedForm) {
    const apps::Hertz h{.P = 8.6307e-3, .R = 1.0, .E_star = 1.0 / (1.0 - 0.09)};
    auto p = scene::load_scene("hertz");
    std::vector<apps::HertzErrors> err;
    for (int level : {0, 1, 2}) {
        p.levels = level;
        const auto r = levels::solve(p);
        ASSERT_TRUE(r.converged) << r.failure;
        const auto prof = apps::pressure_profile(r.nodes);
        err.push_back(apps::compare(prof, h));
        // The discrete half-width is only known to half a node spacing.
        EXPECT_LE(std::abs(prof.half_width - h.half_width()),
                  0.5 * prof.edge_spacing + 0.01 * h.half_width())
            << "level " << level;
    }
    EXPECT_LT(std::abs(err[2].half_width), 0.05);
    EXPECT_LT(std::abs(err[2].peak), 0.05);
    EXPECT_LT(std::abs(err[2].half_width), std::abs(err[0].half_width));
    EXPECT_LT(std::abs(err[2].peak), std::abs(err[0].peak));
    EXPECT_LT(err[2].profile_rms, err[0].profile_rms);
    EXPECT_LT(err[2].profile_rms, 0.03);
}

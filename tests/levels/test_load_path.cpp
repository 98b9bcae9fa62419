// SPDX-License-Identifier: MIT
// Loading paths: proportional loading unchanged, per-step prescribed values and load factors
// interpolated between path points.
#include "levels/checks.hpp"
#include "levels/level.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"

#include <gtest/gtest.h>

using namespace mlc;

TEST(LoadPath, ProportionalLoadingIsTheLoadFactorTimesTheFullLoad) {
    const auto p = scene::load_scene("square");
    ASSERT_EQ(p.n_path_points(), 1);
    const auto L = levels::build_level(p, p.mesh0);
    for (double s : {0.0, 0.2, 0.6, 1.0}) {
        // Bit for bit: s * (the full-load vectors).
        EXPECT_EQ(L.f_at(s), (s * L.elastic.f).eval());
        EXPECT_EQ(L.u_fixed_at(s), (s * L.u_fixed).eval());
        EXPECT_EQ(L.f_nodal_at(s), (s * L.elastic.f_nodal_full).eval());
    }
}

TEST(LoadPath, PerStepValuesAreReachedAtTheirPathPoints) {
    // mindlin: platen u = (0, -d_n) at step 1, (d_t, -d_n) at step 2.
    const auto p = scene::load_scene("mindlin");
    ASSERT_EQ(p.n_path_points(), 2);
    const auto L = levels::build_level(p, p.mesh0);
    const int v = L.mesh.nearest_vertex(Vec2(0.5, 1.0)); // on the platen
    const double dn = 1.85e-2, dt = 4.35e-3;
    EXPECT_DOUBLE_EQ(L.u_fixed_at(0.5)[2 * v], 0.0);
    EXPECT_DOUBLE_EQ(L.u_fixed_at(0.5)[2 * v + 1], -dn);
    EXPECT_DOUBLE_EQ(L.u_fixed_at(1.0)[2 * v], dt);
    EXPECT_DOUBLE_EQ(L.u_fixed_at(1.0)[2 * v + 1], -dn);
    // Linear in between (s = 0.25: half of step 1; s = 0.75: half of step 2).
    EXPECT_DOUBLE_EQ(L.u_fixed_at(0.25)[2 * v + 1], -0.5 * dn);
    EXPECT_DOUBLE_EQ(L.u_fixed_at(0.75)[2 * v], 0.5 * dt);
    EXPECT_DOUBLE_EQ(L.u_fixed_at(0.75)[2 * v + 1], -dn);
    // The load on the unknowns is the lifting of the prescribed values: K_(free,fixed) u_fixed.
    const Vector f_mid = L.f_at(0.5);
    EXPECT_GT(f_mid.norm(), 0.0);
    EXPECT_LT((L.f_at(0.75) - 0.5 * (f_mid + L.f_at(1.0))).norm(), 1e-14 * L.f_at(1.0).norm());
}

TEST(LoadPath, LoadFactorsScaleTractionsPerStep) {
    // square with the top pressure applied in the first step only and the side pressure in
    // the second: factors [1, 1] and [0, 1].
    std::string text = scene::builtin_scene_text("square");
    auto put = [&](const std::string& from, const std::string& to) {
        const auto pos = text.find(from);
        ASSERT_NE(pos, std::string::npos) << from;
        text.replace(pos, from.size(), to);
    };
    put("load_steps = 5", "load_steps = 2");
    put("pressure = 50.0", "pressure = 50.0\nfactors = [1.0, 1.0]");
    put("pressure = 150.0", "pressure = 150.0\nfactors = [0.0, 1.0]");
    auto p = scene::parse_scene(text, "staged.toml");
    ASSERT_EQ(p.n_path_points(), 2);
    const auto L = levels::build_level(p, p.mesh0);
    double fx = 0, fy = 0;
    const Vector F = L.f_nodal_at(0.5);
    for (int v = 0; v < L.mesh.n_vertices(); ++v) {
        fx += F[2 * v];
        fy += F[2 * v + 1];
    }
    EXPECT_NEAR(fx, 0.0, 1e-9);          // the side pressure is not applied yet
    EXPECT_NEAR(fy, -50.0 * 40.0, 1e-9); // the top pressure is
    const auto r = levels::solve(p);
    ASSERT_TRUE(r.converged) << r.failure;
    EXPECT_LT(levels::force_balance_error(r.finest(), 1.0, r.u_full, r.nodes), 1e-12);
}

// SPDX-License-Identifier: MIT
// Loading paths: proportional loading unchanged, per-step prescribed values and load factors
// interpolated between path points.
#include "core/first_touch.hpp"
#include "levels/checks.hpp"
#include "levels/level.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

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

TEST(LoadPath, ValuesOverTheThreadsAreTheWholeVectorExpressionsBitForBit) {
    // Level::u_fixed_at writes chunks of the vector over the threads (core/first_touch); each
    // chunk evaluates the same elementwise expression, so the values are those of the whole
    // vector's, here on vectors of several chunks with random entries.
    const auto p = scene::load_scene("mindlin");
    auto L = levels::build_level(p, p.mesh0);
    const Index n = 5 * static_cast<Index>(parallel::kTouchRowsPerChunk) + 11;
    const Vector a = Vector::Random(n), b = Vector::Random(n);
    L.path_u_fixed = {a, b};
    L.u_fixed = b;
    Vector out = Vector::Constant(7, 3.0); // resized
    for (double s : {0.0, 0.3, 0.5, 0.75, 0.9, 1.0}) {
        const double t = 2.0 * s;
        const int k = std::clamp(static_cast<int>(std::floor(t)), 0, 1);
        const double theta = t - k;
        const Vector want = k == 0 ? Vector(theta * a) : Vector((1.0 - theta) * a + theta * b);
        L.u_fixed_at(s, out);
        EXPECT_EQ(out, want) << "s = " << s;
        EXPECT_EQ(L.u_fixed_at(s), want) << "s = " << s;
    }
    L.path_u_fixed.clear(); // proportional: s * u_fixed
    L.u_fixed_at(0.6, out);
    EXPECT_EQ(out, (0.6 * b).eval());
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

namespace {
levels::RunResult solve_with(levels::Problem p, int levels_, int steps, bool extrapolate) {
    p.levels = levels_;
    p.load_steps = steps;
    levels::SolveOptions so;
    so.extrapolate = extrapolate;
    return levels::solve(p, so);
}
double relative_difference(const Vector& a, const Vector& b) {
    return (a - b).norm() / b.norm();
}
} // namespace

TEST(Extrapolation, LinearLoadStepsAreTakenWithoutANewtonIteration) {
    // The square's statuses are those of step 1 in every later step (proportional loading):
    // each later step is linear, so 2 x^(k-1) - x^(k-2) is its solution to round-off.
    const auto p = scene::load_scene("square");
    const auto plain = solve_with(p, 2, 5, false);
    const auto extra = solve_with(p, 2, 5, true);
    ASSERT_TRUE(plain.converged && extra.converged);
    for (int l = 0; l <= 2; ++l)
        for (int k = 0; k < 5; ++k) {
            const auto& a = plain.level_steps[l][k].report;
            const auto& b = extra.level_steps[l][k].report;
            EXPECT_GE(a.iterations, 1) << "level " << l << " step " << k + 1;
            // Step 1 as without; steps 2.. converged at the extrapolated state.
            EXPECT_EQ(b.iterations, k == 0 ? a.iterations : 0)
                << "level " << l << " step " << k + 1;
            EXPECT_TRUE(b.converged);
            EXPECT_LE(b.residuals.back(), 1e-10);
        }
    EXPECT_LT(relative_difference(extra.x, plain.x), 1e-9);
    EXPECT_LT(relative_difference(extra.u_full, plain.u_full), 1e-12);
}

TEST(Extrapolation, StepsWhoseStatusesChangeStartFromTheUsualGuess) {
    // hertz in 4 steps: the contact zone grows with the load, so statuses change in every step
    // and the extrapolated state is not converged: each step takes the iterations it takes
    // without the option, from the same guess, and ends at the same state.
    const auto p = scene::load_scene("hertz");
    const auto plain = solve_with(p, 1, 4, false);
    const auto extra = solve_with(p, 1, 4, true);
    ASSERT_TRUE(plain.converged && extra.converged);
    for (int l = 0; l <= 1; ++l)
        for (int k = 0; k < 4; ++k) {
            // Level 0 starts from the previous step: its statuses change over every step.
            if (l == 0) {
                EXPECT_GE(plain.level_steps[l][k].report.iterations, 2);
            }
            EXPECT_EQ(extra.level_steps[l][k].report.iterations,
                      plain.level_steps[l][k].report.iterations)
                << "level " << l << " step " << k + 1;
        }
    EXPECT_EQ(extra.x, plain.x);
}

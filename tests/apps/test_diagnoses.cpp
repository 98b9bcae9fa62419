// SPDX-License-Identifier: MIT
// The diagnoses that name a cause (levels/diagnoses.hpp), on exact cases: rigid motions of a
// block under its supports, rotations and strains of linear displacement fields, the force
// balance of a state with no force, and the user part of a check's message.
#include "core/check.hpp"
#include "core/user_message.hpp"
#include "levels/checks.hpp"
#include "levels/diagnoses.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace mlc;

namespace {

/// A 2 x 1 block on a floor; `supports` is the TOML of its [[support]] tables.
levels::Problem block(const std::string& supports, double top_pressure = 0.01) {
    const std::string text = R"(
[scene]
name = "block"
[[body]]
name = "block"
E = 1.0
nu = 0.3
mesh = { type = "rectangle", corner = [0.0, 0.0], size = [2.0, 1.0], divisions = [4, 2] }
[[load]]
tag = "top"
pressure = )" + std::to_string(top_pressure) +
                             R"(
[[contact]]
contactor = "bottom"
mu = 0.3
obstacle = { type = "line", point = [0.0, 0.0], normal = [0.0, 1.0] }
)" + supports;
    return scene::parse_scene(text, "block");
}

levels::Level level0(const levels::Problem& p) {
    return levels::build_level(p, p.mesh0);
}

} // namespace

TEST(Diagnoses, FreeRigidMotionsAreThoseNoSupportHolds) {
    // No support: all three. ux on the left face: the vertical translation only. ux on the left
    // face and uy at one point: none. One point held in x and y: the rotation about it.
    EXPECT_EQ(levels::free_rigid_motions(level0(block("")))[0].basis.size(), 3u);
    const auto ux =
        levels::free_rigid_motions(level0(block("[[support]]\ntag = \"left\"\nux = 0.0\n")));
    ASSERT_EQ(ux[0].basis.size(), 1u);
    EXPECT_NEAR(std::abs(ux[0].basis[0][1]), 1.0, 1e-12);
    EXPECT_EQ(ux[0].describe(ux[0].basis[0]).rfind("translation along (0, ", 0), 0u);
    EXPECT_TRUE(levels::free_rigid_motions(
                    level0(block("[[support]]\ntag = \"left\"\nux = 0.0\n[[support]]\npoint = "
                                 "[2.0, 1.0]\nuy = 0.0\n")))[0]
                    .basis.empty());
    const auto pin = levels::free_rigid_motions(
        level0(block("[[support]]\npoint = [2.0, 1.0]\nux = 0.0\nuy = 0.0\n")));
    ASSERT_EQ(pin[0].basis.size(), 1u);
    EXPECT_EQ(pin[0].describe(pin[0].basis[0]), "rotation about (2, 1)");
}

TEST(Diagnoses, NoEquilibriumOnlyWhenTheLoadPullsOffWhatNothingElseHolds) {
    const std::string ux = "[[support]]\ntag = \"left\"\nux = 0.0\n";
    // Suction on the top: no equilibrium; pressure: equilibrium possible; held in y too: none.
    const auto pulled = block(ux, -0.01);
    EXPECT_NE(levels::no_equilibrium(pulled, level0(pulled), 1.0).find("translation along (0, 1)"),
              std::string::npos);
    const auto pressed = block(ux, 0.01);
    EXPECT_EQ(levels::no_equilibrium(pressed, level0(pressed), 1.0), "");
    const auto held = block(ux + "[[support]]\npoint = [2.0, 1.0]\nuy = 0.0\n", -0.01);
    EXPECT_EQ(levels::no_equilibrium(held, level0(held), 1.0), "");
}

TEST(Diagnoses, RotationAndStrainOfLinearFieldsAreExact) {
    const auto p = block("");
    const auto L = level0(p);
    const int nv = L.mesh.n_vertices();
    // A rotation by theta (linearised): u = theta (-y, x): rotation theta, no strain.
    Vector u(2 * nv);
    for (int v = 0; v < nv; ++v) {
        const Vec2& x = L.mesh.vertices[static_cast<size_t>(v)];
        u[2 * v] = -0.2 * x.y();
        u[2 * v + 1] = 0.2 * x.x();
    }
    auto d = levels::max_deformation(L, u);
    EXPECT_NEAR(d.rotation, 0.2, 1e-14);
    EXPECT_NEAR(d.strain, 0.0, 1e-14);
    // Pure shear eps_xy = 0.03 (u = (0.03 y, 0.03 x)): principal strains +-0.03, no rotation.
    for (int v = 0; v < nv; ++v) {
        const Vec2& x = L.mesh.vertices[static_cast<size_t>(v)];
        u[2 * v] = 0.03 * x.y();
        u[2 * v + 1] = 0.03 * x.x();
    }
    d = levels::max_deformation(L, u);
    EXPECT_NEAR(d.rotation, 0.0, 1e-14);
    EXPECT_NEAR(d.strain, 0.03, 1e-14);
}

TEST(Diagnoses, ForceBalanceOfARigidMotionIsNotApplicable) {
    // The block moved rigidly by the same prescribed displacement of its left and right faces,
    // no load, no contact: no force anywhere but round-off.
    auto p = block("[[support]]\ntag = \"left\"\nux = 0.3\nuy = 0.2\n[[support]]\ntag = "
                   "\"right\"\nux = 0.3\nuy = 0.2\n",
                   0.0);
    p.contacts.clear();
    const levels::RunResult r = levels::solve(p, {});
    ASSERT_TRUE(r.converged) << r.failure;
    EXPECT_FALSE(levels::check_state(p, r).force_balance_applicable);
    // Pressed on a floor: applicable, and small.
    const auto q = block("[[support]]\ntag = \"left\"\nux = 0.0\n");
    const levels::RunResult s = levels::solve(q, {});
    ASSERT_TRUE(s.converged) << s.failure;
    const auto c = levels::check_state(q, s);
    EXPECT_TRUE(c.force_balance_applicable);
    EXPECT_LT(c.force_balance, 1e-12);
}

TEST(Diagnoses, ROutOfScaleNamesTheRatio) {
    EXPECT_EQ(levels::r_out_of_scale(0.1, 1.0), "");
    EXPECT_EQ(levels::r_out_of_scale(1e-6, 1.0), "");
    EXPECT_NE(levels::r_out_of_scale(1e-7, 1.0).find("r = 1e-07 is 1e-07 times E = 1"),
              std::string::npos);
    EXPECT_NE(levels::r_out_of_scale(2e7, 10.0).find("is 2e+06 times E = 10"), std::string::npos);
}

TEST(UserMessage, DropsEveryCheckLocationAndKeepsThemApart) {
    try {
        MLC_CHECK(1 + 1 == 3, "one plus one is two");
        FAIL();
    } catch (const InvalidInput& e) {
        const std::string wrapped = std::string("E: body 'b': ") + e.what() + "; and more";
        std::string where;
        EXPECT_EQ(user_message(wrapped, &where), "E: body 'b': one plus one is two; and more");
        EXPECT_EQ(where.rfind("check `1 + 1 == 3` in ", 0), 0u) << where;
        EXPECT_NE(where.find("test_diagnoses.cpp:"), std::string::npos) << where;
    }
    // Brackets inside the condition, two locations, and text that only looks like one.
    std::string where;
    EXPECT_EQ(
        user_message("a [check `v[0] > 0` in f, x.cpp:12] b [check `y` in g, y.cpp:3]", &where),
        "a b");
    EXPECT_EQ(where, "check `v[0] > 0` in f, x.cpp:12; check `y` in g, y.cpp:3");
    EXPECT_EQ(user_message("range [0, 12] [check `no end"), "range [0, 12] [check `no end");
}

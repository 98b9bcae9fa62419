// SPDX-License-Identifier: MIT
// Supports that hold a contact node's tangential or normal displacement (tests/data/redundant):
// the matching multiplier is pinned to zero on every level, the Newton systems stay regular, and
// the assembled LU, the multigrid without fallback and the cold start give one answer; a scene
// whose support and contact frame share a direction only in part is refused.
#include "core/check.hpp"
#include "levels/checks.hpp"
#include "levels/solve.hpp"
#include "run/run.hpp"
#include "scene/scene.hpp"
#include "scene/scene3.hpp"
#include "tests/common/scene_text.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

using namespace mlc;

namespace {

constexpr unsigned char kT = contact::ContactElement::kPinnedT;
constexpr unsigned char kN = contact::ContactElement::kPinnedN;

std::string data_file(const std::string& name) {
    return std::string(MLC_TEST_DATA_DIR) + "/redundant/" + name;
}

std::string text_of(const std::string& name) {
    std::ifstream f(data_file(name));
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

/// The driver's solve of `p` on `level` (apps::run_solve_options): "lu", "mg" (BiCGStab + the
/// default multigrid, no exact fallback, Krylov tolerance 1e-12) or "cold" (mg, no
/// coarse-to-fine); Newton tolerance 1e-12.
levels::RunResult run(levels::Problem p, int level, const std::string& how) {
    apps::RunOptions opt;
    opt.levels = level;
    if (how == "lu") {
        opt.linear = "lu";
    } else {
        opt.pc = "mg";
        opt.krylov = "bicgstab";
        opt.linear_rel_tol = 1e-12;
        opt.no_fallback = true;
        opt.cold = how == "cold";
    }
    p.newton.rel_tol = 1e-12;
    apps::apply_overrides(p, opt);
    levels::SolverPlan choice;
    const auto so = apps::run_solve_options(p, opt, choice);
    return levels::solve(p, so);
}

int fallbacks(const levels::RunResult& r) {
    int n = 0;
    for (const auto& steps : r.level_steps)
        for (const auto& s : steps)
            n += s.report.fallback_solves;
    return n;
}

const levels::ContactNodeState& node_at(const levels::RunResult& r, Vec2 x) {
    for (const auto& n : r.nodes)
        if ((n.x - x).norm() < 1e-12) return n;
    ADD_FAILURE() << "no contact node at (" << x.x() << ", " << x.y() << ")";
    return r.nodes.front();
}

/// a and b: the same contact nodes, statuses equal, u and lambda equal to 1e-8 of their scale.
void expect_same(const levels::RunResult& a, const levels::RunResult& b, const std::string& what) {
    ASSERT_EQ(a.nodes.size(), b.nodes.size()) << what;
    double us = 0, ls = 0;
    for (const auto& n : a.nodes) {
        us = std::max(us, n.u.cwiseAbs().maxCoeff());
        ls = std::max({ls, std::abs(n.lambda_t), std::abs(n.lambda_n)});
    }
    ASSERT_GT(us, 0) << what;
    ASSERT_GT(ls, 0) << what;
    for (size_t i = 0; i < a.nodes.size(); ++i) {
        const auto &p = a.nodes[i], &q = b.nodes[i];
        ASSERT_EQ(p.vertex, q.vertex) << what;
        EXPECT_EQ(p.status, q.status) << what << " at (" << p.x.x() << ", " << p.x.y() << ")";
        EXPECT_LE((p.u - q.u).cwiseAbs().maxCoeff(), 1e-8 * us) << what;
        EXPECT_LE(std::abs(p.lambda_t - q.lambda_t), 1e-8 * ls) << what;
        EXPECT_LE(std::abs(p.lambda_n - q.lambda_n), 1e-8 * ls) << what;
    }
    const double da = (a.u_full - b.u_full).cwiseAbs().maxCoeff();
    EXPECT_LE(da, 1e-8 * a.u_full.cwiseAbs().maxCoeff()) << what;
}

/// The pinned masks of a level's elements, by contactor position.
std::vector<std::pair<Vec2, unsigned char>> pinned_of(const levels::Problem& p, int level) {
    mesh::Mesh m = p.mesh0;
    for (int l = 0; l < level; ++l)
        m = mesh::refine(m);
    const auto L = levels::build_level(p, m);
    std::vector<std::pair<Vec2, unsigned char>> out;
    for (const auto& e : L.contacts)
        if (e.pinned) out.emplace_back(L.mesh.vertices[static_cast<size_t>(e.vertex[0])], e.pinned);
    return out;
}

/// The held corner's run on levels first..last: statuses and values as expected, the same by
/// every solver.
void check_scene(const levels::Problem& p, Vec2 held, int first, int last) {
    for (int level = first; level <= last; ++level) {
        const auto lu = run(p, level, "lu");
        ASSERT_TRUE(lu.converged) << lu.failure;
        const auto& h = node_at(lu, held);
        EXPECT_EQ(h.status, contact::Status::stick);
        EXPECT_EQ(h.lambda_t, 0.0); // exactly: its support takes the tangential reaction
        EXPECT_LT(h.lambda_n, 0.0);
        const auto c = levels::check_state(p, lu);
        EXPECT_LT(c.force_balance, 1e-10);
        EXPECT_LT(c.coulomb_excess, 1e-8);
        EXPECT_LT(c.penetration, 1e-8);
        for (const std::string how : {"mg", "cold"}) {
            const auto r = run(p, level, how);
            ASSERT_TRUE(r.converged) << how << " level " << level << ": " << r.failure;
            EXPECT_EQ(fallbacks(r), 0) << how << " level " << level;
            expect_same(lu, r, how + " level " + std::to_string(level));
            EXPECT_EQ(node_at(r, held).lambda_t, 0.0) << how;
        }
    }
}

} // namespace

TEST(HeldSupports, OnlyTheContactCornerHeldInUxIsPinned) {
    const auto sq2 = scene::load_scene(data_file("square_held_corner.toml"));
    for (int level : {0, 2}) {
        const auto pins = pinned_of(sq2, level);
        ASSERT_EQ(pins.size(), 1u) << "level " << level;
        EXPECT_EQ(pins[0].first, Vec2(40.0, 0.0));
        EXPECT_EQ(pins[0].second, kT);
    }
    // No built-in scene pins anything: the square's fully held corner is no contact node,
    // axis_release's axis node has a free target (the block), hertz is frictionless (lambda_n
    // alone, along the free u_y).
    for (const auto& name : scene::builtin_scene_names())
        if (scene::scene_dimension(name) == 2) { // 3D scenes have no contact
            EXPECT_TRUE(pinned_of(scene::load_scene(name), 0).empty()) << name;
        }
    EXPECT_TRUE(pinned_of(scene::load_scene("square"), 1).empty());
    const auto hf = pinned_of(scene::load_scene(data_file("hertz_friction.toml")), 1);
    ASSERT_EQ(hf.size(), 1u);
    EXPECT_EQ(hf[0].first, Vec2(0.0, 0.0));
    EXPECT_EQ(hf[0].second, kT);
}

TEST(HeldSupports, SquareWithItsContactCornerHeldInUxSolvesAlikeByEverySolver) {
    check_scene(scene::load_scene(data_file("square_held_corner.toml")), Vec2(40.0, 0.0), 1, 2);
}

TEST(HeldSupports, BlockOnAFloorWithItsLeftFaceHeldSolvesAlikeByEverySolver) {
    check_scene(scene::load_scene(data_file("block_floor.toml")), Vec2(0.0, 0.0), 1, 2);
}

TEST(HeldSupports, FrictionalHertzHalfModelCarriesTheLoadAndSolvesAlikeByEverySolver) {
    const auto p = scene::load_scene(data_file("hertz_friction.toml"));
    check_scene(p, Vec2(0.0, 0.0), 1, 1);
    // The contact carries the whole vertical load (the axis support holds u_x only): P / 2.
    const auto r = run(p, 1, "lu");
    ASSERT_TRUE(r.converged) << r.failure;
    const Vec2 f = levels::contact_resultant(r, 0);
    EXPECT_NEAR(f.y(), 4.31535e-3, 1e-10);
}

TEST(HeldSupports, FinerLevelsOfTheThreeScenesSolveAlikeByEverySolver_Slow) {
    check_scene(scene::load_scene(data_file("square_held_corner.toml")), Vec2(40.0, 0.0), 3, 3);
    check_scene(scene::load_scene(data_file("block_floor.toml")), Vec2(0.0, 0.0), 3, 3);
    check_scene(scene::load_scene(data_file("hertz_friction.toml")), Vec2(0.0, 0.0), 2, 3);
}

TEST(HeldSupports, ANodeHeldInUyCarriesNoContactForce) {
    // The block on the floor with its bottom-right corner also held in u_y: that node's normal
    // is held, so every multiplier of it is pinned; it reports gap and lambda = 0, and its
    // support takes the whole reaction there.
    const std::string text = test::replace(text_of("block_floor.toml"), "[[contact]]",
                                           "[[support]]\npoint = [2.0, 0.0]\nuy = 0.0\n\n"
                                           "[[contact]]");
    const auto p = scene::parse_scene(text, "held_normal.toml");
    const auto pins = pinned_of(p, 1);
    ASSERT_EQ(pins.size(), 2u);
    for (const auto& [x, mask] : pins)
        EXPECT_EQ(mask, x.x() == 0.0 ? kT : kT | kN) << x.x();
    const auto lu = run(p, 1, "lu");
    ASSERT_TRUE(lu.converged) << lu.failure;
    const auto& h = node_at(lu, Vec2(2.0, 0.0));
    EXPECT_EQ(h.status, contact::Status::gap);
    EXPECT_EQ(h.lambda_t, 0.0);
    EXPECT_EQ(h.lambda_n, 0.0);
    EXPECT_LT(levels::check_state(p, lu).force_balance, 1e-10);
    const auto mg = run(p, 1, "mg");
    ASSERT_TRUE(mg.converged) << mg.failure;
    EXPECT_EQ(fallbacks(mg), 0);
    expect_same(lu, mg, "mg");
}

TEST(HeldSupports, ASupportAcrossAnInclinedFrictionalContactIsRefusedNamingTheVertex) {
    // The floor tilted: u_x held at the corner (0, 0) is neither along nor across its normal.
    const std::string text =
        test::replace(text_of("block_floor.toml"), "normal = [0.0, 1.0]", "normal = [-0.1, 1.0]");
    auto build_error = [](const std::string& t) -> std::string {
        try {
            const auto p = scene::parse_scene(t, "tilted.toml");
            levels::build_level(p, p.mesh0);
        } catch (const InvalidInput& e) {
            return e.what();
        }
        return "";
    };
    const std::string msg = build_error(text);
    EXPECT_NE(msg.find("contact 'floor': contactor vertex"), std::string::npos) << msg;
    EXPECT_NE(msg.find("at (0, 0) has u_x prescribed by a support"), std::string::npos) << msg;
    EXPECT_NE(msg.find("neither along nor across"), std::string::npos) << msg;
    EXPECT_NE(msg.find("Prescribe both components of that vertex, release its u_x"),
              std::string::npos)
        << msg;
    // Frictionless, the same scene is regular and accepted.
    EXPECT_EQ(build_error(test::replace(text, "mu = 0.5", "mu = 0.0")), "");
}

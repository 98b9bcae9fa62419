// SPDX-License-Identifier: MIT
// The square test (benchmarks.md): equilibrium, Signorini/Coulomb identities and the expected
// picture of lift-off, slip and stick.
#include "levels/checks.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"

#include <gtest/gtest.h>

using namespace mlc;

namespace {

levels::RunResult solve_square(int level, double mu) {
    auto p = scene::load_scene("square");
    p.levels = level;
    for (auto& c : p.contacts)
        c.mu = mu;
    return levels::solve(p);
}

} // namespace

TEST(Square, UnknownCountsMatchTheBenchmarkLadder) {
    auto p = scene::load_scene("square");
    for (auto [level, n] : {std::pair{0, 592}, {1, 2208}}) {
        p.levels = level;
        mesh::Mesh m = p.mesh0;
        for (int l = 0; l < level; ++l)
            m = mesh::refine(m);
        const auto L = levels::build_level(p, m);
        EXPECT_EQ(L.n_unknowns(), n) << "level " << level;
        EXPECT_EQ(L.n_contact_nodes(), 16 << level);
    }
}

TEST(Square, ConvergedStateSatisfiesEquilibriumAndTheContactLaws) {
    for (int level : {0, 1}) {
        auto p = scene::load_scene("square");
        p.levels = level;
        const auto r = levels::solve(p);
        ASSERT_TRUE(r.converged) << r.failure;
        const auto c = levels::check_state(p, r);
        EXPECT_LT(c.force_balance, 1e-8);
        EXPECT_LT(c.coulomb_excess, 1e-8);
        EXPECT_LT(c.slip_equality, 1e-8);
        EXPECT_LT(c.complementarity, 1e-8);
        EXPECT_LT(c.penetration, 1e-8);
        EXPECT_LT(c.tension, 1e-8);
        for (const auto& s : r.steps)
            EXPECT_LE(s.iterations, 20);
    }
}

TEST(Square, LiftsOffAtTheLeftSlipsForwardAndSticksNearTheSymmetryPlane) {
    const auto r = solve_square(1, 1.0);
    ASSERT_TRUE(r.converged) << r.failure;
    auto nodes = r.nodes;
    std::sort(nodes.begin(), nodes.end(), [](auto& a, auto& b) { return a.x.x() < b.x.x(); });
    using contact::Status;
    EXPECT_EQ(nodes.front().status, Status::gap); // left end lifts off
    EXPECT_GT(nodes.front().u.y(), 0.0);
    EXPECT_EQ(nodes.back().status, Status::stick); // next to the symmetry plane
    int slip = 0, backward = 0;
    for (const auto& n : nodes) {
        slip += n.status == Status::slip_forward;
        backward += n.status == Status::slip_backward;
    }
    EXPECT_GT(slip, static_cast<int>(nodes.size()) / 2); // most of the edge slips toward +x
    EXPECT_EQ(backward, 0);
    // Slipping nodes move toward +x; friction on them opposes it (lambda_t = +mu |lambda_n|).
    for (const auto& n : nodes)
        if (n.status == Status::slip_forward) {
            EXPECT_GT(n.d_t, 0.0);
            EXPECT_NEAR(n.lambda_t, -1.0 * n.lambda_n, 1e-9 * std::abs(n.lambda_n));
        }
    // Zones are contiguous: gap, then slip, then stick from left to right.
    int phase = 0;
    for (const auto& n : nodes) {
        const int ph = n.status == Status::gap ? 0 : (n.status == Status::slip_forward ? 1 : 2);
        EXPECT_GE(ph, phase) << "zones out of order at x = " << n.x.x();
        phase = std::max(phase, ph);
    }
}

TEST(Square, VerticalContactResultantCarriesTheTopLoadWithTheCornerReaction) {
    const auto r = solve_square(1, 0.3);
    ASSERT_TRUE(r.converged) << r.failure;
    double sum_n = 0;
    for (const auto& n : r.nodes)
        sum_n += n.lambda_n;
    // The top load is 50 * 40 = 2000 (N/mm). The fixed corner carries part of it, so the contact
    // resultant is compressive and at most the load.
    EXPECT_LT(sum_n, 0.0);
    EXPECT_GT(sum_n, -2000.0 * (1 + 1e-12));
    EXPECT_LT(levels::force_balance_error(r.finest(), 1.0, r.u_full, r.nodes), 1e-10);
}

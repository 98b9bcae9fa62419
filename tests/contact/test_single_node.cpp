// SPDX-License-Identifier: MIT
// The single-node exact cases of benchmarks.md: one node on springs (k_t, k_n) over a rigid plane,
// one case per status, solved by the generalized Newton method.
#include "contact/law.hpp"
#include "levels/newton.hpp"

#include <gtest/gtest.h>

using namespace mlc;

namespace {

/// A level with one vertex (no triangles): K = diag(k_t, k_n), load f, one node-on-rigid element
/// against the plane y = 0 with zero gap.
levels::Level single_node(double kt, double kn, Vec2 f, double mu, double r) {
    levels::Level L;
    L.mesh.vertices = {Vec2(0, 0)};
    L.fixed = {{false, false}};
    L.u_fixed = Vector::Zero(2);
    contact::Obstacle plane;
    plane.validate();
    L.contacts = contact::node_on_rigid(L.mesh, {0}, plane, mu, r, 0);
    L.dofs = fem::DofMap(L.fixed, {L.contacts[0].n_multipliers()});
    L.lambda_dof = {L.dofs.extra_dof(0)};
    L.contact_of_vertex = {0};
    const Index n = L.dofs.n_dofs();
    L.elastic.K.resize(n, n);
    std::vector<Triplet> t{{0, 0, kt}, {1, 1, kn}};
    L.elastic.K.setFromTriplets(t.begin(), t.end());
    L.elastic.f = Vector::Zero(n);
    L.elastic.f.head<2>() = f;
    L.elastic.f_nodal_full = f;
    return L;
}

struct Solved {
    Vec2 u;
    Vec2 lambda;
    contact::Status status;
    int iterations;
};

Solved solve_single(double kt, double kn, Vec2 f, double mu, double r,
                    solvers::Method solver = solvers::Method::schur) {
    const auto L = single_node(kt, kn, f, mu, r);
    levels::ContactNewton newton(L, {}, levels::make_newton_system_solver(L, {.method = solver}));
    Vector x = Vector::Zero(L.n_unknowns());
    const auto rep = newton.solve(1.0, Vector::Zero(2), x);
    EXPECT_TRUE(rep.converged) << rep.message;
    const auto ns = newton.node_states(1.0, Vector::Zero(2), x);
    return {ns[0].u, Vec2(ns[0].lambda_t, ns[0].lambda_n), ns[0].status, rep.iterations};
}

} // namespace

TEST(SingleNode, SticksWhenTangentialLoadIsInsideTheCone) {
    // |f_t| <= mu |f_n|: u = 0, lambda = f.
    const auto s = solve_single(10.0, 20.0, Vec2(0.9, -2.0), 0.5, 3.0);
    EXPECT_EQ(s.status, contact::Status::stick);
    EXPECT_NEAR(s.u.norm(), 0.0, 1e-14);
    EXPECT_NEAR(s.lambda.x(), 0.9, 1e-13);
    EXPECT_NEAR(s.lambda.y(), -2.0, 1e-13);
}

TEST(SingleNode, SlipsForward) {
    // lambda_n = f_n, lambda_t = mu |f_n| sign f_t, u_t = (f_t - mu |f_n|) / k_t, u_n = 0.
    const auto s = solve_single(10.0, 20.0, Vec2(3.0, -2.0), 0.5, 3.0);
    EXPECT_EQ(s.status, contact::Status::slip_forward);
    EXPECT_NEAR(s.lambda.y(), -2.0, 1e-13);
    EXPECT_NEAR(s.lambda.x(), 1.0, 1e-13);
    EXPECT_NEAR(s.u.x(), (3.0 - 1.0) / 10.0, 1e-14);
    EXPECT_NEAR(s.u.y(), 0.0, 1e-14);
}

TEST(SingleNode, AssembledLUAndCondensedSolversAgree) {
    for (Vec2 f : {Vec2(0.9, -2.0), Vec2(3.0, -2.0), Vec2(-3.0, -2.0), Vec2(1.0, 2.0)}) {
        const auto a = solve_single(10.0, 20.0, f, 0.5, 3.0, solvers::Method::lu);
        const auto b = solve_single(10.0, 20.0, f, 0.5, 3.0, solvers::Method::schur);
        EXPECT_EQ(a.status, b.status);
        EXPECT_EQ(a.iterations, b.iterations);
        EXPECT_NEAR((a.u - b.u).norm(), 0.0, 1e-14);
        EXPECT_NEAR((a.lambda - b.lambda).norm(), 0.0, 1e-12);
    }
}

TEST(SingleNode, SlipsBackward) {
    const auto s = solve_single(10.0, 20.0, Vec2(-3.0, -2.0), 0.5, 3.0);
    EXPECT_EQ(s.status, contact::Status::slip_backward);
    EXPECT_NEAR(s.lambda.x(), -1.0, 1e-13);
    EXPECT_NEAR(s.u.x(), (-3.0 + 1.0) / 10.0, 1e-14);
    EXPECT_NEAR(s.u.y(), 0.0, 1e-14);
}

TEST(SingleNode, LiftsOffUnderATensileLoad) {
    // f_n > 0: u = f / k, lambda = 0.
    const auto s = solve_single(10.0, 20.0, Vec2(1.0, 2.0), 0.5, 3.0);
    EXPECT_EQ(s.status, contact::Status::gap);
    EXPECT_NEAR(s.u.x(), 0.1, 1e-14);
    EXPECT_NEAR(s.u.y(), 0.1, 1e-14);
    EXPECT_NEAR(s.lambda.norm(), 0.0, 1e-14);
}

TEST(SingleNode, FrictionlessHasOneMultiplierAndSlidesFreely) {
    const auto L = single_node(10.0, 20.0, Vec2(3.0, -2.0), 0.0, 3.0);
    EXPECT_EQ(L.n_unknowns(), 3);
    const auto s = solve_single(10.0, 20.0, Vec2(3.0, -2.0), 0.0, 3.0);
    EXPECT_NEAR(s.u.x(), 0.3, 1e-14);
    EXPECT_NEAR(s.lambda.y(), -2.0, 1e-13);
    EXPECT_EQ(s.status, contact::Status::slip_forward);
}

TEST(SingleNode, ResultDoesNotDependOnTheAugmentationParameter) {
    for (double r : {1e-4, 1e-2, 1.0, 1e2, 1e4}) {
        const auto s = solve_single(10.0, 20.0, Vec2(3.0, -2.0), 0.5, r);
        EXPECT_NEAR(s.u.x(), 0.2, 1e-12) << "r = " << r;
        EXPECT_NEAR(s.lambda.x(), 1.0, 1e-11) << "r = " << r;
    }
}

TEST(Projection, MatchesTheTableOfStatuses) {
    using contact::Status;
    const double mu = 0.4;
    auto p = contact::project(1.0, 2.0, mu);
    EXPECT_EQ(p.status, Status::gap);
    EXPECT_EQ(p.M.norm(), 0.0);
    p = contact::project(0.3, -1.0, mu);
    EXPECT_EQ(p.status, Status::stick);
    EXPECT_EQ(p.phi, Eigen::Vector2d(0.3, -1.0));
    EXPECT_EQ(p.M, Eigen::Matrix2d::Identity());
    p = contact::project(0.5, -1.0, mu);
    EXPECT_EQ(p.status, Status::slip_forward);
    EXPECT_DOUBLE_EQ(p.phi[0], 0.4);
    EXPECT_DOUBLE_EQ(p.M(0, 1), -mu);
    EXPECT_DOUBLE_EQ(p.M(1, 1), 1.0);
    EXPECT_DOUBLE_EQ(p.M(0, 0), 0.0);
    p = contact::project(-0.5, -1.0, mu);
    EXPECT_EQ(p.status, Status::slip_backward);
    EXPECT_DOUBLE_EQ(p.phi[0], -0.4);
    EXPECT_DOUBLE_EQ(p.M(0, 1), mu);
}

TEST(Projection, DerivativeMatchesFiniteDifferences) {
    const double mu = 0.3, h = 1e-7;
    for (auto [st, sn] : {std::pair{0.1, -1.0}, {0.5, -1.0}, {-0.5, -1.0}, {0.2, 0.5}}) {
        const auto p = contact::project(st, sn, mu);
        for (int j = 0; j < 2; ++j) {
            Eigen::Vector2d d = Eigen::Vector2d::Zero();
            d[j] = h;
            const auto q = contact::project(st + d[0], sn + d[1], mu);
            const Eigen::Vector2d fd = (q.phi - p.phi) / h;
            EXPECT_NEAR(fd[0], p.M(0, j), 1e-6);
            EXPECT_NEAR(fd[1], p.M(1, j), 1e-6);
        }
    }
}

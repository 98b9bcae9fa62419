// SPDX-License-Identifier: MIT
// Multipliers whose direction supports hold (contact::held_components, ContactElement::pinned):
// which components are pinned, and a single node held tangentially solved exactly.
#include "contact/element.hpp"
#include "core/check.hpp"
#include "levels/newton.hpp"

#include <cmath>
#include <gtest/gtest.h>

using namespace mlc;

namespace {

using Fixed = std::vector<std::array<bool, 2>>;
constexpr unsigned char kT = contact::ContactElement::kPinnedT;
constexpr unsigned char kN = contact::ContactElement::kPinnedN;

contact::ContactElement rigid(Vec2 n, double mu) {
    mesh::Mesh m;
    m.vertices = {Vec2(0, 0)};
    contact::Obstacle plane;
    plane.normal = n;
    plane.validate();
    return contact::node_on_rigid(m, {0}, plane, mu, 1.0, 0)[0];
}

} // namespace

TEST(HeldComponents, ARigidContactPinsTheComponentsAlongHeldDirections) {
    const Vec2 up(0, 1);
    // Friction: u_x held pins lambda_t; u_y held pins lambda_n and with it lambda_t.
    EXPECT_EQ(contact::held_components(rigid(up, 0.5), Fixed{{false, false}}).pinned, 0);
    EXPECT_EQ(contact::held_components(rigid(up, 0.5), Fixed{{true, false}}).pinned, kT);
    EXPECT_EQ(contact::held_components(rigid(up, 0.5), Fixed{{false, true}}).pinned, kT | kN);
    // Frictionless: lambda_n alone.
    EXPECT_EQ(contact::held_components(rigid(up, 0.0), Fixed{{true, false}}).pinned, 0);
    EXPECT_EQ(contact::held_components(rigid(up, 0.0), Fixed{{false, true}}).pinned, kN);
    // A wall x = 0 (normal +x): the roles swap.
    EXPECT_EQ(contact::held_components(rigid(Vec2(1, 0), 0.5), Fixed{{false, true}}).pinned, kT);
    EXPECT_EQ(contact::held_components(rigid(Vec2(1, 0), 0.0), Fixed{{true, false}}).pinned, kN);
    for (const auto& f : {Fixed{{false, false}}, Fixed{{true, false}}, Fixed{{false, true}}})
        EXPECT_FALSE(contact::held_components(rigid(up, 0.5), f).ambiguous);
}

TEST(HeldComponents, AnInclinedFrameWithFrictionIsAmbiguousOnlyWhereAComponentIsHeld) {
    const Vec2 n(std::sin(0.3), std::cos(0.3));
    const auto h = contact::held_components(rigid(n, 0.5), Fixed{{true, false}});
    EXPECT_TRUE(h.ambiguous);
    EXPECT_EQ(h.pinned, 0);
    EXPECT_FALSE(contact::held_components(rigid(n, 0.5), Fixed{{false, false}}).ambiguous);
    // Frictionless: lambda_n along n still meets u_y, which is free: no ambiguity.
    const auto f = contact::held_components(rigid(n, 0.0), Fixed{{true, false}});
    EXPECT_FALSE(f.ambiguous);
    EXPECT_EQ(f.pinned, 0);
    // Within the tolerance a direction counts as held; beyond it, not.
    const double a = 0.5 * contact::kHeldDirectionTolerance;
    EXPECT_EQ(
        contact::held_components(rigid(Vec2(std::sin(a), std::cos(a)), 0.5), Fixed{{true, false}})
            .pinned,
        kT);
    EXPECT_TRUE(contact::held_components(rigid(Vec2(std::sin(4 * a), std::cos(4 * a)), 0.5),
                                         Fixed{{true, false}})
                    .ambiguous);
}

TEST(HeldComponents, TwoBodiesPinOnlyWhereTheTargetIsHeldToo) {
    const auto e = contact::node_on_node(0, 1, Vec2(0, 1), 0.0, 0.5, 1.0, 0);
    // Contactor held in u_x, target free (axis_release's axis node): nothing pinned.
    EXPECT_EQ(contact::held_components(e, Fixed{{true, false}, {false, false}}).pinned, 0);
    EXPECT_FALSE(contact::held_components(e, Fixed{{true, false}, {false, false}}).ambiguous);
    EXPECT_EQ(contact::held_components(e, Fixed{{true, false}, {true, true}}).pinned, kT);
    // Node on facet: every target vertex with a nonzero weight must hold the component.
    const auto f = contact::node_on_facet(0, 1, 2, 0.25, Vec2(0, 1), 0.0, 0.5, 1.0, 0);
    EXPECT_EQ(
        contact::held_components(f, Fixed{{true, false}, {true, false}, {false, false}}).pinned, 0);
    EXPECT_EQ(
        contact::held_components(f, Fixed{{true, false}, {true, false}, {true, false}}).pinned, kT);
    const auto g = contact::node_on_facet(0, 1, 2, 0.0, Vec2(0, 1), 0.0, 0.5, 1.0, 0);
    EXPECT_EQ(
        contact::held_components(g, Fixed{{true, false}, {true, false}, {false, false}}).pinned,
        kT); // vertex 2 has weight 0
}

TEST(HeldComponents, APinnedTangentProjectsOnTheNormalAlone) {
    auto e = rigid(Vec2(0, 1), 0.5);
    e.r = 2.0;
    e.pinned = kT;
    // u = (0.1, -0.01) (u_x is prescribed, u_y penetrates), lambda = (7, -1): sigma_t would slip.
    Vector u(2), u_prev = Vector::Zero(2), x(2);
    u << 0.1, -0.01;
    x << 7.0, -1.0;
    const auto s = contact::evaluate(e, u, u_prev, x, 0);
    EXPECT_EQ(s.proj.status, contact::Status::stick);
    EXPECT_EQ(s.proj.phi[0], 0.0);
    EXPECT_DOUBLE_EQ(s.proj.phi[1], -1.0 - 2.0 * 0.01);
    EXPECT_EQ(s.proj.M(0, 0), 0.0);
    EXPECT_EQ(s.proj.M(0, 1), 0.0);
    EXPECT_EQ(s.proj.M(1, 0), 0.0);
    EXPECT_EQ(s.proj.M(1, 1), 1.0);
    // A pinned normal: no force at all, status gap.
    e.pinned = kT | kN;
    const auto g = contact::evaluate(e, u, u_prev, x, 0);
    EXPECT_EQ(g.proj.status, contact::Status::gap);
    EXPECT_TRUE(g.proj.M.isZero(0.0));
    EXPECT_TRUE(g.proj.phi.isZero(0.0));
}

namespace {

/// One vertex held in u_x on springs k_n (u_y), pressed by f_n < 0 with a tangential load f_t on
/// the held component (taken by the support), node on the rigid plane y = 0 with friction.
levels::Level held_node(double kn, double fn, double mu, double r, bool pin) {
    levels::Level L;
    L.mesh.vertices = {Vec2(0, 0)};
    L.fixed = {{true, false}};
    L.u_fixed = Vector::Zero(2);
    contact::Obstacle plane;
    plane.validate();
    L.contacts = contact::node_on_rigid(L.mesh, {0}, plane, mu, r, 0);
    if (pin) L.contacts[0].pinned = contact::held_components(L.contacts[0], L.fixed).pinned;
    L.dofs = fem::DofMap(L.fixed, {L.contacts[0].n_multipliers()});
    L.lambda_dof = {L.dofs.extra_dof(0)};
    L.contact_of_vertex = {0};
    const Index n = L.dofs.n_dofs();
    L.elastic.K.resize(n, n);
    std::vector<Triplet> t{{0, 0, kn}};
    L.elastic.K.setFromTriplets(t.begin(), t.end());
    L.elastic.f = Vector::Zero(n);
    L.elastic.f[0] = fn;
    L.elastic.f_nodal_full = Vector::Zero(2);
    L.elastic.f_nodal_full[1] = fn;
    return L;
}

} // namespace

TEST(HeldComponents, ANodeHeldTangentiallyIsSolvedExactlyWithLambdaTZero) {
    for (const solvers::Method solver : {solvers::Method::lu, solvers::Method::schur}) {
        const auto L = held_node(20.0, -2.0, 0.5, 3.0, true);
        ASSERT_EQ(L.contacts[0].pinned, kT);
        levels::ContactNewton newton(L, {},
                                     levels::make_newton_system_solver(L, {.method = solver}));
        Vector x = Vector::Zero(L.n_unknowns());
        const auto rep = newton.solve(1.0, Vector::Zero(2), x);
        ASSERT_TRUE(rep.converged) << solver << ": " << rep.message;
        const auto ns = newton.node_states(1.0, Vector::Zero(2), x);
        EXPECT_EQ(ns[0].status, contact::Status::stick) << solver;
        EXPECT_EQ(ns[0].lambda_t, 0.0) << solver; // exactly: the support takes it
        EXPECT_NEAR(ns[0].lambda_n, -2.0, 1e-13) << solver;
        EXPECT_NEAR(ns[0].u.y(), 0.0, 1e-14) << solver;
    }
}

TEST(HeldComponents, WithoutPinningTheStuckNodesNewtonMatrixIsSingular) {
    // The same node with lambda_t left free: it appears in no equation once the node sticks.
    const auto L = held_node(20.0, -2.0, 0.5, 3.0, false);
    ASSERT_EQ(L.contacts[0].pinned, 0);
    auto solver = levels::make_newton_system_solver(L, {.method = solvers::Method::lu});
    const std::vector<Eigen::Matrix2d> stick{Eigen::Matrix2d::Identity()};
    Vector b = Vector::Ones(L.n_unknowns()), dx;
    EXPECT_THROW(solver->solve(stick, b, dx), SolverBreakdown);
    // Pinned, the stuck system is regular: lambda_t's row reads -lambda_t / r = b.
    const auto P = held_node(20.0, -2.0, 0.5, 3.0, true);
    auto pinned = levels::make_newton_system_solver(P, {.method = solvers::Method::lu});
    const std::vector<Eigen::Matrix2d> stick_pinned{Eigen::DiagonalMatrix<double, 2>(0.0, 1.0)};
    ASSERT_TRUE(pinned->solve(stick_pinned, b, dx).converged);
    EXPECT_DOUBLE_EQ(dx[P.lambda_dof[0]], -3.0);
}

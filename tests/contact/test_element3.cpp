// SPDX-License-Identifier: MIT
// Contact elements for dim = 2 and 3 (contact::BasicContactElement): the element tangent equals
// the derivative of the element residual (central differences, in gap, stick and slip, where 3D
// slip is not piecewise linear), the residual's closed form against a rigid plane, and which
// multipliers 3D supports pin.
#include "contact/element.hpp"
#include "core/check.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <random>

using namespace mlc;

namespace {

template <int dim> using Point = Eigen::Matrix<double, dim, 1>;

/// One node against a rigid plane through the origin with normal n (toward the body at
/// height g0 along n), friction mu, augmentation r.
template <int dim>
contact::BasicContactElement<dim> rigid_node(const Point<dim>& n, double g0, double mu, double r) {
    mesh::SimplexMesh<dim> m;
    m.vertices = {g0 * n};
    contact::BasicObstacle<dim> plane;
    plane.normal = n;
    plane.validate();
    return contact::node_on_rigid(m, {0}, plane, mu, r, 0)[0];
}

/// The one-vertex numbering: dim displacements, then the element's multipliers.
template <int dim> fem::BasicDofMap<dim> one_vertex(int n_multipliers) {
    std::array<bool, dim> free{};
    return fem::BasicDofMap<dim>({free}, {n_multipliers});
}

/// The element residual at the unknowns x (u = x's displacements, u_prev = 0).
template <int dim>
Vector residual(const contact::BasicContactElement<dim>& e, const fem::BasicDofMap<dim>& dofs,
                const Vector& x) {
    Vector u = x.head(dim), prev = Vector::Zero(dim), R = Vector::Zero(x.size());
    const auto s = contact::evaluate(e, u, prev, x, dim);
    contact::add_residual(e, s, dofs, dim, R);
    return R;
}

/// max |J - dR/dx| / max |J| over 20 random states of the given regime (the status the state
/// evaluates to); infinity when fewer than 20 of 20000 draws fall into it.
template <int dim> double tangent_error(double mu, contact::Status want, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    Point<dim> n;
    for (int c = 0; c < dim; ++c)
        n[c] = U(rng);
    n.normalize();
    const double r = 2.0;
    const auto e = rigid_node<dim>(n, 0.1, mu, r);
    const auto dofs = one_vertex<dim>(e.n_multipliers());
    const int size = static_cast<int>(dofs.n_dofs());
    double worst = 0.0;
    int found = 0;
    for (int trial = 0; trial < 20000 && found < 20; ++trial) {
        Vector x(size);
        for (int i = 0; i < size; ++i)
            x[i] = U(rng);
        const Vector prev = Vector::Zero(dim);
        const auto s = contact::evaluate(e, Vector(x.head(dim)), prev, x, dim);
        if (s.proj.status != want) continue;
        ++found;
        Eigen::MatrixXd J = Eigen::MatrixXd::Zero(size, size);
        contact::for_each_tangent_entry(e, s.proj.M, dofs, dim,
                                        [&](int i, int j, double v) { J(i, j) += v; });
        Eigen::MatrixXd D(size, size);
        const double h = 1e-6;
        for (int j = 0; j < size; ++j) {
            Vector xp = x, xm = x;
            xp[j] += h;
            xm[j] -= h;
            D.col(j) = (residual(e, dofs, xp) - residual(e, dofs, xm)) / (2 * h);
        }
        worst = std::max(worst, (J - D).cwiseAbs().maxCoeff() / J.cwiseAbs().maxCoeff());
    }
    return found == 20 ? worst : std::numeric_limits<double>::infinity(); // too few states
}

} // namespace

TEST(ContactElement3, TheTangentIsTheDerivativeOfTheResidualInEveryRegime) {
    for (unsigned seed = 1; seed <= 3; ++seed) {
        EXPECT_LT(tangent_error<3>(0.6, contact::Status::slip, seed), 1e-7) << seed;
        EXPECT_LT(tangent_error<3>(0.6, contact::Status::stick, seed), 1e-7) << seed;
        EXPECT_LT(tangent_error<3>(0.0, contact::Status::stick, seed), 1e-7) << seed;
        EXPECT_LT(tangent_error<2>(0.6, contact::Status::slip_forward, seed), 1e-7) << seed;
        EXPECT_LT(tangent_error<2>(0.6, contact::Status::stick, seed), 1e-7) << seed;
    }
}

TEST(ContactElement3, RigidPlaneResidualHasItsClosedForm) {
    const Point<3> n = Point<3>(1.0, 2.0, 2.0) / 3.0;
    const double g0 = 0.25, mu = 0.5, r = 4.0;
    const auto e = rigid_node<3>(n, g0, mu, r);
    ASSERT_EQ(e.n_multipliers(), 3);
    // The frame: orthonormal, right-handed, n from the obstacle.
    Eigen::Matrix3d G;
    G << e.t, e.n;
    EXPECT_LT((G.transpose() * G - Eigen::Matrix3d::Identity()).norm(), 1e-14);
    EXPECT_NEAR(G.determinant(), 1.0, 1e-14);
    EXPECT_NEAR(e.g0, g0, 1e-15);
    // Pressed in by 0.75 along n and moved by (0.3, -0.2) along the tangents, lambda given.
    const Eigen::Vector3d u = e.t * Eigen::Vector2d(0.3, -0.2) - 1.0 * e.n;
    const auto dofs = one_vertex<3>(3);
    Vector x(6);
    x << u, 0.1, 0.2, -1.0;
    const auto s = contact::evaluate(e, Vector(u), Vector::Zero(3), x, 3);
    EXPECT_NEAR(s.d_n, g0 - 1.0, 1e-14);
    EXPECT_NEAR(s.d_t[0], 0.3, 1e-14);
    EXPECT_NEAR(s.d_t[1], -0.2, 1e-14);
    // sigma = lambda + r d = (1.3, -0.6, -4): |sigma_t| = 1.43 <= mu |sigma_n| = 2, stick.
    ASSERT_EQ(s.proj.status, contact::Status::stick);
    Vector R = Vector::Zero(6);
    contact::add_residual(e, s, dofs, 3, R);
    const Eigen::Vector3d force = e.t * Eigen::Vector2d(1.3, -0.6) + (-4.0) * e.n;
    EXPECT_LT((R.head(3) - force).norm(), 1e-13);
    // Stick: Phi = sigma, so R_lambda = -(lambda - Phi) / r = d.
    EXPECT_LT((R.tail(3) - Eigen::Vector3d(0.3, -0.2, g0 - 1.0)).norm(), 1e-14);
}

TEST(ContactElement3, SupportsPinTheMultipliersAlongHeldDirections) {
    using Fixed = std::vector<std::array<bool, 3>>;
    constexpr unsigned char kT = contact::ContactElement3::kPinnedT;
    constexpr unsigned char kN = contact::ContactElement3::kPinnedN;
    const auto e = rigid_node<3>(Point<3>::UnitZ(), 0.0, 0.5, 1.0);
    EXPECT_EQ(contact::held_components(e, Fixed{{false, false, false}}).pinned, 0);
    // Both tangential components held: lambda_t pinned; the normal held pins everything.
    EXPECT_EQ(contact::held_components(e, Fixed{{true, true, false}}).pinned, kT);
    EXPECT_EQ(contact::held_components(e, Fixed{{false, false, true}}).pinned, kT | kN);
    // One tangential direction held (x) and n across it: the first tangent, turned onto x,
    // is pinned alone.
    const auto one = contact::held_components(e, Fixed{{true, false, false}});
    EXPECT_EQ(one.pinned, contact::ContactElement3::kPinnedT1);
    EXPECT_EQ(one.pinned_axis, 0);
    EXPECT_FALSE(one.ambiguous);
    // The normal inclined toward the held x: support and contact would share a force
    // direction, the multipliers are not unique.
    const auto tilted = rigid_node<3>(Point<3>(0.6, 0.0, 0.8), 0.0, 0.5, 1.0);
    const auto amb = contact::held_components(tilted, Fixed{{true, false, false}});
    EXPECT_EQ(amb.pinned, 0);
    EXPECT_TRUE(amb.ambiguous);
    // Frictionless: lambda_n alone, whatever holds the tangents.
    const auto f = rigid_node<3>(Point<3>::UnitZ(), 0.0, 0.0, 1.0);
    EXPECT_EQ(contact::held_components(f, Fixed{{true, false, false}}).pinned, 0);
    EXPECT_FALSE(contact::held_components(f, Fixed{{true, false, false}}).ambiguous);
    EXPECT_EQ(contact::held_components(f, Fixed{{false, false, true}}).pinned, kN);
}

TEST(ContactElement3, APinnedFirstTangentLeavesTheCoulombIntervalOnTheSecond) {
    // n = z, t1 turned onto y (held by a symmetry plane), t2 = n x t1 = -x; mu = 0.5, r = 1.
    auto e = rigid_node<3>(Point<3>::UnitZ(), 0.0, 0.5, 1.0);
    contact::turn_first_tangent_onto_axis(e, 1);
    e.pinned = contact::ContactElement3::kPinnedT1;
    EXPECT_LE((e.t.col(0) - Eigen::Vector3d::UnitY()).norm(), 1e-15);
    EXPECT_LE((e.t.col(1) + Eigen::Vector3d::UnitX()).norm(), 1e-15);
    // Pressed in by 2 (sigma_n = -1 - 2 = -3, limit mu |sigma_n| = 1.5), slid by (5, 1) along
    // (t1, t2), lambda_t = (7, 0.2): sigma_t2 = 0.2 + 1 = 1.2 sticks although |sigma_t| would
    // slip; sigma_t1 counts as 0.
    const Eigen::Vector3d u = e.t * Eigen::Vector2d(5.0, 1.0) - 2.0 * e.n;
    Vector x(6);
    x << u, 7.0, 0.2, -1.0;
    auto s = contact::evaluate(e, Vector(u), Vector::Zero(3), x, 3);
    ASSERT_EQ(s.proj.status, contact::Status::stick);
    EXPECT_EQ(s.proj.phi[0], 0.0);
    EXPECT_NEAR(s.proj.phi[1], 1.2, 1e-14);
    EXPECT_NEAR(s.proj.phi[2], -3.0, 1e-14);
    EXPECT_EQ(s.proj.M.row(0).norm() + s.proj.M.col(0).norm(), 0.0);
    // Slid by 2 along t2: sigma_t2 = 2.2 > 1.5, slip on the interval: phi_t2 = 1.5, and the
    // derivative of phi_t2 along sigma_t2 is 0, along sigma_n -mu sign(sigma_t2) = -0.5.
    const Eigen::Vector3d u2 = e.t * Eigen::Vector2d(5.0, 2.0) - 2.0 * e.n;
    x.head(3) = u2;
    s = contact::evaluate(e, Vector(u2), Vector::Zero(3), x, 3);
    ASSERT_EQ(s.proj.status, contact::Status::slip);
    EXPECT_EQ(s.proj.phi[0], 0.0);
    EXPECT_NEAR(s.proj.phi[1], 1.5, 1e-14);
    EXPECT_NEAR(s.proj.M(1, 1), 0.0, 1e-14);
    EXPECT_NEAR(s.proj.M(1, 2), -0.5, 1e-14);
    EXPECT_EQ(s.proj.M.row(0).norm() + s.proj.M.col(0).norm(), 0.0);
    // The pinned multiplier's residual reads -lambda_t1 / r.
    const auto dofs = one_vertex<3>(3);
    Vector R = Vector::Zero(6);
    contact::add_residual(e, s, dofs, 3, R);
    EXPECT_NEAR(R[3], -7.0, 1e-14);
}

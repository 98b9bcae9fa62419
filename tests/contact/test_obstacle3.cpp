// SPDX-License-Identifier: MIT
// Rigid obstacles for dim = 2 and 3: the tangent basis of a normal, plane, sphere and cylinder
// frames (normal toward the body, signed gap) at known points, the refusals, and the 2D
// obstacle's frames and output kept as they were.
#include "contact/obstacle.hpp"
#include "core/check.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <type_traits>

using namespace mlc;

namespace {

using V3 = Eigen::Vector3d;
using Obstacle3 = contact::BasicObstacle<3>;

/// The message of the InvalidInput `f` throws, without the " [check ...]" place that follows.
std::string obstacle3_refusal(const std::function<void()>& f) {
    try {
        f();
    } catch (const InvalidInput& e) {
        const std::string what = e.what();
        return what.substr(0, what.find(" [check `"));
    }
    return "(no InvalidInput thrown)";
}

/// Frame of `o` at x.
std::pair<V3, double> obstacle3_frame(const Obstacle3& o, const V3& x) {
    V3 n;
    double g0 = 0.0;
    o.frame(x, n, g0);
    return {n, g0};
}

void obstacle3_expect_basis(const V3& n) {
    const Eigen::Matrix<double, 3, 2> t = contact::tangent_basis<3>(n);
    const V3 t1 = t.col(0), t2 = t.col(1);
    EXPECT_NEAR(t1.norm(), 1.0, 1e-15) << n.transpose();
    EXPECT_NEAR(t2.norm(), 1.0, 1e-15) << n.transpose();
    EXPECT_NEAR(t1.dot(t2), 0.0, 1e-15) << n.transpose();
    EXPECT_NEAR(t1.dot(n), 0.0, 1e-15) << n.transpose();
    EXPECT_NEAR(t2.dot(n), 0.0, 1e-15) << n.transpose();
    EXPECT_LE((t1.cross(t2) - n).norm(), 1e-15) << n.transpose(); // right-handed
    // t1 is orthogonal to the least aligned axis e (t1 = e x n / |e x n|).
    int e = 0;
    for (int k = 1; k < 3; ++k)
        if (std::abs(n[k]) < std::abs(n[e])) e = k;
    EXPECT_EQ(t1[e], 0.0) << n.transpose();
}

} // namespace

TEST(Obstacle3, TangentBasisIsOrthonormalAndRightHanded) {
    std::mt19937 rng(31);
    std::normal_distribution<double> g(0.0, 1.0);
    for (int k = 0; k < 2000; ++k)
        obstacle3_expect_basis(V3(g(rng), g(rng), g(rng)).normalized());
    for (int i = 0; i < 3; ++i) {
        obstacle3_expect_basis(V3::Unit(i));
        obstacle3_expect_basis(-V3::Unit(i));
    }
}

TEST(Obstacle3, TangentBasisFollowsTheLeastAlignedAxisRule) {
    const auto basis = [](const V3& n) { return contact::tangent_basis<3>(n); };
    // n = z: x and y tie, x wins: t1 = x cross z = -y, t2 = z cross -y = x.
    Eigen::Matrix<double, 3, 2> t = basis(V3::UnitZ());
    EXPECT_EQ(t.col(0), V3(0, -1, 0));
    EXPECT_EQ(t.col(1), V3(1, 0, 0));
    // n = x: y and z tie, y wins: t1 = y cross x = -z, t2 = x cross -z = y.
    t = basis(V3::UnitX());
    EXPECT_EQ(t.col(0), V3(0, 0, -1));
    EXPECT_EQ(t.col(1), V3(0, 1, 0));
    // n = -y: x wins: t1 = x cross -y = -z, t2 = -y cross -z = x.
    t = basis(-V3::UnitY());
    EXPECT_EQ(t.col(0), V3(0, 0, -1));
    EXPECT_EQ(t.col(1), V3(1, 0, 0));
    // n = (0.6, 0, 0.8): e = y, t1 = y cross n = (0.8, 0, -0.6), t2 = n cross t1 = (0, 1, 0).
    t = basis(V3(0.6, 0.0, 0.8));
    EXPECT_LE((t.col(0) - V3(0.8, 0.0, -0.6)).norm(), 1e-15);
    EXPECT_LE((t.col(1) - V3(0.0, 1.0, 0.0)).norm(), 1e-15);
    // n = (1, 1, 1)/sqrt(3): a three-way tie, e = x: t1 = (0, -1, 1)/sqrt(2).
    t = basis(V3(1, 1, 1).normalized());
    EXPECT_LE((t.col(0) - V3(0, -1, 1) / std::sqrt(2.0)).norm(), 1e-15);
    // n = (0.8, -0.6, 0.0) (smallest |n_i| is z): t1 = z cross n = (0.6, 0.8, 0).
    t = basis(V3(0.8, -0.6, 0.0));
    EXPECT_LE((t.col(0) - V3(0.6, 0.8, 0.0)).norm(), 1e-15);
    EXPECT_LE((t.col(1) - V3(0.0, 0.0, 1.0)).norm(), 1e-15);
}

TEST(Obstacle3, TangentBasisIn2DIsNyMinusNx) {
    std::mt19937 rng(8);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int k = 0; k < 100; ++k) {
        const Vec2 n = Vec2(u(rng), u(rng)).normalized();
        const Vec2 t = contact::tangent_basis<2>(n);
        EXPECT_EQ(t, Vec2(n.y(), -n.x()));
        EXPECT_NEAR(t.x() * n.y() - t.y() * n.x(), 1.0, 1e-15); // (t, n) right-handed
    }
}

TEST(Obstacle3, PlaneGivesItsNormalAndTheSignedDistance) {
    Obstacle3 o;
    o.kind = Obstacle3::Kind::plane;
    o.point = V3(1, 2, 3);
    o.normal = V3(0, 0, 2);
    o.validate();
    EXPECT_EQ(o.normal, V3(0, 0, 1));
    auto [n, g0] = obstacle3_frame(o, V3(5, -1, 4.5));
    EXPECT_EQ(n, V3(0, 0, 1));
    EXPECT_EQ(g0, 1.5);
    std::tie(n, g0) = obstacle3_frame(o, V3(0, 0, 2.75)); // behind the plane: negative gap
    EXPECT_EQ(g0, -0.25);
    // A tilted plane, normal (1, 2, 2)/3: the point 0.6 along the normal plus a tangential part.
    o.normal = V3(1, 2, 2);
    o.validate();
    const V3 nn = V3(1, 2, 2) / 3.0;
    const V3 x = o.point + 0.6 * nn + 4.0 * V3(2, -1, 0) / std::sqrt(5.0);
    std::tie(n, g0) = obstacle3_frame(o, x);
    EXPECT_LE((n - nn).norm(), 1e-15);
    EXPECT_NEAR(g0, 0.6, 1e-14);
}

TEST(Obstacle3, SphereIsRadialFromItsCentreOutsideAndInside) {
    Obstacle3 o;
    o.kind = Obstacle3::Kind::sphere;
    o.center = V3(1, 1, 1);
    o.radius = 2.0;
    o.validate();
    const V3 dir = V3(2, 3, 6) / 7.0;
    auto [n, g0] = obstacle3_frame(o, o.center + 3.0 * dir); // 1 outside the sphere
    EXPECT_LE((n - dir).norm(), 1e-15);
    EXPECT_NEAR(g0, 1.0, 1e-14);
    std::tie(n, g0) = obstacle3_frame(o, o.center + 1.5 * dir); // 0.5 inside: penetrated
    EXPECT_NEAR(g0, -0.5, 1e-14);
    // The body inside a spherical hole: the normal points to the centre, the gap is r - |x - c|.
    o.body_outside = false;
    std::tie(n, g0) = obstacle3_frame(o, o.center + 1.5 * dir);
    EXPECT_LE((n + dir).norm(), 1e-15);
    EXPECT_NEAR(g0, 0.5, 1e-14);
    std::tie(n, g0) = obstacle3_frame(o, o.center + 3.0 * dir);
    EXPECT_NEAR(g0, -1.0, 1e-14);
    EXPECT_EQ(obstacle3_refusal([&] { obstacle3_frame(o, o.center); }),
              "a contact node sits at the centre of a sphere obstacle");
}

TEST(Obstacle3, CylinderIsRadialFromItsAxis) {
    Obstacle3 o;
    o.kind = Obstacle3::Kind::cylinder;
    o.center = V3(1, 2, 3);
    o.axis = V3(0, 0, 5);
    o.radius = 1.0;
    o.validate();
    EXPECT_EQ(o.axis, V3(0, 0, 1));
    // 2 from the axis, anywhere along it.
    auto [n, g0] = obstacle3_frame(o, V3(1 + 1.2, 2 + 1.6, 10));
    EXPECT_LE((n - V3(0.6, 0.8, 0)).norm(), 1e-15);
    EXPECT_NEAR(g0, 1.0, 1e-14);
    o.body_outside = false; // inside a cylindrical hole
    std::tie(n, g0) = obstacle3_frame(o, V3(1 + 0.3, 2 + 0.4, -7));
    EXPECT_LE((n - V3(-0.6, -0.8, 0)).norm(), 1e-15);
    EXPECT_NEAR(g0, 0.5, 1e-14);
    EXPECT_EQ(obstacle3_refusal([&] { obstacle3_frame(o, V3(1, 2, 7)); }),
              "a contact node sits on the axis of a cylinder obstacle");
    // A tilted axis (1, 1, 0)/sqrt(2): a point 7 along it and 3 off it in z.
    o.body_outside = true;
    o.axis = V3(1, 1, 0);
    o.validate();
    std::tie(n, g0) =
        obstacle3_frame(o, o.center + 7.0 * V3(1, 1, 0) / std::sqrt(2.0) + V3(0, 0, 3));
    EXPECT_LE((n - V3(0, 0, 1)).norm(), 1e-14);
    EXPECT_NEAR(g0, 2.0, 1e-14);
}

TEST(Obstacle3, RefusesZeroNormalNonPositiveRadiusAndZeroAxis) {
    Obstacle3 plane;
    plane.kind = Obstacle3::Kind::plane;
    plane.normal = V3::Zero();
    EXPECT_EQ(obstacle3_refusal([&] { plane.validate(); }),
              "a plane obstacle needs a non-zero normal");
    Obstacle3 sphere;
    sphere.kind = Obstacle3::Kind::sphere;
    sphere.radius = -0.5;
    EXPECT_EQ(obstacle3_refusal([&] { sphere.validate(); }),
              "a sphere obstacle needs a positive radius, found a negative radius, -0.5");
    sphere.radius = 0.0;
    EXPECT_EQ(obstacle3_refusal([&] { sphere.validate(); }),
              "a sphere obstacle needs a positive radius, found 0");
    Obstacle3 cylinder;
    cylinder.kind = Obstacle3::Kind::cylinder;
    cylinder.radius = 1.0;
    cylinder.axis = V3::Zero();
    EXPECT_EQ(obstacle3_refusal([&] { cylinder.validate(); }),
              "a cylinder obstacle needs an axis of non-zero length, found axis (0, 0, 0)");
    cylinder.axis = V3(0, 1, 0);
    cylinder.radius = -2.0;
    EXPECT_EQ(obstacle3_refusal([&] { cylinder.validate(); }),
              "a cylinder obstacle needs a positive radius, found a negative radius, -2");
    // In 2D: the same refusals with the 2D names, and no cylinder.
    contact::Obstacle line;
    line.normal = Vec2::Zero();
    EXPECT_EQ(obstacle3_refusal([&] { line.validate(); }),
              "a line obstacle needs a non-zero normal");
    contact::Obstacle circle;
    circle.kind = contact::Obstacle::Kind::circle;
    circle.radius = -1.0;
    EXPECT_EQ(obstacle3_refusal([&] { circle.validate(); }),
              "a circle obstacle needs a positive radius, found a negative radius, -1");
    circle.kind = contact::Obstacle::Kind::cylinder;
    circle.radius = 1.0;
    EXPECT_EQ(obstacle3_refusal([&] { circle.validate(); }),
              "a cylinder obstacle is for 3D scenes; in 2D its section is a circle obstacle");
}

TEST(Obstacle3, TwoDimensionalObstacleKeepsItsFramesAndOutput) {
    static_assert(std::is_same_v<contact::Obstacle, contact::BasicObstacle<2>>);
    static_assert(contact::Obstacle::Kind::plane == contact::Obstacle::Kind::line);
    static_assert(Obstacle3::Kind::sphere == Obstacle3::Kind::circle);
    contact::Obstacle line; // the default: the line y = 0, normal (0, 1)
    line.validate();
    Vec2 n;
    double g0 = 0.0;
    line.frame(Vec2(3.0, 0.25), n, g0);
    EXPECT_EQ(n, Vec2(0, 1));
    EXPECT_EQ(g0, 0.25);
    std::ostringstream os;
    os << line;
    EXPECT_EQ(os.str(), "line through (0, 0) normal (0, 1)");
    contact::Obstacle circle;
    circle.kind = contact::Obstacle::Kind::circle;
    circle.center = Vec2(1, 2);
    circle.radius = 0.5;
    circle.body_outside = false;
    circle.validate();
    circle.frame(Vec2(1.3, 2.4), n, g0); // 0.5 from the centre: on the rim, inside
    EXPECT_LE((n - Vec2(-0.6, -0.8)).norm(), 1e-15);
    EXPECT_NEAR(g0, 0.0, 1e-15);
    os.str("");
    os << circle;
    EXPECT_EQ(os.str(), "circle centre (1, 2) radius 0.5, body inside");
    Obstacle3 cyl;
    cyl.kind = Obstacle3::Kind::cylinder;
    cyl.center = V3(0, 1, 0);
    cyl.axis = V3(1, 0, 0);
    cyl.radius = 2;
    os.str("");
    os << cyl;
    EXPECT_EQ(os.str(), "cylinder axis through (0, 1, 0) along (1, 0, 0) radius 2, body outside");
    Obstacle3 plane;
    os.str("");
    os << plane;
    EXPECT_EQ(os.str(), "plane through (0, 0, 0) normal (0, 0, 1)");
}

// SPDX-License-Identifier: MIT
/// @file Rigid obstacles (2D: a line, a circle; 3D: a plane, a sphere, a cylinder), the local
/// contact frame they give a point, and the tangent basis of a contact normal.
#pragma once

#include "core/types.hpp"

#include <ostream>

namespace mlc::contact {

/// A fixed rigid obstacle in dim = 2 or 3 dimensions. The frame at a body point x: n the unit
/// normal of the obstacle pointing toward the body, the tangents of tangent_basis(n), and the
/// initial gap g0 = signed distance (>= 0 when apart), all evaluated at the reference position
/// (small strain).
template <int dim> struct BasicObstacle {
    static_assert(dim == 2 || dim == 3, "obstacles are for dim = 2 or 3");
    using Point = Eigen::Matrix<double, dim, 1>;
    /// line (2D) / plane (3D): through `point`, normal `normal`; circle (2D) / sphere (3D):
    /// centre `center`, `radius`; cylinder (3D only): axis through `center` along `axis`,
    /// `radius`. plane and sphere name the same enumerators as line and circle.
    enum class Kind { line, circle, cylinder, plane = line, sphere = circle };
    Kind kind = Kind::line;
    Point point = Point::Zero(); ///< line/plane: a point on it
    /// line/plane: normal toward the body (normalized on validate); default the last axis
    Point normal = Point::Unit(dim - 1);
    Point center = Point::Zero(); ///< circle/sphere: centre; cylinder: a point of the axis
    double radius = 0.0;          ///< circle/sphere/cylinder: radius > 0
    bool body_outside = true; ///< circle/sphere/cylinder: body outside the solid or inside a hole
    Point axis = Point::Unit(dim - 1); ///< cylinder: axis direction (normalized on validate)

    /// Throws InvalidInput for a zero normal, a non-positive radius, a cylinder axis of zero
    /// length or a cylinder in 2D; normalizes the normal and the axis.
    void validate();
    /// Normal (toward the body) and initial gap at reference point x. Sphere and cylinder:
    /// radial from the centre or from the axis; throws InvalidInput at the centre or on the axis.
    void frame(const Point& x, Point& n, double& g0) const;
};

/// The 2D obstacle (line or circle).
using Obstacle = BasicObstacle<2>;

extern template struct BasicObstacle<2>;
extern template struct BasicObstacle<3>;

/// "line through (x, y) normal (nx, ny)", "circle centre (x, y) radius r, body outside" and
/// their 3D forms (plane, sphere, "cylinder axis through (..) along (..) radius r, ...").
template <int dim> std::ostream& operator<<(std::ostream& os, const BasicObstacle<dim>& o);

extern template std::ostream& operator<<(std::ostream&, const BasicObstacle<2>&);
extern template std::ostream& operator<<(std::ostream&, const BasicObstacle<3>&);

/// The dim - 1 unit tangents (columns) of the contact frame at unit normal n, such that
/// (tangents, n) is right-handed:
/// - 2D: t = (n_y, -n_x);
/// - 3D: t1 = normalize(e x n), where e is the coordinate axis least aligned with n (the
///   smallest |n_i|; a tie goes to the lowest index i), and t2 = n x t1, so t1 x t2 = n.
/// The rule depends on n alone: two nodes with the same normal get the same tangents.
template <int dim>
Eigen::Matrix<double, dim, dim - 1> tangent_basis(const Eigen::Matrix<double, dim, 1>& n);

extern template Eigen::Matrix<double, 2, 1> tangent_basis<2>(const Eigen::Matrix<double, 2, 1>&);
extern template Eigen::Matrix<double, 3, 2> tangent_basis<3>(const Eigen::Matrix<double, 3, 1>&);

} // namespace mlc::contact

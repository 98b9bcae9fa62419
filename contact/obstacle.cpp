// SPDX-License-Identifier: MIT
// Rigid obstacle frames and the tangent basis of a contact normal.
#include "contact/obstacle.hpp"

#include "core/check.hpp"

#include <Eigen/Geometry>

#include <cmath>

namespace mlc::contact {

namespace {

/// "line" / "circle" in 2D, "plane" / "sphere" in 3D, "cylinder".
template <int dim> const char* kind_name(typename BasicObstacle<dim>::Kind k) {
    using Kind = typename BasicObstacle<dim>::Kind;
    if (k == Kind::cylinder) return "cylinder";
    if (k == Kind::line) return dim == 2 ? "line" : "plane";
    return dim == 2 ? "circle" : "sphere";
}

/// Writes "(x, y)" or "(x, y, z)".
template <int dim> struct Coords { const Eigen::Matrix<double, dim, 1>& p; };
template <int dim> std::ostream& operator<<(std::ostream& os, Coords<dim> c) {
    os << "(" << c.p[0];
    for (int i = 1; i < dim; ++i)
        os << ", " << c.p[i];
    return os << ")";
}

} // namespace

template <int dim> void BasicObstacle<dim>::validate() {
    const char* name = kind_name<dim>(kind);
    if (kind == Kind::line) {
        const double n = normal.norm();
        MLC_CHECK(std::isfinite(n) && n > 0, "a " << name << " obstacle needs a non-zero normal");
        normal /= n;
        return;
    }
    MLC_CHECK(dim == 3 || kind != Kind::cylinder,
              "a cylinder obstacle is for 3D scenes; in 2D its section is a circle obstacle");
    MLC_CHECK(std::isfinite(radius) && radius > 0,
              "a " << name << " obstacle needs a positive radius, found "
                   << (radius < 0 ? "a negative radius, " : "") << radius);
    if (kind == Kind::cylinder) {
        const double a = axis.norm();
        MLC_CHECK(std::isfinite(a) && a > 0,
                  "a cylinder obstacle needs an axis of non-zero length, found axis "
                      << Coords<dim>{axis});
        axis /= a;
    }
}

template <int dim> void BasicObstacle<dim>::frame(const Point& x, Point& n, double& g0) const {
    if (kind == Kind::line) {
        n = normal;
        g0 = n.dot(x - point);
        return;
    }
    Point d = x - center;
    if (kind == Kind::cylinder) {
        MLC_CHECK(dim == 3, "a cylinder obstacle is for 3D scenes");
        d -= d.dot(axis) * axis; // the part of x - center normal to the axis
    }
    const double dist = d.norm();
    MLC_CHECK(dist > 0, "a contact node sits "
                            << (kind == Kind::cylinder ? "on the axis" : "at the centre")
                            << " of a " << kind_name<dim>(kind) << " obstacle");
    if (body_outside) {
        n = d / dist;
        g0 = dist - radius;
    } else {
        n = -d / dist;
        g0 = radius - dist;
    }
}

template struct BasicObstacle<2>;
template struct BasicObstacle<3>;

template <int dim> std::ostream& operator<<(std::ostream& os, const BasicObstacle<dim>& o) {
    using Kind = typename BasicObstacle<dim>::Kind;
    os << kind_name<dim>(o.kind);
    if (o.kind == Kind::line)
        return os << " through " << Coords<dim>{o.point} << " normal " << Coords<dim>{o.normal};
    if (o.kind == Kind::cylinder)
        os << " axis through " << Coords<dim>{o.center} << " along " << Coords<dim>{o.axis};
    else
        os << " centre " << Coords<dim>{o.center};
    return os << " radius " << o.radius << (o.body_outside ? ", body outside" : ", body inside");
}

template std::ostream& operator<<(std::ostream&, const BasicObstacle<2>&);
template std::ostream& operator<<(std::ostream&, const BasicObstacle<3>&);

template <int dim>
Eigen::Matrix<double, dim, dim - 1> tangent_basis(const Eigen::Matrix<double, dim, 1>& n) {
    Eigen::Matrix<double, dim, dim - 1> t;
    if constexpr (dim == 2) {
        t << n.y(), -n.x();
    } else {
        int i = 0; // the coordinate axis least aligned with n; ties to the lowest index
        for (int k = 1; k < 3; ++k)
            if (std::abs(n[k]) < std::abs(n[i])) i = k;
        const Eigen::Vector3d t1 = Eigen::Vector3d::Unit(i).cross(n).normalized();
        t.col(0) = t1;
        t.col(1) = n.cross(t1);
    }
    return t;
}

template Eigen::Matrix<double, 2, 1> tangent_basis<2>(const Eigen::Matrix<double, 2, 1>&);
template Eigen::Matrix<double, 3, 2> tangent_basis<3>(const Eigen::Matrix<double, 3, 1>&);

} // namespace mlc::contact

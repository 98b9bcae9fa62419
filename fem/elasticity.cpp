// SPDX-License-Identifier: MIT
// P1 elasticity kernels.
#include "fem/elasticity.hpp"

#include "core/check.hpp"

#include <cmath>

namespace mlc::fem {

namespace {
/// The range of Young's modulus a solve can represent (Material::validate).
constexpr double kMinYoungModulus = 1e-100, kMaxYoungModulus = 1e100;
} // namespace

void Material::validate() const {
    MLC_CHECK(std::isfinite(E) && E > 0, "Young's modulus E must be positive, found E = " << E);
    // The solve forms E times displacements and sums their squares (norms, inner products,
    // factorizations): outside this range they underflow to 0 or overflow, and the failure
    // surfaces far from its cause (r = r_over_E E = 0, a singular matrix).
    MLC_CHECK(E >= kMinYoungModulus && E <= kMaxYoungModulus,
              "Young's modulus E = " << E << " is " << (E < kMinYoungModulus ? "below " : "above ")
                                     << (E < kMinYoungModulus ? kMinYoungModulus : kMaxYoungModulus)
                                     << ": the solve's products of E "
                                     << (E < kMinYoungModulus ? "underflow to 0" : "overflow")
                                     << "; state E, the loads and the lengths in other units "
                                        "(e.g. GPa instead of Pa)");
    MLC_CHECK(std::isfinite(nu) && nu > -1.0 && nu < 0.5,
              "Poisson's ratio nu must lie in (-1, 0.5), found nu = " << nu);
}

double Material::lambda() const {
    const double lam3d = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    if (plane == Plane::strain) return lam3d;
    const double mu = shear_modulus();
    return 2.0 * mu * lam3d / (lam3d + 2.0 * mu);
}

Eigen::Matrix3d Material::D() const {
    const double lam = lambda(), mu = shear_modulus();
    Eigen::Matrix3d d;
    d << lam + 2 * mu, lam, 0, lam, lam + 2 * mu, 0, 0, 0, mu;
    return d;
}

std::ostream& operator<<(std::ostream& os, const Material& m) {
    return os << "E = " << m.E << ", nu = " << m.nu << ", plane "
              << (m.plane == Plane::strain ? "strain" : "stress");
}

Eigen::Matrix<double, 3, 6> strain_matrix(const Vec2& a, const Vec2& b, const Vec2& c,
                                          double& area) {
    const double det = (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
    area = 0.5 * det;
    // Gradients of the barycentric coordinates: grad l_i = (y_j - y_k, x_k - x_j) / det.
    const double bx[3] = {b.y() - c.y(), c.y() - a.y(), a.y() - b.y()};
    const double by[3] = {c.x() - b.x(), a.x() - c.x(), b.x() - a.x()};
    Eigen::Matrix<double, 3, 6> B = Eigen::Matrix<double, 3, 6>::Zero();
    for (int i = 0; i < 3; ++i) {
        B(0, 2 * i) = bx[i] / det;
        B(1, 2 * i + 1) = by[i] / det;
        B(2, 2 * i) = by[i] / det;
        B(2, 2 * i + 1) = bx[i] / det;
    }
    return B;
}

Eigen::Matrix<double, 6, 6> element_stiffness(const Vec2& a, const Vec2& b, const Vec2& c,
                                              const Material& m) {
    double area = 0;
    const auto B = strain_matrix(a, b, c, area);
    return area * B.transpose() * m.D() * B;
}

Eigen::Matrix<double, 2, 6> element_stiffness_rows(const Vec2& a, const Vec2& b, const Vec2& c,
                                                   const Eigen::Matrix3d& D, int i) {
    double area = 0;
    const auto B = strain_matrix(a, b, c, area);
    // The products of element_stiffness, restricted to rows 2i, 2i + 1: each entry is formed
    // by the same operations in the same order.
    const Eigen::Matrix<double, 2, 3> BtD = (area * B.transpose()).middleRows<2>(2 * i) * D;
    return BtD * B;
}

} // namespace mlc::fem

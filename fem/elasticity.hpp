// SPDX-License-Identifier: MIT
/// @file P1 (constant-strain) triangles for 2D isotropic linear elasticity: material law,
/// element stiffness, strain-displacement matrix and stress recovery.
#pragma once

#include "core/types.hpp"

#include <Eigen/Dense>
#include <ostream>

namespace mlc::fem {

/// 2D reduction of 3D elasticity.
enum class Plane {
    strain, ///< eps_zz = 0 (thick bodies; the default of the papers' tests)
    stress  ///< sigma_zz = 0 (thin plates)
};

/// Isotropic linear elastic material. Units are the scene's (stress units for E).
struct Material {
    double E = 1.0;              ///< Young's modulus, > 0
    double nu = 0.3;             ///< Poisson's ratio, in (-1, 0.5)
    Plane plane = Plane::strain; ///< plane strain unless the scene says otherwise

    /// Throws InvalidInput naming E or nu if out of range.
    void validate() const;
    /// Lamé's first parameter of the 2D law (plane stress uses the reduced lambda).
    double lambda() const;
    /// Shear modulus mu = E / (2 (1 + nu)).
    double shear_modulus() const { return E / (2.0 * (1.0 + nu)); }
    /// Plane-strain modulus E* = E / (1 - nu^2) (plane stress: E).
    double effective_modulus() const { return plane == Plane::strain ? E / (1.0 - nu * nu) : E; }
    /// Voigt matrix D with sigma = D eps, eps = (e_xx, e_yy, 2 e_xy).
    Eigen::Matrix3d D() const;
};

std::ostream& operator<<(std::ostream& os, const Material& m);

/// Strain-displacement matrix B (3 x 6) of a triangle, eps = B (ax, ay, bx, by, cx, cy)^T,
/// and its area (returned through `area`, positive for counter-clockwise vertices).
Eigen::Matrix<double, 3, 6> strain_matrix(const Vec2& a, const Vec2& b, const Vec2& c,
                                          double& area);

/// Element stiffness K_e = area * B^T D B (unit thickness), dofs interleaved per vertex.
Eigen::Matrix<double, 6, 6> element_stiffness(const Vec2& a, const Vec2& b, const Vec2& c,
                                              const Material& m);

/// Rows 2i and 2i + 1 of element_stiffness(a, b, c, m) (vertex i's rows, i in 0..2), bit for bit,
/// for D = m.D(): a third of the work, for assemblies that build one vertex's rows at a time.
Eigen::Matrix<double, 2, 6> element_stiffness_rows(const Vec2& a, const Vec2& b, const Vec2& c,
                                                   const Eigen::Matrix3d& D, int i);

} // namespace mlc::fem

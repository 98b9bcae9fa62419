// SPDX-License-Identifier: MIT
/// @file P1 simplex kernels of isotropic linear elasticity with the dimension as a template
/// parameter: triangles (dim = 2) and tetrahedra (dim = 3). Barycentric gradients, the Voigt
/// strain-displacement matrix, the elasticity matrix and the element stiffness
/// |volume| B^T D B, with the unknowns interleaved per vertex (x, y (, z) of vertex 0, then
/// vertex 1, ...).
///
/// Voigt order: 2D (xx, yy, xy), 3D (xx, yy, zz, xy, yz, xz) (VTK's order of a symmetric
/// tensor), shear strains engineering (2 e_xy). The 2D instantiation is the kernel of
/// fem/elasticity.hpp (strain_matrix, element_stiffness) written for any dimension; the 2D
/// assembly still calls the latter.
#pragma once

#include "fem/elasticity.hpp"

#include <Eigen/Dense>

#include <array>
#include <cmath>

namespace mlc::fem {

/// Number of Voigt components of a symmetric dim x dim tensor.
template <int dim> inline constexpr int kVoigt = dim*(dim + 1) / 2;

/// Unknowns of a P1 simplex element: dim per vertex, dim + 1 vertices.
template <int dim> inline constexpr int kSimplexDofs = dim*(dim + 1);

template <int dim> using Point = Eigen::Matrix<double, dim, 1>;
/// The dim + 1 corners of a simplex.
template <int dim> using SimplexCorners = std::array<Point<dim>, dim + 1>;
/// Column i: the gradient of the barycentric coordinate of corner i.
template <int dim> using BarycentricGradients = Eigen::Matrix<double, dim, dim + 1>;
template <int dim> using VoigtMatrix = Eigen::Matrix<double, kVoigt<dim>, kVoigt<dim>>;
template <int dim> using StrainMatrix = Eigen::Matrix<double, kVoigt<dim>, kSimplexDofs<dim>>;
template <int dim>
using SimplexStiffness = Eigen::Matrix<double, kSimplexDofs<dim>, kSimplexDofs<dim>>;

/// Gradients of the barycentric coordinates of a simplex (columns), and its signed measure
/// (area, volume): det(x1 - x0, .., xd - x0) / d!. Either orientation; the gradients are those
/// of the simplex whatever its sign. A degenerate simplex gives infinite gradients (the mesh
/// checks refuse flat elements).
/// 2D: grad l_i = (y_j - y_k, x_k - x_j) / det, (i, j, k) cyclic, the formulas of
/// strain_matrix. 3D: grad l_1..3 are the rows of J^-1, J = (x1 - x0, x2 - x0, x3 - x0), from
/// cross products ((x2 - x0) x (x3 - x0) / det, ...), and grad l_0 = -(grad l_1 + .. + grad l_3).
template <int dim>
BarycentricGradients<dim> barycentric_gradients(const SimplexCorners<dim>& x, double& measure) {
    BarycentricGradients<dim> G;
    if constexpr (dim == 2) {
        const Point<2>&a = x[0], &b = x[1], &c = x[2];
        const double det = (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
        measure = 0.5 * det;
        const double gx[3] = {b.y() - c.y(), c.y() - a.y(), a.y() - b.y()};
        const double gy[3] = {c.x() - b.x(), a.x() - c.x(), b.x() - a.x()};
        for (int i = 0; i < 3; ++i) {
            G(0, i) = gx[i] / det;
            G(1, i) = gy[i] / det;
        }
    } else {
        static_assert(dim == 3, "P1 simplices of dimension 2 or 3");
        const Eigen::Vector3d e1 = x[1] - x[0], e2 = x[2] - x[0], e3 = x[3] - x[0];
        const Eigen::Vector3d c1 = e2.cross(e3), c2 = e3.cross(e1), c3 = e1.cross(e2);
        const double det = e1.dot(c1);
        measure = det / 6.0;
        G.col(1) = c1 / det;
        G.col(2) = c2 / det;
        G.col(3) = c3 / det;
        G.col(0) = -(G.col(1) + G.col(2) + G.col(3));
    }
    return G;
}

/// Voigt strain-displacement matrix: eps = B u_e, u_e interleaved per vertex.
template <int dim> StrainMatrix<dim> voigt_strain_matrix(const BarycentricGradients<dim>& G) {
    StrainMatrix<dim> B = StrainMatrix<dim>::Zero();
    for (int i = 0; i <= dim; ++i) {
        const int c = dim * i;
        for (int a = 0; a < dim; ++a)
            B(a, c + a) = G(a, i); // e_aa = d u_a / d x_a
        if constexpr (dim == 2) {
            B(2, c) = G(1, i); // 2 e_xy = du_x/dy + du_y/dx
            B(2, c + 1) = G(0, i);
        } else {
            B(3, c) = G(1, i); // 2 e_xy
            B(3, c + 1) = G(0, i);
            B(4, c + 1) = G(2, i); // 2 e_yz
            B(4, c + 2) = G(1, i);
            B(5, c) = G(2, i); // 2 e_xz
            B(5, c + 2) = G(0, i);
        }
    }
    return B;
}

/// Isotropic elasticity matrix, sigma = D eps in Voigt order. 2D: Material::D() (plane strain
/// or stress). 3D: lambda = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu)); diagonal
/// lambda + 2 mu (normal), mu (shear); Material::plane is a 2D reduction and plays no part.
template <int dim> VoigtMatrix<dim> elasticity_matrix(const Material& m) {
    if constexpr (dim == 2) {
        return m.D();
    } else {
        const double lam = m.E * m.nu / ((1.0 + m.nu) * (1.0 - 2.0 * m.nu));
        const double mu = m.shear_modulus();
        VoigtMatrix<3> d = VoigtMatrix<3>::Zero();
        for (int a = 0; a < 3; ++a) {
            for (int b = 0; b < 3; ++b)
                d(a, b) = lam;
            d(a, a) = lam + 2 * mu;
            d(3 + a, 3 + a) = mu;
        }
        return d;
    }
}

/// Element stiffness |measure| B^T D B (unit thickness in 2D).
template <int dim>
SimplexStiffness<dim> simplex_stiffness(const SimplexCorners<dim>& x, const VoigtMatrix<dim>& D) {
    double measure = 0;
    const auto B = voigt_strain_matrix<dim>(barycentric_gradients<dim>(x, measure));
    return std::abs(measure) * B.transpose() * D * B;
}

/// Rows dim i .. dim i + dim - 1 of simplex_stiffness(x, D) (corner i's rows): the assemblies
/// that build one vertex's rows at a time.
template <int dim>
Eigen::Matrix<double, dim, kSimplexDofs<dim>>
simplex_stiffness_rows(const SimplexCorners<dim>& x, const VoigtMatrix<dim>& D, int i) {
    double measure = 0;
    const auto B = voigt_strain_matrix<dim>(barycentric_gradients<dim>(x, measure));
    const Eigen::Matrix<double, dim, kVoigt<dim>> BtD =
        (std::abs(measure) * B.transpose()).template middleRows<dim>(dim * i) * D;
    return BtD * B;
}

} // namespace mlc::fem

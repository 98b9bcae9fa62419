// SPDX-License-Identifier: MIT
// P1 elasticity on tetrahedra against a manufactured smooth solution on the unit cube: order 1
// in the energy norm and 2 in L2 over levels 0..3 of a refined Kuhn box.
#include "fem/assembly.hpp"
#include "fem/simplex.hpp"
#include "mesh/tet_refine.hpp"
#include "tests/fem/elastic3d_test_util.hpp"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

using namespace mlc;
using mesh::Vec3;

namespace {

/// u_i(x) = amp prod_j sin(a_ij x_j + phi_ij), with its derivatives in closed form.
struct Manufactured {
    double amp = 0.01;
    Eigen::Matrix3d a, phi;
    Manufactured() {
        const double pi = std::numbers::pi;
        a.setConstant(pi);
        // sin(pi x) cos(pi y) sin(pi z), cos(pi x) sin(pi y) sin(pi z), and a generic phase.
        phi << 0, pi / 2, 0, pi / 2, 0, 0, 0.3, 0.5, 1.0;
    }
    /// d^(d0 + d1 + d2) u_i / dx^d0 dy^d1 dz^d2, each d_j in 0..2.
    double derivative(int i, const Vec3& x, int d0, int d1, int d2) const {
        const int d[3] = {d0, d1, d2};
        double r = amp;
        for (int j = 0; j < 3; ++j) {
            const double aj = a(i, j), s = aj * x[j] + phi(i, j);
            r *= d[j] == 0 ? std::sin(s) : d[j] == 1 ? aj * std::cos(s) : -aj * aj * std::sin(s);
        }
        return r;
    }
    /// d^2 u_i / dx_j dx_k.
    double second(int i, int j, int k, const Vec3& x) const {
        int d[3] = {0, 0, 0};
        ++d[j];
        ++d[k];
        return derivative(i, x, d[0], d[1], d[2]);
    }
    Vec3 u(const Vec3& x) const {
        return {derivative(0, x, 0, 0, 0), derivative(1, x, 0, 0, 0), derivative(2, x, 0, 0, 0)};
    }
    /// grad(i, j) = du_i / dx_j.
    Eigen::Matrix3d grad(const Vec3& x) const {
        Eigen::Matrix3d g;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                int d[3] = {0, 0, 0};
                d[j] = 1;
                g(i, j) = derivative(i, x, d[0], d[1], d[2]);
            }
        return g;
    }
    /// b = -div sigma = -((lam + mu) grad div u + mu laplace u).
    Vec3 body_force(const Vec3& x, double lam, double mu) const {
        Vec3 b;
        for (int i = 0; i < 3; ++i) {
            double grad_div = 0, lap = 0;
            for (int j = 0; j < 3; ++j) {
                grad_div += second(j, i, j, x);
                lap += second(i, j, j, x);
            }
            b[i] = -((lam + mu) * grad_div + mu * lap);
        }
        return b;
    }
};

Eigen::Matrix<double, 6, 1> voigt_strain(const Eigen::Matrix3d& g) {
    Eigen::Matrix<double, 6, 1> e;
    e << g(0, 0), g(1, 1), g(2, 2), g(0, 1) + g(1, 0), g(1, 2) + g(2, 1), g(0, 2) + g(2, 0);
    return e;
}

/// Errors of u_h against the manufactured solution: energy norm and L2, integrated by a
/// collapsed (Duffy) product of 4-point Gauss rules per tetrahedron (exact to degree 5).
std::pair<double, double> errors(const mesh::TetMesh& m, const Vector& uh, const Manufactured& s,
                                 const fem::VoigtMatrix<3>& D) {
    const double xg[4] = {0.0694318442029737, 0.3300094782075719, 0.6699905217924281,
                          0.9305681557970263};
    const double wg[4] = {0.1739274225687269, 0.3260725774312731, 0.3260725774312731,
                          0.1739274225687269};
    double energy = 0, l2 = 0;
    for (int t = 0; t < m.n_cells(); ++t) {
        const auto& tet = m.cells[static_cast<size_t>(t)];
        fem::SimplexCorners<3> x;
        Eigen::Matrix<double, 3, 4> U;
        for (int i = 0; i < 4; ++i) {
            x[static_cast<size_t>(i)] =
                m.vertices[static_cast<size_t>(tet[static_cast<size_t>(i)])];
            U.col(i) = uh.segment<3>(3 * tet[static_cast<size_t>(i)]);
        }
        double volume = 0;
        const auto G = fem::barycentric_gradients<3>(x, volume);
        const Eigen::Matrix3d grad_h = U * G.transpose();
        for (int p = 0; p < 4; ++p)
            for (int q = 0; q < 4; ++q)
                for (int r = 0; r < 4; ++r) {
                    const double xi = xg[p], eta = (1 - xi) * xg[q],
                                 zeta = (1 - xi) * (1 - xg[q]) * xg[r];
                    const double w = 6 * std::abs(volume) * wg[p] * wg[q] * wg[r] * (1 - xi) *
                                     (1 - xi) * (1 - xg[q]);
                    const double l[4] = {1 - xi - eta - zeta, xi, eta, zeta};
                    Vec3 y = Vec3::Zero(), u_h = Vec3::Zero();
                    for (int i = 0; i < 4; ++i) {
                        y += l[i] * x[static_cast<size_t>(i)];
                        u_h += l[i] * U.col(i);
                    }
                    const auto de = voigt_strain(s.grad(y) - grad_h);
                    energy += w * de.dot(D * de);
                    l2 += w * (s.u(y) - u_h).squaredNorm();
                }
    }
    return {std::sqrt(energy), std::sqrt(l2)};
}

} // namespace

TEST(Elastic3dConvergence, ManufacturedSolutionOrderOneInEnergyTwoInL2) {
    const Manufactured s;
    const fem::Material mat{.E = 1.0, .nu = 0.3};
    const double lam = mat.E * mat.nu / ((1 + mat.nu) * (1 - 2 * mat.nu)), mu = mat.shear_modulus();
    const auto D = fem::elasticity_matrix<3>(mat);
    mesh::TetMesh m = mesh::structured_box({0, 0, 0}, {1, 1, 1}, 2, 2, 2);
    std::vector<double> e_energy, e_l2;
    for (int level = 0; level <= 3; ++level) {
        if (level > 0) m = mesh::refine(m);
        std::vector<fem::VertexSupport3> supports;
        for (int v : fem::testing::box_boundary_vertices(m))
            supports.push_back({{v}, {true, true, true}, s.u(m.vertices[static_cast<size_t>(v)])});
        const Vector F =
            fem::body_force_loads(m, [&](const Vec3& x) { return s.body_force(x, lam, mu); });
        const Vector uh = fem::testing::solve_elastic(m, {mat}, supports, F);
        const auto [ee, el] = errors(m, uh, s, D);
        e_energy.push_back(ee);
        e_l2.push_back(el);
        std::printf("level %d: %d vertices, energy error %.4e, L2 error %.4e\n", level,
                    m.n_vertices(), ee, el);
    }
    for (size_t l = 1; l < e_energy.size(); ++l) {
        EXPECT_LT(e_energy[l], e_energy[l - 1]) << l;
        EXPECT_LT(e_l2[l], e_l2[l - 1]) << l;
    }
    // Observed orders between levels 1 -> 2 and 2 -> 3 (h halves per level).
    for (size_t l = 2; l < e_energy.size(); ++l) {
        const double p_energy = std::log2(e_energy[l - 1] / e_energy[l]);
        const double p_l2 = std::log2(e_l2[l - 1] / e_l2[l]);
        std::printf("observed orders (levels %zu -> %zu): energy %.3f, L2 %.3f\n", l - 1, l,
                    p_energy, p_l2);
        EXPECT_GE(p_energy, 0.9) << l;
        EXPECT_LE(p_energy, 1.2) << l;
        EXPECT_GE(p_l2, 1.8) << l;
        EXPECT_LE(p_l2, 2.3) << l;
    }
}

// SPDX-License-Identifier: MIT
// The P1 simplex kernels with the dimension as a parameter: the 2D instantiation against the
// triangle kernel, the tetrahedron's stiffness (rigid-body kernel, constant strain energy,
// orientation), and the 3D numbering of DofMap3.
#include "core/check.hpp"
#include "fem/dof_map.hpp"
#include "fem/elasticity.hpp"
#include "fem/simplex.hpp"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <random>

using namespace mlc;

TEST(SimplexKernels, TwoDimensionalInstantiationIsTheTriangleKernel) {
    std::mt19937 gen(11);
    std::uniform_real_distribution<double> u(-3.0, 3.0);
    const fem::Material mats[2] = {{.E = 210e3, .nu = 0.3},
                                   {.E = 0.7, .nu = 0.45, .plane = fem::Plane::stress}};
    int compared = 0;
    for (int trial = 0; trial < 200; ++trial) {
        fem::SimplexCorners<2> x = {Vec2(u(gen), u(gen)), Vec2(u(gen), u(gen)),
                                    Vec2(u(gen), u(gen))};
        const double det =
            (x[1] - x[0]).x() * (x[2] - x[0]).y() - (x[2] - x[0]).x() * (x[1] - x[0]).y();
        if (std::abs(det) < 0.1) continue;
        if (det < 0) std::swap(x[1], x[2]); // element_stiffness takes counter-clockwise corners
        for (const auto& mat : mats) {
            EXPECT_EQ(fem::elasticity_matrix<2>(mat), mat.D());
            const auto K = fem::element_stiffness(x[0], x[1], x[2], mat);
            const auto K2 = fem::simplex_stiffness<2>(x, fem::elasticity_matrix<2>(mat));
            EXPECT_LE((K2 - K).norm(), 1e-15 * K.norm());
            double area = 0, measure = 0;
            const auto B = fem::strain_matrix(x[0], x[1], x[2], area);
            const auto B2 = fem::voigt_strain_matrix<2>(fem::barycentric_gradients<2>(x, measure));
            EXPECT_EQ(measure, area);
            EXPECT_LE((B2 - B).norm(), 1e-15 * B.norm());
            for (int i = 0; i < 3; ++i) {
                const auto rows = fem::simplex_stiffness_rows<2>(x, mat.D(), i);
                EXPECT_LE((rows - K.middleRows<2>(2 * i)).norm(), 1e-15 * K.norm());
            }
            ++compared;
        }
    }
    EXPECT_GT(compared, 200);
}

namespace {

fem::SimplexCorners<3> some_tetrahedron() {
    return {Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d(1.7, 0.1, 0.2),
            Eigen::Vector3d(0.4, 1.3, -0.1), Eigen::Vector3d(0.5, 0.4, 1.9)};
}

} // namespace

TEST(SimplexKernels, BarycentricGradientsOfATetrahedron) {
    const auto x = some_tetrahedron();
    double volume = 0;
    const auto G = fem::barycentric_gradients<3>(x, volume);
    // volume = det(x1 - x0, x2 - x0, x3 - x0) / 6, and sum_i x_i grad l_i^T = I (the gradient
    // of the identity map), sum_i grad l_i = 0.
    Eigen::Matrix3d J;
    J << x[1] - x[0], x[2] - x[0], x[3] - x[0];
    EXPECT_NEAR(volume, J.determinant() / 6.0, 1e-15);
    Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
    for (int i = 0; i < 4; ++i)
        I += x[static_cast<size_t>(i)] * G.col(i).transpose();
    EXPECT_LE((I - Eigen::Matrix3d::Identity()).norm(), 1e-14);
    EXPECT_LE(G.rowwise().sum().norm(), 1e-14);
    // Swapping two corners flips the sign of the volume, not the gradients.
    auto y = x;
    std::swap(y[1], y[2]);
    double flipped = 0;
    const auto H = fem::barycentric_gradients<3>(y, flipped);
    EXPECT_NEAR(flipped, -volume, 1e-15);
    EXPECT_LE((H.col(1) - G.col(2)).norm() + (H.col(2) - G.col(1)).norm(), 1e-14);
}

TEST(SimplexKernels, TetrahedronStiffnessHasTheRigidModesAsKernel) {
    const auto x = some_tetrahedron();
    const fem::Material mat{.E = 210e3, .nu = 0.3};
    const auto K = fem::simplex_stiffness<3>(x, fem::elasticity_matrix<3>(mat));
    Eigen::Matrix<double, 12, 6> R = Eigen::Matrix<double, 12, 6>::Zero();
    for (int i = 0; i < 4; ++i) {
        const Eigen::Vector3d& p = x[static_cast<size_t>(i)];
        R.block<3, 3>(3 * i, 0).setIdentity();
        // Rotations about x, y, z: omega x p.
        R.block<3, 1>(3 * i, 3) << 0, -p.z(), p.y();
        R.block<3, 1>(3 * i, 4) << p.z(), 0, -p.x();
        R.block<3, 1>(3 * i, 5) << -p.y(), p.x(), 0;
    }
    EXPECT_LT((K * R).norm(), 1e-12 * K.norm() * R.norm());
    EXPECT_LT((K - K.transpose()).norm(), 1e-14 * K.norm());
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es{Eigen::MatrixXd(K)};
    const auto ev = es.eigenvalues();
    for (int i = 0; i < 6; ++i)
        EXPECT_LT(std::abs(ev[i]), 1e-12 * ev[11]);
    for (int i = 6; i < 12; ++i)
        EXPECT_GT(ev[i], 1e-3 * ev[11]);
    // Rows of one corner are the full matrix's rows.
    for (int i = 0; i < 4; ++i)
        EXPECT_LE((fem::simplex_stiffness_rows<3>(x, fem::elasticity_matrix<3>(mat), i) -
                   K.middleRows<3>(3 * i))
                      .norm(),
                  1e-15 * K.norm());
}

TEST(SimplexKernels, ConstantStrainEnergiesOfATetrahedron) {
    const auto x = some_tetrahedron();
    const fem::Material mat{.E = 100.0, .nu = 0.25};
    const double lam = mat.E * mat.nu / ((1 + mat.nu) * (1 - 2 * mat.nu));
    const double mu = mat.E / (2 * (1 + mat.nu));
    const auto K = fem::simplex_stiffness<3>(x, fem::elasticity_matrix<3>(mat));
    double volume = 0;
    fem::barycentric_gradients<3>(x, volume);
    const double e = 1e-3;
    // u = grad . x for a displacement gradient A: energy 0.5 V (lam tr(eps)^2 + 2 mu eps:eps).
    auto energy_of = [&](const Eigen::Matrix3d& A) {
        Eigen::Matrix<double, 12, 1> u;
        for (int i = 0; i < 4; ++i)
            u.segment<3>(3 * i) = A * x[static_cast<size_t>(i)];
        return 0.5 * u.dot(K * u);
    };
    auto exact = [&](const Eigen::Matrix3d& A) {
        const Eigen::Matrix3d eps = 0.5 * (A + A.transpose());
        return 0.5 * std::abs(volume) *
               (lam * eps.trace() * eps.trace() + 2 * mu * eps.squaredNorm());
    };
    Eigen::Matrix3d uniaxial = Eigen::Matrix3d::Zero(), shear = Eigen::Matrix3d::Zero();
    uniaxial(0, 0) = e; // energy 0.5 V (lam + 2 mu) e^2
    shear(1, 2) = e;    // u_y = e z: engineering strain gamma_yz = e, energy 0.5 V mu e^2
    EXPECT_NEAR(energy_of(uniaxial), 0.5 * std::abs(volume) * (lam + 2 * mu) * e * e, 1e-15);
    EXPECT_NEAR(energy_of(shear), 0.5 * std::abs(volume) * mu * e * e, 1e-15);
    Eigen::Matrix3d general;
    general << 1, 2, -1, 0.5, -3, 2, 1.5, 0.2, 0.7;
    general *= e;
    EXPECT_NEAR(energy_of(general), exact(general), 1e-13 * exact(general));
    // Hydrostatic strain (1, 1, 1, 0, 0, 0): the stress is 3 K = 3 lam + 2 mu on the diagonal.
    const Eigen::Matrix<double, 6, 1> sig =
        fem::elasticity_matrix<3>(mat) *
        (Eigen::Matrix<double, 6, 1>() << 1, 1, 1, 0, 0, 0).finished();
    EXPECT_NEAR(sig[0], mat.E / (1 - 2 * mat.nu), 1e-12);
    EXPECT_EQ(sig.tail<3>().norm(), 0.0);
    // The other orientation gives the same element matrix (corners 1 and 2 swapped back).
    auto y = x;
    std::swap(y[1], y[2]);
    auto Ky = fem::simplex_stiffness<3>(y, fem::elasticity_matrix<3>(mat));
    Eigen::PermutationMatrix<12> P;
    P.indices() << 0, 1, 2, 6, 7, 8, 3, 4, 5, 9, 10, 11;
    EXPECT_LE((P * K * P.transpose() - Ky).norm(), 1e-14 * K.norm());
}

TEST(DofMap3, NumbersFreeComponentsInterleavedWithExtrasAfterTheirVertex) {
    // Vertex 0: all free; 1: uy held; 2: all held; 3: ux free, one extra unknown.
    const std::vector<std::array<bool, 3>> fixed = {
        {false, false, false}, {false, true, false}, {true, true, true}, {false, true, true}};
    const fem::DofMap3 dofs(fixed, {0, 0, 0, 3});
    EXPECT_EQ(dofs.n_dofs(), 3 + 2 + 0 + 1 + 3);
    EXPECT_EQ(dofs.n_displacement_dofs(), 6);
    const int expected[4][3] = {{0, 1, 2}, {3, -1, 4}, {-1, -1, -1}, {5, -1, -1}};
    for (int v = 0; v < 4; ++v)
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(dofs.u_dof(v, c), expected[v][c]) << v << " " << c;
    EXPECT_EQ(dofs.extra_dof(3), 6);
    EXPECT_EQ(dofs.vertex_of(7), 3);
    EXPECT_FALSE(dofs.is_displacement(8));
    // A vertex order numbers vertex 3 first.
    const fem::DofMap3 ordered(fixed, {0, 0, 0, 0}, {3, 2, 1, 0});
    EXPECT_EQ(ordered.u_dof(3, 0), 0);
    EXPECT_EQ(ordered.u_dof(1, 0), 1);
    EXPECT_EQ(ordered.u_dof(0, 2), 5);
    // expand: x on the free components, u_fixed elsewhere.
    Vector x(dofs.n_dofs()), u_fixed(12), u;
    for (Index i = 0; i < x.size(); ++i)
        x[i] = 1.0 + static_cast<double>(i);
    for (Index i = 0; i < 12; ++i)
        u_fixed[i] = -1.0 - static_cast<double>(i);
    dofs.expand(x, u_fixed, u);
    ASSERT_EQ(u.size(), 12);
    for (int v = 0; v < 4; ++v)
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(u[3 * v + c], expected[v][c] >= 0 ? x[expected[v][c]] : u_fixed[3 * v + c]);
    EXPECT_THROW(fem::DofMap3(fixed, {0, 0, 0, 4}), InvalidInput);
    EXPECT_THROW(fem::DofMap3(fixed, {0, 0, 0}), InvalidInput);
    static_assert(fem::DofMap::kDim == 2 && fem::DofMap3::kDim == 3);
}

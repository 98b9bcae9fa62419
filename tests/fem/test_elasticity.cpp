// SPDX-License-Identifier: MIT
// Element stiffness properties and exact patch tests of P1 elasticity.
#include "core/check.hpp"
#include "fem/assembly.hpp"

#include "fem/elasticity.hpp"
#include "mesh/mesh.hpp"
#include "tests/common/direct_solve.hpp"
#include <functional>
#include <map>
#include <random>

#include <Eigen/Dense>
#include <gtest/gtest.h>

using namespace mlc;
using test::lu_solve;

TEST(ElementStiffness, RigidBodyModesAreInTheKernel) {
    const Vec2 a(0.3, -0.2), b(2.1, 0.4), c(0.9, 1.7);
    for (auto plane : {fem::Plane::strain, fem::Plane::stress}) {
        fem::Material m{.E = 210e3, .nu = 0.3, .plane = plane};
        const auto K = fem::element_stiffness(a, b, c, m);
        Eigen::Matrix<double, 6, 3> R;
        for (int i = 0; i < 3; ++i) {
            const Vec2 p = i == 0 ? a : (i == 1 ? b : c);
            R.row(2 * i) << 1, 0, -p.y();
            R.row(2 * i + 1) << 0, 1, p.x();
        }
        EXPECT_LT((K * R).norm(), 1e-12 * K.norm());
        EXPECT_LT((K - K.transpose()).norm(), 1e-14 * K.norm());
        // Exactly three zero eigenvalues, the other three positive.
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es{Eigen::MatrixXd(K)};
        const auto ev = es.eigenvalues();
        for (int i = 0; i < 3; ++i)
            EXPECT_LT(std::abs(ev[i]), 1e-12 * ev[5]);
        for (int i = 3; i < 6; ++i)
            EXPECT_GT(ev[i], 1e-3 * ev[5]);
    }
}

TEST(ElementStiffness, ConstantStrainEnergyIsExact) {
    // Energy of u = (e x, 0) on a triangle of area A: 0.5 A (lambda + 2 mu) e^2 (plane strain).
    const Vec2 a(0, 0), b(2, 0), c(0, 1);
    fem::Material m{.E = 100.0, .nu = 0.25};
    const auto K = fem::element_stiffness(a, b, c, m);
    const double e = 1e-3;
    Eigen::Matrix<double, 6, 1> u;
    u << e * a.x(), 0, e * b.x(), 0, e * c.x(), 0;
    const double energy = 0.5 * u.dot(K * u);
    const double lam = m.E * m.nu / ((1 + m.nu) * (1 - 2 * m.nu)), mu = m.E / (2 * (1 + m.nu));
    EXPECT_NEAR(energy, 0.5 * 1.0 * (lam + 2 * mu) * e * e, 1e-15);
}

TEST(ElementStiffness, RowsOfOneVertexAreTheFullMatrixRowsBitForBit) {
    std::mt19937 gen(7);
    std::uniform_real_distribution<double> u(-3.0, 3.0);
    const fem::Material mats[2] = {{.E = 210e3, .nu = 0.3},
                                   {.E = 0.7, .nu = 0.45, .plane = fem::Plane::stress}};
    int compared = 0;
    for (int trial = 0; trial < 200; ++trial) {
        const Vec2 a(u(gen), u(gen)), b(u(gen), u(gen)), c(u(gen), u(gen));
        if (std::abs((b - a).x() * (c - a).y() - (c - a).x() * (b - a).y()) < 1e-3) continue;
        const auto& mat = mats[trial % 2];
        const auto ke = fem::element_stiffness(a, b, c, mat);
        for (int i = 0; i < 3; ++i) {
            const auto rows = fem::element_stiffness_rows(a, b, c, mat.D(), i);
            for (int r = 0; r < 2; ++r)
                for (int j = 0; j < 6; ++j)
                    ASSERT_EQ(rows(r, j), ke(2 * i + r, j)) << trial << " " << i;
            ++compared;
        }
    }
    EXPECT_GT(compared, 500);
}

TEST(Material, RejectsOutOfRangeParameters) {
    EXPECT_THROW((fem::Material{.E = 0.0, .nu = 0.3}.validate()), InvalidInput);
    EXPECT_THROW((fem::Material{.E = -1.0, .nu = 0.3}.validate()), InvalidInput);
    EXPECT_THROW((fem::Material{.E = 1.0, .nu = 0.5}.validate()), InvalidInput);
    EXPECT_THROW((fem::Material{.E = 1.0, .nu = -1.0}.validate()), InvalidInput);
    EXPECT_NO_THROW((fem::Material{.E = 1.0, .nu = 0.4999}.validate()));
}

namespace {

/// Solves the elastic problem with the boundary displacements prescribed from u_exact on every
/// boundary vertex; returns the max nodal error over the interior.
double patch_error(const mesh::Mesh& m, const fem::Material& mat,
                   const std::function<Vec2(const Vec2&)>& u_exact) {
    std::vector<std::array<bool, 2>> fixed(static_cast<size_t>(m.n_vertices()), {false, false});
    Vector u_fixed = Vector::Zero(2 * m.n_vertices());
    for (const auto& e : m.boundary)
        for (int v : {e.v0, e.v1}) {
            fixed[static_cast<size_t>(v)] = {true, true};
            u_fixed.segment<2>(2 * v) = u_exact(m.vertices[static_cast<size_t>(v)]);
        }
    fem::DofMap dofs(fixed, std::vector<int>(static_cast<size_t>(m.n_vertices()), 0));
    const auto sys =
        fem::assemble_elastic(m, {mat}, dofs, Vector::Zero(2 * m.n_vertices()), u_fixed);
    const Vector x = lu_solve(sys.K, sys.f);
    Vector u;
    dofs.expand(x, u_fixed, u);
    double err = 0;
    for (int v = 0; v < m.n_vertices(); ++v)
        err = std::max(err,
                       (u.segment<2>(2 * v) - u_exact(m.vertices[static_cast<size_t>(v)])).norm());
    return err;
}

} // namespace

TEST(Assembly, LinearDisplacementPatchIsReproducedExactly) {
    // Distorted interior vertices: P1 must still reproduce any linear field exactly.
    mesh::Mesh m =
        mesh::structured_rectangle(Vec2(0, 0), Vec2(3, 2), 6, 4, mesh::Diagonal::alternate);
    for (int j = 1; j < 4; ++j)
        for (int i = 1; i < 6; ++i)
            m.vertices[static_cast<size_t>(j * 7 + i)] +=
                Vec2(0.07 * std::sin(i * j), 0.05 * std::cos(i + j));
    mesh::check_quality(m);
    auto lin = [](const Vec2& p) {
        return Vec2(1e-3 * (0.3 + 2 * p.x() - p.y()), 1e-3 * (0.1 + 0.5 * p.x() + 3 * p.y()));
    };
    EXPECT_LT(patch_error(m, {.E = 7.0, .nu = 0.35}, lin), 1e-15);
    EXPECT_LT(patch_error(m, {.E = 7.0, .nu = 0.35, .plane = fem::Plane::stress}, lin), 1e-15);
}

TEST(Assembly, UniaxialTractionGivesTheClosedFormExtension) {
    // Plane stress bar [0,4]x[0,1], u_x = 0 on the left, u_y = 0 at one point, traction p on the
    // right: u_x(L) = p L / E, u_y = -nu p y / E.
    mesh::Mesh m = mesh::structured_rectangle(Vec2(0, 0), Vec2(4, 1), 8, 2);
    const fem::Material mat{.E = 200.0, .nu = 0.3, .plane = fem::Plane::stress};
    std::vector<std::array<bool, 2>> fixed(static_cast<size_t>(m.n_vertices()), {false, false});
    for (int v : m.vertices_with_tag(m.tag("left")))
        fixed[static_cast<size_t>(v)][0] = true;
    fixed[0][1] = true;
    fem::DofMap dofs(fixed, std::vector<int>(static_cast<size_t>(m.n_vertices()), 0));
    const double p = 2.0;
    const Vector F =
        fem::nodal_loads(m, {{.tag = m.tag("right"), .pressure = 0.0, .vector = Vec2(p, 0)}}, {});
    EXPECT_NEAR(F.sum(), p * 1.0, 1e-14);
    const auto sys = fem::assemble_elastic(m, {mat}, dofs, F, Vector::Zero(2 * m.n_vertices()));
    Vector u;
    dofs.expand(lu_solve(sys.K, sys.f), Vector::Zero(2 * m.n_vertices()), u);
    for (int v = 0; v < m.n_vertices(); ++v) {
        const Vec2 x = m.vertices[static_cast<size_t>(v)];
        EXPECT_NEAR(u[2 * v], p * x.x() / mat.E, 1e-13);
        EXPECT_NEAR(u[2 * v + 1], -mat.nu * p * x.y() / mat.E, 1e-13);
    }
    const auto s = fem::cell_stresses(m, {mat}, u);
    for (int t = 0; t < m.n_cells(); ++t) {
        EXPECT_NEAR(s[static_cast<size_t>(3 * t)], p, 1e-11);
        EXPECT_NEAR(s[static_cast<size_t>(3 * t + 1)], 0.0, 1e-11);
    }
}

TEST(Assembly, RowsOverThreadsAreTheSerialElementLoopBitForBit) {
    // Each vertex's rows gather its triangles' element entries in ascending triangle order, over
    // several chunks of vertices (and threads): K and f must be, bit for bit, those of the serial
    // loop over triangles (element matrix by element matrix, summed per entry), with a prescribed,
    // non-zero displacement on the left side and two materials.
    mesh::Mesh m =
        mesh::structured_rectangle(Vec2(0, 0), Vec2(3, 2), 90, 60, mesh::Diagonal::alternate);
    ASSERT_GT(m.n_vertices(), 2 * 2048);
    m.attribute.assign(static_cast<size_t>(m.n_cells()), 0);
    for (int t = 0; t < m.n_cells(); t += 3)
        m.attribute[static_cast<size_t>(t)] = 1;
    const std::vector<fem::Material> mats{{.E = 7.0, .nu = 0.35}, {.E = 3e3, .nu = 0.1}};
    std::vector<std::array<bool, 2>> fixed(static_cast<size_t>(m.n_vertices()), {false, false});
    Vector u_fixed = Vector::Zero(2 * m.n_vertices());
    for (int v : m.vertices_with_tag(m.tag("left"))) {
        fixed[static_cast<size_t>(v)] = {true, true};
        u_fixed.segment<2>(2 * v) = Vec2(1e-3 * m.vertices[static_cast<size_t>(v)].y(), -2e-3);
    }
    // Vertices numbered backwards: rows and triangles in different orders.
    std::vector<int> order(static_cast<size_t>(m.n_vertices()));
    for (int v = 0; v < m.n_vertices(); ++v)
        order[static_cast<size_t>(v)] = m.n_vertices() - 1 - v;
    fem::DofMap dofs(fixed, std::vector<int>(static_cast<size_t>(m.n_vertices()), 0), order);
    const Vector F = Vector::LinSpaced(2 * m.n_vertices(), -1.0, 1.0);
    const auto sys = fem::assemble_elastic(m, mats, dofs, F, u_fixed);

    const Index n = dofs.n_dofs();
    std::map<std::pair<int, int>, double> K; // summed in triangle order
    Vector f = Vector::Zero(n);
    for (int v = 0; v < m.n_vertices(); ++v)
        for (int c = 0; c < 2; ++c)
            if (const int d = dofs.u_dof(v, c); d >= 0) f[d] = F[2 * v + c];
    const Vector loads = f;
    for (int t = 0; t < m.n_cells(); ++t) {
        const auto& tri = m.cells[static_cast<size_t>(t)];
        const auto ke = fem::element_stiffness(
            m.vertices[static_cast<size_t>(tri[0])], m.vertices[static_cast<size_t>(tri[1])],
            m.vertices[static_cast<size_t>(tri[2])], fem::material_of(m, mats, t));
        for (int i = 0; i < 6; ++i) {
            const int di = dofs.u_dof(tri[static_cast<size_t>(i / 2)], i % 2);
            if (di < 0) continue;
            for (int j = 0; j < 6; ++j) {
                const int w = tri[static_cast<size_t>(j / 2)];
                if (const int dj = dofs.u_dof(w, j % 2); dj >= 0)
                    K[{di, dj}] += ke(i, j);
                else
                    f[di] -= ke(i, j) * u_fixed[2 * w + j % 2];
            }
        }
    }
    // The same entries (the pattern is that of shared triangles), the same values.
    ASSERT_EQ(sys.K.nonZeros(), static_cast<Index>(K.size()));
    size_t mismatches = 0;
    for (int i = 0; i < sys.K.outerSize(); ++i)
        for (SparseMatrix::InnerIterator it(sys.K, i); it; ++it) {
            const auto at = K.find({i, static_cast<int>(it.col())});
            mismatches += at == K.end() || at->second != it.value();
        }
    EXPECT_EQ(mismatches, 0u);
    EXPECT_EQ((sys.f - f).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_GT((sys.f - loads).cwiseAbs().maxCoeff(), 1e-6); // the lifting of u_fixed is in f
}

TEST(Assembly, PressureIsANormalTractionIntoTheBody) {
    // Pressure on the top of a unit square pushes down: resultant (0, -p).
    const mesh::Mesh m = mesh::structured_rectangle(Vec2(0, 0), Vec2(1, 1), 3, 3);
    const Vector F =
        fem::nodal_loads(m, {{.tag = m.tag("top"), .pressure = 5.0, .vector = Vec2::Zero()}}, {});
    double fx = 0, fy = 0;
    for (int v = 0; v < m.n_vertices(); ++v) {
        fx += F[2 * v];
        fy += F[2 * v + 1];
    }
    EXPECT_NEAR(fx, 0.0, 1e-14);
    EXPECT_NEAR(fy, -5.0, 1e-14);
}

TEST(DofMap, NumbersVerticesInTheGivenOrderWithMultipliersAfterTheirDisplacements) {
    // Vertex 0: x fixed; vertex 1: free with 2 multipliers; vertex 2: free.
    const std::vector<std::array<bool, 2>> fixed = {{true, false}, {false, false}, {false, false}};
    const std::vector<int> extra = {0, 2, 0};
    const fem::DofMap natural(fixed, extra);
    EXPECT_EQ(natural.u_dof(0, 0), -1);
    EXPECT_EQ(natural.u_dof(0, 1), 0);
    EXPECT_EQ(natural.u_dof(1, 0), 1);
    EXPECT_EQ(natural.extra_dof(1), 3);
    EXPECT_EQ(natural.u_dof(2, 1), 6);
    const fem::DofMap ordered(fixed, extra, {2, 1, 0});
    EXPECT_EQ(ordered.n_dofs(), 7);
    EXPECT_EQ(ordered.u_dof(2, 0), 0);
    EXPECT_EQ(ordered.u_dof(2, 1), 1);
    EXPECT_EQ(ordered.u_dof(1, 0), 2);
    EXPECT_EQ(ordered.u_dof(1, 1), 3);
    EXPECT_EQ(ordered.extra_dof(1), 4);
    EXPECT_FALSE(ordered.is_displacement(5));
    EXPECT_EQ(ordered.vertex_of(5), 1);
    EXPECT_EQ(ordered.u_dof(0, 1), 6);
    EXPECT_EQ(ordered.u_dof(0, 0), -1);
    EXPECT_THROW(fem::DofMap(fixed, extra, {0, 1}), InvalidInput);    // too short
    EXPECT_THROW(fem::DofMap(fixed, extra, {0, 1, 1}), InvalidInput); // not a permutation
    EXPECT_THROW(fem::DofMap(fixed, extra, {0, 1, 3}), InvalidInput); // out of range
}

TEST(Assembly2D, TheDimensionGenericSupportsAndLoadsSolveTheLinearPatchExactly) {
    // The 2D instances of the supports and loads written for both dimensions: u = A x + c held
    // on the whole boundary (collect_supports over facet_vertices of every tag) is reproduced at
    // the interior vertices, and the body-force rule of degree 2 integrates b(x) = (x, x y)
    // exactly: the resultant is (int x, int x y) over [0, 2] x [0, 1] = (2, 1).
    mesh::Mesh m = mesh::structured_rectangle(Vec2(0, 0), Vec2(2, 1), 6, 3);
    Eigen::Matrix2d A;
    A << 0.01, -0.02, 0.03, 0.015;
    const Vec2 c(0.1, -0.2);
    std::vector<fem::VertexSupport2> supports;
    for (const char* tag : {"left", "right", "bottom", "top"})
        for (int v : fem::facet_vertices(m, m.tag(tag))) {
            const Vec2 x = m.vertices[static_cast<size_t>(v)];
            supports.push_back({.vertices = {v}, .value = A * x + c});
        }
    const fem::BasicSupports<2> s = fem::collect_supports(m, supports);
    const fem::DofMap dofs(s.fixed, std::vector<int>(static_cast<size_t>(m.n_vertices()), 0));
    ASSERT_GT(dofs.n_dofs(), 0);
    const fem::Material mat{.E = 3.0, .nu = 0.25};
    const auto sys =
        fem::assemble_elastic(m, {mat}, dofs, Vector::Zero(2 * m.n_vertices()), s.u_fixed);
    Vector u;
    dofs.expand(lu_solve(sys.K, sys.f), s.u_fixed, u);
    for (int v = 0; v < m.n_vertices(); ++v) {
        const Vec2 x = m.vertices[static_cast<size_t>(v)];
        EXPECT_NEAR((u.segment<2>(2 * v) - (A * x + c)).norm(), 0.0, 1e-14);
    }
    // Reactions balance: the internal forces of the exact field sum to zero.
    const Vector r = fem::internal_forces(m, {mat}, u);
    EXPECT_NEAR(r(Eigen::seq(0, Eigen::last, 2)).sum(), 0.0, 1e-13);
    EXPECT_NEAR(r(Eigen::seq(1, Eigen::last, 2)).sum(), 0.0, 1e-13);

    const Vector F =
        fem::body_force_loads(m, [](const Vec2& x) { return Vec2(x.x(), x.x() * x.y()); });
    EXPECT_NEAR(F(Eigen::seq(0, Eigen::last, 2)).sum(), 2.0, 1e-14);
    EXPECT_NEAR(F(Eigen::seq(1, Eigen::last, 2)).sum(), 1.0, 1e-14);
    // A constant body force: the same loads as nodal_loads' area / 3 per vertex.
    const Vector Fc = fem::body_force_loads(m, [](const Vec2&) { return Vec2(0.5, -1.5); });
    const Vector Fn = fem::nodal_loads(m, {}, {Vec2(0.5, -1.5)});
    EXPECT_LE((Fc - Fn).norm(), 1e-15 * Fn.norm() * m.n_vertices());
}

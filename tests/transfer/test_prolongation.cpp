// SPDX-License-Identifier: MIT
// Tests of the P transfer through Bey's 1->8 refinement: exact on linear fields, equal to the
// coarse P1 field evaluated at the fine vertices, expanded per component and restricted to free
// unknowns, on levels 0..3 of a Kuhn box and of a Gmsh mesh.
#include "mesh/io/gmsh_tet.hpp"
#include "mesh/tet_refine.hpp"
#include "tests/common/random.hpp"
#include "tests/mesh/tet_test_meshes.hpp"
#include "transfer/prolongation.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <filesystem>
#include <fstream>
#include <random>
#include <unistd.h>

using namespace mlc;
using namespace mlc::mesh;
using namespace mlc::transfer;
namespace fs = std::filesystem;
namespace tmesh = mlc::mesh::testing;

namespace {

/// The start meshes: a Kuhn box with unequal cells, and the distorted cube read from a .msh
/// file in format 2.2.
std::vector<std::pair<std::string, TetMesh>> start_meshes() {
    std::vector<std::pair<std::string, TetMesh>> out;
    out.emplace_back("box", structured_box(Vec3(-1, 0.5, 2), Vec3(2, 1.5, 0.75), 2, 2, 1));
    const fs::path file = fs::path(::testing::TempDir()) /
                          ("mlc_tet_transfer_" + std::to_string(::getpid()) + ".msh");
    {
        std::ofstream f(file);
        f << tmesh::msh22(tmesh::distorted_cube());
    }
    out.emplace_back("gmsh", read_gmsh_tet(file));
    fs::remove(file);
    return out;
}

/// Levels 0..3 of a start mesh.
std::vector<TetMesh> hierarchy(const TetMesh& m0) {
    std::vector<TetMesh> levels{m0};
    for (int l = 1; l <= 3; ++l)
        levels.push_back(refine(levels.back()));
    return levels;
}

Vector linear_field(const TetMesh& m, const Vec3& grad, double c) {
    Vector u(m.n_vertices());
    for (int v = 0; v < m.n_vertices(); ++v)
        u[v] = c + grad.dot(m.vertices[static_cast<size_t>(v)]);
    return u;
}

Vector random_field(int n, unsigned seed) {
    return testutil::random_vector(n, seed);
}

/// The coarse P1 field u evaluated at every fine vertex, through the barycentric coordinates of
/// the vertex in the parent of a fine tetrahedron containing it.
Vector evaluate_at_fine_vertices(const TetMesh& coarse, const Vector& u, const TetMesh& fine) {
    Vector out = Vector::Constant(fine.n_vertices(), std::nan(""));
    for (int t = 0; t < fine.n_cells(); ++t) {
        const auto& ct = coarse.cells[static_cast<size_t>(parent_tetrahedron(t))];
        const auto x = tmesh::corners(coarse, parent_tetrahedron(t));
        Eigen::Matrix3d J;
        J << x[1] - x[0], x[2] - x[0], x[3] - x[0];
        const Eigen::PartialPivLU<Eigen::Matrix3d> lu(J);
        for (int v : fine.cells[static_cast<size_t>(t)]) {
            const Vec3 b = lu.solve(fine.vertices[static_cast<size_t>(v)] - x[0]);
            out[v] = (1 - b.sum()) * u[ct[0]] + b[0] * u[ct[1]] + b[1] * u[ct[2]] + b[2] * u[ct[3]];
        }
    }
    return out;
}

/// Per-vertex unknowns, numbered vertex by vertex (interleaved) when `interleaved`, else
/// component by component with a gap of 5 unknowns (standing for multipliers) before each
/// component block; prescribed components get -1. Returns the unknowns and their count.
std::pair<VertexUnknowns, int> number(const std::vector<std::array<bool, 3>>& fixed,
                                      bool interleaved) {
    VertexUnknowns u(fixed.size(), {-1, -1, -1});
    int n = 0;
    if (interleaved) {
        for (size_t v = 0; v < fixed.size(); ++v)
            for (size_t c = 0; c < 3; ++c)
                if (!fixed[v][c]) u[v][c] = n++;
        return {u, n};
    }
    for (size_t c = 0; c < 3; ++c) {
        n += 5;
        for (size_t v = 0; v < fixed.size(); ++v)
            if (!fixed[v][c]) u[v][c] = n++;
    }
    return {u, n};
}

/// Supports: ux on the face tagged xmin, uz on the face tagged zmin (box), or ux on "bottom"
/// and all three on the vertices of "top" (the Gmsh mesh).
std::vector<std::array<bool, 3>> supports(const TetMesh& m, const std::string& name) {
    std::vector<std::array<bool, 3>> fixed(static_cast<size_t>(m.n_vertices()),
                                           {false, false, false});
    const bool box = name == "box";
    for (int v : m.vertices_with_tag(m.tag(box ? "xmin" : "bottom")))
        fixed[static_cast<size_t>(v)][0] = true;
    for (int v : m.vertices_with_tag(m.tag(box ? "zmin" : "top")))
        for (size_t c = box ? 2 : 0; c < 3; ++c)
            fixed[static_cast<size_t>(v)][c] = true;
    return fixed;
}

} // namespace

TEST(TetTransfer, ExactOnLinearFieldsAndEqualToInterpolation) {
    for (const auto& [name, m0] : start_meshes()) {
        const auto levels = hierarchy(m0);
        for (size_t l = 1; l < levels.size(); ++l) {
            SCOPED_TRACE(name + " level " + std::to_string(l));
            const TetMesh &coarse = levels[l - 1], &fine = levels[l];
            const MovableSparseMatrix P = vertex_prolongation(fine);
            ASSERT_EQ(P.rows(), fine.n_vertices());
            ASSERT_EQ(P.cols(), coarse.n_vertices());
            const Vec3 grad(0.7, -1.3, 2.9);
            const Vector lin_f = linear_field(fine, grad, -0.4);
            const Vector diff = P * linear_field(coarse, grad, -0.4) - lin_f;
            EXPECT_LE(diff.lpNorm<Eigen::Infinity>(), 1e-14 * lin_f.lpNorm<Eigen::Infinity>());
            const Vector u = random_field(coarse.n_vertices(), static_cast<unsigned>(l));
            const Vector at = evaluate_at_fine_vertices(coarse, u, fine);
            ASSERT_FALSE(at.hasNaN()); // every fine vertex is in some fine tetrahedron
            EXPECT_LE((P * u - at).lpNorm<Eigen::Infinity>(), 1e-14 * u.lpNorm<Eigen::Infinity>());
            // Each row sums to one: constants are kept.
            EXPECT_LE(
                (P * Vector::Ones(P.cols()) - Vector::Ones(P.rows())).lpNorm<Eigen::Infinity>(),
                0.0);
        }
    }
}

TEST(TetTransfer, ExpandedMatrixInterpolatesVectorFieldsComponentByComponent) {
    for (const auto& [name, m0] : start_meshes()) {
        const auto levels = hierarchy(m0);
        for (size_t l = 1; l < levels.size(); ++l) {
            SCOPED_TRACE(name + " level " + std::to_string(l));
            const TetMesh &coarse = levels[l - 1], &fine = levels[l];
            const MovableSparseMatrix P = vertex_prolongation(fine);
            const MovableSparseMatrix P3 = expand_components(P, 3);
            ASSERT_EQ(P3.rows(), 3 * fine.n_vertices());
            ASSERT_EQ(P3.cols(), 3 * coarse.n_vertices());
            EXPECT_EQ(P3.nonZeros(), 3 * P.nonZeros());
            // A linear displacement u(x) = A x + b, interleaved (ux, uy, uz) per vertex.
            Eigen::Matrix3d A;
            A << 1.0, -0.5, 0.25, 0.3, 2.0, -1.1, -0.7, 0.6, 1.4;
            const Vec3 b(0.1, -0.2, 0.3);
            auto field = [&](const TetMesh& m) {
                Vector u(3 * m.n_vertices());
                for (int v = 0; v < m.n_vertices(); ++v)
                    u.segment<3>(3 * v) = A * m.vertices[static_cast<size_t>(v)] + b;
                return u;
            };
            const Vector uf = field(fine);
            EXPECT_LE((P3 * field(coarse) - uf).lpNorm<Eigen::Infinity>(),
                      1e-14 * uf.lpNorm<Eigen::Infinity>());
            // Component c of a random field goes through P alone.
            const Vector u = random_field(3 * coarse.n_vertices(), 7u + static_cast<unsigned>(l));
            const Vector pu = P3 * u;
            for (int c = 0; c < 3; ++c) {
                Vector uc(coarse.n_vertices());
                for (int v = 0; v < coarse.n_vertices(); ++v)
                    uc[v] = u[3 * v + c];
                const Vector puc = P * uc;
                for (int v = 0; v < fine.n_vertices(); ++v)
                    ASSERT_EQ(pu[3 * v + c], puc[v]) << "vertex " << v << " component " << c;
            }
        }
    }
}

TEST(TetTransfer, RestrictedToFreeUnknownsOfAnyNumbering) {
    for (const auto& [name, m0] : start_meshes()) {
        const auto levels = hierarchy(m0);
        for (size_t l = 1; l < levels.size(); ++l)
            for (bool interleaved : {true, false}) {
                SCOPED_TRACE(name + " level " + std::to_string(l) +
                             (interleaved ? " interleaved" : " blocked"));
                const TetMesh &coarse = levels[l - 1], &fine = levels[l];
                const auto fixed_c = supports(coarse, name), fixed_f = supports(fine, name);
                const auto [uc, nc] = number(fixed_c, interleaved);
                const auto [uf, nf] = number(fixed_f, interleaved);
                const MovableSparseMatrix P = vertex_prolongation(fine);
                const MovableSparseMatrix T = restrict_to_unknowns(P, 3, uc, nc, uf, nf);
                ASSERT_EQ(T.rows(), nf);
                ASSERT_EQ(T.cols(), nc);
                // A coarse correction (zero on prescribed components) prolongated on the
                // unknowns equals the full nodal P3 applied to it, read at the free fine unknowns.
                const Vector x = random_field(nc, 11u + static_cast<unsigned>(l));
                Vector full = Vector::Zero(3 * coarse.n_vertices());
                for (size_t v = 0; v < uc.size(); ++v)
                    for (size_t c = 0; c < 3; ++c)
                        if (uc[v][c] >= 0) full[static_cast<Index>(3 * v + c)] = x[uc[v][c]];
                const Vector pfull = expand_components(P, 3) * full;
                const Vector y = T * x;
                Vector expected = Vector::Zero(nf); // the gaps (multipliers) stay zero
                for (size_t v = 0; v < uf.size(); ++v)
                    for (size_t c = 0; c < 3; ++c)
                        if (uf[v][c] >= 0)
                            expected[uf[v][c]] = pfull[static_cast<Index>(3 * v + c)];
                EXPECT_LE((y - expected).lpNorm<Eigen::Infinity>(),
                          1e-15 * x.lpNorm<Eigen::Infinity>());
                // Coarse vertices keep their free values exactly.
                for (int v = 0; v < coarse.n_vertices(); ++v)
                    for (size_t c = 0; c < 3; ++c) {
                        if (uc[static_cast<size_t>(v)][c] < 0) continue;
                        ASSERT_EQ(y[uf[static_cast<size_t>(v)][c]],
                                  x[uc[static_cast<size_t>(v)][c]]);
                    }
            }
    }
}

TEST(TetTransfer, RefusesSupportsThatDoNotNestAndBadNumberings) {
    const TetMesh coarse = structured_box(Vec3(0, 0, 0), Vec3(1, 1, 1), 1, 1, 1);
    const TetMesh fine = refine(coarse);
    const MovableSparseMatrix P = vertex_prolongation(fine);
    std::vector<std::array<bool, 3>> fc(8, {false, false, false});
    auto ff = std::vector<std::array<bool, 3>>(static_cast<size_t>(fine.n_vertices()),
                                               {false, false, false});
    fc[5][1] = true; // uy of coarse vertex 5 prescribed on the coarse level only
    // Named copies, not structured bindings: clang 14 (the sanitizer build) refuses to capture
    // structured bindings in a lambda.
    const auto coarse_numbering = number(fc, true);
    const auto fine_numbering = number(ff, true);
    const auto& uc = coarse_numbering.first;
    const int nc = coarse_numbering.second;
    const auto& uf = fine_numbering.first;
    const int nf = fine_numbering.second;
    tmesh::expect_invalid([&] { restrict_to_unknowns(P, 3, uc, nc, uf, nf); },
                          {"component 1 of coarse vertex 5", "supports must nest"});
    auto twice = uf;
    twice[9][2] = twice[3][0];
    tmesh::expect_invalid([&] { restrict_to_unknowns(P, 3, uc, nc, twice, nf); },
                          {"fine unknown 9 is used twice", "vertex 9"});
    tmesh::expect_invalid([&] { restrict_to_unknowns(P, 3, uc, nc - 1, uf, nf); },
                          {"component 2 of coarse vertex 7 has unknown 22, outside 0..21"});
    tmesh::expect_invalid([&] { vertex_prolongation(coarse); }, {"must come from mesh::refine"});
    tmesh::expect_invalid([&] { expand_components(P, 4); }, {"4 components per vertex"});
}

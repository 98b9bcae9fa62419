// SPDX-License-Identifier: MIT
/// @file What the 3D elasticity tests share: a direct solve of the assembled system, the
/// vertices of every box face, and a perturbed box read through the Gmsh reader.
#pragma once

#include "fem/assembly.hpp"
#include "mesh/io/gmsh_tet.hpp"
#include "mesh/tet_mesh.hpp"
#include "solvers/cholesky.hpp"
#include "tests/mesh/tet_test_meshes.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <unistd.h>

namespace mlc::fem::testing {

/// The six tags of mesh::structured_box.
inline const char* const kBoxTags[6] = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};

/// Solves the elastic problem with every listed support, the given nodal loads and materials;
/// returns the full displacement (3 per vertex).
inline Vector solve_elastic(const mesh::TetMesh& m, const std::vector<Material>& materials,
                            const std::vector<VertexSupport3>& supports, const Vector& loads) {
    const Supports3 s = collect_supports(m, supports);
    const DofMap3 dofs(s.fixed, std::vector<int>(static_cast<size_t>(m.n_vertices()), 0));
    const ElasticSystem sys = assemble_elastic(m, materials, dofs, loads, s.u_fixed);
    // CHOLMOD on the matrix in a fill-reducing order (order[new] = old).
    const SparseMatrixCol K = sys.K;
    const std::vector<int> order = solvers::SparseCholesky::fill_reducing_order(K);
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> P(K.rows());
    for (size_t k = 0; k < order.size(); ++k)
        P.indices()[order[k]] = static_cast<int>(k);
    SparseMatrixCol Kp;
    Kp = K.selfadjointView<Eigen::Lower>().twistedBy(P);
    solvers::SparseCholesky chol;
    chol.factor(Kp);
    Vector y;
    chol.solve(P * sys.f, y);
    const Vector x = P.transpose() * y;
    Vector u;
    dofs.expand(x, s.u_fixed, u);
    return u;
}

/// Every vertex on a face of a structured box, sorted.
inline std::vector<int> box_boundary_vertices(const mesh::TetMesh& m) {
    std::vector<int> all;
    for (const char* tag : kBoxTags) {
        const auto v = facet_vertices(m, m.tag(tag));
        all.insert(all.end(), v.begin(), v.end());
    }
    std::sort(all.begin(), all.end());
    all.erase(std::unique(all.begin(), all.end()), all.end());
    return all;
}

/// The box [0, 1.2] x [0, 1] x [0, 0.9] with n^3 cells, every vertex moved at random by up to
/// a tenth of a cell (boundary vertices within their faces), written as a .msh file of format
/// `version` ("2.2" or "4.1") in the test's temp dir and read back: tetrahedra in physical
/// volume 1 ("body"), the six faces as physical surfaces 1..6 named as the box's tags.
inline mesh::TetMesh perturbed_gmsh_box(int n, const std::string& version) {
    const mesh::TetMesh box = mesh::structured_box({0, 0, 0}, {1.2, 1.0, 0.9}, n, n, n);
    std::mt19937 gen(5);
    std::uniform_real_distribution<double> jitter(-0.1, 0.1);
    mesh::testing::MshSpec s;
    const Eigen::Array3d cell = Eigen::Array3d(1.2, 1.0, 0.9) / n;
    const Eigen::Array3d top(1.2, 1.0, 0.9);
    for (const auto& p : box.vertices) {
        Eigen::Array3d q = p.array();
        for (int a = 0; a < 3; ++a) {
            const double d = jitter(gen) * cell[a];
            const bool on_face = std::abs(q[a]) < 1e-12 || std::abs(q[a] - top[a]) < 1e-12;
            if (!on_face) q[a] += d;
        }
        s.nodes.push_back(q.matrix());
    }
    for (const auto& f : box.boundary) {
        const int tag = f.tag + 1;
        s.triangles.push_back({tag, {f.v[0] + 1, f.v[1] + 1, f.v[2] + 1}});
    }
    for (std::array<int, 4> k : box.cells) {
        const auto& x = s.nodes;
        const Vec3& a = x[static_cast<size_t>(k[0])];
        if ((x[static_cast<size_t>(k[1])] - a)
                .cross(x[static_cast<size_t>(k[2])] - a)
                .dot(x[static_cast<size_t>(k[3])] - a) < 0)
            std::swap(k[2], k[3]);
        for (int& v : k)
            ++v;
        s.tets.push_back({1, k});
    }
    for (const auto& [name, id] : box.tag_names)
        s.names.push_back("2 " + std::to_string(id + 1) + " \"" + name + "\"");
    s.names.push_back("3 1 \"body\"");
    const std::filesystem::path file =
        std::filesystem::path(::testing::TempDir()) /
        ("mlc_fem3d_box_" + version + "_" + std::to_string(::getpid()) + ".msh");
    std::ofstream(file) << (version == "2.2" ? mesh::testing::msh22(s) : mesh::testing::msh41(s));
    mesh::TetMesh m = mesh::read_gmsh_tet(file, "body");
    std::filesystem::remove(file);
    return m;
}

} // namespace mlc::fem::testing

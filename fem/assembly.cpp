// SPDX-License-Identifier: MIT
// Global assembly of the elastic problem.
#include "fem/assembly.hpp"

#include "core/check.hpp"
#include "core/first_touch.hpp"
#include "core/parallel.hpp"

#include <algorithm>

namespace mlc::fem {

namespace {

void check_materials(const mesh::Mesh& m, const std::vector<Material>& materials) {
    MLC_CHECK(!materials.empty(), "no material given");
    for (const auto& mat : materials)
        mat.validate();
    for (int a : m.attribute)
        MLC_CHECK(a >= 0 && a < static_cast<int>(materials.size()),
                  "triangle attribute " << a << " has no material (" << materials.size()
                                        << " given)");
}

} // namespace

Vector nodal_loads(const mesh::Mesh& m, const std::vector<Traction>& tractions,
                   const std::vector<Vec2>& body_force) {
    Vector F = Vector::Zero(2 * m.n_vertices());
    for (const auto& tr : tractions)
        for (const auto& e : m.boundary) {
            if (e.tag != tr.tag) continue;
            const Vec2 a = m.vertices[static_cast<size_t>(e.v0)];
            const Vec2 b = m.vertices[static_cast<size_t>(e.v1)];
            const Vec2 d = b - a;
            const double L = d.norm();
            const Vec2 n_out(d.y() / L, -d.x() / L); // domain on the left of a -> b
            const Vec2 t = tr.vector - tr.pressure * n_out;
            for (int v : {e.v0, e.v1})
                F.segment<2>(2 * v) += 0.5 * L * t;
        }
    if (!body_force.empty())
        for (int t = 0; t < m.n_cells(); ++t) {
            const int a = m.attribute.empty() ? 0 : m.attribute[static_cast<size_t>(t)];
            MLC_CHECK(a < static_cast<int>(body_force.size()), "no body force for attribute " << a);
            const Vec2 f = m.signed_measure(t) / 3.0 * body_force[static_cast<size_t>(a)];
            for (int v : m.cells[static_cast<size_t>(t)])
                F.segment<2>(2 * v) += f;
        }
    return F;
}

ElasticSystem assemble_elastic(const mesh::Mesh& m, const std::vector<Material>& materials,
                               const DofMap& dofs, const Vector& nodal_load_full,
                               const Vector& u_fixed) {
    check_materials(m, materials);
    MLC_CHECK(dofs.n_vertices() == m.n_vertices(), "DofMap and mesh disagree on vertex count");
    ElasticSystem sys;
    sys.f_nodal_full.resize(nodal_load_full.size());
    parallel::copy(nodal_load_full.data(), static_cast<size_t>(nodal_load_full.size()),
                   sys.f_nodal_full.data());
    const Index n = dofs.n_dofs();
    sys.f = parallel::zeros(n);
    const int nv = m.n_vertices();
    for (int v = 0; v < nv; ++v)
        for (int c = 0; c < 2; ++c)
            if (int d = dofs.u_dof(v, c); d >= 0) sys.f[d] = nodal_load_full[2 * v + c];

    // The pattern, straight into CSR: vertex w's free components are in the row of each free
    // component of v when v and w share a triangle. (Triplets and setFromTriplets would take 36 x
    // 16 bytes per triangle and a sort.) Each vertex's rows are written by one thread: the loops
    // over vertices below run over core/parallel's threads. Triangles of each vertex, ascending per
    // vertex: the serial summation order.
    const mesh::VertexTriangles vtri = mesh::vertex_triangles(m);
    const std::vector<int>& vt_start = vtri.offset;
    const std::vector<int>& vt = vtri.triangles;
    constexpr size_t kVerticesPerChunk = 2048;
    auto for_vertices = [&](auto&& fn) {
        parallel::for_rows(static_cast<size_t>(nv), kVerticesPerChunk, [&](size_t b, size_t e) {
            for (size_t v = b; v < e; ++v)
                fn(static_cast<int>(v));
        });
    };
    // Neighbours of v (v included), sorted, in adj[3 vt_start[v], adj_end[v]).
    // adj is first written here, by the threads (core/first_touch): 300 MB at level 7.
    const auto adj = parallel::uninitialized_array<int>(3 * vt.size());
    std::vector<int> adj_end(static_cast<size_t>(nv));
    for_vertices([&](int v) {
        const int b = 3 * vt_start[static_cast<size_t>(v)];
        int* out = adj.get() + b;
        for (int k = vt_start[static_cast<size_t>(v)]; k < vt_start[static_cast<size_t>(v) + 1];
             ++k)
            for (int w : m.cells[static_cast<size_t>(vt[static_cast<size_t>(k)])])
                *out++ = w;
        std::sort(adj.get() + b, out);
        adj_end[static_cast<size_t>(v)] =
            static_cast<int>(std::unique(adj.get() + b, out) - adj.get());
    });
    sys.K.resize(n, n);
    std::vector<int> row_nnz(static_cast<size_t>(n), 0);
    for_vertices([&](int v) {
        int cols = 0;
        for (int k = 3 * vt_start[static_cast<size_t>(v)]; k < adj_end[static_cast<size_t>(v)]; ++k)
            for (int c = 0; c < 2; ++c)
                cols += dofs.u_dof(adj[static_cast<size_t>(k)], c) >= 0;
        for (int c = 0; c < 2; ++c)
            if (const int d = dofs.u_dof(v, c); d >= 0) row_nnz[static_cast<size_t>(d)] = cols;
    });
    int* outer = sys.K.outerIndexPtr();
    outer[0] = 0;
    for (Index i = 0; i < n; ++i)
        outer[i + 1] = outer[i] + row_nnz[static_cast<size_t>(i)];
    sys.K.resizeNonZeros(outer[n]);
    int* inner = sys.K.innerIndexPtr();
    double* val = sys.K.valuePtr();
    for_vertices([&](int v) {
        for (int c = 0; c < 2; ++c) {
            const int d = dofs.u_dof(v, c);
            if (d < 0) continue;
            int* out = inner + outer[d];
            for (int k = 3 * vt_start[static_cast<size_t>(v)]; k < adj_end[static_cast<size_t>(v)];
                 ++k)
                for (int cw = 0; cw < 2; ++cw)
                    if (const int dw = dofs.u_dof(adj[static_cast<size_t>(k)], cw); dw >= 0)
                        *out++ = dw;
            std::sort(inner + outer[d], out);
            std::fill(val + outer[d], out - inner + val, 0.0);
        }
    });

    // Values: the rows of v gather the element entries of v's triangles, in ascending triangle
    // order (the order of the serial loop over triangles, so the sums are the same bit for bit),
    // each at its place in the row (binary search in ~14 columns). Each vertex forms only its own
    // two rows of the element matrix (element_stiffness_rows, the same sums bit for bit).
    std::vector<Eigen::Matrix3d> D;
    for (const auto& mat : materials)
        D.push_back(mat.D());
    for_vertices([&](int v) {
        if (dofs.u_dof(v, 0) < 0 && dofs.u_dof(v, 1) < 0) return;
        for (int k = vt_start[static_cast<size_t>(v)]; k < vt_start[static_cast<size_t>(v) + 1];
             ++k) {
            const int t = vt[static_cast<size_t>(k)];
            const auto& tri = m.cells[static_cast<size_t>(t)];
            const int a = m.attribute.empty() ? 0 : m.attribute[static_cast<size_t>(t)];
            const int iv = tri[0] == v ? 0 : tri[1] == v ? 1 : 2;
            const auto ke = element_stiffness_rows(
                m.vertices[static_cast<size_t>(tri[0])], m.vertices[static_cast<size_t>(tri[1])],
                m.vertices[static_cast<size_t>(tri[2])], D[static_cast<size_t>(a)], iv);
            int idx[6];
            for (int i = 0; i < 3; ++i)
                for (int c = 0; c < 2; ++c)
                    idx[2 * i + c] = dofs.u_dof(tri[static_cast<size_t>(i)], c);
            for (int c = 0; c < 2; ++c) {
                const int row = idx[2 * iv + c];
                if (row < 0) continue;
                const int* rb = inner + outer[row];
                const int* re = inner + outer[row + 1];
                for (int j = 0; j < 6; ++j) {
                    if (idx[j] >= 0) {
                        const int* at = std::lower_bound(rb, re, idx[j]);
                        val[at - inner] += ke(c, j);
                    } else {
                        const int w = tri[static_cast<size_t>(j / 2)];
                        sys.f[row] -= ke(c, j) * u_fixed[2 * w + j % 2];
                    }
                }
            }
        }
    });
    return sys;
}

Vector internal_forces(const mesh::Mesh& m, const std::vector<Material>& materials,
                       const Vector& u_full) {
    Vector F = Vector::Zero(2 * m.n_vertices());
    for (int t = 0; t < m.n_cells(); ++t) {
        const auto& tri = m.cells[static_cast<size_t>(t)];
        const auto ke = element_stiffness(
            m.vertices[static_cast<size_t>(tri[0])], m.vertices[static_cast<size_t>(tri[1])],
            m.vertices[static_cast<size_t>(tri[2])], material_of(m, materials, t));
        Eigen::Matrix<double, 6, 1> ue;
        for (int i = 0; i < 3; ++i)
            ue.segment<2>(2 * i) = u_full.segment<2>(2 * tri[static_cast<size_t>(i)]);
        const Eigen::Matrix<double, 6, 1> fe = ke * ue;
        for (int i = 0; i < 3; ++i)
            F.segment<2>(2 * tri[static_cast<size_t>(i)]) += fe.segment<2>(2 * i);
    }
    return F;
}

std::vector<double> triangle_stresses(const mesh::Mesh& m, const std::vector<Material>& materials,
                                      const Vector& u_full) {
    std::vector<double> s(static_cast<size_t>(3 * m.n_cells()));
    for (int t = 0; t < m.n_cells(); ++t) {
        const auto& tri = m.cells[static_cast<size_t>(t)];
        double area = 0;
        const auto B = strain_matrix(m.vertices[static_cast<size_t>(tri[0])],
                                     m.vertices[static_cast<size_t>(tri[1])],
                                     m.vertices[static_cast<size_t>(tri[2])], area);
        Eigen::Matrix<double, 6, 1> ue;
        for (int i = 0; i < 3; ++i)
            ue.segment<2>(2 * i) = u_full.segment<2>(2 * tri[static_cast<size_t>(i)]);
        const Eigen::Vector3d sig = material_of(m, materials, t).D() * (B * ue);
        for (int k = 0; k < 3; ++k)
            s[static_cast<size_t>(3 * t + k)] = sig[k];
    }
    return s;
}

} // namespace mlc::fem

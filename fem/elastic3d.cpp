// SPDX-License-Identifier: MIT
// P1 elasticity on tetrahedral meshes.
#include "fem/elastic3d.hpp"

#include "core/check.hpp"
#include "core/first_touch.hpp"
#include "core/parallel.hpp"
#include "fem/simplex.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace mlc::fem {

namespace {

using Tet = std::array<int, 4>;

const Tet& tet_of(const mesh::TetMesh& m, int t) {
    return m.cells[static_cast<size_t>(t)];
}

SimplexCorners<3> corners_of(const mesh::TetMesh& m, int t) {
    SimplexCorners<3> x;
    for (int i = 0; i < 4; ++i)
        x[static_cast<size_t>(i)] =
            m.vertices[static_cast<size_t>(tet_of(m, t)[static_cast<size_t>(i)])];
    return x;
}

int attribute_of(const mesh::TetMesh& m, int t) {
    return m.attribute.empty() ? 0 : m.attribute[static_cast<size_t>(t)];
}

/// The boundary tags of m, named, for messages.
std::string boundary_tags(const mesh::TetMesh& m) {
    std::vector<int> tags;
    for (const auto& f : m.boundary)
        tags.push_back(f.tag);
    std::sort(tags.begin(), tags.end());
    tags.erase(std::unique(tags.begin(), tags.end()), tags.end());
    std::string s;
    for (int t : tags)
        s += (s.empty() ? "'" : ", '") + m.tag_name(t) + "'";
    return s.empty() ? "none" : s;
}

void check_boundary_tag(const mesh::TetMesh& m, int tag, const char* what) {
    MLC_CHECK(m.is_boundary_tag(tag), what << ": no boundary face carries the tag '"
                                           << m.tag_name(tag)
                                           << "'; the boundary tags are: " << boundary_tags(m));
}

/// The elasticity matrices of the materials, after checking them and the attributes.
std::vector<VoigtMatrix<3>> material_matrices(const mesh::TetMesh& m,
                                              const std::vector<Material>& materials) {
    MLC_CHECK(!materials.empty(), "no material given");
    std::vector<VoigtMatrix<3>> D;
    for (size_t k = 0; k < materials.size(); ++k) {
        materials[k].validate();
        MLC_CHECK(materials[k].plane == Plane::strain,
                  "material " << k << " asks for plane stress, a 2D reduction; a 3D body has none");
        D.push_back(elasticity_matrix<3>(materials[k]));
    }
    MLC_CHECK(m.attribute.empty() || m.attribute.size() == m.cells.size(),
              "the mesh has " << m.attribute.size() << " attributes for " << m.n_cells()
                              << " tetrahedra");
    for (size_t t = 0; t < m.attribute.size(); ++t) {
        const int a = m.attribute[t];
        MLC_CHECK(a >= 0 && a < static_cast<int>(materials.size()),
                  "tetrahedron " << t << " has attribute " << a << ", which has no material ("
                                 << materials.size() << " given, attributes 0.."
                                 << materials.size() - 1 << ")");
    }
    return D;
}

/// Tetrahedra of each vertex, ascending: tets[offset[v] .. offset[v + 1]).
struct VertexTets {
    std::vector<int> offset, tets;
};

VertexTets vertex_tets(const mesh::TetMesh& m) {
    VertexTets r;
    r.offset.assign(static_cast<size_t>(m.n_vertices()) + 1, 0);
    for (const auto& tet : m.cells)
        for (int v : tet) {
            MLC_CHECK(v >= 0 && v < m.n_vertices(), "tetrahedron vertex " << v << " out of range");
            ++r.offset[static_cast<size_t>(v) + 1];
        }
    for (size_t v = 0; v < static_cast<size_t>(m.n_vertices()); ++v)
        r.offset[v + 1] += r.offset[v];
    r.tets.resize(static_cast<size_t>(r.offset.back()));
    std::vector<int> next(r.offset.begin(), r.offset.end() - 1);
    for (int t = 0; t < m.n_cells(); ++t)
        for (int v : tet_of(m, t))
            r.tets[static_cast<size_t>(next[static_cast<size_t>(v)]++)] = t;
    return r;
}

template <class Fn> void for_vertices(int nv, Fn&& fn) {
    constexpr size_t kVerticesPerChunk = 1024;
    parallel::for_rows(static_cast<size_t>(nv), kVerticesPerChunk, [&](size_t b, size_t e) {
        for (size_t v = b; v < e; ++v)
            fn(static_cast<int>(v));
    });
}

/// The CSR pattern of K: the row of each free component of v holds the free components of the
/// vertices sharing a tetrahedron with v, in ascending order; values zero.
void build_pattern(const mesh::TetMesh& m, const DofMap3& dofs, const VertexTets& vt,
                   SparseMatrix& K) {
    const int nv = m.n_vertices();
    const Index n = dofs.n_dofs();
    // Neighbours of v (v included), sorted and unique, in adj[4 offset[v], adj_end[v]).
    std::vector<int> adj(4 * vt.tets.size());
    std::vector<int> adj_end(static_cast<size_t>(nv));
    for_vertices(nv, [&](int v) {
        const auto b = static_cast<size_t>(4 * vt.offset[static_cast<size_t>(v)]);
        auto out = adj.begin() + static_cast<std::ptrdiff_t>(b);
        for (int k = vt.offset[static_cast<size_t>(v)]; k < vt.offset[static_cast<size_t>(v) + 1];
             ++k)
            for (int w : tet_of(m, vt.tets[static_cast<size_t>(k)]))
                *out++ = w;
        const auto first = adj.begin() + static_cast<std::ptrdiff_t>(b);
        std::sort(first, out);
        adj_end[static_cast<size_t>(v)] = static_cast<int>(std::unique(first, out) - adj.begin());
    });
    auto neighbours = [&](int v, auto&& fn) {
        for (int k = 4 * vt.offset[static_cast<size_t>(v)]; k < adj_end[static_cast<size_t>(v)];
             ++k)
            fn(adj[static_cast<size_t>(k)]);
    };
    K.resize(n, n);
    std::vector<int> row_nnz(static_cast<size_t>(n), 0);
    for_vertices(nv, [&](int v) {
        int cols = 0;
        neighbours(v, [&](int w) {
            for (int c = 0; c < 3; ++c)
                cols += dofs.u_dof(w, c) >= 0;
        });
        for (int c = 0; c < 3; ++c)
            if (const int d = dofs.u_dof(v, c); d >= 0) row_nnz[static_cast<size_t>(d)] = cols;
    });
    int* outer = K.outerIndexPtr();
    outer[0] = 0;
    for (Index i = 0; i < n; ++i)
        outer[i + 1] = outer[i] + row_nnz[static_cast<size_t>(i)];
    K.resizeNonZeros(outer[n]);
    int* inner = K.innerIndexPtr();
    double* val = K.valuePtr();
    for_vertices(nv, [&](int v) {
        for (int c = 0; c < 3; ++c) {
            const int d = dofs.u_dof(v, c);
            if (d < 0) continue;
            int* out = inner + outer[d];
            neighbours(v, [&](int w) {
                for (int cw = 0; cw < 3; ++cw)
                    if (const int dw = dofs.u_dof(w, cw); dw >= 0) *out++ = dw;
            });
            std::sort(inner + outer[d], out);
            std::fill(val + outer[d], val + (out - inner), 0.0);
        }
    });
}

} // namespace

Supports3 collect_supports(const mesh::TetMesh& m, const std::vector<VertexSupport>& supports) {
    Supports3 s;
    s.fixed.assign(static_cast<size_t>(m.n_vertices()), Components3{false, false, false});
    s.u_fixed = Vector::Zero(3 * m.n_vertices());
    for (size_t k = 0; k < supports.size(); ++k) {
        const auto& sup = supports[k];
        MLC_CHECK(sup.value.allFinite(),
                  "support " << k << " prescribes a value that is not finite");
        for (int v : sup.vertices) {
            MLC_CHECK(v >= 0 && v < m.n_vertices(), "support " << k << " names vertex " << v
                                                               << ", out of range (the mesh has "
                                                               << m.n_vertices() << " vertices)");
            for (int c = 0; c < 3; ++c)
                if (sup.components[static_cast<size_t>(c)]) {
                    s.fixed[static_cast<size_t>(v)][static_cast<size_t>(c)] = true;
                    s.u_fixed[3 * v + c] = sup.value[c];
                }
        }
    }
    return s;
}

std::vector<int> face_vertices(const mesh::TetMesh& m, int tag) {
    check_boundary_tag(m, tag, "face support");
    return m.vertices_with_tag(tag);
}

std::vector<int> line_vertices(const mesh::TetMesh& m, int tag_a, int tag_b) {
    check_boundary_tag(m, tag_a, "line support");
    check_boundary_tag(m, tag_b, "line support");
    const std::vector<int> a = m.vertices_with_tag(tag_a), b = m.vertices_with_tag(tag_b);
    std::vector<int> both;
    std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(both));
    return both;
}

std::vector<int> segment_vertices(const mesh::TetMesh& m, const Vec3& a, const Vec3& b,
                                  double tol) {
    MLC_CHECK(tol >= 0 && std::isfinite(tol), "segment support: tolerance " << tol);
    MLC_CHECK(a.allFinite() && b.allFinite(), "segment support: an end is not finite");
    const Vec3 d = b - a;
    const double dd = d.squaredNorm();
    std::vector<int> out;
    for (int v = 0; v < m.n_vertices(); ++v) {
        const Vec3& p = m.vertices[static_cast<size_t>(v)];
        const double s = dd > 0 ? std::clamp((p - a).dot(d) / dd, 0.0, 1.0) : 0.0;
        if ((a + s * d - p).norm() <= tol) out.push_back(v);
    }
    return out;
}

Vector nodal_loads(const mesh::TetMesh& m, const std::vector<Traction3>& tractions,
                   const std::vector<Vec3>& body_force) {
    Vector F = Vector::Zero(3 * m.n_vertices());
    for (const auto& tr : tractions) {
        check_boundary_tag(m, tr.tag, "traction");
        MLC_CHECK(std::isfinite(tr.pressure) && tr.vector.allFinite(),
                  "traction on '" << m.tag_name(tr.tag) << "' is not finite");
        for (const auto& f : m.boundary) {
            if (f.tag != tr.tag) continue;
            const Vec3& a = m.vertices[static_cast<size_t>(f.v[0])];
            // (v1 - v0) x (v2 - v0) / 2: the face's area times its outer normal.
            const Vec3 area_n = 0.5 * (m.vertices[static_cast<size_t>(f.v[1])] - a)
                                          .cross(m.vertices[static_cast<size_t>(f.v[2])] - a);
            const Vec3 share = (area_n.norm() * tr.vector - tr.pressure * area_n) / 3.0;
            for (int v : f.v)
                F.segment<3>(3 * v) += share;
        }
    }
    if (!body_force.empty())
        for (int t = 0; t < m.n_cells(); ++t) {
            const int a = attribute_of(m, t);
            MLC_CHECK(a >= 0 && a < static_cast<int>(body_force.size()),
                      "tetrahedron " << t << " has attribute " << a << ", which has no body force ("
                                     << body_force.size() << " given)");
            const Vec3 share =
                std::abs(m.signed_measure(t)) / 4.0 * body_force[static_cast<size_t>(a)];
            for (int v : tet_of(m, t))
                F.segment<3>(3 * v) += share;
        }
    return F;
}

Vector body_force_loads(const mesh::TetMesh& m, const std::function<Vec3(const Vec3&)>& b) {
    // The 4-point rule of degree 2: barycentric coordinates (a, c, c, c) and permutations,
    // weights 1/4.
    const double a = 0.5854101966249685, c = 0.1381966011250105;
    Vector F = Vector::Zero(3 * m.n_vertices());
    for (int t = 0; t < m.n_cells(); ++t) {
        const auto x = corners_of(m, t);
        const double w = std::abs(m.signed_measure(t)) / 4.0;
        for (int q = 0; q < 4; ++q) {
            double l[4] = {c, c, c, c};
            l[q] = a;
            const Vec3 p = l[0] * x[0] + l[1] * x[1] + l[2] * x[2] + l[3] * x[3];
            const Vec3 f = w * b(p);
            for (int i = 0; i < 4; ++i)
                F.segment<3>(3 * tet_of(m, t)[static_cast<size_t>(i)]) += l[i] * f;
        }
    }
    return F;
}

ElasticSystem assemble_elastic(const mesh::TetMesh& m, const std::vector<Material>& materials,
                               const DofMap3& dofs, const Vector& nodal_load_full,
                               const Vector& u_fixed) {
    const std::vector<VoigtMatrix<3>> D = material_matrices(m, materials);
    const int nv = m.n_vertices();
    MLC_CHECK(dofs.n_vertices() == nv,
              "the DofMap3 has " << dofs.n_vertices() << " vertices, the mesh " << nv);
    MLC_CHECK(nodal_load_full.size() == 3 * nv && u_fixed.size() == 3 * nv,
              "nodal loads (" << nodal_load_full.size() << ") and prescribed displacements ("
                              << u_fixed.size() << ") need 3 values per vertex (" << 3 * nv << ")");
    ElasticSystem sys;
    sys.f_nodal_full = nodal_load_full;
    sys.f = Vector::Zero(dofs.n_dofs());
    for (int v = 0; v < nv; ++v)
        for (int c = 0; c < 3; ++c)
            if (const int d = dofs.u_dof(v, c); d >= 0) sys.f[d] = nodal_load_full[3 * v + c];
    const VertexTets vt = vertex_tets(m);
    build_pattern(m, dofs, vt, sys.K);

    // Values: the rows of v gather v's rows of the element matrices of its tetrahedra, in
    // ascending order, each at its place in the row (binary search); prescribed columns go to f.
    const int* outer = sys.K.outerIndexPtr();
    const int* inner = sys.K.innerIndexPtr();
    double* val = sys.K.valuePtr();
    for_vertices(nv, [&](int v) {
        if (dofs.u_dof(v, 0) < 0 && dofs.u_dof(v, 1) < 0 && dofs.u_dof(v, 2) < 0) return;
        for (int k = vt.offset[static_cast<size_t>(v)]; k < vt.offset[static_cast<size_t>(v) + 1];
             ++k) {
            const int t = vt.tets[static_cast<size_t>(k)];
            const Tet& tet = tet_of(m, t);
            const int iv = static_cast<int>(std::find(tet.begin(), tet.end(), v) - tet.begin());
            const auto ke = simplex_stiffness_rows<3>(
                corners_of(m, t), D[static_cast<size_t>(attribute_of(m, t))], iv);
            for (int c = 0; c < 3; ++c) {
                const int row = dofs.u_dof(v, c);
                if (row < 0) continue;
                const int* rb = inner + outer[row];
                const int* re = inner + outer[row + 1];
                for (int j = 0; j < 12; ++j) {
                    const int w = tet[static_cast<size_t>(j / 3)];
                    if (const int col = dofs.u_dof(w, j % 3); col >= 0)
                        val[std::lower_bound(rb, re, col) - inner] += ke(c, j);
                    else
                        sys.f[row] -= ke(c, j) * u_fixed[3 * w + j % 3];
                }
            }
        }
    });
    return sys;
}

Vector internal_forces(const mesh::TetMesh& m, const std::vector<Material>& materials,
                       const Vector& u_full) {
    const std::vector<VoigtMatrix<3>> D = material_matrices(m, materials);
    MLC_CHECK(u_full.size() == 3 * m.n_vertices(),
              "displacements: " << u_full.size() << " values for " << m.n_vertices()
                                << " vertices (3 per vertex)");
    Vector F = Vector::Zero(3 * m.n_vertices());
    for (int t = 0; t < m.n_cells(); ++t) {
        const Tet& tet = tet_of(m, t);
        const auto ke =
            simplex_stiffness<3>(corners_of(m, t), D[static_cast<size_t>(attribute_of(m, t))]);
        Eigen::Matrix<double, 12, 1> ue;
        for (int i = 0; i < 4; ++i)
            ue.segment<3>(3 * i) = u_full.segment<3>(3 * tet[static_cast<size_t>(i)]);
        const Eigen::Matrix<double, 12, 1> fe = ke * ue;
        for (int i = 0; i < 4; ++i)
            F.segment<3>(3 * tet[static_cast<size_t>(i)]) += fe.segment<3>(3 * i);
    }
    return F;
}

std::vector<double> tetrahedron_stresses(const mesh::TetMesh& m,
                                         const std::vector<Material>& materials,
                                         const Vector& u_full) {
    const std::vector<VoigtMatrix<3>> D = material_matrices(m, materials);
    MLC_CHECK(u_full.size() == 3 * m.n_vertices(),
              "displacements: " << u_full.size() << " values for " << m.n_vertices()
                                << " vertices (3 per vertex)");
    std::vector<double> s(static_cast<size_t>(6 * m.n_cells()));
    for (int t = 0; t < m.n_cells(); ++t) {
        const Tet& tet = tet_of(m, t);
        double volume = 0;
        const auto B = voigt_strain_matrix<3>(barycentric_gradients<3>(corners_of(m, t), volume));
        Eigen::Matrix<double, 12, 1> ue;
        for (int i = 0; i < 4; ++i)
            ue.segment<3>(3 * i) = u_full.segment<3>(3 * tet[static_cast<size_t>(i)]);
        const Eigen::Matrix<double, 6, 1> sig =
            D[static_cast<size_t>(attribute_of(m, t))] * (B * ue);
        for (int k = 0; k < 6; ++k)
            s[static_cast<size_t>(6 * t + k)] = sig[k];
    }
    return s;
}

} // namespace mlc::fem

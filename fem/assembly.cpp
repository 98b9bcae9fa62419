// SPDX-License-Identifier: MIT
// P1 elasticity on simplex meshes: supports, loads, assembly, internal forces, stresses.
#include "fem/assembly.hpp"

#include "core/check.hpp"
#include "core/first_touch.hpp"
#include "core/parallel.hpp"
#include "fem/simplex.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <string>

namespace mlc::fem {

namespace {

template <int dim> constexpr const char* kFacetName = dim == 2 ? "edge" : "face";
template <int dim> constexpr std::string_view kCellName = mesh::SimplexTraits<dim>::cell_name;

template <int dim> int attribute_of(const mesh::SimplexMesh<dim>& m, int t) {
    return m.attribute.empty() ? 0 : m.attribute[static_cast<size_t>(t)];
}

template <int dim> SimplexCorners<dim> corners_of(const mesh::SimplexMesh<dim>& m, int t) {
    SimplexCorners<dim> x;
    for (int i = 0; i <= dim; ++i)
        x[static_cast<size_t>(i)] = m.vertices[static_cast<size_t>(
            m.cells[static_cast<size_t>(t)][static_cast<size_t>(i)])];
    return x;
}

/// The boundary tags of m, named, for messages.
template <int dim> std::string boundary_tags(const mesh::SimplexMesh<dim>& m) {
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

template <int dim>
void check_boundary_tag(const mesh::SimplexMesh<dim>& m, int tag, const char* what) {
    MLC_CHECK(m.is_boundary_tag(tag),
              what << ": no boundary " << kFacetName<dim> << " carries the tag '" << m.tag_name(tag)
                   << "'; the boundary tags are: " << boundary_tags(m));
}

/// The elasticity matrices of the materials, after checking them and the cells' attributes.
template <int dim>
std::vector<VoigtMatrix<dim>> material_matrices(const mesh::SimplexMesh<dim>& m,
                                                const std::vector<Material>& materials) {
    MLC_CHECK(!materials.empty(), "no material given");
    std::vector<VoigtMatrix<dim>> D;
    for (size_t k = 0; k < materials.size(); ++k) {
        materials[k].validate();
        if constexpr (dim == 3)
            MLC_CHECK(materials[k].plane == Plane::strain,
                      "material " << k
                                  << " asks for plane stress, a 2D reduction; a 3D body has none");
        D.push_back(elasticity_matrix<dim>(materials[k]));
    }
    MLC_CHECK(m.attribute.empty() || m.attribute.size() == m.cells.size(),
              "the mesh has " << m.attribute.size() << " attributes for " << m.n_cells() << " "
                              << kCellName<dim> << "s");
    for (size_t t = 0; t < m.attribute.size(); ++t) {
        const int a = m.attribute[t];
        MLC_CHECK(a >= 0 && a < static_cast<int>(materials.size()),
                  kCellName<dim> << " " << t << " has attribute " << a
                                 << ", which has no material (" << materials.size()
                                 << " given, attributes 0.." << materials.size() - 1 << ")");
    }
    return D;
}

template <int dim>
void check_nodal_size(const mesh::SimplexMesh<dim>& m, const Vector& u, const char* what) {
    MLC_CHECK(u.size() == dim * m.n_vertices(), what << ": " << u.size() << " values for "
                                                     << m.n_vertices() << " vertices (" << dim
                                                     << " values per vertex)");
}

/// Rows dim iv .. dim iv + dim - 1 of cell t's element stiffness (vertex iv's rows). 2D:
/// fem/elasticity.hpp's kernel, the one every 2D result was computed with.
template <int dim>
Eigen::Matrix<double, dim, kSimplexDofs<dim>> element_rows(const mesh::SimplexMesh<dim>& m, int t,
                                                           const VoigtMatrix<dim>& D, int iv) {
    if constexpr (dim == 2) {
        const auto& tri = m.cells[static_cast<size_t>(t)];
        return element_stiffness_rows(m.vertices[static_cast<size_t>(tri[0])],
                                      m.vertices[static_cast<size_t>(tri[1])],
                                      m.vertices[static_cast<size_t>(tri[2])], D, iv);
    } else {
        return simplex_stiffness_rows<dim>(corners_of(m, t), D, iv);
    }
}

/// Cell t's element stiffness (2D: fem/elasticity.hpp's kernel).
template <int dim>
SimplexStiffness<dim> element_matrix(const mesh::SimplexMesh<dim>& m, int t,
                                     const std::vector<Material>& materials,
                                     const std::vector<VoigtMatrix<dim>>& D) {
    if constexpr (dim == 2) {
        const auto& tri = m.cells[static_cast<size_t>(t)];
        return element_stiffness(
            m.vertices[static_cast<size_t>(tri[0])], m.vertices[static_cast<size_t>(tri[1])],
            m.vertices[static_cast<size_t>(tri[2])], material_of(m, materials, t));
    } else {
        return simplex_stiffness<dim>(corners_of(m, t), D[static_cast<size_t>(attribute_of(m, t))]);
    }
}

/// The element's displacements, dim per vertex interleaved.
template <int dim>
Eigen::Matrix<double, kSimplexDofs<dim>, 1> element_values(const mesh::SimplexMesh<dim>& m, int t,
                                                           const Vector& u_full) {
    Eigen::Matrix<double, kSimplexDofs<dim>, 1> ue;
    for (int i = 0; i <= dim; ++i)
        ue.template segment<dim>(dim * i) =
            u_full.segment<dim>(dim * m.cells[static_cast<size_t>(t)][static_cast<size_t>(i)]);
    return ue;
}

template <class Fn> void for_vertices(int nv, Fn&& fn) {
    constexpr size_t kVerticesPerChunk = 2048;
    parallel::for_rows(static_cast<size_t>(nv), kVerticesPerChunk, [&](size_t b, size_t e) {
        for (size_t v = b; v < e; ++v)
            fn(static_cast<int>(v));
    });
}

} // namespace

template <int dim>
BasicSupports<dim>
collect_supports(const mesh::SimplexMesh<dim>& m,
                 const NoDeduce<std::vector<BasicVertexSupport<dim>>>& supports) {
    BasicSupports<dim> s;
    Components<dim> none;
    none.fill(false);
    s.fixed.assign(static_cast<size_t>(m.n_vertices()), none);
    s.u_fixed = Vector::Zero(dim * m.n_vertices());
    for (size_t k = 0; k < supports.size(); ++k) {
        const auto& sup = supports[k];
        MLC_CHECK(sup.value.allFinite(),
                  "support " << k << " prescribes a value that is not finite");
        for (int v : sup.vertices) {
            MLC_CHECK(v >= 0 && v < m.n_vertices(), "support " << k << " names vertex " << v
                                                               << ", out of range (the mesh has "
                                                               << m.n_vertices() << " vertices)");
            for (int c = 0; c < dim; ++c)
                if (sup.components[static_cast<size_t>(c)]) {
                    s.fixed[static_cast<size_t>(v)][static_cast<size_t>(c)] = true;
                    s.u_fixed[dim * v + c] = sup.value[c];
                }
        }
    }
    return s;
}

template <int dim> std::vector<int> facet_vertices(const mesh::SimplexMesh<dim>& m, int tag) {
    const std::string what = std::string(kFacetName<dim>) + " support";
    check_boundary_tag(m, tag, what.c_str());
    return m.vertices_with_tag(tag);
}

template <int dim>
std::vector<int> line_vertices(const mesh::SimplexMesh<dim>& m, int tag_a, int tag_b) {
    check_boundary_tag(m, tag_a, "line support");
    check_boundary_tag(m, tag_b, "line support");
    const std::vector<int> a = m.vertices_with_tag(tag_a), b = m.vertices_with_tag(tag_b);
    std::vector<int> both;
    std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(both));
    return both;
}

template <int dim>
std::vector<int> segment_vertices(const mesh::SimplexMesh<dim>& m, const PointArg<dim>& a,
                                  const PointArg<dim>& b, double tol) {
    MLC_CHECK(tol >= 0 && std::isfinite(tol), "segment support: tolerance " << tol);
    MLC_CHECK(a.allFinite() && b.allFinite(), "segment support: an end is not finite");
    const PointD<dim> d = b - a;
    const double dd = d.squaredNorm();
    std::vector<int> out;
    for (int v = 0; v < m.n_vertices(); ++v) {
        const PointD<dim>& p = m.vertices[static_cast<size_t>(v)];
        const double s = dd > 0 ? std::clamp((p - a).dot(d) / dd, 0.0, 1.0) : 0.0;
        if ((a + s * d - p).norm() <= tol) out.push_back(v);
    }
    return out;
}

template <int dim>
Vector nodal_loads(const mesh::SimplexMesh<dim>& m,
                   const NoDeduce<std::vector<BasicTraction<dim>>>& tractions,
                   const NoDeduce<std::vector<PointD<dim>>>& body_force) {
    Vector F = Vector::Zero(dim * m.n_vertices());
    for (const auto& tr : tractions) {
        MLC_CHECK(std::isfinite(tr.pressure) && tr.vector.allFinite(),
                  "traction on '" << m.tag_name(tr.tag) << "' is not finite");
        for (const auto& f : m.boundary) {
            if (f.tag != tr.tag) continue;
            if constexpr (dim == 2) {
                const Vec2 a = m.vertices[static_cast<size_t>(f.v0)];
                const Vec2 b = m.vertices[static_cast<size_t>(f.v1)];
                const Vec2 d = b - a;
                const double L = d.norm();
                const Vec2 n_out(d.y() / L, -d.x() / L); // domain on the left of a -> b
                const Vec2 t = tr.vector - tr.pressure * n_out;
                for (int v : {f.v0, f.v1})
                    F.segment<2>(2 * v) += 0.5 * L * t;
            } else {
                const Vec3& a = m.vertices[static_cast<size_t>(f.v[0])];
                // (v1 - v0) x (v2 - v0) / 2: the face's area times its outer normal.
                const Vec3 area_n = 0.5 * (m.vertices[static_cast<size_t>(f.v[1])] - a)
                                              .cross(m.vertices[static_cast<size_t>(f.v[2])] - a);
                const Vec3 share = (area_n.norm() * tr.vector - tr.pressure * area_n) / 3.0;
                for (int v : f.v)
                    F.segment<3>(3 * v) += share;
            }
        }
    }
    if (!body_force.empty())
        for (int t = 0; t < m.n_cells(); ++t) {
            const int a = attribute_of(m, t);
            MLC_CHECK(a >= 0 && a < static_cast<int>(body_force.size()),
                      kCellName<dim> << " " << t << " has attribute " << a
                                     << ", which has no body force (" << body_force.size()
                                     << " given)");
            const PointD<dim> share =
                std::abs(m.signed_measure(t)) / (dim + 1.0) * body_force[static_cast<size_t>(a)];
            for (int v : m.cells[static_cast<size_t>(t)])
                F.segment<dim>(dim * v) += share;
        }
    return F;
}

template <int dim>
Vector body_force_loads(const mesh::SimplexMesh<dim>& m,
                        const NoDeduce<std::function<PointD<dim>(const PointD<dim>&)>>& b) {
    // Degree 2: barycentric coordinates (a, c, ..) and their permutations, weights 1/(dim + 1):
    // 2D (2/3, 1/6, 1/6), 3D (0.585.., 0.138.., ..).
    const double a = dim == 2 ? 2.0 / 3.0 : 0.5854101966249685;
    const double c = dim == 2 ? 1.0 / 6.0 : 0.1381966011250105;
    Vector F = Vector::Zero(dim * m.n_vertices());
    for (int t = 0; t < m.n_cells(); ++t) {
        const auto x = corners_of(m, t);
        const double w = std::abs(m.signed_measure(t)) / (dim + 1.0);
        for (int q = 0; q <= dim; ++q) {
            std::array<double, dim + 1> l;
            l.fill(c);
            l[static_cast<size_t>(q)] = a;
            PointD<dim> p = PointD<dim>::Zero();
            for (int i = 0; i <= dim; ++i)
                p += l[static_cast<size_t>(i)] * x[static_cast<size_t>(i)];
            const PointD<dim> f = w * b(p);
            for (int i = 0; i <= dim; ++i)
                F.segment<dim>(dim * m.cells[static_cast<size_t>(t)][static_cast<size_t>(i)]) +=
                    l[static_cast<size_t>(i)] * f;
        }
    }
    return F;
}

template <int dim>
ElasticSystem assemble_elastic(const mesh::SimplexMesh<dim>& m,
                               const std::vector<Material>& materials, const BasicDofMap<dim>& dofs,
                               const Vector& nodal_load_full, const Vector& u_fixed) {
    const std::vector<VoigtMatrix<dim>> D = material_matrices(m, materials);
    const int nv = m.n_vertices();
    MLC_CHECK(dofs.n_vertices() == nv,
              "the DofMap has " << dofs.n_vertices() << " vertices, the mesh " << nv);
    check_nodal_size(m, nodal_load_full, "nodal loads");
    check_nodal_size(m, u_fixed, "prescribed displacements");
    ElasticSystem sys;
    sys.f_nodal_full.resize(nodal_load_full.size());
    parallel::copy(nodal_load_full.data(), static_cast<size_t>(nodal_load_full.size()),
                   sys.f_nodal_full.data());
    const Index n = dofs.n_dofs();
    sys.f = parallel::zeros(n);
    for (int v = 0; v < nv; ++v)
        for (int c = 0; c < dim; ++c)
            if (const int d = dofs.u_dof(v, c); d >= 0) sys.f[d] = nodal_load_full[dim * v + c];

    // The pattern, straight into CSR: vertex w's free components are in the row of each free
    // component of v when v and w share a cell. (Triplets and setFromTriplets would take
    // (dim (dim + 1))^2 x 16 bytes per cell and a sort.) Each vertex's rows are written by one
    // thread: the loops over vertices below run over core/parallel's threads. Cells of each
    // vertex ascending: the serial summation order.
    const mesh::VertexCells vc = mesh::vertex_cells(m);
    const std::vector<int>& vc_start = vc.offset;
    const std::vector<int>& vcell = vc.cells;
    constexpr int kCorners = dim + 1;
    // Neighbours of v (v included), sorted, in adj[kCorners vc_start[v], adj_end[v]).
    // adj is first written here, by the threads (core/first_touch): 300 MB at 2D level 7.
    const auto adj = parallel::uninitialized_array<int>(kCorners * vcell.size());
    std::vector<int> adj_end(static_cast<size_t>(nv));
    for_vertices(nv, [&](int v) {
        const int b = kCorners * vc_start[static_cast<size_t>(v)];
        int* out = adj.get() + b;
        for (int k = vc_start[static_cast<size_t>(v)]; k < vc_start[static_cast<size_t>(v) + 1];
             ++k)
            for (int w : m.cells[static_cast<size_t>(vcell[static_cast<size_t>(k)])])
                *out++ = w;
        std::sort(adj.get() + b, out);
        adj_end[static_cast<size_t>(v)] =
            static_cast<int>(std::unique(adj.get() + b, out) - adj.get());
    });
    sys.K.resize(n, n);
    std::vector<int> row_nnz(static_cast<size_t>(n), 0);
    for_vertices(nv, [&](int v) {
        int cols = 0;
        for (int k = kCorners * vc_start[static_cast<size_t>(v)];
             k < adj_end[static_cast<size_t>(v)]; ++k)
            for (int c = 0; c < dim; ++c)
                cols += dofs.u_dof(adj[static_cast<size_t>(k)], c) >= 0;
        for (int c = 0; c < dim; ++c)
            if (const int d = dofs.u_dof(v, c); d >= 0) row_nnz[static_cast<size_t>(d)] = cols;
    });
    int* outer = sys.K.outerIndexPtr();
    outer[0] = 0;
    for (Index i = 0; i < n; ++i)
        outer[i + 1] = outer[i] + row_nnz[static_cast<size_t>(i)];
    sys.K.resizeNonZeros(outer[n]);
    int* inner = sys.K.innerIndexPtr();
    double* val = sys.K.valuePtr();
    for_vertices(nv, [&](int v) {
        for (int c = 0; c < dim; ++c) {
            const int d = dofs.u_dof(v, c);
            if (d < 0) continue;
            int* out = inner + outer[d];
            for (int k = kCorners * vc_start[static_cast<size_t>(v)];
                 k < adj_end[static_cast<size_t>(v)]; ++k)
                for (int cw = 0; cw < dim; ++cw)
                    if (const int dw = dofs.u_dof(adj[static_cast<size_t>(k)], cw); dw >= 0)
                        *out++ = dw;
            std::sort(inner + outer[d], out);
            std::fill(val + outer[d], out - inner + val, 0.0);
        }
    });

    // Values: the rows of v gather the element entries of v's cells, in ascending cell order (the
    // order of the serial loop over cells, so the sums are the same bit for bit), each at its
    // place in the row (binary search); prescribed columns go to f. Each vertex forms only its
    // own dim rows of the element matrix (the same sums bit for bit).
    for_vertices(nv, [&](int v) {
        bool any_free = false;
        for (int c = 0; c < dim; ++c)
            any_free = any_free || dofs.u_dof(v, c) >= 0;
        if (!any_free) return;
        for (int k = vc_start[static_cast<size_t>(v)]; k < vc_start[static_cast<size_t>(v) + 1];
             ++k) {
            const int t = vcell[static_cast<size_t>(k)];
            const auto& cell = m.cells[static_cast<size_t>(t)];
            const int iv = static_cast<int>(std::find(cell.begin(), cell.end(), v) - cell.begin());
            const auto ke = element_rows(m, t, D[static_cast<size_t>(attribute_of(m, t))], iv);
            int idx[kSimplexDofs<dim>];
            for (int i = 0; i < kCorners; ++i)
                for (int c = 0; c < dim; ++c)
                    idx[dim * i + c] = dofs.u_dof(cell[static_cast<size_t>(i)], c);
            for (int c = 0; c < dim; ++c) {
                const int row = idx[dim * iv + c];
                if (row < 0) continue;
                const int* rb = inner + outer[row];
                const int* re = inner + outer[row + 1];
                for (int j = 0; j < kSimplexDofs<dim>; ++j) {
                    if (idx[j] >= 0) {
                        const int* at = std::lower_bound(rb, re, idx[j]);
                        val[at - inner] += ke(c, j);
                    } else {
                        const int w = cell[static_cast<size_t>(j / dim)];
                        sys.f[row] -= ke(c, j) * u_fixed[dim * w + j % dim];
                    }
                }
            }
        }
    });
    return sys;
}

template <int dim>
Vector internal_forces(const mesh::SimplexMesh<dim>& m, const std::vector<Material>& materials,
                       const Vector& u_full) {
    const std::vector<VoigtMatrix<dim>> D = material_matrices(m, materials);
    check_nodal_size(m, u_full, "displacements");
    Vector F = Vector::Zero(dim * m.n_vertices());
    for (int t = 0; t < m.n_cells(); ++t) {
        const auto& cell = m.cells[static_cast<size_t>(t)];
        const Eigen::Matrix<double, kSimplexDofs<dim>, 1> fe =
            element_matrix(m, t, materials, D) * element_values(m, t, u_full);
        for (int i = 0; i <= dim; ++i)
            F.segment<dim>(dim * cell[static_cast<size_t>(i)]) += fe.template segment<dim>(dim * i);
    }
    return F;
}

template <int dim>
std::vector<double> cell_stresses(const mesh::SimplexMesh<dim>& m,
                                  const std::vector<Material>& materials, const Vector& u_full) {
    const std::vector<VoigtMatrix<dim>> D = material_matrices(m, materials);
    check_nodal_size(m, u_full, "displacements");
    constexpr int nv = kVoigt<dim>;
    std::vector<double> s(static_cast<size_t>(nv * m.n_cells()));
    for (int t = 0; t < m.n_cells(); ++t) {
        const auto ue = element_values(m, t, u_full);
        Eigen::Matrix<double, nv, 1> sig;
        if constexpr (dim == 2) {
            const auto& tri = m.cells[static_cast<size_t>(t)];
            double area = 0;
            const auto B = strain_matrix(m.vertices[static_cast<size_t>(tri[0])],
                                         m.vertices[static_cast<size_t>(tri[1])],
                                         m.vertices[static_cast<size_t>(tri[2])], area);
            sig = material_of(m, materials, t).D() * (B * ue);
        } else {
            double volume = 0;
            const auto B =
                voigt_strain_matrix<dim>(barycentric_gradients<dim>(corners_of(m, t), volume));
            sig = D[static_cast<size_t>(attribute_of(m, t))] * (B * ue);
        }
        for (int k = 0; k < nv; ++k)
            s[static_cast<size_t>(nv * t + k)] = sig[k];
    }
    return s;
}

#define MLC_FEM_INSTANTIATE(dim)                                                                   \
    template BasicSupports<dim> collect_supports<dim>(                                             \
        const mesh::SimplexMesh<dim>&, const std::vector<BasicVertexSupport<dim>>&);               \
    template std::vector<int> facet_vertices<dim>(const mesh::SimplexMesh<dim>&, int);             \
    template std::vector<int> line_vertices<dim>(const mesh::SimplexMesh<dim>&, int, int);         \
    template std::vector<int> segment_vertices<dim>(                                               \
        const mesh::SimplexMesh<dim>&, const PointD<dim>&, const PointD<dim>&, double);            \
    template Vector nodal_loads<dim>(const mesh::SimplexMesh<dim>&,                                \
                                     const std::vector<BasicTraction<dim>>&,                       \
                                     const std::vector<PointD<dim>>&);                             \
    template Vector body_force_loads<dim>(const mesh::SimplexMesh<dim>&,                           \
                                          const std::function<PointD<dim>(const PointD<dim>&)>&);  \
    template ElasticSystem assemble_elastic<dim>(                                                  \
        const mesh::SimplexMesh<dim>&, const std::vector<Material>&, const BasicDofMap<dim>&,      \
        const Vector&, const Vector&);                                                             \
    template Vector internal_forces<dim>(const mesh::SimplexMesh<dim>&,                            \
                                         const std::vector<Material>&, const Vector&);             \
    template std::vector<double> cell_stresses<dim>(const mesh::SimplexMesh<dim>&,                 \
                                                    const std::vector<Material>&, const Vector&);
MLC_FEM_INSTANTIATE(2)
MLC_FEM_INSTANTIATE(3)
#undef MLC_FEM_INSTANTIATE

} // namespace mlc::fem

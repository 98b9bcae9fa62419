// SPDX-License-Identifier: MIT
// Global assembly of the elastic problem.
#include "fem/assembly.hpp"

#include "core/check.hpp"

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
        for (int t = 0; t < m.n_triangles(); ++t) {
            const int a = m.attribute.empty() ? 0 : m.attribute[static_cast<size_t>(t)];
            MLC_CHECK(a < static_cast<int>(body_force.size()), "no body force for attribute " << a);
            const Vec2 f = m.signed_area(t) / 3.0 * body_force[static_cast<size_t>(a)];
            for (int v : m.triangles[static_cast<size_t>(t)])
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
    sys.f_nodal_full = nodal_load_full;
    sys.f = Vector::Zero(dofs.n_dofs());
    for (int v = 0; v < m.n_vertices(); ++v)
        for (int c = 0; c < 2; ++c)
            if (int d = dofs.u_dof(v, c); d >= 0) sys.f[d] = nodal_load_full[2 * v + c];
    std::vector<Triplet> trip;
    trip.reserve(static_cast<size_t>(36 * m.n_triangles()));
    for (int t = 0; t < m.n_triangles(); ++t) {
        const auto& tri = m.triangles[static_cast<size_t>(t)];
        const auto ke = element_stiffness(
            m.vertices[static_cast<size_t>(tri[0])], m.vertices[static_cast<size_t>(tri[1])],
            m.vertices[static_cast<size_t>(tri[2])], material_of(m, materials, t));
        int idx[6];
        for (int i = 0; i < 3; ++i)
            for (int c = 0; c < 2; ++c)
                idx[2 * i + c] = dofs.u_dof(tri[static_cast<size_t>(i)], c);
        for (int i = 0; i < 6; ++i) {
            if (idx[i] < 0) continue;
            for (int j = 0; j < 6; ++j) {
                if (idx[j] >= 0) {
                    trip.emplace_back(idx[i], idx[j], ke(i, j));
                } else {
                    const int v = tri[static_cast<size_t>(j / 2)];
                    sys.f[idx[i]] -= ke(i, j) * u_fixed[2 * v + j % 2];
                }
            }
        }
    }
    sys.K.resize(dofs.n_dofs(), dofs.n_dofs());
    sys.K.setFromTriplets(trip.begin(), trip.end());
    return sys;
}

Vector internal_forces(const mesh::Mesh& m, const std::vector<Material>& materials,
                       const Vector& u_full) {
    Vector F = Vector::Zero(2 * m.n_vertices());
    for (int t = 0; t < m.n_triangles(); ++t) {
        const auto& tri = m.triangles[static_cast<size_t>(t)];
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
    std::vector<double> s(static_cast<size_t>(3 * m.n_triangles()));
    for (int t = 0; t < m.n_triangles(); ++t) {
        const auto& tri = m.triangles[static_cast<size_t>(t)];
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

// SPDX-License-Identifier: MIT
/// @file What the distributed 3D tests (test_distributed3.cpp, test_distributed3_mg.cpp) share:
/// the one-process and distributed levels of a scene, the match of a part's unknowns with the
/// one-process level's (by their vertices' exact coordinates and bodies: midpoints are computed
/// by the same arithmetic on every process), and a serial state that puts the contact nodes in
/// every status. Include only with MLC_HAVE_HYPRE.
#pragma once

#include "levels/distributed3.hpp"
#include "levels/elastic3d_levels.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

namespace mlc::distributed3_fixtures {

using P3 = std::array<double, 3>;

inline P3 p3(const mesh::Vec3& x) {
    return {x.x(), x.y(), x.z()};
}

/// A reproducible "random" value of serial unknown i (the same on every process).
inline double pseudo_random(Index i) {
    return std::sin(12.9898 * static_cast<double>(i) + 0.7) * 43758.5453 -
           std::floor(std::sin(12.9898 * static_cast<double>(i) + 0.7) * 43758.5453) - 0.5;
}

/// The body (cell attribute) of every vertex of m: two bodies' vertices may coincide.
inline std::vector<int> vertex_bodies(const mesh::TetMesh& m) {
    std::vector<int> body(static_cast<size_t>(m.n_vertices()), 0);
    for (int t = 0; t < m.n_cells(); ++t)
        for (const int v : m.cells[static_cast<size_t>(t)])
            body[static_cast<size_t>(v)] =
                m.attribute.empty() ? 0 : m.attribute[static_cast<size_t>(t)];
    return body;
}

/// The serial vertex of every local vertex of a part (-1: none), matched by coordinates and
/// body.
inline std::vector<int> serial_vertices(const levels::DistributedLevel3& d,
                                        const levels::Level3& s) {
    std::map<std::pair<P3, int>, int> serial_vertex;
    const std::vector<int> serial_body = vertex_bodies(s.mesh);
    for (int v = 0; v < s.mesh.n_vertices(); ++v)
        serial_vertex[{p3(s.mesh.vertices[static_cast<size_t>(v)]),
                       serial_body[static_cast<size_t>(v)]}] = v;
    const std::vector<int> body = vertex_bodies(d.local.mesh);
    std::vector<int> out(static_cast<size_t>(d.local.mesh.n_vertices()), -1);
    for (int v = 0; v < d.local.mesh.n_vertices(); ++v) {
        const auto it = serial_vertex.find(
            {p3(d.local.mesh.vertices[static_cast<size_t>(v)]), body[static_cast<size_t>(v)]});
        EXPECT_NE(it, serial_vertex.end()) << "local vertex " << v << " is no serial vertex";
        if (it != serial_vertex.end()) out[static_cast<size_t>(v)] = it->second;
    }
    return out;
}

/// The multipliers of serial vertex v (0 when it is no contact node).
inline int serial_n_extra(const levels::Level3& s, int v) {
    const int e = s.contact_of_vertex[static_cast<size_t>(v)];
    return e < 0 ? 0 : s.contacts[static_cast<size_t>(e)].n_multipliers();
}

/// The serial unknown of every local unknown of a part (-1: none), matched by coordinates;
/// expects every local vertex in the serial mesh with the same fixed components and multipliers.
inline std::vector<Index> serial_dofs(const levels::DistributedLevel3& d, const levels::Level3& s) {
    const std::vector<int> sv = serial_vertices(d, s);
    const auto& dofs = d.local.dofs;
    std::vector<Index> out(static_cast<size_t>(dofs.n_dofs()), -1);
    for (int v = 0; v < d.local.mesh.n_vertices(); ++v) {
        const int w = sv[static_cast<size_t>(v)];
        if (w < 0) continue;
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(d.local.fixed[static_cast<size_t>(v)][static_cast<size_t>(c)],
                      s.fixed[static_cast<size_t>(w)][static_cast<size_t>(c)])
                << "vertex " << v << " component " << c;
            if (const int i = dofs.u_dof(v, c); i >= 0)
                out[static_cast<size_t>(i)] = s.dofs.u_dof(w, c);
        }
        const int n = d.n_extra[static_cast<size_t>(v)];
        EXPECT_EQ(n, serial_n_extra(s, w)) << "vertex " << v;
        if (n > 0 && n == serial_n_extra(s, w) && dofs.extra_dof(v) >= 0)
            for (int k = 0; k < n; ++k)
                out[static_cast<size_t>(dofs.extra_dof(v) + k)] = s.dofs.extra_dof(w) + k;
    }
    return out;
}

/// The serial vector x (of level s) at the owned unknowns of a part.
inline Vector owned_part(const std::vector<Index>& to_serial, Index n_owned, const Vector& x) {
    Vector y(n_owned);
    for (Index i = 0; i < n_owned; ++i)
        y[i] = x[to_serial[static_cast<size_t>(i)]];
    return y;
}

/// The levels of a scene, serial (build_hierarchy) and distributed (partitioned on level 0).
struct Block3dLevels {
    levels::ElasticProblem3 p;
    levels::Hierarchy3 serial;
    levels::DistributedHierarchy3 dist;
};

/// Levels 0 .. n_refinements of p, serial and partitioned on level 0.
inline Block3dLevels levels_up_to(levels::ElasticProblem3 p, int n_refinements,
                                  const Communicator& comm) {
    Block3dLevels r;
    r.p = std::move(p);
    r.serial = levels::build_hierarchy(r.p, n_refinements);
    r.dist = levels::build_distributed_hierarchy3(r.p, 0, n_refinements, comm);
    return r;
}

/// A smooth displacement of amplitude a at x (mesh of diameter h), component c, with a jump
/// between the bodies (`body`), so that two-body gaps open and close.
inline double smooth_u(const mesh::Vec3& x, int c, int body, double h, double a) {
    const mesh::Vec3 y = x / h;
    return a * (std::sin(2.1 * y.x() + 0.7 * c) * std::cos(1.3 * y.y() - 0.4 * c) +
                0.5 * std::sin(1.7 * y.z() + c) + 0.3 * body * (c - 1.0));
}

/// The serial state of the residual test: displacement unknowns from smooth_u, multipliers
/// pseudo-random of the size of r times the displacements (the tangents' a quarter of it); and
/// u_prev_full, the state's displacements less a smaller smooth field (a slip increment), so
/// that the nodes fall in every status.
struct State3 {
    Vector x, u_prev_full;
};
inline State3 serial_state(const levels::Level3& s, double a) {
    const auto& m = s.mesh;
    const std::vector<int> body = vertex_bodies(m);
    const double h = m.diameter();
    State3 st;
    st.x = Vector::Zero(s.dofs.n_dofs());
    for (int v = 0; v < m.n_vertices(); ++v)
        for (int c = 0; c < 3; ++c)
            if (const int d = s.dofs.u_dof(v, c); d >= 0)
                st.x[d] = smooth_u(m.vertices[static_cast<size_t>(v)], c,
                                   body[static_cast<size_t>(v)], h, a);
    for (size_t e = 0; e < s.contacts.size(); ++e) {
        const int nm = s.contacts[e].n_multipliers();
        for (int q = 0; q < nm; ++q) {
            const int d = s.lambda_dof[e] + q;
            st.x[d] = (q + 1 < nm ? 1.0 : 4.0) * a * s.contacts[e].r * pseudo_random(d);
        }
    }
    s.dofs.expand(st.x, s.u_fixed, st.u_prev_full);
    for (int v = 0; v < m.n_vertices(); ++v)
        for (int c = 0; c < 3; ++c)
            st.u_prev_full[3 * v + c] -=
                smooth_u(m.vertices[static_cast<size_t>(v)], 2 - c, 0, h, 0.2 * a);
    return st;
}

/// The serial state st on a part: x with the owned unknowns from st and the ghosts from their
/// owners, u_prev_full from the serial vertices.
inline State3 part_state(const levels::DistributedLevel3& d, const levels::Level3& s,
                         const State3& st) {
    const auto& L = d.local;
    const std::vector<Index> to_serial = serial_dofs(d, s);
    const std::vector<int> sv = serial_vertices(d, s);
    State3 out;
    out.x = Vector::Constant(L.dofs.n_dofs(), std::nan(""));
    for (Index i = 0; i < d.n_owned; ++i)
        out.x[i] = st.x[to_serial[static_cast<size_t>(i)]];
    d.ghosts.update(L.dofs, out.x);
    EXPECT_TRUE(out.x.allFinite()) << "a ghost unknown got no value";
    out.u_prev_full.resize(3 * L.mesh.n_vertices());
    for (int v = 0; v < L.mesh.n_vertices(); ++v)
        out.u_prev_full.segment<3>(3 * v) =
            st.u_prev_full.segment<3>(3 * sv[static_cast<size_t>(v)]);
    return out;
}

} // namespace mlc::distributed3_fixtures

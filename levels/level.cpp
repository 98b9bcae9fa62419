// SPDX-License-Identifier: MIT
// Level construction: supports, contact candidates, numbering, assembly.
#include "levels/level.hpp"

#include "core/check.hpp"

namespace mlc::levels {

Level build_level(const Problem& problem, mesh::Mesh m) {
    mesh::check_quality(m);
    Level L;
    L.mesh = std::move(m);
    const auto& mesh = L.mesh;
    const int nv = mesh.n_vertices();
    for (const auto& b : problem.bodies)
        L.materials.push_back(b.material);

    // Supports.
    L.fixed.assign(static_cast<size_t>(nv), {false, false});
    L.u_fixed = Vector::Zero(2 * nv);
    const double diam = mesh.diameter();
    for (const auto& s : problem.supports) {
        std::vector<int> verts;
        if (s.point) {
            const int v = mesh.nearest_vertex(*s.point);
            const double d = (mesh.vertices[static_cast<size_t>(v)] - *s.point).norm();
            MLC_CHECK(d <= 1e-8 * diam, "support point (" << s.point->x() << ", " << s.point->y()
                                                          << ") is not a mesh vertex (nearest at "
                                                             "distance "
                                                          << d << ")");
            verts.push_back(v);
        } else {
            verts = mesh.vertices_with_tag(mesh.tag(s.tag));
        }
        for (int v : verts) {
            if (s.ux) {
                L.fixed[static_cast<size_t>(v)][0] = true;
                L.u_fixed[2 * v] = *s.ux;
            }
            if (s.uy) {
                L.fixed[static_cast<size_t>(v)][1] = true;
                L.u_fixed[2 * v + 1] = *s.uy;
            }
        }
    }

    // Contactor nodes per pair (a vertex belongs to the first pair that claims it).
    L.contact_of_vertex.assign(static_cast<size_t>(nv), -1);
    std::vector<int> n_extra(static_cast<size_t>(nv), 0);
    for (size_t p = 0; p < problem.contacts.size(); ++p) {
        const auto& pair = problem.contacts[p];
        std::vector<int> nodes;
        for (int v : mesh.vertices_with_tag(mesh.tag(pair.contactor))) {
            if (pair.region && !pair.region->contains(mesh.vertices[static_cast<size_t>(v)]))
                continue;
            if (L.fixed[static_cast<size_t>(v)][0] && L.fixed[static_cast<size_t>(v)][1]) continue;
            if (L.contact_of_vertex[static_cast<size_t>(v)] >= 0) continue;
            nodes.push_back(v);
        }
        MLC_CHECK(!nodes.empty(), "contact '" << pair.name << "' has no contactor node on '"
                                              << pair.contactor << "'");
        auto elems = contact::node_on_rigid(mesh, nodes, *pair.obstacle, pair.mu, pair.r,
                                            static_cast<int>(p));
        for (const auto& e : elems) {
            L.contact_of_vertex[static_cast<size_t>(e.vertex[0])] =
                static_cast<int>(L.contacts.size());
            n_extra[static_cast<size_t>(e.vertex[0])] = e.n_multipliers();
            L.contacts.push_back(e);
        }
    }

    L.dofs = fem::DofMap(L.fixed, n_extra);
    L.lambda_dof.reserve(L.contacts.size());
    for (const auto& e : L.contacts)
        L.lambda_dof.push_back(L.dofs.extra_dof(e.vertex[0]));

    std::vector<fem::Traction> tractions;
    for (const auto& ld : problem.loads)
        tractions.push_back({mesh.tag(ld.tag), ld.pressure, ld.traction});
    std::vector<Vec2> body_force;
    bool any_body_force = false;
    for (const auto& b : problem.bodies) {
        body_force.push_back(b.body_force);
        any_body_force = any_body_force || b.body_force.squaredNorm() > 0;
    }
    if (!any_body_force) body_force.clear();
    const Vector F = fem::nodal_loads(mesh, tractions, body_force);
    L.elastic = fem::assemble_elastic(mesh, L.materials, L.dofs, F, L.u_fixed);
    return L;
}

} // namespace mlc::levels

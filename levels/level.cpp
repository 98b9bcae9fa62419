// SPDX-License-Identifier: MIT
// Level construction: supports, contact candidates, numbering, assembly.
#include "levels/level.hpp"

#include "contact/search.hpp"
#include "core/check.hpp"
#include "core/first_touch.hpp"
#include "mesh/lattice.hpp"

#include <algorithm>
#include <cmath>

namespace mlc::levels {

namespace {

/// Piecewise-linear interpolation of path values P[k-1] at s = k / K, with P = 0 at s = 0.
/// For K = 1 this is s * P[0], bit for bit the proportional loading.
/// A level made by hand (tests) has no path: then proportional to `full`.
/// Written into `out` with the rows over the threads (an elementwise expression: the same values
/// as evaluated whole; chunks start at multiples of parallel::kTouchRowsPerChunk).
void path_at(const std::vector<Vector>& P, const Vector& full, double s, Vector& out) {
    const int K = static_cast<int>(P.size());
    const Index n = K == 0 ? full.size() : P[0].size();
    out.resize(n);
    auto each = [&](auto&& expr_of) {
        parallel::for_rows(static_cast<size_t>(n), parallel::kTouchRowsPerChunk,
                           [&](size_t b, size_t e) {
                               const auto i = static_cast<Index>(b);
                               const auto m = static_cast<Index>(e - b);
                               out.segment(i, m) = expr_of(i, m);
                           });
    };
    if (K == 0) return each([&](Index i, Index m) { return s * full.segment(i, m); });
    const double t = s * K;
    const int k = std::clamp(static_cast<int>(std::floor(t)), 0, K - 1);
    const double theta = t - k;
    if (k == 0) return each([&](Index i, Index m) { return theta * P[0].segment(i, m); });
    const Vector& a = P[static_cast<size_t>(k - 1)];
    const Vector& b = P[static_cast<size_t>(k)];
    each([&](Index i, Index m) {
        return (1.0 - theta) * a.segment(i, m) + theta * b.segment(i, m);
    });
}

Vector path_at(const std::vector<Vector>& P, const Vector& full, double s) {
    Vector out;
    path_at(P, full, s, out);
    return out;
}

/// The two-body elements of `pair` for `nodes` (the search build_level runs). A process's part
/// (`is_part`) may hold no target facet: its nodes are then further than the search reaches from
/// the target (the ghost layer holds every facet within reach, mesh::GhostReach), not found.
contact::SearchResult two_body_search(const Problem& problem, const mesh::Mesh& mesh, size_t p,
                                      const std::vector<int>& nodes, bool is_part = false) {
    const auto& pair = problem.contacts[p];
    const int ip = static_cast<int>(p);
    if (is_part) {
        const int target = mesh.tag(pair.target);
        if (std::none_of(mesh.boundary.begin(), mesh.boundary.end(),
                         [&](const mesh::BoundaryEdge& e) { return e.tag == target; }))
            return {{}, nodes};
    }
    if (pair.element == ContactElementKind::node_on_node)
        return contact::node_on_node_search(mesh, nodes, mesh.tag(pair.target),
                                            pair.match_tolerance, pair.mu, pair.r, ip);
    // Whether a vertex is a contact node is decided on the level-0 target facets: the same on
    // every level, so that the contact nodes nest (transfer/ requires it).
    const auto& m0 = problem.mesh0;
    const contact::FacetIndex reference(m0.vertices,
                                        contact::target_facets(m0, m0.tag(pair.target)));
    return contact::node_on_facet_search(mesh, nodes, mesh.tag(pair.target), reference,
                                         pair.search_radius, pair.mu, pair.r, ip, pair.integration,
                                         mesh.tag(pair.contactor));
}

/// Level::ghost_contacts of a part: the two-body contact nodes of other processes
/// (contact_pair >= 0 at a vertex not owned) whose elements reach an owned vertex.
template <class Owned>
void build_ghost_contacts(const Problem& problem, Level& L, const std::vector<int>& contact_pair,
                          Owned&& owned) {
    for (size_t p = 0; p < problem.contacts.size(); ++p) {
        if (problem.contacts[p].element == ContactElementKind::node_on_rigid) continue;
        std::vector<int> nodes;
        for (int v = 0; v < L.mesh.n_vertices(); ++v)
            if (!owned(v) && contact_pair[static_cast<size_t>(v)] == static_cast<int>(p))
                nodes.push_back(v);
        if (nodes.empty()) continue;
        // A node whose search finds nothing here has no target near this part's vertices (the
        // ghost layer holds every facet within reach of them: mesh::GhostReach).
        for (auto& e : two_body_search(problem, L.mesh, p, nodes, true).elements) {
            bool reaches = false;
            for (int j = 1; j < e.n_nodes(); ++j)
                reaches = reaches || owned(e.vertex[static_cast<size_t>(j)]);
            if (reaches) L.ghost_contacts.push_back(e);
        }
    }
}

/// Sets ContactElement::pinned of every element of L (its own and its ghost elements) from the
/// fixed components of its vertices (contact::held_components); throws InvalidInput for an
/// element of L's own whose supports and contact frame share a direction only in part.
void pin_held_components(const Problem& problem, Level& L) {
    for (auto& e : L.ghost_contacts)
        e.pinned = contact::held_components(e, L.fixed).pinned; // refused by their owners
    for (auto& e : L.contacts) {
        const auto h = contact::held_components(e, L.fixed);
        const int v = e.vertex[0];
        const Vec2& x = L.mesh.vertices[static_cast<size_t>(v)];
        const char* held = L.fixed[static_cast<size_t>(v)][0] ? "u_x" : "u_y";
        MLC_CHECK(!h.ambiguous,
                  "contact '" << problem.contacts[static_cast<size_t>(e.pair)].name
                              << "': contactor vertex " << v << " at (" << x.x() << ", " << x.y()
                              << ") has " << held << " prescribed by a support"
                              << (e.n_nodes() == 1 ? "" : " (and so have its target vertices)")
                              << ", but the contact normal there, (" << e.n.x() << ", " << e.n.y()
                              << "), is neither along nor across that direction: with friction the "
                                 "support and the contact would share a force direction and their "
                                 "reactions would not be unique. Prescribe both components of that "
                                 "vertex, release its "
                              << held << ", or leave it out of the contact (its region)");
        e.pinned = h.pinned;
    }
}

} // namespace

template <int dim> Vector BasicLevel<dim>::u_fixed_at(double s) const {
    return path_at(path_u_fixed, u_fixed, s);
}
template <int dim> Vector BasicLevel<dim>::f_at(double s) const {
    return path_at(path_f, elastic.f, s);
}
template <int dim> Vector BasicLevel<dim>::f_nodal_at(double s) const {
    return path_at(path_f_nodal, elastic.f_nodal_full, s);
}
template <int dim> void BasicLevel<dim>::u_fixed_at(double s, Vector& out) const {
    path_at(path_u_fixed, u_fixed, s, out);
}
template <int dim> void BasicLevel<dim>::f_at(double s, Vector& out) const {
    path_at(path_f, elastic.f, s, out);
}
template <int dim> std::vector<int> BasicLevel<dim>::vertex_of_dof() const {
    std::vector<int> out(static_cast<size_t>(dofs.n_dofs()));
    for (Index i = 0; i < dofs.n_dofs(); ++i)
        out[static_cast<size_t>(i)] = dofs.vertex_of(i);
    return out;
}

template struct BasicLevel<2>;
template struct BasicLevel<3>;

Level build_level(const Problem& problem, mesh::Mesh m) {
    return build_level(problem, std::move(m), nullptr);
}

namespace {

/// Whether vertex v of a level is this process's (always, without a part).
bool owns(const LevelPart* part, int v) {
    return !part || part->owned[static_cast<size_t>(v)] != 0;
}

/// The supports active in step 1: Level::fixed, the prescribed values at every path point
/// (path_u_fixed) and at the end (u_fixed).
void set_supports(const Problem& problem, Level& L, const LevelPart* part) {
    auto owned = [part](int v) { return owns(part, v); };
    const auto& mesh = L.mesh;
    const int nv = mesh.n_vertices();
    const int K = problem.n_path_points();
    L.fixed.assign(static_cast<size_t>(nv), {false, false});
    L.path_u_fixed.assign(static_cast<size_t>(K), Vector::Zero(2 * nv));
    const double diam = mesh.diameter();
    for (const auto& s : problem.supports) {
        // Released in step 1: not held (Problem::at_step gives the problem of a later step).
        if (!problem.support_active(s, 1)) continue;
        std::vector<int> verts;
        if (s.point) {
            const int v = mesh.nearest_vertex(*s.point);
            const double d = (mesh.vertices[static_cast<size_t>(v)] - *s.point).norm();
            // A part holds the point only where it is near (its owner checks it is a vertex).
            if (part && (d > 1e-8 * diam || !owned(v))) continue;
            MLC_CHECK(d <= 1e-8 * diam, "support point (" << s.point->x() << ", " << s.point->y()
                                                          << ") is not a mesh vertex (nearest at "
                                                             "distance "
                                                          << d << ")");
            verts.push_back(v);
        } else {
            verts = mesh.vertices_on_tag(mesh.tag(s.tag)); // boundary edges and interior lines
        }
        for (int v : verts)
            for (int c = 0; c < 2; ++c) {
                const auto& full = c == 0 ? s.ux : s.uy;
                if (!full) continue;
                L.fixed[static_cast<size_t>(v)][static_cast<size_t>(c)] = true;
                for (int k = 1; k <= K; ++k)
                    L.path_u_fixed[static_cast<size_t>(k - 1)][2 * v + c] =
                        Problem::path_value(c == 0 ? s.ux_path : s.uy_path, *full, k, K);
            }
    }
    L.u_fixed = L.path_u_fixed.back();
}

/// The contact elements of every pair (Level::contacts, contact_of_vertex, not_found) and the
/// multipliers of each vertex (n_extra, resized to the vertices).
void find_contact_nodes(const Problem& problem, Level& L, const LevelPart* part,
                        std::vector<int>& n_extra) {
    auto owned = [part](int v) { return owns(part, v); };
    const auto& mesh = L.mesh;
    const int nv = mesh.n_vertices();
    // Contactor nodes per pair (a vertex belongs to the first pair that claims it).
    L.contact_of_vertex.assign(static_cast<size_t>(nv), -1);
    L.not_found.assign(problem.contacts.size(), {});
    n_extra.assign(static_cast<size_t>(nv), 0);
    for (size_t p = 0; p < problem.contacts.size(); ++p) {
        const auto& pair = problem.contacts[p];
        std::vector<int> nodes;
        for (int v : mesh.vertices_with_tag(mesh.tag(pair.contactor))) {
            if (pair.region && !pair.region->contains(mesh.vertices[static_cast<size_t>(v)]))
                continue;
            if (L.fixed[static_cast<size_t>(v)][0] && L.fixed[static_cast<size_t>(v)][1]) continue;
            if (L.contact_of_vertex[static_cast<size_t>(v)] >= 0) continue;
            if (!owned(v)) continue; // a part's contact nodes are those of its own vertices
            nodes.push_back(v);
        }
        // A part may hold no node of a pair: the distributed build checks the pair over all parts.
        if (part && nodes.empty()) continue;
        MLC_CHECK(!nodes.empty(), "contact '" << pair.name << "' has no contactor node on '"
                                              << pair.contactor << "'");
        std::vector<contact::ContactElement> elems;
        const int ip = static_cast<int>(p);
        switch (pair.element) {
        case ContactElementKind::node_on_rigid:
            elems = contact::node_on_rigid(mesh, nodes, *pair.obstacle, pair.mu, pair.r, ip);
            break;
        case ContactElementKind::node_on_facet:
        case ContactElementKind::node_on_node: {
            auto found = two_body_search(problem, mesh, p, nodes, part != nullptr);
            elems = std::move(found.elements);
            L.not_found[p] = std::move(found.not_found);
            break;
        }
        }
        // (A part's nodes may all lie away from the target: the pair is checked over all parts.)
        MLC_CHECK(part || !elems.empty(),
                  "contact '" << pair.name << "': none of the " << nodes.size()
                              << " contactor nodes on '" << pair.contactor << "' found a "
                              << (pair.element == ContactElementKind::node_on_node
                                      ? "coincident target node"
                                      : "target facet within the search radius")
                              << " on '" << pair.target
                              << "' (check the tags, or raise search_radius)");
        for (const auto& e : elems) {
            L.contact_of_vertex[static_cast<size_t>(e.vertex[0])] =
                static_cast<int>(L.contacts.size());
            n_extra[static_cast<size_t>(e.vertex[0])] = e.n_multipliers();
            L.contacts.push_back(e);
        }
    }
}

/// A part completed by its owners' data (LevelPart::complete, ghost contacts), the held
/// components pinned, and the unknowns numbered: Level::dofs, lattice, lambda_dof,
/// ghost_lambda_dof.
void number_unknowns(const Problem& problem, Level& L, const LevelPart* part,
                     std::vector<int>& n_extra) {
    auto owned = [part](int v) { return owns(part, v); };
    const int nv = L.mesh.n_vertices();
    // Unknowns numbered along a Hilbert curve: refinement appends the new vertices after the
    // coarse ones, and in that order the mat-vecs and sweeps of the large levels gather x from
    // all over memory.
    if (part && part->complete) {
        std::vector<int> contact_pair(static_cast<size_t>(nv), -1);
        for (const auto& e : L.contacts)
            contact_pair[static_cast<size_t>(e.vertex[0])] = e.pair;
        part->complete(L, n_extra, contact_pair);
        build_ghost_contacts(problem, L, contact_pair, owned);
    }
    pin_held_components(problem, L);
    std::vector<int> order;
    std::optional<mesh::MacroLattice> lattice;
    if (part) {
        // The part's order (levels/distributed.cpp numbers it, by lattices too).
        if (!part->order.empty()) order = part->order;
    } else if (problem.numbering == Problem::Numbering::lattice) {
        // The refinements of mesh0 this level is, when it is (4^d times mesh0's triangles).
        const long t0 = problem.mesh0.n_cells(), t = L.mesh.n_cells();
        int depth = -1;
        for (int d = 0; d <= 14 && t0 > 0; ++d)
            if (t0 << (2 * d) == t) depth = d;
        if (depth >= 4) // levels with lattice smoothing (solvers::kMinLatticeSubdivisions)
            lattice = mesh::macro_lattice(L.mesh, depth);
        if (lattice) order = mesh::lattice_vertex_order(L.mesh, *lattice);
    }
    if (order.empty()) order = mesh::hilbert_order(L.mesh.vertices);
    L.dofs = fem::DofMap(L.fixed, n_extra, order);
    if (lattice)
        L.lattice = std::make_shared<const smoothers::LatticeRows>(lattice_rows(L, *lattice));
    L.lambda_dof.reserve(L.contacts.size());
    for (const auto& e : L.contacts)
        L.lambda_dof.push_back(L.dofs.extra_dof(e.vertex[0]));
    for (const auto& e : L.ghost_contacts)
        L.ghost_lambda_dof.push_back(L.dofs.extra_dof(e.vertex[0]));
}

/// The elastic operator and the loads at every path point (Level::elastic, path_f,
/// path_f_nodal); with one path point (proportional loading) the paths are left empty.
void assemble_loads(const Problem& problem, Level& L) {
    const auto& mesh = L.mesh;
    const int nv = mesh.n_vertices();
    const int K = problem.n_path_points();
    // Loads at every path point; the last one gives the assembled right-hand side.
    std::vector<Vec2> body_force;
    bool any_body_force = false;
    for (const auto& b : problem.bodies) {
        body_force.push_back(b.body_force);
        any_body_force = any_body_force || b.body_force.squaredNorm() > 0;
    }
    if (!any_body_force) body_force.clear();
    auto nodal_loads_at = [&](int k) {
        std::vector<fem::Traction> tractions;
        for (const auto& ld : problem.loads) {
            const double a = Problem::path_value(ld.factors, 1.0, k, K);
            tractions.push_back({mesh.tag(ld.tag), a * ld.pressure, a * ld.traction});
        }
        // Body forces grow in proportion to s (they take no per-point factors).
        std::vector<Vec2> bf = body_force;
        for (auto& b : bf)
            b *= static_cast<double>(k) / K;
        return fem::nodal_loads(mesh, tractions, bf);
    };
    L.elastic = fem::assemble_elastic(mesh, L.materials, L.dofs, nodal_loads_at(K), L.u_fixed);
    L.path_f.resize(static_cast<size_t>(K));
    L.path_f_nodal.resize(static_cast<size_t>(K));
    for (int k = 1; k < K; ++k) {
        // f_k = F_k,free - K_(free,fixed) u_fixed,k, the lifting from element-wise K u.
        const Vector F = nodal_loads_at(k);
        // (No element loop when every prescribed value is zero at this point, as for the square.)
        const Vector& uk = L.path_u_fixed[static_cast<size_t>(k - 1)];
        const Vector Ku =
            uk.isZero(0.0) ? Vector::Zero(uk.size()) : fem::internal_forces(mesh, L.materials, uk);
        Vector f = Vector::Zero(L.dofs.n_dofs());
        for (int v = 0; v < nv; ++v)
            for (int c = 0; c < 2; ++c)
                if (const int d = L.dofs.u_dof(v, c); d >= 0) f[d] = F[2 * v + c] - Ku[2 * v + c];
        L.path_f[static_cast<size_t>(k - 1)] = std::move(f);
        L.path_f_nodal[static_cast<size_t>(k - 1)] = F;
    }
    L.path_f.back() = L.elastic.f;
    L.path_f_nodal.back() = L.elastic.f_nodal_full;
    if (K == 1) {
        // Proportional loading: the one path point is u_fixed, elastic.f, elastic.f_nodal_full
        // themselves, and path_at gives s times them from empty paths, bit for bit: three
        // vectors of the level's size fewer.
        L.path_u_fixed.clear();
        L.path_f.clear();
        L.path_f_nodal.clear();
        L.path_u_fixed.shrink_to_fit();
        L.path_f.shrink_to_fit();
        L.path_f_nodal.shrink_to_fit();
    }
}

} // namespace

Level build_level(const Problem& problem, mesh::Mesh m, const LevelPart* part) {
    // A refined mesh (of a checked one, as the hierarchy builds them) only needs its areas checked;
    // so does a process's part of a level (cut from the whole level, which the levels up to p
    // check; its interior lines may have a triangle on one side only, at the edge of the part).
    if (m.n_coarse_vertices > 0 || part)
        mesh::check_refined_quality(m);
    else
        mesh::check_quality(m);
    Level L;
    L.mesh = std::move(m);
    for (const auto& b : problem.bodies)
        L.materials.push_back(b.material);
    set_supports(problem, L, part);
    std::vector<int> n_extra;
    find_contact_nodes(problem, L, part, n_extra);
    number_unknowns(problem, L, part, n_extra);
    assemble_loads(problem, L);
    return L;
}

smoothers::LatticeRows lattice_rows(const Level& L, const mesh::MacroLattice& lattice) {
    smoothers::LatticeRows rows;
    rows.n = lattice.n;
    rows.first_row.resize(lattice.vertex.size());
    for (size_t k = 0; k < lattice.vertex.size(); ++k) {
        const int v = lattice.vertex[k];
        const int d0 = L.dofs.u_dof(v, 0), d1 = L.dofs.u_dof(v, 1);
        rows.first_row[k] = d0 >= 0 && d1 == d0 + 1 && L.dofs.extra_dof(v) < 0 ? d0 : -1;
    }
    // The visit: the blocks in the numbering's order, each macro's interior in serpentine rows
    // (row j = 1, 3, ... left to right, j = 2, 4, ... right to left): as cheap to sweep as the
    // numbering's row-by-row order (the rows still stream) and a better Gauss-Seidel order on
    // the square (fewer BiCGStab iterations per Newton step;
    // docs/solver-guide.md#solver-why-default).
    const int N = rows.n;
    const long np = mesh::MacroLattice::interior_points(N);
    const long n_macros = np > 0 ? static_cast<long>(rows.first_row.size()) / np : 0;
    std::vector<int> macro_at(static_cast<size_t>(L.n_unknowns()), -1);
    std::vector<char> interior(static_cast<size_t>(L.n_unknowns()), 0);
    for (long m = 0; m < n_macros; ++m) { // the macro is visited at its smallest row
        Index first = -1;
        for (long q = 0; q < np; ++q) {
            const Index r = rows.first_row[static_cast<size_t>(m * np + q)];
            if (r < 0) continue;
            interior[static_cast<size_t>(r)] = 1;
            if (first < 0 || r < first) first = r;
        }
        if (first >= 0) macro_at[static_cast<size_t>(first)] = static_cast<int>(m);
    }
    rows.visit.reserve(static_cast<size_t>(L.n_unknowns()) / 2 + 1);
    for (Index d = 0; d < L.n_unknowns(); ++d) {
        if (d > 0 && L.dofs.vertex_of(d) == L.dofs.vertex_of(d - 1)) continue; // not a block start
        const int m = macro_at[static_cast<size_t>(d)];
        if (m >= 0) {
            for (int j = 1; j <= N - 2; ++j) {
                const int len = N - 1 - j;
                for (int t = 0; t < len; ++t) {
                    const int i = j % 2 == 1 ? 1 + t : len - t;
                    const Index r = rows.first_row[static_cast<size_t>(
                        m * np + mesh::MacroLattice::point_index(N, i, j))];
                    if (r >= 0) rows.visit.push_back(r);
                }
            }
        } else if (!interior[static_cast<size_t>(d)]) {
            rows.visit.push_back(d);
        }
    }
    return rows;
}

} // namespace mlc::levels

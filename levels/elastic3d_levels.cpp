// SPDX-License-Identifier: MIT
// 3D levels: the problem's checks, the levels (supports, contact elements, numbering, assembly)
// and transfers, and the multigrid on them (sizes and memory: elastic3d_sizes.cpp).
#include "levels/elastic3d_levels.hpp"

#include "levels/elastic3d_detail.hpp"

#include "contact/element.hpp"
#include "contact/search3.hpp"
#include "core/check.hpp"
#include "fem/assembly.hpp"
#include "mesh/tet_refine.hpp"
#include "solvers/pc_spec.hpp"
#include "transfer/prolongation.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

namespace mlc::levels {

namespace {

/// Relative distance under which a support point is a vertex, or a vertex on a support line.
constexpr double kPointTol = 1e-9;

/// The support's vertices on mesh m (a tag's faces and lines, the line's, or the point's
/// level-0 vertex).
std::vector<int> support_vertices(const ElasticProblem3& p, const Support3& s,
                                  const mesh::TetMesh& m) {
    if (!s.tag.empty()) return m.vertices_on_tag(m.tag(s.tag)); // its faces' and lines'

    if (s.line) {
        std::vector<int> v = line_vertices(m, *s.line);
        std::sort(v.begin(), v.end());
        return v;
    }
    return {p.mesh0.nearest_vertex(*s.point)};
}

/// "(x, y, z)".
std::string point_text(const Vec3& x) {
    std::ostringstream os;
    os << "(" << x.x() << ", " << x.y() << ", " << x.z() << ")";
    return os.str();
}

/// Throws InvalidInput unless x is a vertex of the level-0 mesh m0 (within kPointTol of its
/// diameter); `what` names x in the message ("support point", "support line: its end").
void check_vertex0(const mesh::TetMesh& m0, const Vec3& x, const std::string& what) {
    const int v = m0.nearest_vertex(x);
    const double d = (m0.vertices[static_cast<size_t>(v)] - x).norm();
    MLC_CHECK(d <= kPointTol * m0.diameter(),
              what << " " << point_text(x) << " is no vertex of the level-0 mesh (the nearest "
                   << "vertex lies " << d << " away)");
}

/// The names of the tags some boundary face of m carries, "a, b, c" ("none" without any).
std::string face_tags(const mesh::TetMesh& m) {
    std::string s;
    for (const auto& [name, id] : m.tag_names)
        if (m.is_boundary_tag(id)) s += (s.empty() ? "" : ", ") + name;
    return s.empty() ? "none" : s;
}

/// "u_x", "u_x and u_z", "u_x, u_y and u_z": the components of `held` that are true.
std::string component_list(const std::array<bool, 3>& held) {
    std::vector<std::string> names;
    for (int c = 0; c < 3; ++c)
        if (held[static_cast<size_t>(c)]) names.push_back(std::string("u_") + "xyz"[c]);
    std::string s;
    for (size_t k = 0; k < names.size(); ++k)
        s += (k == 0 ? "" : k + 1 == names.size() ? " and " : ", ") + names[k];
    return s;
}

} // namespace

// The edges of m (mesh::tet_edges, smaller vertex first), sorted.
std::vector<std::array<int, 2>> detail::sorted_edges(const mesh::TetMesh& m) {
    std::vector<std::array<int, 2>> e = mesh::tet_edges(m).edges;
    std::sort(e.begin(), e.end());
    return e;
}

// The level-0 edges of a line support (pairs of vertices, smaller first), after checking that
// its ends are level-0 vertices and its segment runs along level-0 edges (`edges`: those of
// sorted_edges(m0)).
std::vector<std::pair<int, int>> detail::line_edges0(const mesh::TetMesh& m0,
                                                     const std::vector<std::array<int, 2>>& edges,
                                                     const std::array<Vec3, 2>& line) {
    for (const Vec3& x : line)
        check_vertex0(m0, x, "support line: its end");
    MLC_CHECK((line[1] - line[0]).norm() > kPointTol * m0.diameter(),
              "support line: its two ends are the same point " << point_text(line[0]));
    const std::vector<int> on = line_vertices(m0, line);
    std::vector<std::pair<int, int>> out;
    for (size_t k = 0; k + 1 < on.size(); ++k) {
        const auto [a, b] = std::minmax(on[k], on[k + 1]);
        MLC_CHECK(std::binary_search(edges.begin(), edges.end(), std::array<int, 2>{a, b}),
                  "support line from "
                      << point_text(line[0]) << " to " << point_text(line[1])
                      << " does not run along edges of the level-0 mesh: its vertices "
                      << point_text(m0.vertices[static_cast<size_t>(on[k])]) << " and "
                      << point_text(m0.vertices[static_cast<size_t>(on[k + 1])])
                      << " are not joined by an edge");
        out.emplace_back(a, b);
    }
    return out;
}

double mean_face_edge_length(const mesh::TetMesh& m, const std::string& tag) {
    const auto id = m.find_tag(tag);
    MLC_CHECK(id && m.is_boundary_tag(*id),
              "no boundary face carries the tag '"
                  << tag << "' (the boundary face tags are: " << face_tags(m) << ")");
    std::set<std::pair<int, int>> edges;
    for (const mesh::BoundaryFace& f : m.boundary) {
        if (f.tag != *id) continue;
        for (int i = 0; i < 3; ++i) {
            const int a = f.v[static_cast<size_t>(i)], b = f.v[static_cast<size_t>((i + 1) % 3)];
            edges.insert({std::min(a, b), std::max(a, b)});
        }
    }
    double sum = 0.0;
    for (const auto& [a, b] : edges)
        sum += (m.vertices[static_cast<size_t>(a)] - m.vertices[static_cast<size_t>(b)]).norm();
    return sum / static_cast<double>(edges.size());
}

std::vector<int> line_vertices(const mesh::TetMesh& m, const std::array<Vec3, 2>& line) {
    const double tol = kPointTol * m.diameter();
    const Vec3 d = line[1] - line[0];
    const double len2 = d.squaredNorm();
    std::vector<std::pair<double, int>> on;
    for (int v = 0; v < m.n_vertices(); ++v) {
        const Vec3 x = m.vertices[static_cast<size_t>(v)] - line[0];
        const double s = len2 > 0 ? x.dot(d) / len2 : 0.0;
        if (s < -tol || s > 1 + tol) continue;
        if ((x - s * d).norm() <= tol) on.push_back({s, v});
    }
    std::sort(on.begin(), on.end());
    std::vector<int> out;
    for (const auto& [s, v] : on)
        out.push_back(v);
    return out;
}

void ElasticProblem3::validate() const {
    MLC_CHECK(!bodies.empty(), "the 3D problem has no body");
    MLC_CHECK(levels >= 0 && levels <= kMaxLevels3,
              "levels must lie in [0, " << kMaxLevels3 << "], found " << levels);
    MLC_CHECK(mesh0.n_cells() > 0, "the 3D problem's mesh has no tetrahedra");
    for (size_t t = 0; t < mesh0.attribute.size(); ++t)
        MLC_CHECK(mesh0.attribute[t] >= 0 && mesh0.attribute[t] < static_cast<int>(bodies.size()),
                  "tetrahedron " << t << " belongs to body " << mesh0.attribute[t] << ", but "
                                 << bodies.size() << " bodies are given");
    for (const Body3& b : bodies) {
        b.material.validate();
        MLC_CHECK(b.material.plane == fem::Plane::strain,
                  "body '" << b.name << "': plane stress is a 2D reduction");
        MLC_CHECK(b.body_force.allFinite(), "body '" << b.name << "': body force not finite");
    }
    for (const FaceLoad3& l : loads) {
        MLC_CHECK(mesh0.find_tag(l.tag) && mesh0.is_boundary_tag(mesh0.tag(l.tag)),
                  "load: no boundary face carries the tag '" << l.tag << "'");
        MLC_CHECK(std::isfinite(l.pressure) && l.traction.allFinite(),
                  "load on '" << l.tag << "' is not finite");
    }
    for (const Support3& s : supports) {
        MLC_CHECK(s.u[0] || s.u[1] || s.u[2], "a support fixes nothing: give ux, uy and/or uz");
        MLC_CHECK(int(!s.tag.empty()) + int(s.point.has_value()) + int(s.line.has_value()) == 1,
                  "a support takes one of a tag, a line or a point");
        if (s.line) {
            detail::line_edges0(mesh0, detail::sorted_edges(mesh0), *s.line);
        } else if (!s.tag.empty()) {
            const auto id = mesh0.find_tag(s.tag);
            MLC_CHECK(id && !mesh0.vertices_on_tag(*id).empty(),
                      "support: no boundary face or line carries the tag '" << s.tag << "'");
        } else {
            check_vertex0(mesh0, *s.point, "support point");
        }
    }
    MLC_CHECK(load_steps >= 1, "load_steps must be at least 1, found " << load_steps);
    // Loading path: every per-point list has the same length (the 2D check and message).
    int K = 0;
    for (const FaceLoad3& l : loads)
        check_path_length(K, l.factors.size(), "load on '" + l.tag + "'");
    for (const Support3& s : supports) {
        const std::string where = !s.tag.empty() ? "support on '" + s.tag + "'"
                                  : s.line       ? std::string("support along a line")
                                                 : std::string("support at a point");
        for (size_t c = 0; c < 3; ++c) {
            const std::string key = std::string("u") + "xyz"[c];
            check_path_length(K, s.u_path[c].size(), where + " (" + key + ")");
            MLC_CHECK(s.u_path[c].empty() || (s.u[c] && *s.u[c] == s.u_path[c].back()),
                      where << ": " << key << " must equal the last entry of its per-point list");
        }
    }
    newton.validate();
    for (const ContactPair3& c : contacts) {
        const std::string w = "contact '" + c.name + "'";
        const auto id = mesh0.find_tag(c.contactor);
        MLC_CHECK(id && mesh0.is_boundary_tag(*id),
                  w << ": the contactor tag '" << c.contactor
                    << "' is a tag of no boundary face (the boundary face tags are: "
                    << face_tags(mesh0) << ")");
        MLC_CHECK(std::isfinite(c.mu) && c.mu >= 0,
                  w << ": the friction coefficient mu must be >= 0, found " << c.mu);
        MLC_CHECK(std::isfinite(c.r) && c.r > 0,
                  w << ": the augmentation parameter r must be > 0, found " << c.r);
        if (c.region)
            MLC_CHECK((c.region->lo.array() <= c.region->hi.array()).all(),
                      w << ": the region's min " << point_text(c.region->lo) << " exceeds its max "
                        << point_text(c.region->hi) << " in some coordinate");
        if (c.two_body()) {
            const auto tid = mesh0.find_tag(c.target);
            MLC_CHECK(tid && mesh0.is_boundary_tag(*tid),
                      w << ": the target tag '" << c.target
                        << "' is a tag of no boundary face (the boundary face tags are: "
                        << face_tags(mesh0) << ")");
            MLC_CHECK(c.target != c.contactor,
                      w << ": the target and the contactor are the same tag '" << c.target
                        << "'; a body's face cannot contact itself");
            MLC_CHECK(std::isfinite(c.search_radius) && c.search_radius > 0,
                      w << ": search_radius must be > 0, found " << c.search_radius);
            MLC_CHECK(std::isfinite(c.match_tolerance) && c.match_tolerance > 0,
                      w << ": match_tolerance must be > 0, found " << c.match_tolerance);
            MLC_CHECK(c.element == ContactElementKind::node_on_facet ||
                          c.integration == contact::FacetIntegration::nodal,
                      w << ": integration = \"" << contact::to_string(c.integration)
                        << "\" is for node_on_facet elements; node_on_node pairs have the "
                           "weights (1, -1)");
            continue;
        }
        contact::BasicObstacle<3> o = c.obstacle;
        try {
            o.validate();
        } catch (const InvalidInput& e) {
            throw InvalidInput(w + ": " + e.what());
        }
    }
}

int ElasticProblem3::n_path_points() const {
    for (const FaceLoad3& l : loads)
        if (!l.factors.empty()) return static_cast<int>(l.factors.size());
    for (const Support3& s : supports)
        for (const auto& path : s.u_path)
            if (!path.empty()) return static_cast<int>(path.size());
    return 1;
}

// ------------------------------------------------------------------------------------------

// The two-body elements of pair k for the contactor vertices `nodes` of level mesh m. Whether a
// vertex is a contact node is decided on the level-0 target faces (node on facet), the same on
// every level, so that the contact nodes nest (transfer/ requires it).
contact::SearchResult3 detail::two_body_search3(const ElasticProblem3& p, const mesh::TetMesh& m,
                                                size_t k, const std::vector<int>& nodes,
                                                bool is_part) {
    const ContactPair3& pair = p.contacts[k];
    const int ip = static_cast<int>(k);
    if (is_part) {
        // A part without target faces: its nodes lie beyond the search's reach of the target
        // (the ghost layer holds every target face within it: contact_ghost_reach3).
        const int target = m.tag(pair.target);
        if (std::none_of(m.boundary.begin(), m.boundary.end(),
                         [&](const mesh::BoundaryFace& f) { return f.tag == target; }))
            return {{}, nodes};
    }
    if (pair.element == ContactElementKind::node_on_node)
        return contact::node_on_node_search3(m, nodes, m.tag(pair.target), pair.match_tolerance,
                                             pair.mu, pair.r, ip);
    const auto& m0 = p.mesh0;
    const contact::FacetIndex3 reference(m0.vertices,
                                         contact::target_facets3(m0, m0.tag(pair.target)));
    return contact::node_on_facet_search3(m, nodes, m.tag(pair.target), reference,
                                          pair.search_radius, pair.mu, pair.r, ip,
                                          pair.integration, m.tag(pair.contactor));
}

std::string detail::no_target_message(const ContactPair3& pair, std::size_t n_nodes) {
    std::ostringstream os;
    os << "contact '" << pair.name << "': none of the " << n_nodes << " contactor vertices on '"
       << pair.contactor << "' found a target on '" << pair.target << "' ("
       << (pair.element == ContactElementKind::node_on_node
               ? "no target vertex within match_tolerance"
               : "no target face within search_radius")
       << " of any of them)";
    return os.str();
}

// The contact elements of every pair (Level3::contacts, contact_of_vertex, not_found) and the
// multipliers of each vertex (n_extra, sized to the vertices); L.fixed is set.
void detail::find_contact_nodes3(const ElasticProblem3& p, Level3& L, std::vector<int>& n_extra,
                                 const std::vector<char>* owned) {
    const mesh::TetMesh& m = L.mesh;
    const auto nv = static_cast<size_t>(m.n_vertices());
    L.contact_of_vertex.assign(nv, -1);
    L.not_found.assign(p.contacts.size(), {});
    n_extra.assign(nv, 0);
    for (size_t k = 0; k < p.contacts.size(); ++k) {
        const ContactPair3& pair = p.contacts[k];
        std::vector<int> nodes;
        const std::vector<int> on_tag = m.vertices_with_tag(m.tag(pair.contactor));
        int outside = 0, fixed = 0, claimed = 0;
        for (int v : on_tag) {
            const auto vi = static_cast<size_t>(v);
            if (pair.region && !pair.region->contains(m.vertices[vi])) {
                ++outside;
            } else if (L.fixed[vi][0] && L.fixed[vi][1] && L.fixed[vi][2]) {
                ++fixed;
            } else if (L.contact_of_vertex[vi] >= 0) {
                ++claimed;
            } else if (owned && !(*owned)[vi]) {
                continue; // a part's contact nodes are those of the vertices it owns
            } else {
                nodes.push_back(v);
                L.contact_of_vertex[vi] = -2; // claimed; the element index is set below
            }
        }
        if (owned && nodes.empty()) continue; // the caller checks the pair over all parts
        MLC_CHECK(!nodes.empty(), "contact '" << pair.name << "' has no contactor node on '"
                                              << pair.contactor << "': of its " << on_tag.size()
                                              << " vertices, " << outside
                                              << " lie outside the region, " << fixed
                                              << " have all three components fixed by supports and "
                                              << claimed << " belong to an earlier contact pair");
        std::vector<contact::ContactElement3> elements;
        if (pair.two_body()) {
            auto found = two_body_search3(p, m, k, nodes, owned != nullptr);
            for (int v : found.not_found)
                L.contact_of_vertex[static_cast<size_t>(v)] = -1;
            MLC_CHECK(owned || !found.elements.empty(), no_target_message(pair, nodes.size()));
            L.not_found[k] = std::move(found.not_found);
            elements = std::move(found.elements);
        } else {
            elements = contact::node_on_rigid<3>(m, nodes, pair.obstacle, pair.mu, pair.r,
                                                 static_cast<int>(k));
        }
        for (const auto& e : elements) {
            L.contact_of_vertex[static_cast<size_t>(e.vertex[0])] =
                static_cast<int>(L.contacts.size());
            n_extra[static_cast<size_t>(e.vertex[0])] = e.n_multipliers();
            L.contacts.push_back(e);
        }
    }
}

namespace {

/// The held components of a 3D element (contact::held_components), with one more case: a
/// frictional two-body element whose own components leave it unpinned, but whose contactor
/// vertex alone would pin its first tangent (one component held, the normal across it), pins
/// it. That is a symmetry plane through two-body contact nodes: the contactor's support holds
/// it on the plane, and the target facets its weights reach leave the plane (segment and dual
/// weights spread over them), so not every vertex of the element is held. By symmetry the
/// traction across the plane vanishes; pinning says so, where the unpinned stick equation
/// would hold the targets' weighted displacement across the plane at zero (an equation that
/// couples to the contactor's block only by rounding, which the multigrid's Galerkin coarse
/// operators cannot smooth).
contact::HeldComponents held_components3(const contact::ContactElement3& e,
                                         const std::vector<std::array<bool, 3>>& fixed) {
    const auto h = contact::held_components<3>(e, fixed);
    if (h.pinned != 0 || h.ambiguous || !e.frictional() || e.n_nodes() == 1) return h;
    contact::ContactElement3 contactor = e;
    contactor.vertex.resize(1);
    contactor.weight.assign(1, 1.0);
    const auto own = contact::held_components<3>(contactor, fixed);
    return own.pinned == contact::ContactElement3::kPinnedT1 ? own : h;
}

} // namespace

// Sets ContactElement3::pinned of every element (Level3::contacts and ghost_contacts) from the
// fixed components of its vertices (held_components3), turning the frame of an element whose
// first tangent alone is pinned onto the held axis (a symmetry plane across frictional contact
// nodes); throws InvalidInput for an element of L.contacts whose supports hold a direction its
// frame meets only in part (a ghost element is its owner's to refuse).
void detail::pin_held_components3(const ElasticProblem3& p, Level3& L) {
    for (auto& e : L.ghost_contacts) {
        const auto h = held_components3(e, L.fixed);
        if (h.ambiguous) continue;
        if (h.pinned & contact::ContactElement3::kPinnedT1)
            contact::turn_first_tangent_onto_axis(e, h.pinned_axis);
        e.pinned = h.pinned;
    }
    for (auto& e : L.contacts) {
        const auto h = held_components3(e, L.fixed);
        const int v = e.vertex[0];
        const std::array<bool, 3>& held = L.fixed[static_cast<size_t>(v)];
        MLC_CHECK(
            !h.ambiguous,
            "contact '" << p.contacts[static_cast<size_t>(e.pair)].name << "': contactor vertex "
                        << v << " at " << point_text(L.mesh.vertices[static_cast<size_t>(v)])
                        << " has " << component_list(held)
                        << " prescribed by a support, but its contact frame there, normal "
                        << point_text(e.n) << " with tangents " << point_text(e.t.col(0)) << " and "
                        << point_text(e.t.col(1))
                        << ", meets the held directions only in part (a tangent or the normal "
                           "neither along nor across them): with friction the support and the "
                           "contact would share a force direction and their reactions would not be "
                           "unique (a node's tangential multipliers are pinned together or not at "
                           "all). Prescribe all three components of that vertex, release its "
                        << component_list(held)
                        << ", make the pair frictionless (mu = 0), or leave the vertex out of the "
                           "contact (its region)");
        if (h.pinned & contact::ContactElement3::kPinnedT1)
            contact::turn_first_tangent_onto_axis(e, h.pinned_axis);
        e.pinned = h.pinned;
    }
}

void detail::set_load_path3(const ElasticProblem3& p, Level3& L,
                            std::vector<fem::VertexSupport3> vs,
                            const std::function<Vector(int)>& nodal_loads_at,
                            const std::function<void(Vector&)>& share) {
    const int K = p.n_path_points();
    const int nv = L.mesh.n_vertices();
    L.path_u_fixed.assign(static_cast<size_t>(K), Vector());
    L.path_f.assign(static_cast<size_t>(K), Vector());
    L.path_f_nodal.assign(static_cast<size_t>(K), Vector());
    for (int k = 1; k < K; ++k) {
        // The same vertices and components, the values of point k (a later support's value
        // counts where two hold one component, as at the last point).
        for (size_t i = 0; i < vs.size(); ++i) {
            const Support3& s = p.supports[i];
            for (size_t c = 0; c < 3; ++c)
                if (s.u[c])
                    vs[i].value[static_cast<Index>(c)] =
                        Problem::path_value(s.u_path[c], *s.u[c], k, K);
        }
        Vector uk = fem::collect_supports(L.mesh, vs).u_fixed;
        if (share) share(uk);
        // f_k = F_k,free - K_(free,fixed) u_k, the lifting from the element-wise K u.
        const Vector F = nodal_loads_at(k);
        const Vector Ku = uk.isZero(0.0) ? Vector::Zero(uk.size())
                                         : fem::internal_forces(L.mesh, L.materials, uk);
        Vector f = Vector::Zero(L.dofs.n_dofs());
        for (int v = 0; v < nv; ++v)
            for (int c = 0; c < 3; ++c)
                if (const int d = L.dofs.u_dof(v, c); d >= 0) f[d] = F[3 * v + c] - Ku[3 * v + c];
        L.path_u_fixed[static_cast<size_t>(k - 1)] = std::move(uk);
        L.path_f[static_cast<size_t>(k - 1)] = std::move(f);
        L.path_f_nodal[static_cast<size_t>(k - 1)] = F;
    }
    L.path_u_fixed.back() = L.u_fixed;
    L.path_f.back() = L.elastic.f;
    L.path_f_nodal.back() = L.elastic.f_nodal_full;
}

Level3 build_level(const ElasticProblem3& p, mesh::TetMesh m) {
    Level3 L;
    std::vector<fem::VertexSupport3> vs;
    for (const Support3& s : p.supports) {
        fem::VertexSupport3 v;
        v.vertices = support_vertices(p, s, m);
        for (int c = 0; c < 3; ++c) {
            v.components[static_cast<size_t>(c)] = s.u[static_cast<size_t>(c)].has_value();
            v.value[c] = s.u[static_cast<size_t>(c)].value_or(0.0);
        }
        vs.push_back(std::move(v));
    }
    fem::Supports3 sup = fem::collect_supports(m, vs);
    L.fixed = std::move(sup.fixed);
    L.mesh = std::move(m);
    std::vector<int> n_extra;
    detail::find_contact_nodes3(p, L, n_extra);
    detail::pin_held_components3(p, L);
    L.dofs = fem::DofMap3(L.fixed, n_extra);
    L.lambda_dof.reserve(L.contacts.size());
    for (const auto& e : L.contacts)
        L.lambda_dof.push_back(L.dofs.extra_dof(e.vertex[0]));
    L.u_fixed = std::move(sup.u_fixed);
    std::vector<Vec3> bf;
    bool any_force = false;
    for (const Body3& b : p.bodies) {
        bf.push_back(b.body_force);
        L.materials.push_back(b.material);
        any_force = any_force || !b.body_force.isZero(0.0);
    }
    if (!any_force) bf.clear();
    // The nodal loads at path point k of K: each load times its factor there, the body forces
    // in proportion to s (they take no per-point factors). Point K of K = 1 is the full load.
    const int K = p.n_path_points();
    auto nodal_loads_at = [&](int k) {
        std::vector<fem::Traction3> tr;
        for (const FaceLoad3& l : p.loads) {
            const double a = K == 1 ? 1.0 : Problem::path_value(l.factors, 1.0, k, K);
            tr.push_back({L.mesh.tag(l.tag), a * l.pressure, a * l.traction});
        }
        std::vector<Vec3> bk = bf;
        if (K > 1)
            for (Vec3& b : bk)
                b *= static_cast<double>(k) / K;
        return fem::nodal_loads(L.mesh, tr, bk);
    };
    L.elastic = fem::assemble_elastic(L.mesh, L.materials, L.dofs, nodal_loads_at(K), L.u_fixed);
    if (K > 1) detail::set_load_path3(p, L, std::move(vs), nodal_loads_at);
    return L;
}

Hierarchy3 build_hierarchy(const ElasticProblem3& p, int levels) {
    p.validate();
    MLC_CHECK(levels >= 0 && levels <= kMaxLevels3,
              "levels must lie in [0, " << kMaxLevels3 << "], found " << levels);
    Hierarchy3 h;
    h.levels.push_back(build_level(p, p.mesh0));
    for (int l = 1; l <= levels; ++l) {
        mesh::TetMesh fine = mesh::refine(h.levels.back().mesh);
        mesh::check_refined_quality(fine);
        transfer::LevelTransfer t;
        t.P_vertex = transfer::vertex_prolongation(fine);
        Level3 L = build_level(p, std::move(fine));
        const Level3& C = h.levels.back();
        t.T = transfer::restrict_to_unknowns(
            t.P_vertex, 3, transfer::vertex_unknowns(C.dofs, 3), static_cast<int>(C.dofs.n_dofs()),
            transfer::vertex_unknowns(L.dofs, 3), static_cast<int>(L.dofs.n_dofs()));
        t.R = SparseMatrix(t.T.transpose());
        h.transfers.push_back(std::move(t));
        h.levels.push_back(std::move(L));
    }
    return h;
}

std::unique_ptr<solvers::Multigrid> elastic3_multigrid(const Hierarchy3& h,
                                                       solvers::MultigridParams params) {
    MLC_CHECK(h.levels.size() >= 2,
              "the 3D multigrid needs at least two levels (levels >= 1), found "
                  << h.levels.size());
    // What runs in 3D is the registry's to say (PreconditionerEntry::dimensions).
    solvers::MgOptions as_mg;
    as_mg.smoother = params.smoother;
    const std::string why = solvers::preconditioner_entry("mg")->dimension_reason(as_mg, 3);
    MLC_CHECK(why.empty(), why);
    const size_t n = h.levels.size();
    std::vector<solvers::MultigridLevelData> data(n);
    for (size_t l = 0; l < n; ++l) {
        if (l > 0) {
            data[l].T = &h.transfers[l - 1].T;
            data[l].R = &h.transfers[l - 1].R;
        }
        data[l].block_starts = solvers::vertex_block_starts(h.levels[l].vertex_of_dof());
    }
    auto mg = std::make_unique<solvers::Multigrid>(std::move(data), params);
    for (size_t l = 0; l + 1 < n; ++l)
        mg->set_operator(static_cast<int>(l), h.levels[l].elastic.K);
    mg->setup(h.levels[n - 1].elastic.K);
    return mg;
}

solvers::MultigridParams elastic3_mg_params() {
    solvers::MultigridParams p;
    p.pre_sweeps = 2;
    p.post_sweeps = 2;
    p.cycles = 2;
    return p;
}

std::unique_ptr<solvers::Multigrid> elastic3_multigrid(const Hierarchy3& h) {
    return elastic3_multigrid(h, elastic3_mg_params());
}

std::vector<Vector> rigid_body_modes3(const Level3& L) {
    const mesh::TetMesh& m = L.mesh;
    Vec3 lo = m.vertices.front(), hi = m.vertices.front();
    for (const Vec3& x : m.vertices) {
        lo = lo.cwiseMin(x);
        hi = hi.cwiseMax(x);
    }
    const Vec3 c = 0.5 * (lo + hi);
    std::vector<Vector> modes(6, Vector::Zero(L.dofs.n_dofs()));
    for (int v = 0; v < m.n_vertices(); ++v) {
        const Vec3 r = m.vertices[static_cast<size_t>(v)] - c;
        for (int k = 0; k < 3; ++k) {
            // Rotation about axis k: e_k x r.
            const Vec3 rot = Vec3::Unit(k).cross(r);
            for (int comp = 0; comp < 3; ++comp) {
                const int d = L.dofs.u_dof(v, comp);
                if (d < 0) continue;
                modes[static_cast<size_t>(k)][d] = comp == k ? 1.0 : 0.0;
                modes[static_cast<size_t>(3 + k)][d] = rot[comp];
            }
        }
    }
    return modes;
}

} // namespace mlc::levels

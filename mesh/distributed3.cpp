// SPDX-License-Identifier: MIT
// One process's part of a tetrahedral hierarchy refined from a partitioned level: local
// tetrahedra with one ghost layer, local refinement with the serial geometry, owners from the
// level-p location, global numbers by exchange (detail::number_vertices, shared with 2D).
#include "mesh/distributed3.hpp"
#include "mesh/distributed_piece.hpp"

#include "core/check.hpp"
#include "mesh/io/vtu_tet.hpp"
#include "mesh/tet_refine.hpp"

#include <algorithm>
#include <limits>
#include <map>
#include <optional>
#include <string>

namespace mlc::mesh {

namespace {
namespace tets { // (named: the unity build shares a batch with distributed.cpp)

using Key = std::pair<std::int64_t, std::int64_t>;

/// Level-p data every process holds: edge, face and tetrahedron numbers, the owner of the
/// interior of every edge and face, and the curved surface (TetMesh::shapes) that moves the
/// vertices refinement creates inside an edge or face, as the serial refinement does.
struct LevelP {
    std::map<std::array<int, 2>, int> edge_of;
    std::map<std::array<int, 3>, int> face_of;
    std::map<std::array<int, 4>, int> tet_of; ///< sorted vertices -> tetrahedron
    std::vector<std::array<int, 2>> edges;
    std::vector<std::array<int, 3>> faces;
    std::vector<std::array<int, 6>> tet_edges;
    std::vector<std::array<int, 4>> tet_faces; ///< the face opposite each vertex
    std::vector<int> edge_owner, face_owner;   ///< lowest part around the edge / beside the face
    std::vector<int> face_tet;                 ///< the lowest tetrahedron beside every face
    /// Shape of the first curved tagged boundary face (TetMesh::boundary order) whose closure
    /// holds the edge or face, or -1: refine() moves a midpoint by the first such face.
    std::vector<int> edge_shape, face_shape;
};

std::array<int, 3> sorted(std::array<int, 3> f) {
    std::sort(f.begin(), f.end());
    return f;
}

LevelP level_p(const TetMesh& m, const Partition& part) {
    LevelP lp;
    TetEdges te = tet_edges(m);
    lp.edges = std::move(te.edges);
    lp.tet_edges = std::move(te.tet_edges);
    lp.edge_owner.assign(lp.edges.size(), part.parts);
    for (size_t e = 0; e < lp.edges.size(); ++e)
        lp.edge_of.emplace(lp.edges[e], static_cast<int>(e));
    lp.tet_faces.resize(m.cells.size());
    for (size_t t = 0; t < m.cells.size(); ++t) {
        const auto& c = m.cells[t];
        const int pt = part.triangle_part[t];
        for (int e : lp.tet_edges[t]) {
            int& o = lp.edge_owner[static_cast<size_t>(e)];
            o = std::min(o, pt);
        }
        std::array<int, 4> q = c;
        std::sort(q.begin(), q.end());
        lp.tet_of.emplace(q, static_cast<int>(t));
        for (size_t k = 0; k < 4; ++k) {
            const auto f = sorted({c[(k + 1) % 4], c[(k + 2) % 4], c[(k + 3) % 4]});
            auto [it, fresh] = lp.face_of.emplace(f, static_cast<int>(lp.faces.size()));
            if (fresh) {
                lp.faces.push_back(f);
                lp.face_owner.push_back(pt);
                lp.face_tet.push_back(static_cast<int>(t));
            } else {
                int& o = lp.face_owner[static_cast<size_t>(it->second)];
                o = std::min(o, pt);
            }
            lp.tet_faces[t][k] = it->second;
        }
    }
    lp.edge_shape.assign(lp.edges.size(), -1);
    lp.face_shape.assign(lp.faces.size(), -1);
    for (const BoundaryFace& b : m.boundary) {
        const auto it = lp.face_of.find(sorted(b.v));
        MLC_CHECK(it != lp.face_of.end(), "distribute: boundary face (" << b.v[0] << ", " << b.v[1]
                                                                        << ", " << b.v[2]
                                                                        << ") is no face of a "
                                                                           "tetrahedron");
        if (b.shape < 0) continue;
        int& fs = lp.face_shape[static_cast<size_t>(it->second)];
        if (fs < 0) fs = b.shape;
        for (size_t k = 0; k < 3; ++k) {
            const auto [a, c] = std::minmax(b.v[k], b.v[(k + 1) % 3]);
            int& es = lp.edge_shape[static_cast<size_t>(lp.edge_of.at({a, c}))];
            if (es < 0) es = b.shape;
        }
    }
    return lp;
}

using Vec = Vec3;

/// Distance from p to the closed triangle (a, b, c) (Ericson, Real-Time Collision Detection,
/// 5.1.5: the closest point by its Voronoi region).
double point_triangle(const Vec& p, const Vec& a, const Vec& b, const Vec& c) {
    const Vec ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0 && d2 <= 0) return ap.norm();
    const Vec bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0 && d4 <= d3) return bp.norm();
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return (p - (a + d1 / (d1 - d3) * ab)).norm();
    const Vec cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0 && d5 <= d6) return cp.norm();
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return (p - (a + d2 / (d2 - d6) * ac)).norm();
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
        return (p - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b))).norm();
    const double denom = va + vb + vc;
    return (p - (a + vb / denom * ab + vc / denom * ac)).norm();
}

/// Distance between the segments p1 q1 and p2 q2 (Ericson 5.1.9).
double segment_segment(const Vec& p1, const Vec& q1, const Vec& p2, const Vec& q2) {
    const Vec d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
    const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
    double s = 0, t = 0;
    if (a <= 0 && e <= 0) return r.norm();
    if (a <= 0) {
        t = std::clamp(f / e, 0.0, 1.0);
    } else {
        const double c = d1.dot(r);
        if (e <= 0) {
            s = std::clamp(-c / a, 0.0, 1.0);
        } else {
            const double b = d1.dot(d2), denom = a * e - b * b;
            s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
            t = (b * s + f) / e;
            if (t < 0) {
                t = 0;
                s = std::clamp(-c / a, 0.0, 1.0);
            } else if (t > 1) {
                t = 1;
                s = std::clamp((b - c) / a, 0.0, 1.0);
            }
        }
    }
    return ((p1 + s * d1) - (p2 + t * d2)).norm();
}

/// Distance between two triangles that do not cross: the least of the distances of a corner of
/// one to the other and of an edge of one to an edge of the other.
double triangle_triangle(const std::array<Vec, 3>& x, const std::array<Vec, 3>& y) {
    double d = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < 3; ++i) {
        d = std::min(
            {d, point_triangle(x[i], y[0], y[1], y[2]), point_triangle(y[i], x[0], x[1], x[2])});
        for (size_t j = 0; j < 3; ++j)
            d = std::min(d, segment_segment(x[i], x[(i + 1) % 3], y[j], y[(j + 1) % 3]));
    }
    return d;
}

/// The tetrahedra (flagged in `local`) added by `reach` to a local set (GhostReach).
void widen_along_contact(const TetMesh& m, const LevelP& lp, const std::vector<GhostReach>& reach,
                         std::vector<char>& local) {
    std::vector<char> add(local.size(), 0);
    auto corners = [&](const BoundaryFace& f) {
        return std::array<Vec, 3>{m.vertices[static_cast<size_t>(f.v[0])],
                                  m.vertices[static_cast<size_t>(f.v[1])],
                                  m.vertices[static_cast<size_t>(f.v[2])]};
    };
    for (const GhostReach& r : reach) {
        std::vector<std::pair<int, int>> seeds, candidates; // (boundary face, its tetrahedron)
        for (size_t i = 0; i < m.boundary.size(); ++i) {
            const BoundaryFace& f = m.boundary[i];
            if (std::find(r.tags.begin(), r.tags.end(), f.tag) == r.tags.end()) continue;
            const int t = lp.face_tet[static_cast<size_t>(lp.face_of.at(sorted(f.v)))];
            (local[static_cast<size_t>(t)] ? seeds : candidates)
                .emplace_back(static_cast<int>(i), t);
        }
        for (const auto& [ci, ct] : candidates) {
            if (add[static_cast<size_t>(ct)]) continue;
            const auto c = corners(m.boundary[static_cast<size_t>(ci)]);
            for (const auto& [si, st] : seeds)
                if (triangle_triangle(c, corners(m.boundary[static_cast<size_t>(si)])) <=
                    r.distance) {
                    add[static_cast<size_t>(ct)] = 1;
                    break;
                }
        }
    }
    for (size_t t = 0; t < local.size(); ++t)
        local[t] = local[t] || add[t];
}

/// The local mesh of level p: owned tetrahedra, those sharing a vertex with one, and those
/// `reach` adds along contact interfaces.
LocalTetLevel local_level_p(const TetMesh& m, const LevelP& lp, const Partition& part, int rank,
                            const std::vector<GhostReach>& reach) {
    const int nv = m.n_vertices(), nt = m.n_cells();
    std::vector<char> touched(static_cast<size_t>(nv), 0);
    for (int t = 0; t < nt; ++t)
        if (part.triangle_part[static_cast<size_t>(t)] == rank)
            for (int v : m.cells[static_cast<size_t>(t)])
                touched[static_cast<size_t>(v)] = 1;
    std::vector<char> local_tet(static_cast<size_t>(nt), 0);
    for (size_t t = 0; t < local_tet.size(); ++t)
        for (int v : m.cells[t])
            local_tet[t] = local_tet[t] || touched[static_cast<size_t>(v)];
    if (!reach.empty()) widen_along_contact(m, lp, reach, local_tet);
    LocalTetLevel L;
    std::vector<int> local_of(static_cast<size_t>(nv), -1);
    std::vector<char> local_edge(lp.edges.size(), 0), local_face(lp.faces.size(), 0);
    for (size_t t = 0; t < local_tet.size(); ++t)
        if (local_tet[t]) {
            for (int v : m.cells[t])
                local_of[static_cast<size_t>(v)] = 0;
            for (int e : lp.tet_edges[t])
                local_edge[static_cast<size_t>(e)] = 1;
            for (int f : lp.tet_faces[t])
                local_face[static_cast<size_t>(f)] = 1;
        }
    for (int v = 0; v < nv; ++v)
        if (local_of[static_cast<size_t>(v)] == 0) {
            local_of[static_cast<size_t>(v)] = L.mesh.n_vertices();
            L.mesh.vertices.push_back(m.vertices[static_cast<size_t>(v)]);
            L.vertex_location.push_back({TetLocation::Kind::vertex, v});
            L.vertex_owner.push_back(part.vertex_owner[static_cast<size_t>(v)]);
        }
    auto to_local = [&](int v) { return local_of[static_cast<size_t>(v)]; };
    for (int t = 0; t < nt; ++t) {
        if (!local_tet[static_cast<size_t>(t)]) continue;
        const auto& c = m.cells[static_cast<size_t>(t)];
        L.mesh.cells.push_back({to_local(c[0]), to_local(c[1]), to_local(c[2]), to_local(c[3])});
        if (!m.attribute.empty()) L.mesh.attribute.push_back(m.attribute[static_cast<size_t>(t)]);
        L.tet_ancestor.push_back(t);
        L.tet_owned.push_back(part.triangle_part[static_cast<size_t>(t)] == rank ? 1 : 0);
    }
    // The tagged faces of the local tetrahedra and the tagged lines on their edges, in the
    // level-p order (on one process: all of them, as the serial mesh has them).
    for (const BoundaryFace& b : m.boundary)
        if (local_face[static_cast<size_t>(lp.face_of.at(sorted(b.v)))])
            L.mesh.boundary.push_back(
                {{to_local(b.v[0]), to_local(b.v[1]), to_local(b.v[2])}, b.tag, b.shape});
    for (const BoundaryEdge& l : m.lines) {
        const auto it = lp.edge_of.find({std::min(l.v0, l.v1), std::max(l.v0, l.v1)});
        MLC_CHECK(it != lp.edge_of.end(),
                  "distribute: line (" << l.v0 << ", " << l.v1 << ") is no edge of a tetrahedron");
        if (local_edge[static_cast<size_t>(it->second)])
            L.mesh.lines.push_back({to_local(l.v0), to_local(l.v1), l.tag, l.shape});
    }
    L.mesh.shapes = m.shapes;
    L.mesh.tag_names = m.tag_names;
    return L;
}

/// Adds the level-p vertices of the closure of a location's entity to the sorted set s[0, n)
/// (the vertices of the level-p tetrahedron both ends of a new vertex's edge lie in: at most 4).
void add_closure(const TetLocation& l, const LevelP& lp, const TetMesh& m, std::array<int, 4>& s,
                 size_t& n) {
    auto insert = [&](int v) {
        size_t i = 0;
        while (i < n && s[i] < v)
            ++i;
        if (i < n && s[i] == v) return;
        MLC_CHECK(n < s.size(), "distribute: a new vertex's edge spans more than a tetrahedron");
        for (size_t j = n; j > i; --j)
            s[j] = s[j - 1];
        s[i] = v;
        ++n;
    };
    const auto id = static_cast<size_t>(l.id);
    switch (l.kind) {
    case TetLocation::Kind::vertex:
        insert(l.id);
        return;
    case TetLocation::Kind::edge:
        for (int v : lp.edges[id])
            insert(v);
        return;
    case TetLocation::Kind::face:
        for (int v : lp.faces[id])
            insert(v);
        return;
    case TetLocation::Kind::tet:
        for (int v : m.cells[id])
            insert(v);
        return;
    }
}

/// The next level of a process's part: local refinement, inherited tetrahedron data, and the
/// location, owner and serial position of every new vertex.
LocalTetLevel refine_local(const LocalTetLevel& c, const LevelP& lp, const TetMesh& m,
                           const Partition& part) {
    LocalTetLevel f;
    f.mesh = refine(c.mesh);
    const size_t nt = c.mesh.cells.size();
    f.tet_ancestor.resize(kTetrahedronChildren * nt);
    f.tet_owned.resize(kTetrahedronChildren * nt);
    for (size_t t = 0; t < nt; ++t)
        for (size_t k = 0; k < kTetrahedronChildren; ++k) {
            f.tet_ancestor[kTetrahedronChildren * t + k] = c.tet_ancestor[t];
            f.tet_owned[kTetrahedronChildren * t + k] = c.tet_owned[t];
        }
    f.vertex_location = c.vertex_location;
    f.vertex_owner = c.vertex_owner;
    using Kind = TetLocation::Kind;
    const size_t nc = c.vertex_location.size();
    for (size_t v = nc; v < static_cast<size_t>(f.mesh.n_vertices()); ++v) {
        const auto& [a, b] = f.mesh.parents[v - nc];
        // The midpoint lies inside the entity spanned by the vertices of its ends' entities.
        std::array<int, 4> s{};
        size_t n = 0;
        add_closure(c.vertex_location[static_cast<size_t>(a)], lp, m, s, n);
        add_closure(c.vertex_location[static_cast<size_t>(b)], lp, m, s, n);
        TetLocation loc;
        int owner = -1, shape = -1;
        if (n == 2) {
            loc = {Kind::edge, lp.edge_of.at({s[0], s[1]})};
            owner = lp.edge_owner[static_cast<size_t>(loc.id)];
            shape = lp.edge_shape[static_cast<size_t>(loc.id)];
        } else if (n == 3) {
            loc = {Kind::face, lp.face_of.at({s[0], s[1], s[2]})};
            owner = lp.face_owner[static_cast<size_t>(loc.id)];
            shape = lp.face_shape[static_cast<size_t>(loc.id)];
        } else {
            MLC_CHECK(n == 4, "distribute: new vertex " << v << " between local vertices " << a
                                                        << " and " << b
                                                        << " lies at a level-p vertex");
            loc = {Kind::tet, lp.tet_of.at({s[0], s[1], s[2], s[3]})};
            owner = part.triangle_part[static_cast<size_t>(loc.id)];
        }
        f.vertex_location.push_back(loc);
        f.vertex_owner.push_back(owner);
        // Where refine() of the serial mesh puts it: the midpoint of its (serially placed) ends,
        // moved onto the surface of the first curved face whose closure holds the edge, which
        // need not be a face of a local tetrahedron.
        Vec3 x = 0.5 * (f.mesh.vertices[static_cast<size_t>(a)] +
                        f.mesh.vertices[static_cast<size_t>(b)]);
        if (shape >= 0) {
            const CurvedSurface& surface = m.shapes[static_cast<size_t>(shape)];
            const std::optional<Vec3> on = surface.project(x);
            MLC_CHECK(on, "distribute: the midpoint of vertices "
                              << a << " and " << b << " lies at the centre or on the axis of its "
                              << surface.describe());
            x = *on;
        }
        f.mesh.vertices[v] = x;
    }
    return f;
}

/// Global numbers and the global tetrahedron count of a level.
void number_vertices(LocalTetLevel& L, const std::vector<Key>& keys, const Communicator& comm) {
    detail::VertexNumbers n = detail::number_vertices(L.vertex_owner, keys, comm);
    L.global_vertex = std::move(n.global_vertex);
    L.owned_vertices = std::move(n.owned_vertices);
    L.first_vertex = n.first_vertex;
    L.n_global_vertices = n.n_global_vertices;
    std::int64_t owned = 0;
    for (char o : L.tet_owned)
        owned += o;
    L.n_global_tets = comm.sum(owned);
}

} // namespace tets
} // namespace

DistributedTetHierarchy distribute(const TetMesh& level_p, int n_refinements,
                                   const Communicator& comm, const std::vector<int>& weights,
                                   const std::vector<GhostReach>& reach) {
    MLC_CHECK(n_refinements >= 0,
              "distribute: n_refinements must be >= 0, found " << n_refinements);
    DistributedTetHierarchy H;
    H.rank = comm.rank();
    H.n_processes = comm.size();
    H.partition = partition_tets(level_p, comm.size(), weights);
    const tets::LevelP lp = tets::level_p(level_p, H.partition);
    H.edges = lp.edges;
    H.faces = lp.faces;
    H.levels.reserve(static_cast<size_t>(n_refinements) + 1);
    H.levels.push_back(tets::local_level_p(level_p, lp, H.partition, H.rank, reach));
    {
        LocalTetLevel& L = H.levels.back();
        std::vector<tets::Key> keys(L.vertex_location.size());
        for (size_t v = 0; v < keys.size(); ++v)
            keys[v] = {L.vertex_location[v].id, -1};
        tets::number_vertices(L, keys, comm);
    }
    for (int k = 1; k <= n_refinements; ++k) {
        const LocalTetLevel& c = H.levels.back();
        LocalTetLevel f = tets::refine_local(c, lp, level_p, H.partition);
        std::vector<tets::Key> keys(static_cast<size_t>(f.mesh.n_vertices()));
        const size_t nc = static_cast<size_t>(c.mesh.n_vertices());
        for (size_t v = 0; v < nc; ++v)
            keys[v] = {c.global_vertex[v], -1};
        for (size_t v = nc; v < keys.size(); ++v) {
            const auto& pr = f.mesh.parents[v - nc];
            const std::int64_t a = c.global_vertex[static_cast<size_t>(pr[0])];
            const std::int64_t b = c.global_vertex[static_cast<size_t>(pr[1])];
            keys[v] = {std::min(a, b), std::max(a, b)};
        }
        tets::number_vertices(f, keys, comm);
        H.levels.push_back(std::move(f));
    }
    return H;
}

void write_distributed_vtu(const std::filesystem::path& file, const LocalTetLevel& L,
                           const std::vector<Field>& point_fields,
                           const std::vector<Field>& cell_fields, const Communicator& comm) {
    detail::on_every_process(comm, "write_distributed_vtu (pieces)", [&] {
        auto piece =
            detail::owned_piece(L.mesh, L.tet_owned, point_fields, cell_fields, "tetrahedra");
        if (!L.mesh.attribute.empty())
            for (int t : piece.cells)
                piece.mesh.attribute.push_back(L.mesh.attribute[static_cast<size_t>(t)]);
        write_vtu(piece_path(file, comm.rank()), piece.mesh,
                  detail::subset(point_fields, piece.vertices),
                  detail::subset(cell_fields, piece.cells));
    });
    detail::on_every_process(comm, "write_distributed_vtu (.pvtu)", [&] {
        if (comm.rank() != 0) return;
        // The pieces hold the cell field "body" first (write_vtu for a TetMesh).
        std::vector<Field> cells{Field{"body", 1, {}}};
        cells.insert(cells.end(), cell_fields.begin(), cell_fields.end());
        write_pvtu(file, detail::piece_names(file, comm), point_fields, cells);
    });
}

} // namespace mlc::mesh

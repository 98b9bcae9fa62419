// SPDX-License-Identifier: MIT
// One process's part of a hierarchy refined from a partitioned level: local triangles with one
// ghost layer, local refinement, owners from the level-p location, global numbers by exchange.
#include "mesh/distributed.hpp"
#include "mesh/distributed_piece.hpp"

#include "core/check.hpp"

#include <algorithm>
#include <exception>
#include <map>
#include <stdexcept>
#include <unordered_map>

namespace mlc::mesh {

namespace {

using Key = std::pair<std::int64_t, std::int64_t>;

struct KeyHash {
    size_t operator()(const Key& k) const {
        return std::hash<std::int64_t>()(k.first * 0x9E3779B97F4A7C15LL ^ k.second);
    }
};

/// Level-p data every process holds: edge numbers and the owner of each edge's interior.
struct LevelP {
    std::map<std::pair<int, int>, int> edge_of;
    std::vector<std::array<int, 2>> edges;
    std::vector<int> edge_owner; // lowest part beside the edge
};

LevelP level_p_edges(const Mesh& m, const Partition& part) {
    LevelP e;
    for (int t = 0; t < m.n_cells(); ++t) {
        const auto& tri = m.cells[static_cast<size_t>(t)];
        const int pt = part.triangle_part[static_cast<size_t>(t)];
        for (int k = 0; k < 3; ++k) {
            const auto [a, b] =
                std::minmax(tri[static_cast<size_t>(k)], tri[static_cast<size_t>((k + 1) % 3)]);
            auto [it, fresh] =
                e.edge_of.emplace(std::make_pair(a, b), static_cast<int>(e.edges.size()));
            if (fresh) {
                e.edges.push_back({a, b});
                e.edge_owner.push_back(pt);
            } else {
                int& o = e.edge_owner[static_cast<size_t>(it->second)];
                o = std::min(o, pt);
            }
        }
    }
    return e;
}

double point_segment_distance(const Vec2& x, const Vec2& a, const Vec2& b) {
    const Vec2 d = b - a;
    const double len2 = d.squaredNorm();
    const double t = len2 > 0 ? std::clamp((x - a).dot(d) / len2, 0.0, 1.0) : 0.0;
    return (x - (a + t * d)).norm();
}

/// Distance between two segments that do not cross (boundary edges): the least distance of an
/// end point of one to the other.
double segment_distance(const Vec2& a0, const Vec2& a1, const Vec2& b0, const Vec2& b1) {
    return std::min({point_segment_distance(a0, b0, b1), point_segment_distance(a1, b0, b1),
                     point_segment_distance(b0, a0, a1), point_segment_distance(b1, a0, a1)});
}

/// The triangles (flagged in `local`) added by `reach` to a local set (GhostReach).
void widen_along_contact(const Mesh& m, const std::vector<GhostReach>& reach,
                         std::vector<char>& local) {
    if (reach.empty()) return;
    // The triangle of every boundary edge.
    std::map<std::pair<int, int>, int> triangle_of;
    for (int t = 0; t < m.n_cells(); ++t) {
        const auto& tri = m.cells[static_cast<size_t>(t)];
        for (int k = 0; k < 3; ++k)
            triangle_of.emplace(
                std::minmax(tri[static_cast<size_t>(k)], tri[static_cast<size_t>((k + 1) % 3)]), t);
    }
    std::vector<char> add(local.size(), 0);
    for (const GhostReach& r : reach) {
        std::vector<std::pair<int, int>> seeds, candidates; // (boundary edge, its triangle)
        for (size_t i = 0; i < m.boundary.size(); ++i) {
            const auto& e = m.boundary[i];
            if (std::find(r.tags.begin(), r.tags.end(), e.tag) == r.tags.end()) continue;
            const auto it = triangle_of.find(std::minmax(e.v0, e.v1));
            MLC_CHECK(it != triangle_of.end(), "distribute: boundary edge (" << e.v0 << ", " << e.v1
                                                                             << ") is no edge of a "
                                                                             << "triangle");
            (local[static_cast<size_t>(it->second)] ? seeds : candidates)
                .emplace_back(static_cast<int>(i), it->second);
        }
        for (const auto& [ci, ct] : candidates) {
            if (add[static_cast<size_t>(ct)]) continue;
            const auto& c = m.boundary[static_cast<size_t>(ci)];
            const Vec2& c0 = m.vertices[static_cast<size_t>(c.v0)];
            const Vec2& c1 = m.vertices[static_cast<size_t>(c.v1)];
            for (const auto& [si, st] : seeds) {
                const auto& e = m.boundary[static_cast<size_t>(si)];
                if (segment_distance(c0, c1, m.vertices[static_cast<size_t>(e.v0)],
                                     m.vertices[static_cast<size_t>(e.v1)]) <= r.distance) {
                    add[static_cast<size_t>(ct)] = 1;
                    break;
                }
            }
        }
    }
    for (size_t t = 0; t < local.size(); ++t)
        local[t] = local[t] || add[t];
}

/// The local mesh of level p: owned triangles and those sharing a vertex with one, and those
/// `reach` adds along contact interfaces.
LocalLevel local_level_p(const Mesh& m, const Partition& part, int rank,
                         const std::vector<GhostReach>& reach) {
    const int nv = m.n_vertices(), nt = m.n_cells();
    std::vector<char> touched(static_cast<size_t>(nv), 0);
    for (int t = 0; t < nt; ++t)
        if (part.triangle_part[static_cast<size_t>(t)] == rank)
            for (int v : m.cells[static_cast<size_t>(t)])
                touched[static_cast<size_t>(v)] = 1;
    std::vector<char> local_triangle(static_cast<size_t>(nt), 0);
    for (int t = 0; t < nt; ++t) {
        const auto& tri = m.cells[static_cast<size_t>(t)];
        local_triangle[static_cast<size_t>(t)] = touched[static_cast<size_t>(tri[0])] ||
                                                 touched[static_cast<size_t>(tri[1])] ||
                                                 touched[static_cast<size_t>(tri[2])];
    }
    widen_along_contact(m, reach, local_triangle);
    LocalLevel L;
    std::vector<int> local_of(static_cast<size_t>(nv), -1);
    std::vector<int> tris;
    for (int t = 0; t < nt; ++t) {
        const auto& tri = m.cells[static_cast<size_t>(t)];
        if (local_triangle[static_cast<size_t>(t)]) {
            tris.push_back(t);
            for (int v : tri)
                local_of[static_cast<size_t>(v)] = 0;
        }
    }
    for (int v = 0; v < nv; ++v)
        if (local_of[static_cast<size_t>(v)] == 0) {
            local_of[static_cast<size_t>(v)] = L.mesh.n_vertices();
            L.mesh.vertices.push_back(m.vertices[static_cast<size_t>(v)]);
            L.vertex_location.push_back({Location::Kind::vertex, v});
            L.vertex_owner.push_back(part.vertex_owner[static_cast<size_t>(v)]);
        }
    std::map<std::pair<int, int>, int> local_edges;
    for (int t : tris) {
        const auto& tri = m.cells[static_cast<size_t>(t)];
        L.mesh.cells.push_back({local_of[static_cast<size_t>(tri[0])],
                                local_of[static_cast<size_t>(tri[1])],
                                local_of[static_cast<size_t>(tri[2])]});
        if (!m.attribute.empty()) L.mesh.attribute.push_back(m.attribute[static_cast<size_t>(t)]);
        L.triangle_ancestor.push_back(t);
        L.triangle_owned.push_back(part.triangle_part[static_cast<size_t>(t)] == rank ? 1 : 0);
        for (int k = 0; k < 3; ++k)
            local_edges.emplace(
                std::minmax(tri[static_cast<size_t>(k)], tri[static_cast<size_t>((k + 1) % 3)]), 0);
    }
    // Boundary edges and lines of the local triangles (all of them, so that refinement moves
    // every midpoint on a circle exactly as the serial refinement does).
    auto keep = [&](const std::vector<BoundaryEdge>& from, std::vector<BoundaryEdge>& to) {
        for (const auto& e : from)
            if (local_edges.count(std::minmax(e.v0, e.v1)))
                to.push_back({local_of[static_cast<size_t>(e.v0)],
                              local_of[static_cast<size_t>(e.v1)], e.tag, e.shape});
    };
    keep(m.boundary, L.mesh.boundary);
    keep(m.lines, L.mesh.lines);
    L.mesh.shapes = m.shapes;
    L.mesh.tag_names = m.tag_names;
    return L;
}

/// The next level of a process's part: local refinement, inherited triangle data, and the
/// location and owner of every new vertex.
LocalLevel refine_local(const LocalLevel& c, const LevelP& lp, const Partition& part) {
    LocalLevel f;
    f.mesh = refine(c.mesh);
    const size_t nt = c.mesh.cells.size();
    f.triangle_ancestor.resize(4 * nt);
    f.triangle_owned.resize(4 * nt);
    for (size_t t = 0; t < nt; ++t)
        for (size_t k = 0; k < 4; ++k) {
            f.triangle_ancestor[4 * t + k] = c.triangle_ancestor[t];
            f.triangle_owned[4 * t + k] = c.triangle_owned[t];
        }
    const size_t nv = static_cast<size_t>(f.mesh.n_vertices());
    f.vertex_location.assign(nv, Location{});
    f.vertex_owner.assign(nv, -1);
    std::copy(c.vertex_location.begin(), c.vertex_location.end(), f.vertex_location.begin());
    std::copy(c.vertex_owner.begin(), c.vertex_owner.end(), f.vertex_owner.begin());
    using Kind = Location::Kind;
    auto on_edge = [&](const Location& v, int edge) {
        const auto& e = lp.edges[static_cast<size_t>(edge)];
        return v.kind == Kind::vertex && (v.id == e[0] || v.id == e[1]);
    };
    auto locate = [&](int a, int b, int ancestor) -> Location {
        const Location& la = c.vertex_location[static_cast<size_t>(a)];
        const Location& lb = c.vertex_location[static_cast<size_t>(b)];
        if (la.kind == Kind::vertex && lb.kind == Kind::vertex)
            return {Kind::edge, lp.edge_of.at(std::minmax(la.id, lb.id))};
        if (la.kind == Kind::edge && (lb.kind == Kind::edge ? lb.id == la.id : on_edge(lb, la.id)))
            return la;
        if (lb.kind == Kind::edge && on_edge(la, lb.id)) return lb;
        return {Kind::triangle, ancestor};
    };
    // refine(): children 4t = {a, ab, ca}, 4t+1 = {ab, b, bc}: the midpoints of t's edges.
    for (size_t t = 0; t < nt; ++t) {
        const auto& tri = c.mesh.cells[t];
        const auto& c0 = f.mesh.cells[4 * t];
        const auto& c1 = f.mesh.cells[4 * t + 1];
        const std::array<std::array<int, 3>, 3> mids = {
            {{tri[0], tri[1], c0[1]}, {tri[1], tri[2], c1[2]}, {tri[2], tri[0], c0[2]}}};
        for (const auto& [a, b, m] : mids) {
            if (f.vertex_owner[static_cast<size_t>(m)] >= 0) continue;
            const Location loc = locate(a, b, c.triangle_ancestor[t]);
            f.vertex_location[static_cast<size_t>(m)] = loc;
            f.vertex_owner[static_cast<size_t>(m)] =
                loc.kind == Kind::edge ? lp.edge_owner[static_cast<size_t>(loc.id)]
                                       : part.triangle_part[static_cast<size_t>(loc.id)];
        }
    }
    return f;
}

/// Global numbers and the global triangle count of a level (detail::number_vertices).
void number_vertices(LocalLevel& L, const std::vector<Key>& keys, const Communicator& comm) {
    detail::VertexNumbers n = detail::number_vertices(L.vertex_owner, keys, comm);
    L.global_vertex = std::move(n.global_vertex);
    L.owned_vertices = std::move(n.owned_vertices);
    L.first_vertex = n.first_vertex;
    L.n_global_vertices = n.n_global_vertices;
    std::int64_t owned_triangles = 0;
    for (char o : L.triangle_owned)
        owned_triangles += o;
    L.n_global_triangles = comm.sum(owned_triangles);
}

} // namespace

DistributedHierarchy distribute(const Mesh& level_p, int n_refinements, const Communicator& comm,
                                const std::vector<int>& weights,
                                const std::vector<GhostReach>& reach) {
    MLC_CHECK(n_refinements >= 0,
              "distribute: n_refinements must be >= 0, found " << n_refinements);
    DistributedHierarchy H;
    H.rank = comm.rank();
    H.n_processes = comm.size();
    H.partition = partition_triangles(level_p, comm.size(), weights);
    const LevelP lp = level_p_edges(level_p, H.partition);
    H.edges = lp.edges;
    H.levels.reserve(static_cast<size_t>(n_refinements) + 1);
    H.levels.push_back(local_level_p(level_p, H.partition, H.rank, reach));
    {
        LocalLevel& L = H.levels.back();
        std::vector<Key> keys(L.vertex_location.size());
        for (size_t v = 0; v < keys.size(); ++v)
            keys[v] = {L.vertex_location[v].id, -1};
        number_vertices(L, keys, comm);
    }
    for (int k = 1; k <= n_refinements; ++k) {
        const LocalLevel& c = H.levels.back();
        LocalLevel f = refine_local(c, lp, H.partition);
        std::vector<Key> keys(static_cast<size_t>(f.mesh.n_vertices()));
        const size_t nc = static_cast<size_t>(c.mesh.n_vertices());
        for (size_t v = 0; v < nc; ++v)
            keys[v] = {c.global_vertex[v], -1};
        for (size_t v = nc; v < keys.size(); ++v) {
            const auto& pr = f.mesh.parents[v - nc];
            const std::int64_t a = c.global_vertex[static_cast<size_t>(pr[0])];
            const std::int64_t b = c.global_vertex[static_cast<size_t>(pr[1])];
            keys[v] = {std::min(a, b), std::max(a, b)};
        }
        number_vertices(f, keys, comm);
        H.levels.push_back(std::move(f));
    }
    return H;
}

std::filesystem::path piece_path(const std::filesystem::path& file, int rank) {
    return file.parent_path() / (file.stem().string() + "_" + std::to_string(rank) + ".vtu");
}

namespace detail {

// Global numbers: owned vertices numbered in rank order, the others asked of their owners by
// a key every process computes alike (the level-p index, or the global numbers of the two
// parents on the level above).
VertexNumbers number_vertices(const std::vector<int>& vertex_owner, const std::vector<Key>& keys,
                              const Communicator& comm) {
    VertexNumbers L;
    const int rank = comm.rank(), np = comm.size();
    const size_t nv = vertex_owner.size();
    L.owned_vertices.clear();
    for (size_t v = 0; v < nv; ++v)
        if (vertex_owner[v] == rank) L.owned_vertices.push_back(static_cast<int>(v));
    const auto n_owned = static_cast<std::int64_t>(L.owned_vertices.size());
    L.first_vertex = comm.exclusive_sum(n_owned);
    L.n_global_vertices = comm.sum(n_owned);
    L.global_vertex.assign(nv, -1);
    std::unordered_map<Key, std::int64_t, KeyHash> owned_key;
    owned_key.reserve(L.owned_vertices.size());
    for (size_t i = 0; i < L.owned_vertices.size(); ++i) {
        const auto v = static_cast<size_t>(L.owned_vertices[i]);
        L.global_vertex[v] = L.first_vertex + static_cast<std::int64_t>(i);
        owned_key.emplace(keys[v], L.global_vertex[v]);
    }
    std::vector<std::vector<std::int64_t>> ask(static_cast<size_t>(np));
    std::vector<std::vector<int>> asked(static_cast<size_t>(np));
    for (size_t v = 0; v < nv; ++v) {
        const int o = vertex_owner[v];
        if (o == rank) continue;
        MLC_CHECK(o >= 0 && o < np, "distribute: vertex " << v << " has owner " << o);
        ask[static_cast<size_t>(o)].push_back(keys[v].first);
        ask[static_cast<size_t>(o)].push_back(keys[v].second);
        asked[static_cast<size_t>(o)].push_back(static_cast<int>(v));
    }
    const auto requests = comm.exchange(ask);
    std::vector<std::vector<std::int64_t>> answer(static_cast<size_t>(np));
    for (size_t q = 0; q < requests.size(); ++q)
        for (size_t i = 0; i + 1 < requests[q].size(); i += 2) {
            const auto it = owned_key.find({requests[q][i], requests[q][i + 1]});
            // The owner holds every vertex it owns (see the header), so a miss is a bug.
            answer[q].push_back(it == owned_key.end() ? -1 : it->second);
        }
    const auto answers = comm.exchange(answer);
    for (size_t q = 0; q < answers.size(); ++q) {
        MLC_CHECK(answers[q].size() == asked[q].size(),
                  "distribute: process " << q << " answered " << answers[q].size() << " of "
                                         << asked[q].size() << " vertex numbers");
        for (size_t i = 0; i < answers[q].size(); ++i) {
            MLC_CHECK(answers[q][i] >= 0, "distribute: process " << q << " does not hold vertex "
                                                                 << asked[q][i] << " it owns");
            L.global_vertex[static_cast<size_t>(asked[q][i])] = answers[q][i];
        }
    }
    return L;
}

void on_every_process(const Communicator& comm, const char* what,
                      const std::function<void()>& write) {
    std::exception_ptr error;
    try {
        write();
    } catch (...) {
        error = std::current_exception();
    }
    if (comm.max(error ? 1 : 0) == 0) return;
    if (error) std::rethrow_exception(error);
    throw std::runtime_error(std::string(what) + ": another process failed (see its message)");
}

std::vector<Field> subset(const std::vector<Field>& fields, const std::vector<int>& entities) {
    std::vector<Field> out;
    for (const Field& f : fields) {
        Field g{f.name, f.n_components, {}};
        const auto nc = static_cast<size_t>(f.n_components);
        g.values.reserve(entities.size() * nc);
        for (int e : entities)
            for (size_t c = 0; c < nc; ++c)
                g.values.push_back(f.values[static_cast<size_t>(e) * nc + c]);
        out.push_back(std::move(g));
    }
    return out;
}

} // namespace detail

void write_distributed_vtu(const std::filesystem::path& file, const LocalLevel& L,
                           const std::vector<Field>& point_fields,
                           const std::vector<Field>& cell_fields, const Communicator& comm,
                           VtuFormat format) {
    detail::on_every_process(comm, "write_distributed_vtu (pieces)", [&] {
        const auto piece =
            detail::owned_piece(L.mesh, L.triangle_owned, point_fields, cell_fields, "triangles");
        write_vtu(piece_path(file, comm.rank()), piece.mesh,
                  detail::subset(point_fields, piece.vertices),
                  detail::subset(cell_fields, piece.cells), format);
    });
    detail::on_every_process(comm, "write_distributed_vtu (.pvtu)", [&] {
        if (comm.rank() == 0)
            write_pvtu(file, detail::piece_names(file, comm), point_fields, cell_fields);
    });
}

} // namespace mlc::mesh

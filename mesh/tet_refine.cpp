// SPDX-License-Identifier: MIT
// Bey's 1->8 refinement of a tetrahedral mesh and the predicted sizes of its levels.
#include "mesh/tet_refine.hpp"

#include "core/check.hpp"

#include <cstdint>
#include <limits>
#include <unordered_map>

namespace mlc::mesh {

namespace {

std::uint64_t edge_key(int a, int b) {
    if (a > b) std::swap(a, b);
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
           static_cast<std::uint32_t>(b);
}

} // namespace

TetMesh refine(const TetMesh& coarse) {
    const TetEdges edges = tet_edges(coarse);
    const std::int64_t nv =
        std::int64_t{coarse.n_vertices()} + static_cast<std::int64_t>(edges.edges.size());
    const std::int64_t nt = 8 * std::int64_t{coarse.n_tetrahedra()};
    MLC_CHECK(std::max(nv, nt) <= std::numeric_limits<int>::max(),
              "refining a mesh of " << coarse.n_tetrahedra() << " tetrahedra gives " << nv
                                    << " vertices and " << nt
                                    << " tetrahedra, more than an int index can address; use "
                                       "fewer levels");
    TetMesh fine;
    fine.tag_names = coarse.tag_names;
    fine.n_coarse_vertices = coarse.n_vertices();
    fine.vertices.reserve(static_cast<size_t>(nv));
    fine.vertices = coarse.vertices;
    fine.parents = edges.edges;
    for (const auto& e : edges.edges)
        fine.vertices.push_back(0.5 * (coarse.vertices[static_cast<size_t>(e[0])] +
                                       coarse.vertices[static_cast<size_t>(e[1])]));
    const int n0 = coarse.n_vertices();
    fine.tetrahedra.reserve(static_cast<size_t>(nt));
    for (size_t t = 0; t < coarse.tetrahedra.size(); ++t) {
        std::array<int, 10> p{};
        for (int i = 0; i < 4; ++i)
            p[static_cast<size_t>(i)] = coarse.tetrahedra[t][static_cast<size_t>(i)];
        for (int e = 0; e < 6; ++e)
            p[static_cast<size_t>(4 + e)] = n0 + edges.tet_edges[t][static_cast<size_t>(e)];
        for (const auto& child : kBeyChildren)
            fine.tetrahedra.push_back(
                {p[static_cast<size_t>(child[0])], p[static_cast<size_t>(child[1])],
                 p[static_cast<size_t>(child[2])], p[static_cast<size_t>(child[3])]});
    }
    if (!coarse.attribute.empty()) {
        fine.attribute.reserve(static_cast<size_t>(nt));
        for (int a : coarse.attribute)
            for (int c = 0; c < kTetrahedronChildren; ++c)
                fine.attribute.push_back(a);
    }
    if (!coarse.boundary.empty()) {
        std::unordered_map<std::uint64_t, int> midpoint;
        midpoint.reserve(edges.edges.size());
        for (size_t e = 0; e < edges.edges.size(); ++e)
            midpoint.emplace(edge_key(edges.edges[e][0], edges.edges[e][1]),
                             n0 + static_cast<int>(e));
        auto mid = [&](int a, int b) {
            const auto it = midpoint.find(edge_key(a, b));
            MLC_CHECK(it != midpoint.end(), "boundary face edge (" << a << ", " << b
                                                                   << ") is not an edge of a "
                                                                      "tetrahedron");
            return it->second;
        };
        fine.boundary.reserve(4 * coarse.boundary.size());
        for (const auto& f : coarse.boundary) {
            const std::array<int, 6> p{f.v[0],
                                       f.v[1],
                                       f.v[2],
                                       mid(f.v[0], f.v[1]),
                                       mid(f.v[1], f.v[2]),
                                       mid(f.v[2], f.v[0])};
            for (const auto& child : kFaceChildrenOf)
                fine.boundary.push_back(
                    {{p[static_cast<size_t>(child[0])], p[static_cast<size_t>(child[1])],
                      p[static_cast<size_t>(child[2])]},
                     f.tag});
        }
    }
    return fine;
}

std::vector<TetLevelSize> predict_tet_level_sizes(const TetMesh& level0, int levels) {
    MLC_CHECK(levels >= 0, "the number of levels must be at least 0, got " << levels);
    TetLevelSize s;
    s.vertices = level0.n_vertices();
    s.edges = static_cast<double>(tet_edges(level0).edges.size());
    s.faces = static_cast<double>(count_faces(level0));
    s.tetrahedra = level0.n_tetrahedra();
    s.boundary_faces = 2 * s.faces - 4 * s.tetrahedra; // 4 T = 2 F_interior + F_boundary
    s.tagged_faces = static_cast<double>(level0.boundary.size());
    const bool attributes = !level0.attribute.empty();
    std::vector<TetLevelSize> out;
    for (int l = 0; l <= levels; ++l) {
        s.level = l;
        // 24 B a vertex, 16 B a tetrahedron (+ 4 B its attribute), 16 B a tagged face, 8 B the
        // parents of a new vertex.
        const double new_vertices = l == 0 ? 0.0 : out.back().edges;
        s.bytes = 24 * s.vertices + (attributes ? 20 : 16) * s.tetrahedra + 16 * s.tagged_faces +
                  8 * new_vertices;
        out.push_back(s);
        TetLevelSize n;
        n.vertices = s.vertices + s.edges;
        n.edges = 2 * s.edges + 3 * s.faces + s.tetrahedra;
        n.faces = 4 * s.faces + 8 * s.tetrahedra;
        n.tetrahedra = 8 * s.tetrahedra;
        n.boundary_faces = 4 * s.boundary_faces;
        n.tagged_faces = 4 * s.tagged_faces;
        s = n;
    }
    return out;
}

} // namespace mlc::mesh

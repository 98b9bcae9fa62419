// SPDX-License-Identifier: MIT
// Bey's 1->8 refinement of a tetrahedral mesh and the predicted sizes of its levels.
#include "mesh/tet_refine.hpp"
#include "mesh/edge_key.hpp"

#include "core/check.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <optional>
#include <unordered_map>

namespace mlc::mesh {

namespace {

/// Splits the boundary faces and the lines of `coarse` into fine (whose vertices are in place)
/// and moves the midpoints of edges of curved faces onto their surfaces. Returns for each new
/// vertex the coarse boundary face whose surface moved it, or -1.
std::vector<int> refine_boundary(const TetMesh& coarse, const TetEdges& edges, TetMesh& fine) {
    const int n0 = coarse.n_vertices();
    std::vector<int> moved(edges.edges.size(), -1);
    if (coarse.boundary.empty() && coarse.lines.empty()) return moved;
    std::unordered_map<std::uint64_t, int> midpoint;
    midpoint.reserve(edges.edges.size());
    for (size_t e = 0; e < edges.edges.size(); ++e)
        midpoint.emplace(detail::edge_key(edges.edges[e][0], edges.edges[e][1]),
                         n0 + static_cast<int>(e));
    auto mid = [&](int a, int b) {
        const auto it = midpoint.find(detail::edge_key(a, b));
        MLC_CHECK(it != midpoint.end(),
                  "the edge (" << a << ", " << b
                               << ") of a boundary face or line is not an edge of a tetrahedron");
        return it->second;
    };
    fine.lines.reserve(2 * coarse.lines.size());
    for (const BoundaryEdge& l : coarse.lines) { // tagged edges: both halves keep the tag
        const int m = mid(l.v0, l.v1);
        fine.lines.push_back({l.v0, m, l.tag, -1});
        fine.lines.push_back({m, l.v1, l.tag, -1});
    }
    fine.boundary.reserve(4 * coarse.boundary.size());
    for (size_t b = 0; b < coarse.boundary.size(); ++b) {
        const BoundaryFace& f = coarse.boundary[b];
        const std::array<int, 6> p{
            f.v[0], f.v[1], f.v[2], mid(f.v[0], f.v[1]), mid(f.v[1], f.v[2]), mid(f.v[2], f.v[0])};
        for (const auto& child : kFaceChildrenOf)
            fine.boundary.push_back(
                {{p[static_cast<size_t>(child[0])], p[static_cast<size_t>(child[1])],
                  p[static_cast<size_t>(child[2])]},
                 f.tag,
                 f.shape});
        if (f.shape < 0) continue;
        const CurvedSurface& s = coarse.shapes[static_cast<size_t>(f.shape)];
        for (int k = 3; k < 6; ++k) {
            const int v = p[static_cast<size_t>(k)];
            if (moved[static_cast<size_t>(v - n0)] >= 0) continue;
            Vec3& x = fine.vertices[static_cast<size_t>(v)];
            const std::optional<Vec3> on = s.project(x);
            MLC_CHECK(on, "the midpoint " << v << " of an edge of tag '" << coarse.tag_name(f.tag)
                                          << "' lies at the centre or on the axis of its "
                                          << s.describe() << "; expected it off it");
            x = *on;
            moved[static_cast<size_t>(v - n0)] = static_cast<int>(b);
        }
    }
    return moved;
}

/// Every child of a tetrahedron with a moved midpoint keeps the orientation Bey's rule gives it
/// and is not flat.
void check_moved(const TetMesh& coarse, const TetEdges& edges, const std::vector<int>& moved,
                 const TetMesh& fine) {
    const int n0 = coarse.n_vertices();
    for (int t = 0; t < coarse.n_cells(); ++t) {
        const auto& te = edges.tet_edges[static_cast<size_t>(t)];
        if (std::none_of(te.begin(), te.end(),
                         [&](int e) { return moved[static_cast<size_t>(e)] >= 0; }))
            continue;
        const double parent = coarse.signed_measure(t);
        for (int k = 0; k < kTetrahedronChildren; ++k) {
            const int c = kTetrahedronChildren * t + k;
            const auto& kv = fine.cells[static_cast<size_t>(c)];
            double longest = 0;
            for (int i = 0; i < 4; ++i)
                for (int j = i + 1; j < 4; ++j)
                    longest = std::max(longest, (fine.vertices[static_cast<size_t>(kv[i])] -
                                                 fine.vertices[static_cast<size_t>(kv[j])])
                                                    .norm());
            const double v = fine.signed_measure(c);
            const double expected = (parent > 0) == (k == 5 || k == 7) ? -1.0 : 1.0;
            if (6 * v * expected > kFlatTetrahedronTol * longest * longest * longest) continue;
            int w = -1; // a moved vertex of the child
            for (int x : kv)
                if (x >= n0 && moved[static_cast<size_t>(x - n0)] >= 0) w = x;
            const BoundaryFace& f = coarse.boundary[static_cast<size_t>(
                moved[static_cast<size_t>(w < 0 ? te[0] : w - n0)])];
            const Vec3& p = fine.vertices[static_cast<size_t>(w < 0 ? kv[0] : w)];
            MLC_CHECK(false,
                      "moving vertex "
                          << w << " to (" << p.x() << ", " << p.y() << ", " << p.z() << ") on the "
                          << coarse.shapes[static_cast<size_t>(f.shape)].describe() << " of tag '"
                          << coarse.tag_name(f.tag) << "' inverts tetrahedron " << c << " (child "
                          << k << " of coarse tetrahedron " << t << "): its volume becomes " << v
                          << "; expected " << (expected > 0 ? "positive" : "negative")
                          << " as Bey's rule orders it: the coarse faces are too large "
                             "for the curvature there; refine the start mesh near the "
                             "curved boundary");
        }
    }
}

} // namespace

TetMesh refine(const TetMesh& coarse) {
    const TetEdges edges = tet_edges(coarse);
    const std::int64_t nv =
        std::int64_t{coarse.n_vertices()} + static_cast<std::int64_t>(edges.edges.size());
    const std::int64_t nt = 8 * std::int64_t{coarse.n_cells()};
    MLC_CHECK(std::max(nv, nt) <= std::numeric_limits<int>::max(),
              "refining a mesh of " << coarse.n_cells() << " tetrahedra gives " << nv
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
    fine.cells.reserve(static_cast<size_t>(nt));
    for (size_t t = 0; t < coarse.cells.size(); ++t) {
        std::array<int, 10> p{};
        for (int i = 0; i < 4; ++i)
            p[static_cast<size_t>(i)] = coarse.cells[t][static_cast<size_t>(i)];
        for (int e = 0; e < 6; ++e)
            p[static_cast<size_t>(4 + e)] = n0 + edges.tet_edges[t][static_cast<size_t>(e)];
        for (const auto& child : kBeyChildren)
            fine.cells.push_back(
                {p[static_cast<size_t>(child[0])], p[static_cast<size_t>(child[1])],
                 p[static_cast<size_t>(child[2])], p[static_cast<size_t>(child[3])]});
    }
    if (!coarse.attribute.empty()) {
        fine.attribute.reserve(static_cast<size_t>(nt));
        for (int a : coarse.attribute)
            for (int c = 0; c < kTetrahedronChildren; ++c)
                fine.attribute.push_back(a);
    }
    fine.shapes = coarse.shapes;
    const std::vector<int> moved = refine_boundary(coarse, edges, fine);
    if (std::any_of(moved.begin(), moved.end(), [](int f) { return f >= 0; }))
        check_moved(coarse, edges, moved, fine);
    return fine;
}

std::vector<TetLevelSize> predict_tet_level_sizes(const TetMesh& level0, int levels) {
    MLC_CHECK(levels >= 0, "the number of levels must be at least 0, got " << levels);
    TetLevelSize s;
    s.vertices = level0.n_vertices();
    s.edges = static_cast<double>(tet_edges(level0).edges.size());
    s.faces = static_cast<double>(count_faces(level0));
    s.tetrahedra = level0.n_cells();
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

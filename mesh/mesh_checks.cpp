// SPDX-License-Identifier: MIT
// Mesh checks: indices, areas, duplicate vertices (check_quality) and conformity (check_topology:
// duplicated elements, non-manifold edges, hanging nodes).
#include "mesh/edge_key.hpp"
#include "mesh/mesh.hpp"
#include "mesh/topology.hpp"

#include "core/check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <limits>
#include <sstream>
#include <tuple>

namespace mlc::mesh {

namespace {
void check_triangle_areas(const Mesh& m, double diam) {
    const int nv = m.n_vertices();
    for (int t = 0; t < m.n_cells(); ++t) {
        const auto& tri = m.cells[static_cast<size_t>(t)];
        for (int k = 0; k < 3; ++k)
            MLC_CHECK(tri[static_cast<size_t>(k)] >= 0 && tri[static_cast<size_t>(k)] < nv,
                      "triangle " << t << " refers to vertex " << tri[static_cast<size_t>(k)]
                                  << " but the mesh has " << nv << " vertices");
        const double a = m.signed_measure(t);
        const Vec2& p = m.vertices[static_cast<size_t>(tri[0])];
        MLC_CHECK(a > 1e-14 * diam * diam, "degenerate or inverted triangle "
                                               << t << " (vertices " << tri[0] << ", " << tri[1]
                                               << ", " << tri[2] << " near (" << p.x() << ", "
                                               << p.y() << ")): signed area " << a
                                               << "; triangles must be counter-clockwise "
                                                  "with positive area");
    }
}
} // namespace

void check_refined_quality(const Mesh& m) {
    MLC_CHECK(m.n_cells() > 0, "the mesh has no triangles");
    check_triangle_areas(m, m.diameter());
}

void check_quality(const Mesh& m) {
    check_quality(m, TriangleNamer{});
}

void check_quality(const Mesh& m, const TriangleNamer& name) {
    MLC_CHECK(m.n_cells() > 0, "the mesh has no triangles");
    const int nv = m.n_vertices();
    MLC_CHECK(m.attribute.empty() || m.attribute.size() == m.cells.size(),
              "the mesh has " << m.attribute.size() << " triangle attributes for " << m.cells.size()
                              << " triangles");
    for (const auto& v : m.vertices)
        MLC_CHECK(std::isfinite(v.x()) && std::isfinite(v.y()), "a mesh vertex is not finite");
    const double diam = m.diameter();
    MLC_CHECK(diam > 0, "the mesh has zero extent");
    check_triangle_areas(m, diam);
    // Duplicate vertices: pairs of one body closer than tol. Two bodies (triangle attributes) may
    // touch: their vertices may coincide (a matching interface).
    std::vector<int> body(static_cast<size_t>(nv), -1);
    if (!m.attribute.empty())
        for (int t = 0; t < m.n_cells(); ++t)
            for (int v : m.cells[static_cast<size_t>(t)])
                if (body[static_cast<size_t>(v)] < 0)
                    body[static_cast<size_t>(v)] = m.attribute[static_cast<size_t>(t)];
    // Each vertex goes into a square cell of side h >= tol, so that a pair closer than tol lies in
    // one cell or in two neighbouring ones, and is compared with the vertices of its own and the
    // neighbouring cells (in the vertices sorted by cell): O(n log n) for any mesh. Sorting by x
    // alone and scanning the x-window was quadratic in the number of vertices sharing an x, as the
    // columns of a structured mesh do.
    const double tol = 1e-10 * diam;
    const double h = std::max(tol, 1e-9 * diam); // <= 1e9 + 1 cells per axis: 32-bit indices
    Vec2 lo = m.vertices[0];
    for (const auto& v : m.vertices)
        lo = lo.cwiseMin(v);
    auto key = [](std::int64_t cx, std::int64_t cy) {
        return (static_cast<std::uint64_t>(cx) << 32) | static_cast<std::uint64_t>(cy);
    };
    std::vector<std::array<std::int64_t, 2>> cell_of(static_cast<size_t>(nv));
    std::vector<std::pair<std::uint64_t, int>> by_cell(static_cast<size_t>(nv)); // (key, vertex)
    for (int v = 0; v < nv; ++v) {
        const Vec2& p = m.vertices[static_cast<size_t>(v)];
        const auto cx = static_cast<std::int64_t>((p.x() - lo.x()) / h);
        const auto cy = static_cast<std::int64_t>((p.y() - lo.y()) / h);
        cell_of[static_cast<size_t>(v)] = {cx, cy};
        by_cell[static_cast<size_t>(v)] = {key(cx, cy), v};
    }
    std::sort(by_cell.begin(), by_cell.end());
    // Each pair once, from the vertex that comes first in cell order: the rest of its own column
    // up to the cell above it, and the next column's cells beside it (found by a pointer that
    // only moves forward: the cells beside a vertex move up and right with it).
    const size_t n_sorted = by_cell.size();
    auto compare = [&](int v, int w) {
        if (body[static_cast<size_t>(v)] != body[static_cast<size_t>(w)]) return;
        if (w < v) std::swap(v, w);
        const Vec2& a = m.vertices[static_cast<size_t>(v)];
        const Vec2& b = m.vertices[static_cast<size_t>(w)];
        MLC_CHECK((a - b).norm() > tol, "duplicate vertices " << v << " and " << w << " at ("
                                                              << a.x() << ", " << a.y() << ")");
    };
    size_t next = 0;
    for (size_t i = 0; i < n_sorted; ++i) {
        const int v = by_cell[i].second;
        const std::int64_t cx = cell_of[static_cast<size_t>(v)][0];
        const std::int64_t cy = cell_of[static_cast<size_t>(v)][1];
        const std::uint64_t above = key(cx, cy + 1);
        for (size_t k = i + 1; k < n_sorted && by_cell[k].first <= above; ++k)
            compare(v, by_cell[k].second);
        const std::uint64_t first = key(cx + 1, std::max<std::int64_t>(cy - 1, 0));
        const std::uint64_t last = key(cx + 1, cy + 1);
        while (next < n_sorted && by_cell[next].first < first)
            ++next;
        for (size_t k = next; k < n_sorted && by_cell[k].first <= last; ++k)
            compare(v, by_cell[k].second);
    }
    check_topology(m, name);
    // A boundary edge lies on one triangle, an interior line on two.
    const VertexTriangles vtri = vertex_triangles(m);
    auto triangles_on = [&](int a, int b) { return vtri.on_edge(m, a, b).count; };
    for (const auto& e : m.boundary) {
        MLC_CHECK(triangles_on(e.v0, e.v1) == 1,
                  "boundary edge (" << e.v0 << ", " << e.v1 << ") tagged '" << m.tag_name(e.tag)
                                    << "' is not a boundary edge of the triangulation");
    }
    for (const auto& e : m.lines) {
        MLC_CHECK(e.v0 >= 0 && e.v0 < nv && e.v1 >= 0 && e.v1 < nv,
                  "interior line (" << e.v0 << ", " << e.v1 << ") tagged '" << m.tag_name(e.tag)
                                    << "' refers to a vertex out of range");
        MLC_CHECK(triangles_on(e.v0, e.v1) == 2,
                  "interior line (" << e.v0 << ", " << e.v1 << ") tagged '" << m.tag_name(e.tag)
                                    << "' is not an interior edge of the triangulation");
    }
}

namespace {

std::string point_text(const Vec2& p) {
    std::ostringstream os;
    os << std::setprecision(9) << "(" << p.x() << ", " << p.y() << ")";
    return os.str();
}

} // namespace

namespace {

/// How check_topology's messages name triangles and vertices.
struct TopologyNames {
    const Mesh& m;
    const TriangleNamer& name;
    std::string triangle(int t) const { return name ? name(t) : "triangle " + std::to_string(t); }
    std::string vertex(int v) const {
        return "vertex " + std::to_string(v) + " " + point_text(m.vertices[static_cast<size_t>(v)]);
    }
};

/// An edge of one triangle t, from a to b.
struct BoundarySide {
    int a, b, t;
};

/// Duplicated elements: the same vertex set, in any order.
void check_duplicate_elements(const Mesh& m, const TopologyNames& names) {
    const size_t nt = m.cells.size();
    std::vector<std::pair<std::array<int, 3>, int>> sorted(nt);
    for (size_t t = 0; t < nt; ++t) {
        std::array<int, 3> k = m.cells[t];
        std::sort(k.begin(), k.end());
        sorted[t] = {k, static_cast<int>(t)};
    }
    std::sort(sorted.begin(), sorted.end());
    for (size_t i = 1; i < nt; ++i)
        if (sorted[i].first == sorted[i - 1].first) {
            const auto& k = sorted[i].first;
            throw InvalidInput(
                "duplicated element: " + names.triangle(sorted[i - 1].second) + " and " +
                names.triangle(sorted[i].second) + " have the same vertices, " +
                names.vertex(k[0]) + ", " + names.vertex(k[1]) + " and " + names.vertex(k[2]) +
                " (the body is counted twice there: its stiffness doubles and its boundary "
                "edges become interior ones); remove one of the two");
        }
}

/// Edges and how many triangles share each: 1 on the boundary, 2 inside, more is an error.
/// Returns the boundary edges.
std::vector<BoundarySide> boundary_sides(const Mesh& m, const TopologyNames& names) {
    const size_t nt = m.cells.size();
    struct Side {
        std::uint64_t key;
        int t;
        bool operator<(const Side& o) const { return key != o.key ? key < o.key : t < o.t; }
    };
    std::vector<Side> sides;
    sides.reserve(3 * nt);
    for (size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k)
            sides.push_back({detail::edge_key(m.cells[t][static_cast<size_t>(k)],
                                              m.cells[t][static_cast<size_t>((k + 1) % 3)]),
                             static_cast<int>(t)});
    std::sort(sides.begin(), sides.end());
    std::vector<BoundarySide> boundary; // edges of one triangle
    for (size_t i = 0; i < sides.size();) {
        size_t j = i + 1;
        while (j < sides.size() && sides[j].key == sides[i].key)
            ++j;
        const int a = static_cast<int>(sides[i].key >> 32);
        const int b = static_cast<int>(sides[i].key & 0xffffffffu);
        if (j - i > 2) {
            std::string ts;
            for (size_t k = i; k < j; ++k)
                ts += (k > i ? (k + 1 == j ? " and " : ", ") : "") + names.triangle(sides[k].t);
            throw InvalidInput(
                "non-manifold edge: the edge from " + names.vertex(a) + " to " + names.vertex(b) +
                " is shared by " + std::to_string(j - i) + " triangles (" + ts +
                "), but an edge of a body has one triangle (on the boundary) or two (inside): "
                "the triangles overlap or fold over; remesh so that they tile the body");
        }
        if (j - i == 1) boundary.push_back({a, b, sides[i].t});
        i = j;
    }
    return boundary;
}

/// The boundary edges in grids: each edge goes into the (at most four) cells of a grid whose
/// cell side is the power-of-two multiple of the shortest boundary edge that holds the edge's box
/// widened by the tolerance.
struct EdgeGrids {
    struct Entry {
        int level;
        std::int64_t cx, cy;
        int edge;
        bool operator<(const Entry& o) const {
            return std::tie(level, cx, cy, edge) < std::tie(o.level, o.cx, o.cy, o.edge);
        }
    };
    Vec2 lo;
    double shortest = std::numeric_limits<double>::infinity();
    std::vector<Entry> grid; // sorted
    std::vector<int> levels; // the grids that hold an edge, sorted

    /// False when the shortest edge has zero length (refused by the area check).
    bool build(const Mesh& m, const std::vector<BoundarySide>& boundary, double tol) {
        lo = m.vertices[static_cast<size_t>(boundary[0].a)];
        for (const BoundarySide& e : boundary) {
            lo = lo.cwiseMin(m.vertices[static_cast<size_t>(e.a)]);
            lo = lo.cwiseMin(m.vertices[static_cast<size_t>(e.b)]);
            shortest = std::min(shortest, (m.vertices[static_cast<size_t>(e.b)] -
                                           m.vertices[static_cast<size_t>(e.a)])
                                              .norm());
        }
        if (!(shortest > 0)) return false;
        grid.reserve(4 * boundary.size());
        for (size_t i = 0; i < boundary.size(); ++i) {
            const Vec2& p = m.vertices[static_cast<size_t>(boundary[i].a)];
            const Vec2& q = m.vertices[static_cast<size_t>(boundary[i].b)];
            const double pad = tol * (q - p).norm();
            const Vec2 bl = p.cwiseMin(q).array() - pad, tr = p.cwiseMax(q).array() + pad;
            const double extent = (tr - bl).maxCoeff();
            int level = std::max(0, static_cast<int>(std::ceil(std::log2(extent / shortest))));
            while (std::ldexp(shortest, level) < extent)
                ++level;
            const double cell = std::ldexp(shortest, level);
            const auto x0 = static_cast<std::int64_t>(std::floor((bl.x() - lo.x()) / cell));
            const auto x1 = static_cast<std::int64_t>(std::floor((tr.x() - lo.x()) / cell));
            const auto y0 = static_cast<std::int64_t>(std::floor((bl.y() - lo.y()) / cell));
            const auto y1 = static_cast<std::int64_t>(std::floor((tr.y() - lo.y()) / cell));
            for (std::int64_t cx = x0; cx <= x1; ++cx)
                for (std::int64_t cy = y0; cy <= y1; ++cy)
                    grid.push_back({level, cx, cy, static_cast<int>(i)});
            levels.push_back(level);
        }
        std::sort(grid.begin(), grid.end());
        std::sort(levels.begin(), levels.end());
        levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
        return true;
    }
};

/// Hanging nodes: a boundary vertex inside a boundary edge (of its body) it is not an end of.
/// Each boundary vertex looks into its cell on every grid that holds an edge.
void check_hanging_nodes(const Mesh& m, const std::vector<BoundarySide>& boundary,
                         const TopologyNames& names) {
    const double tol = kHangingNodeTol;
    EdgeGrids grids;
    if (!grids.build(m, boundary, tol)) return;
    std::vector<int> vertices;
    vertices.reserve(2 * boundary.size());
    for (const BoundarySide& e : boundary) {
        vertices.push_back(e.a);
        vertices.push_back(e.b);
    }
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
    auto body_of_triangle = [&](int t) {
        return m.attribute.empty() ? 0 : m.attribute[static_cast<size_t>(t)];
    };
    // A vertex's bodies: those of its boundary edges (two bodies may share a vertex).
    std::vector<std::pair<int, int>> vertex_body; // (vertex, body), sorted
    for (const BoundarySide& e : boundary) {
        vertex_body.emplace_back(e.a, body_of_triangle(e.t));
        vertex_body.emplace_back(e.b, body_of_triangle(e.t));
    }
    std::sort(vertex_body.begin(), vertex_body.end());
    const Vec2 lo = grids.lo;
    for (int v : vertices) {
        const Vec2& x = m.vertices[static_cast<size_t>(v)];
        for (int level : grids.levels) {
            const double cell = std::ldexp(grids.shortest, level);
            const EdgeGrids::Entry key{
                level, static_cast<std::int64_t>(std::floor((x.x() - lo.x()) / cell)),
                static_cast<std::int64_t>(std::floor((x.y() - lo.y()) / cell)), -1};
            for (auto it = std::lower_bound(grids.grid.begin(), grids.grid.end(), key);
                 it != grids.grid.end() && it->level == level && it->cx == key.cx &&
                 it->cy == key.cy;
                 ++it) {
                const BoundarySide& e = boundary[static_cast<size_t>(it->edge)];
                if (e.a == v || e.b == v) continue;
                const Vec2& p = m.vertices[static_cast<size_t>(e.a)];
                const Vec2& q = m.vertices[static_cast<size_t>(e.b)];
                const Vec2 d = q - p, w = x - p;
                const double len2 = d.squaredNorm();
                const double s = w.dot(d) / len2; // along the edge, 0 .. 1
                const double off = std::abs(d.x() * w.y() - d.y() * w.x()) / len2; // across
                if (s <= tol || s >= 1 - tol || off > tol) continue;
                // The same body only: bodies of one mesh may touch along non-matching edges.
                if (!std::binary_search(vertex_body.begin(), vertex_body.end(),
                                        std::pair<int, int>{v, body_of_triangle(e.t)}))
                    continue;
                throw InvalidInput(
                    "hanging node (T-junction): " + names.vertex(v) +
                    " lies inside the edge from " + names.vertex(e.a) + " to " + names.vertex(e.b) +
                    " of " + names.triangle(e.t) +
                    " but is not a vertex of it, so the triangles on the two sides of that edge "
                    "do not share their nodes and the body has a slit there; split the edge at "
                    "the vertex (or remesh conformingly)");
            }
        }
    }
}

} // namespace

void check_topology(const Mesh& m, const TriangleNamer& name) {
    const TopologyNames names{m, name};
    check_duplicate_elements(m, names);
    const std::vector<BoundarySide> boundary = boundary_sides(m, names);
    if (boundary.empty()) return;
    check_hanging_nodes(m, boundary, names);
}

} // namespace mlc::mesh

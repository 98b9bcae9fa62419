// SPDX-License-Identifier: MIT
// Mesh queries, quality checks, uniform 1->4 refinement and structured rectangles.
#include "mesh/mesh.hpp"
#include "mesh/topology.hpp"

#include "core/check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <limits>
#include <numeric>
#include <sstream>
#include <tuple>
#include <unordered_map>

namespace mlc::mesh {

int Mesh::tag(const std::string& name) const {
    auto it = tag_names.find(name);
    if (it == tag_names.end()) {
        std::string known;
        for (const auto& [n, id] : tag_names)
            known += (known.empty() ? "" : ", ") + n;
        MLC_CHECK(false, "unknown boundary tag '" << name << "'; the mesh has: " << known);
    }
    return it->second;
}

std::optional<int> Mesh::find_tag(const std::string& name) const {
    auto it = tag_names.find(name);
    if (it == tag_names.end()) return std::nullopt;
    return it->second;
}

std::string Mesh::tag_name(int t) const {
    for (const auto& [n, id] : tag_names)
        if (id == t) return n;
    return "tag " + std::to_string(t);
}

int Mesh::add_tag(const std::string& name) {
    auto it = tag_names.find(name);
    if (it != tag_names.end()) return it->second;
    int id = 0;
    for (const auto& [n, t] : tag_names)
        id = std::max(id, t + 1);
    tag_names[name] = id;
    return id;
}

double Mesh::signed_area(int t) const {
    const auto& tri = triangles[static_cast<size_t>(t)];
    const Vec2& a = vertices[static_cast<size_t>(tri[0])];
    const Vec2& b = vertices[static_cast<size_t>(tri[1])];
    const Vec2& c = vertices[static_cast<size_t>(tri[2])];
    return 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
}

namespace {

// The sorted distinct end vertices of the edges tagged t in each of the lists.
template <class... Edges> std::vector<int> end_vertices(int t, const Edges&... lists) {
    std::vector<int> out;
    auto add = [&](const auto& edges) {
        for (const auto& e : edges)
            if (e.tag == t) {
                out.push_back(e.v0);
                out.push_back(e.v1);
            }
    };
    (add(lists), ...);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

} // namespace

std::vector<int> Mesh::vertices_with_tag(int t) const {
    return end_vertices(t, boundary);
}

std::vector<int> Mesh::vertices_on_tag(int t) const {
    return end_vertices(t, boundary, lines);
}

bool Mesh::is_boundary_tag(int t) const {
    return std::any_of(boundary.begin(), boundary.end(),
                       [t](const BoundaryEdge& e) { return e.tag == t; });
}

std::pair<double, double> Mesh::edge_length_range() const {
    double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
    for (const auto& tri : triangles)
        for (int k = 0; k < 3; ++k) {
            double l = (vertices[static_cast<size_t>(tri[static_cast<size_t>(k)])] -
                        vertices[static_cast<size_t>(tri[static_cast<size_t>((k + 1) % 3)])])
                           .norm();
            lo = std::min(lo, l);
            hi = std::max(hi, l);
        }
    return {lo, hi};
}

double Mesh::diameter() const {
    if (vertices.empty()) return 0.0;
    Vec2 lo = vertices[0], hi = vertices[0];
    for (const auto& v : vertices) {
        lo = lo.cwiseMin(v);
        hi = hi.cwiseMax(v);
    }
    return (hi - lo).norm();
}

int Mesh::nearest_vertex(const Vec2& p) const {
    int best = -1;
    double bd = std::numeric_limits<double>::infinity();
    for (int v = 0; v < n_vertices(); ++v) {
        double d = (vertices[static_cast<size_t>(v)] - p).squaredNorm();
        if (d < bd) {
            bd = d;
            best = v;
        }
    }
    return best;
}

namespace {

std::uint64_t edge_key(int a, int b) {
    if (a > b) std::swap(a, b);
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
           static_cast<std::uint32_t>(b);
}

} // namespace

namespace {
void check_triangle_areas(const Mesh& m, double diam) {
    const int nv = m.n_vertices();
    for (int t = 0; t < m.n_triangles(); ++t) {
        const auto& tri = m.triangles[static_cast<size_t>(t)];
        for (int k = 0; k < 3; ++k)
            MLC_CHECK(tri[static_cast<size_t>(k)] >= 0 && tri[static_cast<size_t>(k)] < nv,
                      "triangle " << t << " refers to vertex " << tri[static_cast<size_t>(k)]
                                  << " but the mesh has " << nv << " vertices");
        const double a = m.signed_area(t);
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
    MLC_CHECK(m.n_triangles() > 0, "the mesh has no triangles");
    check_triangle_areas(m, m.diameter());
}

void check_quality(const Mesh& m) {
    check_quality(m, TriangleNamer{});
}

void check_quality(const Mesh& m, const TriangleNamer& name) {
    MLC_CHECK(m.n_triangles() > 0, "the mesh has no triangles");
    const int nv = m.n_vertices();
    MLC_CHECK(m.attribute.empty() || m.attribute.size() == m.triangles.size(),
              "the mesh has " << m.attribute.size() << " triangle attributes for "
                              << m.triangles.size() << " triangles");
    for (const auto& v : m.vertices)
        MLC_CHECK(std::isfinite(v.x()) && std::isfinite(v.y()), "a mesh vertex is not finite");
    const double diam = m.diameter();
    MLC_CHECK(diam > 0, "the mesh has zero extent");
    check_triangle_areas(m, diam);
    // Duplicate vertices: pairs of one body closer than tol. Two bodies (triangle attributes) may
    // touch: their vertices may coincide (a matching interface).
    std::vector<int> body(static_cast<size_t>(nv), -1);
    if (!m.attribute.empty())
        for (int t = 0; t < m.n_triangles(); ++t)
            for (int v : m.triangles[static_cast<size_t>(t)])
                if (body[static_cast<size_t>(v)] < 0)
                    body[static_cast<size_t>(v)] = m.attribute[static_cast<size_t>(t)];
    // Each vertex goes into a square cell of side h >= tol, so that a pair closer than tol lies in
    // one cell or in two neighbouring ones, and is compared with the vertices of its own and the
    // neighbouring cells (in the vertices sorted by cell): O(n log n) for any mesh. Sorting by x
    // alone and scanning the x-window was quadratic in the number of vertices sharing an x, as the
    // columns of a structured mesh do (35 s for a 1 x 100000 strip).
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

void check_topology(const Mesh& m, const TriangleNamer& name) {
    auto tri_name = [&](int t) { return name ? name(t) : "triangle " + std::to_string(t); };
    auto vertex_text = [&](int v) {
        return "vertex " + std::to_string(v) + " " + point_text(m.vertices[static_cast<size_t>(v)]);
    };
    auto fail = [](const std::string& msg) { throw InvalidInput(msg); };
    const size_t nt = m.triangles.size();
    // Duplicated elements: the same vertex set, in any order.
    {
        std::vector<std::pair<std::array<int, 3>, int>> sorted(nt);
        for (size_t t = 0; t < nt; ++t) {
            std::array<int, 3> k = m.triangles[t];
            std::sort(k.begin(), k.end());
            sorted[t] = {k, static_cast<int>(t)};
        }
        std::sort(sorted.begin(), sorted.end());
        for (size_t i = 1; i < nt; ++i)
            if (sorted[i].first == sorted[i - 1].first) {
                const auto& k = sorted[i].first;
                fail("duplicated element: " + tri_name(sorted[i - 1].second) + " and " +
                     tri_name(sorted[i].second) + " have the same vertices, " + vertex_text(k[0]) +
                     ", " + vertex_text(k[1]) + " and " + vertex_text(k[2]) +
                     " (the body is counted twice there: its stiffness doubles and its boundary "
                     "edges become interior ones); remove one of the two");
            }
    }
    // Edges and how many triangles share each: 1 on the boundary, 2 inside, more is an error.
    struct Side {
        std::uint64_t key;
        int t;
        bool operator<(const Side& o) const { return key != o.key ? key < o.key : t < o.t; }
    };
    std::vector<Side> sides;
    sides.reserve(3 * nt);
    for (size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k)
            sides.push_back({edge_key(m.triangles[t][static_cast<size_t>(k)],
                                      m.triangles[t][static_cast<size_t>((k + 1) % 3)]),
                             static_cast<int>(t)});
    std::sort(sides.begin(), sides.end());
    struct Edge {
        int a, b, t;
    };
    std::vector<Edge> boundary; // edges of one triangle
    for (size_t i = 0; i < sides.size();) {
        size_t j = i + 1;
        while (j < sides.size() && sides[j].key == sides[i].key)
            ++j;
        const int a = static_cast<int>(sides[i].key >> 32);
        const int b = static_cast<int>(sides[i].key & 0xffffffffu);
        if (j - i > 2) {
            std::string ts;
            for (size_t k = i; k < j; ++k)
                ts += (k > i ? (k + 1 == j ? " and " : ", ") : "") + tri_name(sides[k].t);
            fail("non-manifold edge: the edge from " + vertex_text(a) + " to " + vertex_text(b) +
                 " is shared by " + std::to_string(j - i) + " triangles (" + ts +
                 "), but an edge of a body has one triangle (on the boundary) or two (inside): "
                 "the triangles overlap or fold over; remesh so that they tile the body");
        }
        if (j - i == 1) boundary.push_back({a, b, sides[i].t});
        i = j;
    }
    if (boundary.empty()) return;
    // Hanging nodes: a boundary vertex inside a boundary edge it is not an end of. Each edge goes
    // into the (at most four) cells of a grid whose cell side is the power-of-two multiple of the
    // shortest boundary edge that holds the edge's box widened by the tolerance; each boundary
    // vertex looks into its cell on every grid that holds an edge.
    const double tol = kHangingNodeTol;
    Vec2 lo = m.vertices[static_cast<size_t>(boundary[0].a)];
    double shortest = std::numeric_limits<double>::infinity();
    for (const Edge& e : boundary) {
        lo = lo.cwiseMin(m.vertices[static_cast<size_t>(e.a)]);
        lo = lo.cwiseMin(m.vertices[static_cast<size_t>(e.b)]);
        shortest = std::min(
            shortest,
            (m.vertices[static_cast<size_t>(e.b)] - m.vertices[static_cast<size_t>(e.a)]).norm());
    }
    if (!(shortest > 0)) return; // zero-length edges are refused by the area check
    struct Entry {
        int level;
        std::int64_t cx, cy;
        int edge;
        bool operator<(const Entry& o) const {
            return std::tie(level, cx, cy, edge) < std::tie(o.level, o.cx, o.cy, o.edge);
        }
    };
    std::vector<Entry> grid;
    grid.reserve(4 * boundary.size());
    std::vector<int> levels;
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
    std::vector<int> vertices;
    vertices.reserve(2 * boundary.size());
    for (const Edge& e : boundary) {
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
    for (const Edge& e : boundary) {
        vertex_body.emplace_back(e.a, body_of_triangle(e.t));
        vertex_body.emplace_back(e.b, body_of_triangle(e.t));
    }
    std::sort(vertex_body.begin(), vertex_body.end());
    for (int v : vertices) {
        const Vec2& x = m.vertices[static_cast<size_t>(v)];
        for (int level : levels) {
            const double cell = std::ldexp(shortest, level);
            const Entry key{level, static_cast<std::int64_t>(std::floor((x.x() - lo.x()) / cell)),
                            static_cast<std::int64_t>(std::floor((x.y() - lo.y()) / cell)), -1};
            for (auto it = std::lower_bound(grid.begin(), grid.end(), key);
                 it != grid.end() && it->level == level && it->cx == key.cx && it->cy == key.cy;
                 ++it) {
                const Edge& e = boundary[static_cast<size_t>(it->edge)];
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
                fail("hanging node (T-junction): " + vertex_text(v) +
                     " lies inside the edge from " + vertex_text(e.a) + " to " + vertex_text(e.b) +
                     " of " + tri_name(e.t) +
                     " but is not a vertex of it, so the triangles on the two sides of that edge "
                     "do not share their nodes and the body has a slit there; split the edge at "
                     "the vertex (or remesh conformingly)");
            }
        }
    }
}

std::vector<int> hilbert_order(const std::vector<Vec2>& points) {
    const size_t n = points.size();
    std::vector<int> order(n);
    std::iota(order.begin(), order.end(), 0);
    if (n < 2) return order;
    Vec2 lo = points[0], hi = points[0];
    for (const Vec2& p : points) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
    const double span = std::max(hi.x() - lo.x(), hi.y() - lo.y());
    constexpr std::uint32_t side = 1u << 16;
    std::vector<std::uint64_t> key(n, 0);
    if (span > 0.0) {
        for (size_t i = 0; i < n; ++i) {
            // Cell of the point, then its distance along the curve (the classic xy -> d walk).
            auto cell = [&](double t) {
                const double c = std::floor(t / span * (side - 1));
                return static_cast<std::uint32_t>(std::clamp(c, 0.0, double(side - 1)));
            };
            std::uint32_t x = cell(points[i].x() - lo.x()), y = cell(points[i].y() - lo.y());
            std::uint64_t d = 0;
            for (std::uint32_t s = side / 2; s > 0; s /= 2) {
                const std::uint32_t rx = (x & s) ? 1 : 0, ry = (y & s) ? 1 : 0;
                d += static_cast<std::uint64_t>(s) * s * ((3 * rx) ^ ry);
                if (ry == 0) {
                    if (rx == 1) {
                        x = side - 1 - x;
                        y = side - 1 - y;
                    }
                    std::swap(x, y);
                }
            }
            key[i] = d;
        }
    }
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
        return key[static_cast<size_t>(a)] < key[static_cast<size_t>(b)];
    });
    return order;
}

Mesh refine(const Mesh& coarse) {
    Mesh fine;
    fine.circles = coarse.circles;
    fine.tag_names = coarse.tag_names;
    fine.n_coarse_vertices = coarse.n_vertices();
    fine.vertices = coarse.vertices;
    const size_t nt = coarse.triangles.size();
    fine.vertices.reserve(coarse.vertices.size() + 2 * nt);
    fine.parents.reserve(2 * nt);
    std::unordered_map<std::uint64_t, int> midpoint;
    midpoint.reserve(3 * nt);
    auto mid = [&](int a, int b) {
        auto [it, inserted] = midpoint.try_emplace(edge_key(a, b), 0);
        if (inserted) {
            it->second = static_cast<int>(fine.vertices.size());
            fine.vertices.push_back(0.5 * (coarse.vertices[static_cast<size_t>(a)] +
                                           coarse.vertices[static_cast<size_t>(b)]));
            fine.parents.push_back({std::min(a, b), std::max(a, b)});
        }
        return it->second;
    };
    fine.triangles.reserve(4 * nt);
    for (const auto& t : coarse.triangles) {
        const int a = t[0], b = t[1], c = t[2];
        const int ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
        fine.triangles.push_back({a, ab, ca});
        fine.triangles.push_back({ab, b, bc});
        fine.triangles.push_back({ca, bc, c});
        fine.triangles.push_back({ab, bc, ca});
    }
    if (!coarse.attribute.empty()) {
        fine.attribute.reserve(4 * nt);
        for (int a : coarse.attribute)
            for (int k = 0; k < 4; ++k)
                fine.attribute.push_back(a);
    }
    fine.boundary.reserve(2 * coarse.boundary.size());
    for (const auto& e : coarse.boundary) {
        const int m = mid(e.v0, e.v1);
        if (e.curve >= 0) {
            const Circle& c = coarse.circles[static_cast<size_t>(e.curve)];
            Vec2& p = fine.vertices[static_cast<size_t>(m)];
            Vec2 d = p - c.center;
            const double n = d.norm();
            MLC_CHECK(n > 0, "boundary edge midpoint at the centre of its circle");
            p = c.center + (c.radius / n) * d;
        }
        fine.boundary.push_back({e.v0, m, e.tag, e.curve});
        fine.boundary.push_back({m, e.v1, e.tag, e.curve});
    }
    fine.lines.reserve(2 * coarse.lines.size());
    for (const auto& e : coarse.lines) {
        const int m = mid(e.v0, e.v1);
        fine.lines.push_back({e.v0, m, e.tag, -1});
        fine.lines.push_back({m, e.v1, e.tag, -1});
    }
    return fine;
}

Mesh structured_rectangle(Vec2 corner, Vec2 size, int nx, int ny, Diagonal diagonal) {
    MLC_CHECK(nx >= 1 && ny >= 1, "a structured rectangle needs at least one square each way, got "
                                      << nx << " x " << ny);
    MLC_CHECK(size.x() > 0 && size.y() > 0, "a structured rectangle needs a positive size, got "
                                                << size.x() << " x " << size.y());
    // Vertex and triangle indices are int: check the counts in 64 bits before computing them.
    const std::int64_t n_vertices = (std::int64_t{nx} + 1) * (std::int64_t{ny} + 1);
    const std::int64_t n_triangles = 2 * std::int64_t{nx} * std::int64_t{ny};
    MLC_CHECK(std::max(n_vertices, n_triangles) <= std::numeric_limits<int>::max(),
              "a structured rectangle of " << nx << " x " << ny << " squares has " << n_vertices
                                           << " vertices and " << n_triangles
                                           << " triangles, more than an int index can address");
    Mesh m;
    m.vertices.reserve(static_cast<size_t>(n_vertices));
    for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i)
            m.vertices.push_back(corner + Vec2(size.x() * i / nx, size.y() * j / ny));
    auto id = [&](int i, int j) { return j * (nx + 1) + i; };
    m.triangles.reserve(static_cast<size_t>(n_triangles));
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
            bool slash = diagonal == Diagonal::right ||
                         (diagonal == Diagonal::alternate && (i + j) % 2 == 0);
            if (slash) {
                m.triangles.push_back({a, b, c});
                m.triangles.push_back({a, c, d});
            } else {
                m.triangles.push_back({a, b, d});
                m.triangles.push_back({b, c, d});
            }
        }
    const int bottom = m.add_tag("bottom"), right = m.add_tag("right"), top = m.add_tag("top"),
              left = m.add_tag("left");
    for (int i = 0; i < nx; ++i)
        m.boundary.push_back({id(i, 0), id(i + 1, 0), bottom, -1});
    for (int j = 0; j < ny; ++j)
        m.boundary.push_back({id(nx, j), id(nx, j + 1), right, -1});
    for (int i = nx; i > 0; --i)
        m.boundary.push_back({id(i, ny), id(i - 1, ny), top, -1});
    for (int j = ny; j > 0; --j)
        m.boundary.push_back({id(0, j), id(0, j - 1), left, -1});
    return m;
}

VertexTriangles vertex_triangles(const Mesh& m) {
    const size_t nv = m.vertices.size();
    VertexTriangles r;
    r.offset.assign(nv + 1, 0);
    for (const auto& tri : m.triangles)
        for (int v : tri)
            ++r.offset[static_cast<size_t>(v) + 1];
    for (size_t v = 0; v < nv; ++v)
        r.offset[v + 1] += r.offset[v];
    r.triangles.resize(static_cast<size_t>(r.offset.back()));
    std::vector<int> fill(r.offset.begin(), r.offset.end() - 1);
    for (size_t t = 0; t < m.triangles.size(); ++t) // ascending per vertex
        for (int v : m.triangles[t])
            r.triangles[static_cast<size_t>(fill[static_cast<size_t>(v)]++)] = static_cast<int>(t);
    return r;
}

VertexTriangles::OnEdge VertexTriangles::on_edge(const Mesh& m, int a, int b) const {
    OnEdge r;
    const int nv = static_cast<int>(offset.size()) - 1;
    if (a < 0 || a >= nv || b < 0 || b >= nv || a == b) return r;
    for (int k = offset[static_cast<size_t>(a)]; k < offset[static_cast<size_t>(a) + 1]; ++k) {
        const int t = triangles[static_cast<size_t>(k)];
        const auto& tri = m.triangles[static_cast<size_t>(t)];
        if (tri[0] != b && tri[1] != b && tri[2] != b) continue;
        if (r.count < 2) r.first[static_cast<size_t>(r.count)] = t;
        ++r.count;
    }
    return r;
}

std::optional<Mesh> unrefine(const Mesh& f, double tol) {
    const int nt = f.n_triangles(), nv = f.n_vertices();
    if (nt < 4 || nt % 4 != 0) return std::nullopt;
    // The neighbour across local edge e (opposite local vertex e) of every triangle, -1 on the
    // boundary; an edge of more than two triangles is no refinement of ours.
    const VertexTriangles vtri = vertex_triangles(f);
    std::vector<std::array<int, 3>> nb(static_cast<size_t>(nt), {-1, -1, -1});
    for (int t = 0; t < nt; ++t)
        for (int e = 0; e < 3; ++e) {
            const auto& tri = f.triangles[static_cast<size_t>(t)];
            const auto on = vtri.on_edge(f, tri[(e + 1) % 3], tri[(e + 2) % 3]);
            if (on.count > 2) return std::nullopt; // a third triangle on an edge
            if (on.count == 2)
                nb[static_cast<size_t>(t)][static_cast<size_t>(e)] =
                    on.first[0] == t ? on.first[1] : on.first[0];
        }
    auto local = [&](int t, int v) {
        const auto& tri = f.triangles[static_cast<size_t>(t)];
        for (int i = 0; i < 3; ++i)
            if (tri[i] == v) return i;
        return -1;
    };
    // Label per triangle: -2 unknown, -1 the middle child of its coarse triangle (its three
    // vertices are midpoints), 0..2 a corner child whose local vertex i is a coarse vertex.
    // Rules of the 1->4 split: across each edge of a middle child lies a corner child whose
    // vertex off that edge is coarse; across a corner child's edge opposite its coarse vertex
    // lies the middle child, across its two other edges corner children of the same vertex.
    std::vector<int> label(static_cast<size_t>(nt), -2);
    std::vector<int> stack, touched;
    auto propagate = [&](int seed, int seed_label) {
        touched.clear();
        stack.assign(1, seed);
        label[static_cast<size_t>(seed)] = seed_label;
        touched.push_back(seed);
        auto put = [&](int t, int l) {
            int& cur = label[static_cast<size_t>(t)];
            if (cur == -2) {
                cur = l;
                touched.push_back(t);
                stack.push_back(t);
                return true;
            }
            return cur == l;
        };
        while (!stack.empty()) {
            const int t = stack.back();
            stack.pop_back();
            const int l = label[static_cast<size_t>(t)];
            const auto& tri = f.triangles[static_cast<size_t>(t)];
            for (int e = 0; e < 3; ++e) {
                const int n = nb[static_cast<size_t>(t)][static_cast<size_t>(e)];
                if (l == -1 || e == l) { // a middle child's edge, or a corner's edge off its vertex
                    if (n < 0) return false;
                    if (l == -1) {
                        // n's vertex off the shared edge (tri[e+1], tri[e+2]) is coarse
                        const auto& tn = f.triangles[static_cast<size_t>(n)];
                        int off = -1;
                        for (int i = 0; i < 3; ++i)
                            if (tn[i] != tri[(e + 1) % 3] && tn[i] != tri[(e + 2) % 3]) off = i;
                        if (off < 0 || !put(n, off)) return false;
                    } else if (!put(n, -1)) {
                        return false;
                    }
                } else if (n >= 0) { // a corner's edge through its coarse vertex
                    const int i = local(n, tri[l]);
                    if (i < 0 || !put(n, i)) return false;
                }
            }
        }
        return true;
    };
    for (int t0 = 0; t0 < nt; ++t0) {
        if (label[static_cast<size_t>(t0)] != -2) continue;
        bool ok = false;
        for (int guess : {-1, 0, 1, 2}) { // each component: the four roles of its first triangle
            if (propagate(t0, guess)) {
                ok = true;
                break;
            }
            for (int t : touched)
                label[static_cast<size_t>(t)] = -2;
        }
        if (!ok) return std::nullopt;
    }
    // Coarse vertices: the corners' vertices; no triangle may hold two of them.
    std::vector<int> coarse_of(static_cast<size_t>(nv), -1);
    for (int t = 0; t < nt; ++t)
        if (const int l = label[static_cast<size_t>(t)]; l >= 0)
            coarse_of[static_cast<size_t>(f.triangles[static_cast<size_t>(t)][l])] = 0;
    for (int t = 0; t < nt; ++t) {
        int n_coarse = 0;
        for (int v : f.triangles[static_cast<size_t>(t)])
            n_coarse += coarse_of[static_cast<size_t>(v)] == 0;
        if (n_coarse != (label[static_cast<size_t>(t)] >= 0 ? 1 : 0)) return std::nullopt;
    }
    Mesh c;
    c.circles = f.circles;
    c.tag_names = f.tag_names;
    for (int v = 0; v < nv; ++v)
        if (coarse_of[static_cast<size_t>(v)] == 0) {
            coarse_of[static_cast<size_t>(v)] = c.n_vertices();
            c.vertices.push_back(f.vertices[static_cast<size_t>(v)]);
        }
    const int nc = c.n_vertices();
    // Each middle child (ab, bc, ca) with the corners across its edges: coarse triangle (a, b, c),
    // a = the coarse vertex across the edge opposite bc, and so on. Every corner in one group.
    std::vector<char> grouped(static_cast<size_t>(nt), 0);
    std::vector<std::array<int, 2>> edge_of(static_cast<size_t>(nv), {-1, -1}); // midpoint's pair
    auto set_mid = [&](int m, int a, int b) {
        std::array<int, 2> pair{std::min(a, b), std::max(a, b)};
        auto& cur = edge_of[static_cast<size_t>(m)];
        if (cur[0] < 0) cur = pair;
        return cur == pair;
    };
    for (int t = 0; t < nt; ++t) {
        if (label[static_cast<size_t>(t)] != -1) continue;
        const auto& mid = f.triangles[static_cast<size_t>(t)];
        std::array<int, 3> p{};
        for (int e = 0; e < 3; ++e) {
            const int n = nb[static_cast<size_t>(t)][static_cast<size_t>(e)];
            if (grouped[static_cast<size_t>(n)]) return std::nullopt;
            grouped[static_cast<size_t>(n)] = 1;
            p[static_cast<size_t>(e)] =
                f.triangles[static_cast<size_t>(n)][label[static_cast<size_t>(n)]];
        }
        grouped[static_cast<size_t>(t)] = 1;
        // mid = (ab, bc, ca): across (bc, ca) lies c = p[0], across (ca, ab) a = p[1], b = p[2].
        const int a = p[1], b = p[2], cc = p[0];
        if (!set_mid(mid[0], a, b) || !set_mid(mid[1], b, cc) || !set_mid(mid[2], cc, a))
            return std::nullopt;
        c.triangles.push_back({coarse_of[static_cast<size_t>(a)], coarse_of[static_cast<size_t>(b)],
                               coarse_of[static_cast<size_t>(cc)]});
        if (!f.attribute.empty()) {
            const int at = f.attribute[static_cast<size_t>(t)];
            for (int e = 0; e < 3; ++e)
                if (f.attribute[static_cast<size_t>(nb[static_cast<size_t>(t)][e])] != at)
                    return std::nullopt;
            c.attribute.push_back(at);
        }
    }
    if (4 * c.n_triangles() != nt) return std::nullopt;
    // Boundary edges and lines: the two halves (a, m), (m, b) of each coarse edge, same tag and
    // curve, m the midpoint of (a, b).
    auto join = [&](const std::vector<BoundaryEdge>& halves, std::vector<BoundaryEdge>& out,
                    bool oriented) {
        std::vector<int> first(static_cast<size_t>(nv), -1);
        for (size_t h = 0; h < halves.size(); ++h) {
            const BoundaryEdge& e = halves[h];
            const bool c0 = coarse_of[static_cast<size_t>(e.v0)] >= 0 &&
                            edge_of[static_cast<size_t>(e.v0)][0] < 0;
            const bool c1 = coarse_of[static_cast<size_t>(e.v1)] >= 0 &&
                            edge_of[static_cast<size_t>(e.v1)][0] < 0;
            if (c0 == c1) return false; // one end coarse, one a midpoint
            const int m = c0 ? e.v1 : e.v0;
            int& other = first[static_cast<size_t>(m)];
            if (other < 0) {
                other = static_cast<int>(h);
                continue;
            }
            const BoundaryEdge& g = halves[static_cast<size_t>(other)];
            if (g.tag != e.tag || g.curve != e.curve) return false;
            const int ga = g.v0 == m ? g.v1 : g.v0, ea = c0 ? e.v0 : e.v1;
            const auto& pair = edge_of[static_cast<size_t>(m)];
            if (std::array<int, 2>{std::min(ga, ea), std::max(ga, ea)} != pair) return false;
            int a = ga, b = ea; // unoriented: any order
            if (oriented) {
                if (g.v1 == m && e.v0 == m) {
                    a = g.v0;
                    b = e.v1;
                } else if (e.v1 == m && g.v0 == m) {
                    a = e.v0;
                    b = g.v1;
                } else {
                    return false;
                }
            }
            out.push_back({coarse_of[static_cast<size_t>(a)], coarse_of[static_cast<size_t>(b)],
                           e.tag, e.curve});
            other = -2;
        }
        for (int v = 0; v < nv; ++v)
            if (first[static_cast<size_t>(v)] >= 0) return false; // an unpaired half
        return true;
    };
    if (!join(f.boundary, c.boundary, true) || !join(f.lines, c.lines, false)) return std::nullopt;
    // The check that settles it: refining the coarse mesh gives back f, every vertex within tol
    // and every triangle, boundary half and line half present.
    Mesh r;
    try {
        r = refine(c);
    } catch (const InvalidInput&) {
        return std::nullopt; // e.g. an arc whose chord's midpoint is its centre
    }
    if (r.n_vertices() != nv || r.n_triangles() != nt || r.boundary.size() != f.boundary.size() ||
        r.lines.size() != f.lines.size())
        return std::nullopt;
    std::vector<int> to_f(static_cast<size_t>(nv), -1); // r's vertex -> f's
    for (int v = 0; v < nv; ++v) {
        const int cv = coarse_of[static_cast<size_t>(v)];
        if (cv >= 0 && edge_of[static_cast<size_t>(v)][0] < 0) to_f[static_cast<size_t>(cv)] = v;
    }
    // f's midpoint of each coarse edge, listed under the edge's first coarse vertex.
    std::vector<int> mo_off(static_cast<size_t>(nc) + 1, 0);
    std::vector<std::array<int, 2>> mo(static_cast<size_t>(nv - nc)); // (second vertex, midpoint)
    for (int v = 0; v < nv; ++v)
        if (const auto& pr = edge_of[static_cast<size_t>(v)]; pr[0] >= 0)
            ++mo_off[static_cast<size_t>(coarse_of[static_cast<size_t>(pr[0])]) + 1];
    for (int v = 0; v < nc; ++v)
        mo_off[static_cast<size_t>(v) + 1] += mo_off[static_cast<size_t>(v)];
    {
        std::vector<int> fill(mo_off.begin(), mo_off.end() - 1);
        for (int v = 0; v < nv; ++v)
            if (const auto& pr = edge_of[static_cast<size_t>(v)]; pr[0] >= 0) {
                const int a = coarse_of[static_cast<size_t>(pr[0])];
                const int b = coarse_of[static_cast<size_t>(pr[1])];
                mo[static_cast<size_t>(fill[static_cast<size_t>(std::min(a, b))]++)] = {
                    std::max(a, b), v};
            }
    }
    for (int v = nc; v < nv; ++v) {
        const auto& pr = r.parents[static_cast<size_t>(v - nc)]; // (min, max)
        for (int k = mo_off[static_cast<size_t>(pr[0])]; k < mo_off[static_cast<size_t>(pr[0]) + 1];
             ++k)
            if (mo[static_cast<size_t>(k)][0] == pr[1])
                to_f[static_cast<size_t>(v)] = mo[static_cast<size_t>(k)][1];
    }
    for (int v = 0; v < nv; ++v) {
        const int w = to_f[static_cast<size_t>(v)];
        if (w < 0 ||
            (r.vertices[static_cast<size_t>(v)] - f.vertices[static_cast<size_t>(w)]).norm() > tol)
            return std::nullopt;
    }
    for (const auto& t : r.triangles) {
        const int x = to_f[static_cast<size_t>(t[0])], y = to_f[static_cast<size_t>(t[1])],
                  z = to_f[static_cast<size_t>(t[2])];
        bool found = false; // a triangle of f on the edge (x, y) holds z (f's edges hold <= 2)
        for (const int u : vtri.on_edge(f, x, y).first) {
            if (u < 0) continue;
            const auto& tu = f.triangles[static_cast<size_t>(u)];
            found = found || tu[0] == z || tu[1] == z || tu[2] == z;
        }
        if (!found) return std::nullopt;
    }
    return c;
}

} // namespace mlc::mesh

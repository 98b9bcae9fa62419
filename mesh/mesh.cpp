// SPDX-License-Identifier: MIT
// Mesh queries, uniform 1->4 refinement and structured rectangles (checks: mesh_checks.cpp, the
// inverse of refinement: unrefine.cpp).
#include "mesh/mesh.hpp"
#include "mesh/edge_key.hpp"

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
    fine.shapes = coarse.shapes;
    fine.tag_names = coarse.tag_names;
    fine.n_coarse_vertices = coarse.n_vertices();
    fine.vertices = coarse.vertices;
    const size_t nt = coarse.cells.size();
    fine.vertices.reserve(coarse.vertices.size() + 2 * nt);
    fine.parents.reserve(2 * nt);
    std::unordered_map<std::uint64_t, int> midpoint;
    midpoint.reserve(3 * nt);
    auto mid = [&](int a, int b) {
        auto [it, inserted] = midpoint.try_emplace(detail::edge_key(a, b), 0);
        if (inserted) {
            it->second = static_cast<int>(fine.vertices.size());
            fine.vertices.push_back(0.5 * (coarse.vertices[static_cast<size_t>(a)] +
                                           coarse.vertices[static_cast<size_t>(b)]));
            fine.parents.push_back({std::min(a, b), std::max(a, b)});
        }
        return it->second;
    };
    fine.cells.reserve(4 * nt);
    for (const auto& t : coarse.cells) {
        const int a = t[0], b = t[1], c = t[2];
        const int ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
        fine.cells.push_back({a, ab, ca});
        fine.cells.push_back({ab, b, bc});
        fine.cells.push_back({ca, bc, c});
        fine.cells.push_back({ab, bc, ca});
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
        if (e.shape >= 0) {
            const Circle& c = coarse.shapes[static_cast<size_t>(e.shape)];
            Vec2& p = fine.vertices[static_cast<size_t>(m)];
            Vec2 d = p - c.center;
            const double n = d.norm();
            MLC_CHECK(n > 0, "boundary edge midpoint at the centre of its circle");
            p = c.center + (c.radius / n) * d;
        }
        fine.boundary.push_back({e.v0, m, e.tag, e.shape});
        fine.boundary.push_back({m, e.v1, e.tag, e.shape});
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
    m.cells.reserve(static_cast<size_t>(n_triangles));
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
            bool slash = diagonal == Diagonal::right ||
                         (diagonal == Diagonal::alternate && (i + j) % 2 == 0);
            if (slash) {
                m.cells.push_back({a, b, c});
                m.cells.push_back({a, c, d});
            } else {
                m.cells.push_back({a, b, d});
                m.cells.push_back({b, c, d});
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
    VertexCells c = vertex_cells(m);
    VertexTriangles r;
    r.offset = std::move(c.offset);
    r.triangles = std::move(c.cells);
    return r;
}

VertexTriangles::OnEdge VertexTriangles::on_edge(const Mesh& m, int a, int b) const {
    OnEdge r;
    const int nv = static_cast<int>(offset.size()) - 1;
    if (a < 0 || a >= nv || b < 0 || b >= nv || a == b) return r;
    for (int k = offset[static_cast<size_t>(a)]; k < offset[static_cast<size_t>(a) + 1]; ++k) {
        const int t = triangles[static_cast<size_t>(k)];
        const auto& tri = m.cells[static_cast<size_t>(t)];
        if (tri[0] != b && tri[1] != b && tri[2] != b) continue;
        if (r.count < 2) r.first[static_cast<size_t>(r.count)] = t;
        ++r.count;
    }
    return r;
}

} // namespace mlc::mesh

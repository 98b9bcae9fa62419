// SPDX-License-Identifier: MIT
// TetMesh queries, its edges and faces, and the structured Kuhn box.
#include "mesh/tet_mesh.hpp"

#include "core/check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <limits>
#include <sstream>
#include <unordered_map>

namespace mlc::mesh {

std::optional<Vec3> CurvedSurface::project(const Vec3& p) const {
    Vec3 d = p - center;
    if (kind == Kind::cylinder) d -= d.dot(axis) * axis;
    const double n = d.norm();
    if (!(n > 0)) return std::nullopt;
    return p + (radius / n - 1.0) * d;
}

double CurvedSurface::distance(const Vec3& p) const {
    Vec3 d = p - center;
    if (kind == Kind::cylinder) d -= d.dot(axis) * axis;
    return std::abs(d.norm() - radius);
}

std::string CurvedSurface::describe() const {
    std::ostringstream os;
    os << std::setprecision(9);
    auto point = [&](const Vec3& p) {
        os << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
    };
    if (kind == Kind::sphere) {
        os << "sphere (center ";
        point(center);
    } else {
        os << "cylinder (axis through ";
        point(center);
        os << " along ";
        point(axis);
    }
    os << ", radius " << radius << ")";
    return os.str();
}

void attach_surface(TetMesh& m, const std::string& tag, CurvedSurface surface) {
    const auto id = m.find_tag(tag);
    if (!id || !m.is_boundary_tag(*id)) {
        std::string known;
        for (const auto& [name, k] : m.tag_names)
            if (m.is_boundary_tag(k)) known += (known.empty() ? "" : ", ") + name;
        MLC_CHECK(false, "the mesh has no boundary tag '" << tag << "' to put on a curved surface; "
                                                          << "expected one of: " << known);
    }
    MLC_CHECK(surface.radius > 0 && std::isfinite(surface.radius),
              "the curved surface of tag '" << tag << "' needs a positive radius, got "
                                            << surface.radius);
    if (surface.kind == CurvedSurface::Kind::cylinder) {
        const double n = surface.axis.norm();
        MLC_CHECK(n > 0 && std::isfinite(n),
                  "the cylinder of tag '" << tag << "' needs a nonzero axis direction");
        surface.axis /= n;
    }
    const double tol = kOnSurfaceTol * surface.radius;
    for (int v : m.vertices_with_tag(*id)) {
        const Vec3& p = m.vertices[static_cast<size_t>(v)];
        const double off = surface.distance(p);
        MLC_CHECK(off <= tol, "vertex " << v << " at (" << p.x() << ", " << p.y() << ", " << p.z()
                                        << ") of tag '" << tag << "' lies " << off << " off the "
                                        << surface.describe() << "; expected on it (within "
                                        << kOnSurfaceTol
                                        << " of the radius): check the centre, axis and radius "
                                           "against the mesh (in its frame and units)");
    }
    const int index = static_cast<int>(m.shapes.size());
    m.shapes.push_back(surface);
    for (auto& f : m.boundary)
        if (f.tag == *id) f.shape = index;
}

TetEdges tet_edges(const TetMesh& m) {
    static constexpr int kLocal[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    TetEdges out;
    const size_t nt = m.cells.size();
    out.tet_edges.resize(nt);
    std::unordered_map<std::uint64_t, int> index;
    index.reserve(2 * nt);
    for (size_t t = 0; t < nt; ++t)
        for (int e = 0; e < 6; ++e) {
            int a = m.cells[t][static_cast<size_t>(kLocal[e][0])];
            int b = m.cells[t][static_cast<size_t>(kLocal[e][1])];
            if (a > b) std::swap(a, b);
            const std::uint64_t key =
                (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
                static_cast<std::uint32_t>(b);
            auto [it, inserted] = index.try_emplace(key, static_cast<int>(out.edges.size()));
            if (inserted) out.edges.push_back({a, b});
            out.tet_edges[t][static_cast<size_t>(e)] = it->second;
        }
    return out;
}

long long count_faces(const TetMesh& m) {
    std::vector<std::array<int, 3>> faces;
    faces.reserve(4 * m.cells.size());
    for (const auto& k : m.cells)
        for (int skip = 0; skip < 4; ++skip) {
            std::array<int, 3> f{};
            int n = 0;
            for (int i = 0; i < 4; ++i)
                if (i != skip) f[static_cast<size_t>(n++)] = k[static_cast<size_t>(i)];
            std::sort(f.begin(), f.end());
            faces.push_back(f);
        }
    std::sort(faces.begin(), faces.end());
    return static_cast<long long>(std::unique(faces.begin(), faces.end()) - faces.begin());
}

namespace {

/// Appends the triangle (a, b, c) tagged `tag`, turned so that its normal has a positive dot
/// product with `outward`.
void add_face(TetMesh& m, int a, int b, int c, int tag, const Vec3& outward) {
    const Vec3& pa = m.vertices[static_cast<size_t>(a)];
    const Vec3 n =
        (m.vertices[static_cast<size_t>(b)] - pa).cross(m.vertices[static_cast<size_t>(c)] - pa);
    if (n.dot(outward) < 0) std::swap(b, c);
    m.boundary.push_back({{a, b, c}, tag});
}

} // namespace

TetMesh structured_box(Vec3 corner, Vec3 size, int nx, int ny, int nz) {
    MLC_CHECK(nx >= 1 && ny >= 1 && nz >= 1,
              "a structured box needs at least one cell each way, got " << nx << " x " << ny
                                                                        << " x " << nz);
    MLC_CHECK(size.x() > 0 && size.y() > 0 && size.z() > 0,
              "a structured box needs a positive size, got " << size.x() << " x " << size.y()
                                                             << " x " << size.z());
    const std::int64_t n_vertices =
        (std::int64_t{nx} + 1) * (std::int64_t{ny} + 1) * (std::int64_t{nz} + 1);
    const std::int64_t n_tets = 6 * std::int64_t{nx} * std::int64_t{ny} * std::int64_t{nz};
    MLC_CHECK(std::max(n_vertices, n_tets) <= std::numeric_limits<int>::max(),
              "a structured box of " << nx << " x " << ny << " x " << nz << " cells has "
                                     << n_vertices << " vertices and " << n_tets
                                     << " tetrahedra, more than an int index can address");
    TetMesh m;
    m.vertices.reserve(static_cast<size_t>(n_vertices));
    for (int k = 0; k <= nz; ++k)
        for (int j = 0; j <= ny; ++j)
            for (int i = 0; i <= nx; ++i)
                m.vertices.push_back(corner +
                                     Vec3(size.x() * i / nx, size.y() * j / ny, size.z() * k / nz));
    auto id = [&](int i, int j, int k) { return (k * (ny + 1) + j) * (nx + 1) + i; };
    static constexpr int kPaths[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                         {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    m.cells.reserve(static_cast<size_t>(n_tets));
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i)
                for (const auto& path : kPaths) {
                    std::array<int, 3> c{i, j, k};
                    std::array<int, 4> tet{id(i, j, k), 0, 0, 0};
                    for (int s = 0; s < 3; ++s) {
                        ++c[static_cast<size_t>(path[s])];
                        tet[static_cast<size_t>(s + 1)] = id(c[0], c[1], c[2]);
                    }
                    m.cells.push_back(tet);
                }
    // Each side: the axis it is normal to, low or high, its tag.
    static constexpr const char* kNames[3][2] = {
        {"xmin", "xmax"}, {"ymin", "ymax"}, {"zmin", "zmax"}};
    const int n[3] = {nx, ny, nz};
    for (int axis = 0; axis < 3; ++axis)
        for (int high = 0; high < 2; ++high) {
            const int tag = m.add_tag(kNames[axis][high]);
            Vec3 outward = Vec3::Zero();
            outward[axis] = high ? 1.0 : -1.0;
            const int u = (axis + 1) % 3, w = (axis + 2) % 3; // the side's two axes
            for (int b = 0; b < n[w]; ++b)
                for (int a = 0; a < n[u]; ++a) {
                    auto vertex = [&](int da, int db) {
                        std::array<int, 3> c{};
                        c[static_cast<size_t>(axis)] = high ? n[axis] : 0;
                        c[static_cast<size_t>(u)] = a + da;
                        c[static_cast<size_t>(w)] = b + db;
                        return id(c[0], c[1], c[2]);
                    };
                    add_face(m, vertex(0, 0), vertex(1, 0), vertex(1, 1), tag, outward);
                    add_face(m, vertex(0, 0), vertex(1, 1), vertex(0, 1), tag, outward);
                }
        }
    return m;
}

} // namespace mlc::mesh

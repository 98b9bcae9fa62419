// SPDX-License-Identifier: MIT
// Quality and conformity checks of a tetrahedral mesh: flat, duplicated, inverted elements,
// faces of over two tetrahedra, non-manifold boundaries, misplaced boundary faces.
#include "core/check.hpp"
#include "mesh/tet_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <numeric>
#include <sstream>

namespace mlc::mesh {

namespace {

/// One face of one tetrahedron: its sorted vertices, the tetrahedron, the vertex opposite.
struct FaceRecord {
    std::array<int, 3> f;
    int tet;
    int opposite;
    bool operator<(const FaceRecord& o) const { return f != o.f ? f < o.f : tet < o.tet; }
};

/// What the messages need: the mesh and how it names a tetrahedron.
struct Names {
    const TetMesh& m;
    const TetrahedronNamer& name;

    std::string point(int v) const {
        const Vec3& p = m.vertices[static_cast<size_t>(v)];
        std::ostringstream os;
        os << std::setprecision(9) << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
        return os.str();
    }
    std::string tet(int t) const { return name ? name(t) : "tetrahedron " + std::to_string(t); }
    /// "tetrahedron t (vertices a, b, c, d at (..), (..), (..), (..))".
    std::string tet_with_vertices(int t) const {
        const auto& k = m.cells[static_cast<size_t>(t)];
        return tet(t) + " (vertices " + std::to_string(k[0]) + ", " + std::to_string(k[1]) + ", " +
               std::to_string(k[2]) + ", " + std::to_string(k[3]) + " at " + point(k[0]) + ", " +
               point(k[1]) + ", " + point(k[2]) + ", " + point(k[3]) + ")";
    }
    /// "(a, b, c)".
    static std::string indices(const std::array<int, 3>& f) {
        std::ostringstream os;
        os << "(" << f[0] << ", " << f[1] << ", " << f[2] << ")";
        return os.str();
    }
    std::string face(const std::array<int, 3>& f) const {
        return indices(f) + " at " + point(f[0]) + ", " + point(f[1]) + ", " + point(f[2]);
    }
};

double orient(const TetMesh& m, int a, int b, int c, int d) {
    const Vec3& pa = m.vertices[static_cast<size_t>(a)];
    return (m.vertices[static_cast<size_t>(b)] - pa)
        .cross(m.vertices[static_cast<size_t>(c)] - pa)
        .dot(m.vertices[static_cast<size_t>(d)] - pa);
}

void check_indices(const TetMesh& m) {
    MLC_CHECK(m.n_cells() > 0, "the mesh has no tetrahedra");
    MLC_CHECK(m.attribute.empty() || m.attribute.size() == m.cells.size(),
              "the mesh has " << m.attribute.size() << " tetrahedron attributes for "
                              << m.cells.size() << " tetrahedra; expected one each");
    for (const auto& v : m.vertices)
        MLC_CHECK(v.allFinite(), "a mesh vertex is not finite");
    const int nv = m.n_vertices();
    for (int t = 0; t < m.n_cells(); ++t)
        for (int v : m.cells[static_cast<size_t>(t)])
            MLC_CHECK(v >= 0 && v < nv, "tetrahedron " << t << " refers to vertex " << v
                                                       << " but the mesh has " << nv
                                                       << " vertices");
    for (const auto& f : m.boundary) {
        for (int v : f.v)
            MLC_CHECK(v >= 0 && v < nv, "a boundary face tagged '"
                                            << m.tag_name(f.tag) << "' refers to vertex " << v
                                            << " but the mesh has " << nv << " vertices");
        MLC_CHECK(f.shape >= -1 && f.shape < static_cast<int>(m.shapes.size()),
                  "a boundary face tagged '" << m.tag_name(f.tag) << "' refers to curved surface "
                                             << f.shape << " but the mesh has " << m.shapes.size());
    }
}

void check_flat(const TetMesh& m, const Names& names) {
    for (int t = 0; t < m.n_cells(); ++t) {
        const auto& k = m.cells[static_cast<size_t>(t)];
        double longest = 0;
        for (int i = 0; i < 4; ++i)
            for (int j = i + 1; j < 4; ++j)
                longest = std::max(longest, (m.vertices[static_cast<size_t>(k[i])] -
                                             m.vertices[static_cast<size_t>(k[j])])
                                                .norm());
        const double v6 = std::abs(orient(m, k[0], k[1], k[2], k[3]));
        const double rel = longest > 0 ? v6 / (longest * longest * longest) : 0.0;
        MLC_CHECK(rel > kFlatTetrahedronTol,
                  "flat tetrahedron: " << names.tet_with_vertices(t) << " has volume " << v6 / 6
                                       << ", relative volume 6|V|/L^3 = " << rel
                                       << " (L its longest edge); expected more than "
                                       << kFlatTetrahedronTol
                                       << ": its vertices lie in one plane or two coincide; "
                                          "remove the element or remesh");
    }
}

void check_duplicates(const TetMesh& m, const Names& names) {
    std::vector<std::pair<std::array<int, 4>, int>> sorted(m.cells.size());
    for (size_t t = 0; t < m.cells.size(); ++t) {
        sorted[t] = {m.cells[t], static_cast<int>(t)};
        std::sort(sorted[t].first.begin(), sorted[t].first.end());
    }
    std::sort(sorted.begin(), sorted.end());
    for (size_t i = 1; i < sorted.size(); ++i)
        MLC_CHECK(sorted[i].first != sorted[i - 1].first,
                  "duplicated element: " << names.tet_with_vertices(sorted[i - 1].second) << " and "
                                         << names.tet(sorted[i].second)
                                         << " have the same vertices; expected each "
                                            "tetrahedron once: remove one of them");
}

std::vector<FaceRecord> face_records(const TetMesh& m) {
    std::vector<FaceRecord> faces;
    faces.reserve(4 * m.cells.size());
    for (int t = 0; t < m.n_cells(); ++t) {
        const auto& k = m.cells[static_cast<size_t>(t)];
        for (int skip = 0; skip < 4; ++skip) {
            FaceRecord r{{}, t, k[static_cast<size_t>(skip)]};
            int n = 0;
            for (int i = 0; i < 4; ++i)
                if (i != skip) r.f[static_cast<size_t>(n++)] = k[static_cast<size_t>(i)];
            std::sort(r.f.begin(), r.f.end());
            faces.push_back(r);
        }
    }
    std::sort(faces.begin(), faces.end());
    return faces;
}

/// Faces of over two tetrahedra, and pairs folded over each other. Returns the boundary faces
/// (records of faces of one tetrahedron).
std::vector<FaceRecord> check_faces(const TetMesh& m, const std::vector<FaceRecord>& faces,
                                    const Names& names) {
    std::vector<FaceRecord> boundary;
    for (size_t i = 0; i < faces.size();) {
        size_t j = i + 1;
        while (j < faces.size() && faces[j].f == faces[i].f)
            ++j;
        const auto& f = faces[i].f;
        if (j - i > 2) {
            std::string tets;
            for (size_t k = i; k < j; ++k)
                tets += (k > i ? ", " : "") + names.tet(faces[k].tet);
            MLC_CHECK(false, "a face shared by " << j - i << " tetrahedra: the face "
                                                 << names.face(f) << " belongs to " << tets
                                                 << "; expected at most two: the elements "
                                                    "overlap; remove the extra ones or remesh");
        }
        if (j - i == 2) {
            const double s0 = orient(m, f[0], f[1], f[2], faces[i].opposite);
            const double s1 = orient(m, f[0], f[1], f[2], faces[i + 1].opposite);
            MLC_CHECK((s0 > 0) != (s1 > 0),
                      "inverted tetrahedron: "
                          << names.tet_with_vertices(faces[i + 1].tet) << " and "
                          << names.tet(faces[i].tet)
                          << " lie on the same side of their common face " << names.face(f)
                          << "; expected them on opposite sides: one is folded over the other "
                             "(inverted, e.g. by a moved vertex) or they overlap; remesh");
        }
        if (j - i == 1) boundary.push_back(faces[i]);
        i = j;
    }
    return boundary;
}

/// Every edge of the boundary on exactly two boundary faces.
void check_boundary_edges(const std::vector<FaceRecord>& boundary, const Names& names) {
    std::vector<std::pair<std::array<int, 2>, int>> edges; // (edge, tetrahedron)
    edges.reserve(3 * boundary.size());
    for (const auto& r : boundary)
        for (int s = 0; s < 3; ++s) {
            std::array<int, 2> e{r.f[static_cast<size_t>(s)],
                                 r.f[static_cast<size_t>((s + 1) % 3)]};
            std::sort(e.begin(), e.end());
            edges.push_back({e, r.tet});
        }
    std::sort(edges.begin(), edges.end());
    for (size_t i = 0; i < edges.size();) {
        size_t j = i + 1;
        while (j < edges.size() && edges[j].first == edges[i].first)
            ++j;
        if (j - i != 2) {
            std::string tets;
            for (size_t k = i; k < j; ++k)
                tets += (k > i ? ", " : "") + names.tet(edges[k].second);
            const auto& e = edges[i].first;
            MLC_CHECK(false, "non-manifold boundary: the edge ("
                                 << e[0] << ", " << e[1] << ") from " << names.point(e[0]) << " to "
                                 << names.point(e[1]) << " lies on " << j - i
                                 << " boundary faces (of " << tets << "); expected two: "
                                 << (j - i > 2 ? "parts of the mesh touch only along this edge; "
                                                 "join them with elements or mesh them apart"
                                               : "the mesh is not conforming there (a hanging "
                                                 "node or a crack); remesh"));
        }
        i = j;
    }
}

/// Union-find root with path halving.
int root(std::vector<int>& parent, int i) {
    while (parent[static_cast<size_t>(i)] != i) {
        const int grandparent = parent[static_cast<size_t>(parent[static_cast<size_t>(i)])];
        parent[static_cast<size_t>(i)] = grandparent;
        i = grandparent;
    }
    return i;
}

/// The boundary faces around each vertex form one fan (their links one cycle).
void check_boundary_vertices(const std::vector<FaceRecord>& boundary, const Names& names) {
    std::vector<std::pair<int, int>> at; // (vertex, boundary record)
    at.reserve(3 * boundary.size());
    for (size_t r = 0; r < boundary.size(); ++r)
        for (int v : boundary[r].f)
            at.push_back({v, static_cast<int>(r)});
    std::sort(at.begin(), at.end());
    std::vector<int> link, parent;
    for (size_t i = 0; i < at.size();) {
        size_t j = i + 1;
        while (j < at.size() && at[j].first == at[i].first)
            ++j;
        const int v = at[i].first;
        link.clear();
        for (size_t k = i; k < j; ++k)
            for (int w : boundary[static_cast<size_t>(at[k].second)].f)
                if (w != v) link.push_back(w);
        std::sort(link.begin(), link.end());
        link.erase(std::unique(link.begin(), link.end()), link.end());
        parent.resize(link.size());
        std::iota(parent.begin(), parent.end(), 0);
        auto local = [&](int w) {
            return static_cast<int>(std::lower_bound(link.begin(), link.end(), w) - link.begin());
        };
        for (size_t k = i; k < j; ++k) {
            std::array<int, 2> ends{};
            int n = 0;
            for (int w : boundary[static_cast<size_t>(at[k].second)].f)
                if (w != v) ends[static_cast<size_t>(n++)] = local(w);
            parent[static_cast<size_t>(root(parent, ends[0]))] = root(parent, ends[1]);
        }
        auto face_of = [&](size_t k) { return boundary[static_cast<size_t>(at[k].second)]; };
        auto other = [&](size_t k) {
            return face_of(k).f[0] == v ? face_of(k).f[1] : face_of(k).f[0];
        };
        const int first = root(parent, local(other(i)));
        for (size_t k = i + 1; k < j; ++k)
            MLC_CHECK(root(parent, local(other(k))) == first,
                      "non-manifold boundary: vertex "
                          << v << " at " << names.point(v)
                          << " joins separate sheets of the boundary (" << names.tet(face_of(i).tet)
                          << " and " << names.tet(face_of(k).tet)
                          << " touch only there); expected one: parts of the mesh touch only "
                             "at this point; join them with elements or mesh them apart");
        i = j;
    }
}

/// Every BoundaryFace a face of one tetrahedron, its normal out of it.
void check_tagged_faces(const TetMesh& m, const std::vector<FaceRecord>& faces,
                        const Names& names) {
    for (const auto& b : m.boundary) {
        FaceRecord key{b.v, -1, -1};
        std::sort(key.f.begin(), key.f.end());
        const auto lo = std::lower_bound(faces.begin(), faces.end(), key);
        auto hi = lo;
        while (hi != faces.end() && hi->f == key.f)
            ++hi;
        const std::string face = Names::indices(b.v);
        MLC_CHECK(hi - lo == 1, "boundary face " << face << " tagged '" << m.tag_name(b.tag)
                                                 << "' is a face of " << hi - lo
                                                 << " tetrahedra; expected one (a face on the "
                                                    "boundary of the mesh)");
        MLC_CHECK(orient(m, b.v[0], b.v[1], b.v[2], lo->opposite) < 0,
                  "boundary face " << face << " tagged '" << m.tag_name(b.tag)
                                   << "' has its normal (v1 - v0) x (v2 - v0) pointing into "
                                   << names.tet(lo->tet)
                                   << "; expected it out of the body: list its vertices in the "
                                      "other order");
    }
}

/// Every tagged line joins two vertices of the mesh along an edge of a tetrahedron.
void check_lines(const TetMesh& m) {
    if (m.lines.empty()) return;
    const int nv = m.n_vertices();
    std::vector<std::array<int, 2>> edges = tet_edges(m).edges;
    std::sort(edges.begin(), edges.end());
    for (size_t i = 0; i < m.lines.size(); ++i) {
        const BoundaryEdge& l = m.lines[i];
        MLC_CHECK(l.v0 >= 0 && l.v0 < nv && l.v1 >= 0 && l.v1 < nv,
                  "line " << i << " of tag '" << m.tag_name(l.tag) << "' refers to vertices ("
                          << l.v0 << ", " << l.v1 << ") but the mesh has " << nv << " vertices");
        const std::array<int, 2> e{std::min(l.v0, l.v1), std::max(l.v0, l.v1)};
        MLC_CHECK(l.v0 != l.v1 && std::binary_search(edges.begin(), edges.end(), e),
                  "line " << i << " of tag '" << m.tag_name(l.tag) << "' from vertex " << l.v0
                          << " to vertex " << l.v1
                          << " is no edge of a tetrahedron; a tagged line (a physical curve) "
                             "must follow edges of the mesh: embed the curve in the volume "
                             "before meshing");
    }
}

} // namespace

void check_quality(const TetMesh& m, const TetrahedronNamer& name) {
    const Names names{m, name};
    check_indices(m);
    check_flat(m, names);
    check_duplicates(m, names);
    const std::vector<FaceRecord> faces = face_records(m);
    const std::vector<FaceRecord> boundary = check_faces(m, faces, names);
    check_boundary_edges(boundary, names);
    check_boundary_vertices(boundary, names);
    check_tagged_faces(m, faces, names);
    check_lines(m);
}

void check_refined_quality(const TetMesh& m) {
    const TetrahedronNamer none;
    check_indices(m);
    check_flat(m, Names{m, none});
}

} // namespace mlc::mesh

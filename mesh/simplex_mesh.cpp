// SPDX-License-Identifier: MIT
// The queries every SimplexMesh answers the same way in 2D and 3D: tags, measures, tagged
// vertices, edge lengths, the bounding box and the nearest vertex.
#include "mesh/simplex_mesh.hpp"

#include "core/check.hpp"

#include <Eigen/Geometry> // cross

#include <algorithm>
#include <limits>

namespace mlc::mesh {

template <int dim> int SimplexMesh<dim>::tag(const std::string& name) const {
    auto it = tag_names.find(name);
    if (it == tag_names.end()) {
        std::string known;
        for (const auto& [n, id] : tag_names)
            known += (known.empty() ? "" : ", ") + n;
        MLC_CHECK(false, "unknown boundary tag '" << name << "'; the mesh has: " << known);
    }
    return it->second;
}

template <int dim> std::optional<int> SimplexMesh<dim>::find_tag(const std::string& name) const {
    auto it = tag_names.find(name);
    if (it == tag_names.end()) return std::nullopt;
    return it->second;
}

template <int dim> std::string SimplexMesh<dim>::tag_name(int t) const {
    for (const auto& [n, id] : tag_names)
        if (id == t) return n;
    return "tag " + std::to_string(t);
}

template <int dim> int SimplexMesh<dim>::add_tag(const std::string& name) {
    auto it = tag_names.find(name);
    if (it != tag_names.end()) return it->second;
    int id = 0;
    for (const auto& [n, t] : tag_names)
        id = std::max(id, t + 1);
    tag_names[name] = id;
    return id;
}

template <int dim> double SimplexMesh<dim>::signed_measure(int c) const {
    const Cell& k = cells[static_cast<size_t>(c)];
    const Point& a = vertices[static_cast<size_t>(k[0])];
    const Point b = vertices[static_cast<size_t>(k[1])] - a;
    const Point d = vertices[static_cast<size_t>(k[2])] - a;
    if constexpr (dim == 2) {
        return 0.5 * (b.x() * d.y() - b.y() * d.x());
    } else {
        return b.cross(d).dot(vertices[static_cast<size_t>(k[3])] - a) / 6.0;
    }
}

namespace {

// The sorted distinct vertices of the facets or edges tagged t in each of the lists.
template <class... Lists> std::vector<int> tagged_vertices(int t, const Lists&... lists) {
    std::vector<int> out;
    auto add = [&](const auto& list) {
        for (const auto& f : list)
            if (f.tag == t)
                for (int v : f.vertices())
                    out.push_back(v);
    };
    (add(lists), ...);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

} // namespace

template <int dim> std::vector<int> SimplexMesh<dim>::vertices_with_tag(int t) const {
    return tagged_vertices(t, boundary);
}

template <int dim> std::vector<int> SimplexMesh<dim>::vertices_on_tag(int t) const {
    return tagged_vertices(t, boundary, lines);
}

template <int dim> bool SimplexMesh<dim>::is_boundary_tag(int t) const {
    return std::any_of(boundary.begin(), boundary.end(),
                       [t](const Facet& f) { return f.tag == t; });
}

template <int dim> std::pair<double, double> SimplexMesh<dim>::edge_length_range() const {
    double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
    for (const Cell& k : cells)
        for (int i = 0; i <= dim; ++i)
            for (int j = i + 1; j <= dim; ++j) {
                const double l = (vertices[static_cast<size_t>(k[static_cast<size_t>(i)])] -
                                  vertices[static_cast<size_t>(k[static_cast<size_t>(j)])])
                                     .norm();
                lo = std::min(lo, l);
                hi = std::max(hi, l);
            }
    return {lo, hi};
}

template <int dim> double SimplexMesh<dim>::diameter() const {
    if (vertices.empty()) return 0.0;
    Point lo = vertices[0], hi = vertices[0];
    for (const Point& v : vertices) {
        lo = lo.cwiseMin(v);
        hi = hi.cwiseMax(v);
    }
    return (hi - lo).norm();
}

template <int dim> int SimplexMesh<dim>::nearest_vertex(const Point& p) const {
    int best = -1;
    double bd = std::numeric_limits<double>::infinity();
    for (int v = 0; v < n_vertices(); ++v) {
        const double d = (vertices[static_cast<size_t>(v)] - p).squaredNorm();
        if (d < bd) {
            bd = d;
            best = v;
        }
    }
    return best;
}

template <int dim> VertexCells vertex_cells(const SimplexMesh<dim>& m) {
    const size_t nv = m.vertices.size();
    VertexCells r;
    r.offset.assign(nv + 1, 0);
    for (const auto& cell : m.cells)
        for (int v : cell) {
            MLC_CHECK(v >= 0 && static_cast<size_t>(v) < nv,
                      SimplexTraits<dim>::cell_name << " vertex " << v << " out of range");
            ++r.offset[static_cast<size_t>(v) + 1];
        }
    for (size_t v = 0; v < nv; ++v)
        r.offset[v + 1] += r.offset[v];
    r.cells.resize(static_cast<size_t>(r.offset.back()));
    std::vector<int> fill(r.offset.begin(), r.offset.end() - 1);
    for (size_t t = 0; t < m.cells.size(); ++t) // ascending per vertex
        for (int v : m.cells[t])
            r.cells[static_cast<size_t>(fill[static_cast<size_t>(v)]++)] = static_cast<int>(t);
    return r;
}

template struct SimplexMesh<2>;
template struct SimplexMesh<3>;
template VertexCells vertex_cells(const SimplexMesh<2>&);
template VertexCells vertex_cells(const SimplexMesh<3>&);

} // namespace mlc::mesh

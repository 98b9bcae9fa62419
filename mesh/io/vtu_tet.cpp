// SPDX-License-Identifier: MIT
// VTU output of tetrahedral meshes and of their tagged boundary faces, through the binary grid
// writer of vtu.cpp.
#include "mesh/io/vtu_tet.hpp"

#include "core/check.hpp"
#include "mesh/io/vtu_grid.hpp"

#include <string>

namespace mlc::mesh {

namespace {

/// The vertices as the grid's points, checked finite.
std::vector<double> checked_points(const TetMesh& m, const char* who) {
    std::vector<double> xyz(3 * m.vertices.size());
    for (std::size_t v = 0; v < m.vertices.size(); ++v) {
        const Vec3& x = m.vertices[v];
        MLC_CHECK(x.allFinite(), who << ": vertex " << v << " has a non-finite coordinate ("
                                     << x.x() << ", " << x.y() << ", " << x.z()
                                     << "); nothing was written");
        for (int c = 0; c < 3; ++c)
            xyz[3 * v + static_cast<std::size_t>(c)] = x[c];
    }
    return xyz;
}

/// Appends one cell of k points (checked in range) to the grid.
template <std::size_t K>
void add_cell(detail::VtuGrid& g, const std::array<int, K>& cell, std::uint8_t type, int n_vertices,
              const char* who, const char* entity, std::size_t index) {
    for (int v : cell) {
        MLC_CHECK(v >= 0 && v < n_vertices, who << ": " << entity << " " << index
                                                << " refers to vertex " << v << " but the mesh has "
                                                << n_vertices << " vertices");
        g.connectivity.push_back(v);
    }
    g.offsets.push_back(static_cast<std::int64_t>(g.connectivity.size()));
    g.types.push_back(type);
}

/// The library's cell fields first, then the caller's (whose names must differ from them).
std::vector<Field> with_own_fields(std::vector<Field> own, const std::vector<Field>& given,
                                   const char* who) {
    for (const Field& f : given)
        for (const Field& o : own)
            MLC_CHECK(f.name != o.name, who << ": the cell field '" << f.name
                                            << "' is written by the library; choose another name");
    own.insert(own.end(), given.begin(), given.end());
    return own;
}

} // namespace

void write_vtu(const std::filesystem::path& file, const TetMesh& m,
               const std::vector<Field>& point_fields, const std::vector<Field>& cell_fields) {
    const std::size_t nt = m.cells.size();
    MLC_CHECK(m.attribute.empty() || m.attribute.size() == nt,
              "write_vtu: " << m.attribute.size() << " attributes for " << nt << " tetrahedra");
    detail::VtuGrid g;
    g.xyz = checked_points(m, "write_vtu");
    g.connectivity.reserve(4 * nt);
    g.offsets.reserve(nt);
    g.types.reserve(nt);
    for (std::size_t t = 0; t < nt; ++t)
        add_cell(g, m.cells[t], detail::kVtkTetra, m.n_vertices(), "write_vtu", "tetrahedron", t);
    Field body{"body", 1, std::vector<double>(nt, 0.0)};
    for (std::size_t t = 0; t < m.attribute.size(); ++t)
        body.values[t] = m.attribute[t];
    const std::vector<Field> cells = with_own_fields({std::move(body)}, cell_fields, "write_vtu");
    detail::check_vtu_fields(point_fields, "point", "vertex", m.vertices.size());
    detail::check_vtu_fields(cells, "cell", "tetrahedron", nt);
    detail::write_vtu_grid(file, std::move(g), point_fields, cells);
}

void write_boundary_vtu(const std::filesystem::path& file, const TetMesh& m,
                        const std::vector<Field>& point_fields,
                        const std::vector<Field>& cell_fields) {
    const std::size_t nf = m.boundary.size();
    detail::VtuGrid g;
    g.xyz = checked_points(m, "write_boundary_vtu");
    g.connectivity.reserve(3 * nf);
    g.offsets.reserve(nf);
    g.types.reserve(nf);
    Field tag{"tag", 1, std::vector<double>(nf)}, surface{"surface", 1, std::vector<double>(nf)};
    for (std::size_t f = 0; f < nf; ++f) {
        add_cell(g, m.boundary[f].v, detail::kVtkTriangle, m.n_vertices(), "write_boundary_vtu",
                 "boundary face", f);
        tag.values[f] = m.boundary[f].tag;
        surface.values[f] = m.boundary[f].shape;
    }
    const std::vector<Field> cells =
        with_own_fields({std::move(tag), std::move(surface)}, cell_fields, "write_boundary_vtu");
    detail::check_vtu_fields(point_fields, "point", "vertex", m.vertices.size());
    detail::check_vtu_fields(cells, "cell", "boundary face", nf);
    detail::write_vtu_grid(file, std::move(g), point_fields, cells);
}

} // namespace mlc::mesh

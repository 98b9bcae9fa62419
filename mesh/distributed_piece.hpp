// SPDX-License-Identifier: MIT
/// @file The piece of a distributed level that one process writes (write_distributed_vtu for
/// triangles and for tetrahedra): the sizes of the fields checked against the local level, the
/// owned cells and the vertices they use renumbered, and the piece names the .pvtu lists.
#pragma once

#include "core/check.hpp"
#include "core/communicator.hpp"
#include "mesh/distributed.hpp"
#include "mesh/simplex_mesh.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace mlc::mesh::detail {

/// One process's piece of a local level: its owned cells (local indices, in order), the
/// vertices they use (local indices, in order) and the mesh of those, renumbered.
template <int dim> struct OwnedPiece {
    SimplexMesh<dim> mesh;
    std::vector<int> vertices, cells;
};

/// Throws InvalidInput when a point field does not hold n_components values per local vertex of
/// `m` or a cell field per local cell (`cell_word`: "triangles", "tetrahedra"); then cuts the
/// piece of the cells flagged in `owned` (vertices and cells only: attributes are the caller's).
template <int dim>
OwnedPiece<dim> owned_piece(const SimplexMesh<dim>& m, const std::vector<char>& owned,
                            const std::vector<Field>& point_fields,
                            const std::vector<Field>& cell_fields, const char* cell_word) {
    const int nv = m.n_vertices(), nt = m.n_cells();
    for (const Field& f : point_fields)
        MLC_CHECK(f.n_components >= 1 && f.values.size() == static_cast<size_t>(nv * f.n_components),
                  "write_distributed_vtu: point field '" << f.name << "' has " << f.values.size()
                                                         << " values for " << nv
                                                         << " local vertices");
    for (const Field& f : cell_fields)
        MLC_CHECK(f.n_components >= 1 && f.values.size() == static_cast<size_t>(nt * f.n_components),
                  "write_distributed_vtu: cell field '" << f.name << "' has " << f.values.size()
                                                        << " values for " << nt << " local "
                                                        << cell_word);
    OwnedPiece<dim> p;
    std::vector<int> piece_of(static_cast<size_t>(nv), -1);
    for (int t = 0; t < nt; ++t)
        if (owned[static_cast<size_t>(t)]) {
            p.cells.push_back(t);
            for (int v : m.cells[static_cast<size_t>(t)])
                piece_of[static_cast<size_t>(v)] = 0;
        }
    for (int v = 0; v < nv; ++v)
        if (piece_of[static_cast<size_t>(v)] == 0) {
            piece_of[static_cast<size_t>(v)] = static_cast<int>(p.vertices.size());
            p.vertices.push_back(v);
            p.mesh.vertices.push_back(m.vertices[static_cast<size_t>(v)]);
        }
    for (int t : p.cells) {
        auto c = m.cells[static_cast<size_t>(t)];
        for (auto& v : c)
            v = piece_of[static_cast<size_t>(v)];
        p.mesh.cells.push_back(c);
    }
    return p;
}

/// The file names of every process's piece of `file`, in rank order (what the .pvtu lists).
inline std::vector<std::string> piece_names(const std::filesystem::path& file,
                                            const Communicator& comm) {
    std::vector<std::string> pieces;
    for (int r = 0; r < comm.size(); ++r)
        pieces.push_back(piece_path(file, r).filename().string());
    return pieces;
}

} // namespace mlc::mesh::detail

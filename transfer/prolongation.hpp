// SPDX-License-Identifier: MIT
/// @file The P transfer of displacements between two nested levels of a simplex mesh, in 2D (1->4
/// refinement, mesh/mesh.hpp) and 3D (Bey's 1->8, mesh/tet_refine.hpp): the nodal interpolation
/// as a sparse matrix, per vertex and per interleaved component, and its restriction to the free
/// unknowns of two numberings.
#pragma once

#include "core/types.hpp"
#include "mesh/simplex_mesh.hpp"

#include <array>
#include <vector>

namespace mlc::transfer {

/// The unknowns of one level, per vertex: unknowns[v][c] is the index of component c of vertex
/// v, or -1 when that component is prescribed (or does not exist: entries c >= dim are unused).
/// Any numbering: interleaved, blocked, with other unknowns (multipliers) between the vertices.
using VertexUnknowns = std::vector<std::array<int, 3>>;

/// Nodal interpolation from the coarse mesh to `fine` = mesh::refine(coarse), one scalar per
/// vertex (n_fine_vertices x n_coarse_vertices): row v < n_coarse is the unit row of v (coarse
/// vertices keep their index), row n_coarse + e has 1/2 at both parents of edge e
/// (SimplexMesh::parents). P u_H is the coarse P1 field evaluated at the fine vertices (at the
/// edge midpoints, also where refinement moved a midpoint onto a curved boundary). Each row's
/// entries are in column order. Throws InvalidInput when `fine` has no parents (not made by
/// refine) or a parent is out of range.
template <int dim> MovableSparseMatrix vertex_prolongation(const mesh::SimplexMesh<dim>& fine);

extern template MovableSparseMatrix vertex_prolongation(const mesh::SimplexMesh<2>&);
extern template MovableSparseMatrix vertex_prolongation(const mesh::SimplexMesh<3>&);

/// The same interpolation for `dim` components per vertex, interleaved (component c of vertex v
/// at dim v + c): (dim rows x dim cols) of P_vertex, each entry w at (i, j) becoming w at
/// (dim i + c, dim j + c). Throws InvalidInput unless 1 <= dim <= 3.
MovableSparseMatrix expand_components(const SparseMatrix& P_vertex, int dim);

/// P on unknowns (n_fine_unknowns x n_coarse_unknowns): the row of fine unknown fine[v][c] holds
/// w at column coarse[p][c] for every entry w at (v, p) of P_vertex with coarse[p][c] >= 0. A
/// prescribed coarse component contributes 0 (P maps homogeneous corrections), a prescribed fine
/// component has no row, and rows and columns of unknowns that belong to no vertex component
/// (multipliers) stay empty. Components 0..dim-1 are read. Throws InvalidInput on sizes that do
/// not match P_vertex, indices outside 0..n-1 or used twice, or a coarse vertex (a unit row of
/// P_vertex) whose component is prescribed on one level and free on the other: supports nest.
MovableSparseMatrix restrict_to_unknowns(const SparseMatrix& P_vertex, int dim,
                                         const VertexUnknowns& coarse, int n_coarse_unknowns,
                                         const VertexUnknowns& fine, int n_fine_unknowns);

/// The VertexUnknowns of a DofMap-like numbering: anything with n_vertices() and
/// u_dof(vertex, component) (-1 when prescribed), read for components 0..dim-1.
template <class DofMapLike> VertexUnknowns vertex_unknowns(const DofMapLike& dofs, int dim) {
    VertexUnknowns out(static_cast<size_t>(dofs.n_vertices()), {-1, -1, -1});
    for (int v = 0; v < dofs.n_vertices(); ++v)
        for (int c = 0; c < dim; ++c)
            out[static_cast<size_t>(v)][static_cast<size_t>(c)] = dofs.u_dof(v, c);
    return out;
}

} // namespace mlc::transfer

// SPDX-License-Identifier: MIT
/// @file The lattice of a uniformly refined mesh inside each level-0 triangle ("macro triangle").
///
/// `refine` splits triangle t = (a, b, c) into its children 4t .. 4t+3 = (a, ab, ca), (ab, b, bc),
/// (ca, bc, c), (ab, bc, ca). After `depth` refinements the n = 2^depth subdivisions of a macro
/// triangle (A, B, C) put its vertices on the lattice A + (i/n)(B - A) + (j/n)(C - A), i, j >= 0,
/// i + j <= n, and every fine triangle of the macro is the same triangle up to a translation or a
/// point reflection: one element stiffness, so every vertex whose six lattice neighbours lie in
/// the same macro has the same stencil. Structured kernels (smoothers/lattice_gs.hpp) use it.
#pragma once

#include "mesh/mesh.hpp"

#include <optional>
#include <vector>

namespace mlc::mesh {

/// The vertices of the interior lattice points of every macro triangle.
struct MacroLattice {
    int n = 1;        ///< subdivisions per macro edge, 2^depth
    int n_macros = 0; ///< level-0 triangles
    /// vertex[m * interior_points(n) + p]: the vertex at interior point p of macro m. Interior
    /// points are i >= 1, j >= 1, i + j <= n - 1, numbered row by row: j = 1 .. n-2, and in row j,
    /// i = 1 .. n-1-j (point_index).
    std::vector<int> vertex;

    /// Interior points of one macro: (n-1)(n-2)/2.
    static long interior_points(int n) { return static_cast<long>(n - 1) * (n - 2) / 2; }
    /// Index of interior point (i, j) in its macro's row-by-row numbering.
    static long point_index(int n, int i, int j) {
        // rows 1 .. j-1 hold (n-2) + (n-3) + ... + (n-j) points
        return static_cast<long>(j - 1) * (2 * n - 2 - j) / 2 + (i - 1);
    }
};

/// The lattice of `fine` when it is `depth` uniform refinements (mesh::refine, its triangle
/// order) of a mesh with fine.n_triangles() / 4^depth triangles; std::nullopt when its triangles
/// do not fit that structure (the vertices they put on one lattice point differ, or a vertex sits
/// on two points). depth >= 0; depth 0 or 1 gives a lattice without interior points.
std::optional<MacroLattice> macro_lattice(const Mesh& fine, int depth);

/// A vertex order (a permutation of fine's vertices, for fem::DofMap) macro by macro: each
/// macro's interior points in their numbering, then the vertices on its edges and corners that
/// no smaller macro holds (in vertex index order). The order in which smoothers::LatticeGS
/// sweeps, so that it works in place.
std::vector<int> lattice_vertex_order(const Mesh& fine, const MacroLattice& lattice);

} // namespace mlc::mesh

// SPDX-License-Identifier: MIT
/// @file The 2D algorithms on SimplexMesh<2> (Mesh, mesh/simplex_mesh.hpp): uniform 1->4
/// refinement, its inverse, quality checks, the structured rectangle and the Hilbert order.
#pragma once

#include "core/types.hpp"
#include "mesh/simplex_mesh.hpp"

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace mlc::mesh {

/// Checks a mesh for use: at least one triangle, indices in range, every triangle with positive
/// area (relative to the square of the mesh diameter), no two vertices of one body (attribute)
/// closer than 1e-10 of the diameter (two touching bodies' may coincide), no duplicated element,
/// edge of over two triangles or hanging node (check_topology, mesh/topology.hpp), boundary edges
/// of one triangle, interior lines of two. Throws InvalidInput naming the first defect (indices).
void check_quality(const Mesh& m);

/// The part of check_quality a refinement of a checked mesh still needs: every triangle with
/// positive area (a midpoint moved onto a circular boundary can fold a thin triangle). Its
/// vertices are distinct and its boundary edges are halves of checked ones by construction.
void check_refined_quality(const Mesh& m);

/// Uniform refinement: every triangle split into four by its edge midpoints. Boundary edges and
/// interior lines are split in two with the tag and curve inherited; a midpoint on a circular
/// boundary edge is moved onto the circle. Coarse vertex indices are kept; `parents` is filled.
Mesh refine(const Mesh& coarse);

/// The triangles of every vertex (CSR): those of vertex v are triangles[offset[v] ..
/// offset[v + 1]), in ascending triangle order.
struct VertexTriangles {
    std::vector<int> offset;    ///< n_vertices + 1 entries
    std::vector<int> triangles; ///< 3 n_triangles entries
    /// The triangles of m with the edge (a, b): how many, and the first two in triangle order
    /// (-1 where there are fewer). None for a == b or a vertex out of range.
    struct OnEdge {
        int count = 0;
        std::array<int, 2> first{-1, -1};
    };
    OnEdge on_edge(const Mesh& m, int a, int b) const;
};
/// The VertexTriangles of m (its triangles' indices must lie in [0, n_vertices)).
VertexTriangles vertex_triangles(const Mesh& m);

/// The inverse of `refine`, when `fine` is a uniform 1->4 refinement (what Gmsh's `RefineMesh`
/// and `gmsh -refine`, or `mlcontact show --msh-level`, write): the coarse mesh c with
/// refine(c) = fine up to the vertex numbering (every vertex of refine(c) within `tol` of its
/// vertex of `fine`; the same triangles, boundary halves and interior-line halves, with their
/// tags, curves and attributes). Found from the topology alone (the middle child of each coarse
/// triangle has three midpoints; the children around it have one coarse vertex each), then
/// checked by refining. nullopt when `fine` is not such a refinement. The coarse vertices keep
/// the order of their indices in `fine`; `parents` is empty.
std::optional<Mesh> unrefine(const Mesh& fine, double tol);

/// The vertices in the order of a Hilbert curve through their bounding box (2^16 cells a side;
/// ties keep index order): neighbours in the mesh get nearby positions, so vectors indexed in
/// this order are read with few cache misses by the sparse mat-vecs and sweeps of a level.
/// Returns a permutation of 0..n-1 (position -> vertex).
std::vector<int> hilbert_order(const std::vector<Vec2>& points);

/// How a structured rectangle's squares are cut into two triangles.
enum class Diagonal {
    right,    ///< "/" from lower-left to upper-right in every square
    left,     ///< "\" from lower-right to upper-left
    alternate ///< union-jack style alternation
};

/// Structured mesh of [x0, x0+lx] x [y0, y0+ly] with nx x ny squares cut along one diagonal.
/// Boundary tags "bottom", "right", "top", "left". Vertex (i, j) has index j*(nx+1) + i.
Mesh structured_rectangle(Vec2 corner, Vec2 size, int nx, int ny,
                          Diagonal diagonal = Diagonal::right);

} // namespace mlc::mesh

// SPDX-License-Identifier: MIT
/// @file The 3D algorithms on SimplexMesh<3> (TetMesh, mesh/simplex_mesh.hpp): curved surfaces
/// attached to tags, the quality checks, edges and faces, and the structured (Kuhn) box.
/// Refinement is in mesh/tet_refine.hpp: the children of coarse tetrahedron t are the fine cells
/// 8 t .. 8 t + 7 (Bey's order), those of coarse boundary face f the fine faces 4 f .. 4 f + 3.
#pragma once

#include "core/types.hpp"
#include "mesh/simplex_mesh.hpp"

#include <Eigen/Geometry> // Vec3::cross

#include <array>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace mlc::mesh {

/// Tolerance of attach_surface, relative to the surface's radius.
inline constexpr double kOnSurfaceTol = 1e-6;

/// Declares that the boundary faces tagged `tag` lie on `surface` (a cylinder's axis is
/// normalized), so that refinement moves the vertices it creates on them onto it. Throws
/// InvalidInput naming the tag when it is no boundary tag (listing those there are), the radius
/// is not positive or the axis zero, or a vertex of the tag lies farther than kOnSurfaceTol
/// times the radius off the surface (naming the vertex, its position and the distance).
void attach_surface(TetMesh& m, const std::string& tag, CurvedSurface surface);

/// How a message names tetrahedron t (e.g. its element and line in a file); empty:
/// "tetrahedron t".
using TetrahedronNamer = std::function<std::string(int)>;

/// Relative volume below which a tetrahedron is flat: 6 |V| / L^3 with L its longest edge (a
/// regular tetrahedron has 0.71, a Kuhn tetrahedron 0.19).
inline constexpr double kFlatTetrahedronTol = 1e-10;

/// Checks a tetrahedral mesh for use, and throws InvalidInput naming the first defect:
/// - no tetrahedra, an attribute list of the wrong size, a vertex not finite, an index out of
///   range;
/// - a flat tetrahedron (6 |V| / L^3 <= kFlatTetrahedronTol, L its longest edge);
/// - a duplicated element (two tetrahedra with the same four vertices);
/// - a face shared by more than two tetrahedra;
/// - an inverted tetrahedron: two tetrahedra on the same side of their common face (one is
///   folded over the other), whatever the vertex order;
/// - a non-manifold boundary: an edge on more than two boundary faces (parts touching along an
///   edge) or a vertex where separate sheets of the boundary meet (parts touching at a point);
/// - a BoundaryFace that is not a face of exactly one tetrahedron, or whose normal points into
///   the body, or whose surface is not in TetMesh::shapes;
/// - a tagged line (SimplexMesh::lines) that is no edge of a tetrahedron.
/// O(n log n) (sorting faces and edges). Tetrahedra are named by `name`.
void check_quality(const TetMesh& m, const TetrahedronNamer& name = {});

/// The part of check_quality a refinement of a checked mesh still needs: no flat tetrahedron.
/// Bey's children of a checked mesh are conforming and manifold by construction.
void check_refined_quality(const TetMesh& m);

/// The edges of a mesh: edges[e] = (a, b) with a < b, in the order of their first appearance
/// over the tetrahedra (local edges 01, 02, 03, 12, 13, 23), and tet_edges[t] the six edge
/// indices of tetrahedron t in that local order.
struct TetEdges {
    std::vector<std::array<int, 2>> edges;
    std::vector<std::array<int, 6>> tet_edges;
};
TetEdges tet_edges(const TetMesh& m);

/// Number of distinct faces (triangles) of the tetrahedra: interior faces once, boundary faces
/// once.
long long count_faces(const TetMesh& m);

/// Structured mesh of the box [x0, x0+lx] x [y0, y0+ly] x [z0, z0+lz] with nx x ny x nz cells,
/// each cut into six tetrahedra around its main diagonal from (x0, y0, z0) to the far corner
/// (the Kuhn/Freudenthal split), so that the faces of neighbouring cells match. Vertex
/// (i, j, k) has index (k (ny + 1) + j) (nx + 1) + i. The tetrahedra of a cell follow its
/// Kuhn paths (corner, +e_a, +e_a +e_b, far corner) for the permutations (a, b, c) of the axes
/// in lexicographic order; with cubic cells all are congruent. Boundary tags "xmin", "xmax",
/// "ymin", "ymax", "zmin", "zmax", each square face cut into two triangles along its diagonal
/// from its lowest to its highest corner.
TetMesh structured_box(Vec3 corner, Vec3 size, int nx, int ny, int nz);

} // namespace mlc::mesh

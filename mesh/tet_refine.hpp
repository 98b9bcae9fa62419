// SPDX-License-Identifier: MIT
/// @file Uniform 1->8 refinement of a tetrahedral mesh by Bey's rule, and the sizes of its levels
/// predicted before any is built.
#pragma once

#include "mesh/tet_mesh.hpp"

#include <vector>

namespace mlc::mesh {

/// Children per tetrahedron and per boundary face.
inline constexpr int kTetrahedronChildren = 8;
inline constexpr int kFaceChildren = 4;

/// Bey's regular refinement (J. Bey, "Tetrahedral grid refinement", Computing 55, 1995): the
/// parent (x0, x1, x2, x3) is cut at its edge midpoints xij. Local points 0..3 are its corners,
/// 4..9 the midpoints x01, x02, x03, x12, x13, x23. Child c is (kBeyChildren[c][0..3]) in this
/// vertex order, which the next refinement reads:
///   0: (x0, x01, x02, x03)    1: (x01, x1, x12, x13)   2: (x02, x12, x2, x23)
///   3: (x03, x13, x23, x3)    4: (x01, x02, x03, x13)  5: (x01, x02, x12, x13)
///   6: (x02, x03, x13, x23)   7: (x02, x12, x13, x23)
/// Children 0-3 are the corners (parent scaled by 1/2, same order); 4-7 fill the inner
/// octahedron, cut along its diagonal x02 - x13 whatever its length. Kept over all levels, this
/// order puts every descendant of a tetrahedron in at most three similarity classes, and the
/// eight children of a Kuhn tetrahedron listed along its path are similar to it. Children 5 and
/// 7 have the opposite orientation to their parent.
inline constexpr int kBeyChildren[8][4] = {{0, 4, 5, 6}, {4, 1, 7, 8}, {5, 7, 2, 9}, {6, 8, 9, 3},
                                           {4, 5, 6, 8}, {4, 5, 7, 8}, {5, 6, 8, 9}, {5, 7, 8, 9}};

/// A boundary face (a, b, c) with midpoints 3 = ab, 4 = bc, 5 = ca: its children, all oriented
/// as the parent.
inline constexpr int kFaceChildrenOf[4][3] = {{0, 3, 5}, {3, 1, 4}, {5, 4, 2}, {3, 4, 5}};

/// Uniform 1->8 refinement by Bey's rule (kBeyChildren). Coarse vertex indices are kept; the
/// midpoint of coarse edge e (tet_edges order) is vertex n_coarse + e, and parents[e] its two
/// coarse vertices. The children of tetrahedron t are 8 t + c (c as in kBeyChildren) with t's
/// attribute; the children of boundary face f are 4 f + k (kFaceChildrenOf), with f's tag and
/// surface. A midpoint of an edge of a boundary face on a curved surface is moved onto that
/// surface (of the first such face in TetMesh::boundary); then every child with a moved vertex
/// must keep the orientation Bey's rule gives it and not be flat, or InvalidInput names it,
/// its parent and the surface's tag (the coarse mesh is too coarse for the curvature there).
TetMesh refine(const TetMesh& coarse);

/// The coarse tetrahedron a tetrahedron of refine(coarse) lies in, and which child it is.
inline int parent_tetrahedron(int child) {
    return child / kTetrahedronChildren;
}
inline int child_number(int child) {
    return child % kTetrahedronChildren;
}

/// Predicted size of one level of a tetrahedral hierarchy.
struct TetLevelSize {
    int level = 0;
    double vertices = 0, edges = 0, faces = 0, tetrahedra = 0;
    double boundary_faces = 0; ///< faces of one tetrahedron (tagged or not)
    double tagged_faces = 0;   ///< TetMesh::boundary entries
    double bytes = 0;          ///< the arrays of a TetMesh of this size (without map overheads)
};

/// Sizes of levels 0..levels from the level-0 mesh alone (its edges and faces are counted;
/// nothing finer is built). Exact, from the 1 -> 8 refinement: V' = V + E,
/// E' = 2 E + 3 F + T (each face gets three inner edges, each tetrahedron its diagonal),
/// F' = 4 F + 8 T, T' = 8 T, boundary and tagged faces times 4.
std::vector<TetLevelSize> predict_tet_level_sizes(const TetMesh& level0, int levels);

} // namespace mlc::mesh

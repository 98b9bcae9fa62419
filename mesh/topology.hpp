// SPDX-License-Identifier: MIT
/// @file Conformity checks of a triangle mesh: duplicated elements, non-manifold edges and
/// hanging nodes (T-junctions), and check_quality with triangles named by the caller.
#pragma once

#include "mesh/mesh.hpp"

#include <functional>
#include <string>

namespace mlc::mesh {

/// How a message names triangle t (e.g. its element and line in a file); empty: "triangle t".
using TriangleNamer = std::function<std::string(int)>;

/// Relative tolerance of the hanging-node check: a vertex within kHangingNodeTol times an edge's
/// length of that edge, and farther than that from both its ends, lies inside it.
inline constexpr double kHangingNodeTol = 1e-6;

/// The conformity part of check_quality, on a mesh whose indices are in range: no two triangles
/// with the same three vertices (in any order: a duplicated element), no edge shared by more
/// than two triangles (a non-manifold edge: overlapping or folded elements), and no hanging node
/// (T-junction): a vertex of a body lying inside an edge of a triangle of the same body (triangle
/// attribute) that it is not an end of, within kHangingNodeTol of the edge's length. Such a
/// vertex lies on the boundary of the triangulation and so does the edge, so only boundary edges
/// and vertices are compared, through grids of cells sized to the edges: O(n log n). Throws
/// InvalidInput naming the triangles, their vertices and the coordinates, and what to do.
/// Refinement cannot create these defects, so the levels `refine` builds are not checked again.
void check_topology(const Mesh& m, const TriangleNamer& name = {});

/// check_quality (mesh/mesh.hpp), which calls check_topology, with the triangles of its messages
/// named by `name`.
void check_quality(const Mesh& m, const TriangleNamer& name);

} // namespace mlc::mesh

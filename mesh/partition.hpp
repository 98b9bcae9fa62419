// SPDX-License-Identifier: MIT
/// @file Graph partitioning of a mesh for the distributed solve (METIS, the only place that
/// includes it): triangles or tetrahedra split into parts of balanced work, vertices owned by one
/// part each.
#pragma once

#include "mesh/mesh.hpp"
#include "mesh/tet_mesh.hpp"

#include <vector>

namespace mlc::mesh {

/// A partition of a mesh's cells (triangles, or tetrahedra from partition_tets) into `parts`
/// parts.
struct Partition {
    int parts = 1;
    std::vector<int> triangle_part; ///< part of every cell (triangle or tetrahedron), in [0, parts)
    /// Owner of every vertex: the part holding most of the cells around it, ties to the lower
    /// part number (a contact node belongs to the owner of its vertex).
    std::vector<int> vertex_owner;
    /// Interior facets (2D: edges, 3D: faces) between cells of different parts.
    int cut_edges = 0;
    std::vector<double> part_work; ///< sum of the cell weights of each part
    /// max part work / mean part work (1 is perfect balance).
    double imbalance() const;
};

/// Splits the triangles of `m` into `parts` parts of balanced weight with few cut edges: METIS
/// k-way on the dual graph (triangles adjacent through an edge), contiguous parts when the
/// mesh is connected (a mesh of several bodies has parts that may hold pieces of several bodies).
/// `weights` (one positive integer per triangle, or empty for all 1) is the work a triangle stands
/// for, e.g. on the finest level of a hierarchy refined from `m`. One part gives everything to part
/// 0 without calling METIS. The result depends only on the mesh, the weights and `parts`. Throws
/// InvalidInput for parts < 1, more parts than triangles, or a weight that is not positive.
Partition partition_triangles(const Mesh& m, int parts, const std::vector<int>& weights = {});

/// Splits the tetrahedra of `m` into `parts` parts as partition_triangles does the triangles of a
/// 2D mesh: METIS k-way on the dual graph (tetrahedra adjacent through a face), contiguous parts
/// on a connected mesh, `weights` one positive integer per tetrahedron (or empty for all 1);
/// Partition::triangle_part holds the part of every tetrahedron, cut_edges counts the cut faces,
/// vertex_owner is the part with most tetrahedra around the vertex (ties to the lower part).
/// Deterministic (the same on every process); throws InvalidInput for parts < 1, more parts than
/// tetrahedra, or a weight that is not positive.
Partition partition_tets(const TetMesh& m, int parts, const std::vector<int>& weights = {});

} // namespace mlc::mesh

// SPDX-License-Identifier: MIT
/// @file Graph partitioning of a mesh for the distributed solve (METIS, the only place that
/// includes it): triangles split into parts of balanced work, vertices owned by one part each.
#pragma once

#include "mesh/mesh.hpp"

#include <vector>

namespace mlc::mesh {

/// A partition of a mesh's triangles into `parts` parts.
struct Partition {
    int parts = 1;
    std::vector<int> triangle_part; ///< part of every triangle, in [0, parts)
    /// Owner of every vertex: the part holding most of the triangles around it, ties to the lower
    /// part number (a contact node belongs to the owner of its vertex).
    std::vector<int> vertex_owner;
    int cut_edges = 0;             ///< interior edges between triangles of different parts
    std::vector<double> part_work; ///< sum of the triangle weights of each part
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

} // namespace mlc::mesh

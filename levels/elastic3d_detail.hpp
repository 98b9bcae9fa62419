// SPDX-License-Identifier: MIT
/// @file What levels/elastic3d_levels.cpp and levels/elastic3d_sizes.cpp share: the level-0 edges
/// and the edges of line supports. Internal to mlc_levels.
#pragma once

#include "levels/elastic3d_levels.hpp"

#include <array>
#include <utility>
#include <vector>

namespace mlc::levels::detail {

/// The edges of m (mesh::tet_edges, smaller vertex first), sorted.
std::vector<std::array<int, 2>> sorted_edges(const mesh::TetMesh& m);

/// The level-0 edges of a line support (pairs of vertices, smaller first), after checking that
/// its ends are level-0 vertices and its segment runs along level-0 edges (`edges`: those of
/// sorted_edges(m0)). Throws InvalidInput otherwise.
std::vector<std::pair<int, int>> line_edges0(const mesh::TetMesh& m0,
                                             const std::vector<std::array<int, 2>>& edges,
                                             const std::array<Vec3, 2>& line);

} // namespace mlc::levels::detail

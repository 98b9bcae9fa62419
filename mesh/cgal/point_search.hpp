// SPDX-License-Identifier: MIT
/// @file Nearest-point and range queries over a fixed set of points in the plane: a CGAL Kd-tree
/// (Orthogonal_k_neighbor_search, Fuzzy_sphere), or linear scans in a build without CGAL.
#pragma once

#include "core/types.hpp"

#include <memory>
#include <vector>

namespace mlc::mesh {

/// Spatial index over a set of points, identified by their position in the input (0 .. n-1).
///
/// With CGAL (MLC_WITH_CGAL) the points go into a Kd-tree built once by the constructor; queries
/// cost O(log n) on average. Without CGAL (point_search_linear.cpp) every query scans all
/// points: O(n), fine for the contact boundaries of test meshes. The two may break ties (points
/// at exactly the same distance) differently. Holds a copy of the points: `points` need not
/// outlive it.
class PointSearch {
public:
    /// Builds the index over `points` (may be empty; then nearest() must not be called).
    explicit PointSearch(const std::vector<Vec2>& points);
    ~PointSearch();
    PointSearch(PointSearch&&) noexcept;
    PointSearch& operator=(PointSearch&&) noexcept;

    /// Number of points indexed.
    int size() const;
    /// Index of the point nearest to x (Euclidean distance). Without CGAL a tie goes to the lower
    /// index. Throws InvalidInput when the index holds no point.
    int nearest(const Vec2& x) const;
    /// Indices of the points within distance `radius` of x (boundary included), in no particular
    /// order (sort them when the order matters). Allocates the result.
    std::vector<int> within(const Vec2& x, double radius) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace mlc::mesh

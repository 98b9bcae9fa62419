// SPDX-License-Identifier: MIT
/// @file The domain mesher's shared pieces: the CGAL triangulation types, the size function, the
/// resolved segments and the boundary polylines (domain_boundary.cpp builds them, domain_mesher.cpp
/// triangulates). Internal to mlc_mesh; only mesh/cgal/ includes CGAL.
#pragma once

#include "mesh/cgal/domain_mesher.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <ostream>
#include <string>
#include <vector>

namespace mlc::mesh::domain {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_2;

/// Per-vertex data: index in the boundary point list (-1 for vertices the mesher added) and the
/// output index (-1 while unassigned or unused).
struct VertexInfo {
    int input = -1;
    int id = -1;
};

using Vb = CGAL::Triangulation_vertex_base_with_info_2<VertexInfo, K,
                                                       CGAL::Delaunay_mesh_vertex_base_2<K>>;
using Fb = CGAL::Delaunay_mesh_face_base_2<K>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
// Any crossing or touching of boundary constraints is an input error, not something to resolve.
using CDT =
    CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::No_constraint_intersection_tag>;
using VertexHandle = CDT::Vertex_handle;
using FaceHandle = CDT::Face_handle;

/// Squared sine of the smallest angle the mesher guarantees (20.7 degrees).
constexpr double shape_bound = 0.125;
/// Largest angle an arc piece may span: keeps the chord close to the circle, so that moving a
/// mesher-added vertex from the chord onto the circle cannot fold a triangle.
constexpr double max_arc_angle = std::numbers::pi / 12;
/// Guard against size fields that would need an absurd number of boundary points.
constexpr std::size_t max_boundary_points = 20'000'000;

inline Vec2 to_vec(const Point& p) {
    return {p.x(), p.y()};
}

/// h(x) of a SizeField, with the nearest focus point found by a k-d tree and a cut-off beyond
/// which h = max_size anyway (so most queries touch a handful of nodes).
class SizeFunction {
public:
    explicit SizeFunction(const SizeField& f)
        : h_max_(f.max_size), h_min_(f.min_size > 0 ? f.min_size : f.max_size), grading_(f.grading),
          pts_(f.focus) {
        cutoff2_ = std::pow((h_max_ - h_min_) / grading_, 2);
        build(0, static_cast<int>(pts_.size()), 0);
    }

    double operator()(const Vec2& x) const {
        if (pts_.empty() || h_min_ == h_max_) return h_max_;
        double best2 = cutoff2_;
        nearest(x, 0, static_cast<int>(pts_.size()), 0, best2);
        return std::min(h_max_, h_min_ + grading_ * std::sqrt(best2));
    }
    /// The largest spacing anywhere: length / max() bounds a segment's point count from below.
    double max() const { return h_max_; }

private:
    void build(int lo, int hi, int depth) {
        if (hi - lo <= 1) return;
        const int mid = (lo + hi) / 2, axis = depth % 2;
        std::nth_element(pts_.begin() + lo, pts_.begin() + mid, pts_.begin() + hi,
                         [axis](const Vec2& a, const Vec2& b) { return a[axis] < b[axis]; });
        build(lo, mid, depth + 1);
        build(mid + 1, hi, depth + 1);
    }

    void nearest(const Vec2& q, int lo, int hi, int depth, double& best2) const {
        if (lo >= hi) return;
        const int mid = (lo + hi) / 2, axis = depth % 2;
        best2 = std::min(best2, (pts_[mid] - q).squaredNorm());
        const double diff = q[axis] - pts_[mid][axis];
        if (diff < 0) {
            nearest(q, lo, mid, depth + 1, best2);
            if (diff * diff < best2) nearest(q, mid + 1, hi, depth + 1, best2);
        } else {
            nearest(q, mid + 1, hi, depth + 1, best2);
            if (diff * diff < best2) nearest(q, lo, mid, depth + 1, best2);
        }
    }

    double h_max_, h_min_, grading_, cutoff2_ = 0;
    std::vector<Vec2> pts_;
};

/// A validated segment between its snapped end points.
struct SegmentGeometry {
    int loop = 0, index = 0; // position in the input, for messages
    bool arc = false;
    Vec2 a, b;             // end points (exactly on the circle for arcs)
    Vec2 c = Vec2::Zero(); // arc center
    double r = 0;          // arc radius
    double angle0 = 0;     // arc start angle
    double sweep = 0;      // signed arc angle (> 0 counter-clockwise)
    int circle = -1;       // index into Mesh::circles
    std::string tag;

    double length() const { return arc ? r * std::abs(sweep) : (b - a).norm(); }
    Vec2 at(double t) const {
        if (!arc) return a + t * (b - a);
        const double phi = angle0 + t * sweep;
        return c + r * Vec2(std::cos(phi), std::sin(phi));
    }
    Vec2 project(const Vec2& p) const { return c + r * (p - c).normalized(); }
};

/// A closed boundary polyline: point k is joined to point k+1 (cyclically) by a chord of
/// segment seg[k].
struct LoopPoints {
    std::vector<Vec2> x;
    std::vector<int> seg;
};

inline std::string where(int loop, int index) {
    return "loop " + std::to_string(loop) + ", segment " + std::to_string(index);
}

inline std::ostream& operator<<(std::ostream& os, const Vec2& p) {
    return os << "(" << p.x() << ", " << p.y() << ")";
}

/// Signed area of the closed polygon x (> 0 counter-clockwise).
inline double signed_area(const std::vector<Vec2>& x) {
    double a = 0;
    for (std::size_t k = 0; k < x.size(); ++k) {
        const Vec2& p = x[k];
        const Vec2& q = x[(k + 1) % x.size()];
        a += p.x() * q.y() - p.y() * q.x();
    }
    return a / 2;
}

/// Validates the loops and resolves each segment's end points (shared between neighbours, so
/// consecutive segments meet in exactly one vertex). domain_boundary.cpp.
std::vector<SegmentGeometry> resolve_segments(const std::vector<std::vector<Segment>>& loops,
                                              std::vector<Circle>& circles, double& diameter);

/// Splits every segment with spacing following h (and at most max_arc_angle per arc piece).
/// domain_boundary.cpp.
std::vector<LoopPoints> discretize(const std::vector<SegmentGeometry>& segs, const SizeFunction& h,
                                   int n_loops);

} // namespace mlc::mesh::domain

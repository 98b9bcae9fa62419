// SPDX-License-Identifier: MIT
// Domain mesher: boundary split along the size field, CGAL constrained Delaunay refinement with a
// size-field criterion, and arc vertices snapped onto their circles.
#include "mesh/cgal/domain_mesher.hpp"

#include "core/check.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Spatial_sort_traits_adapter_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/hilbert_sort.h>
#include <CGAL/property_map.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numbers>
#include <ostream>
#include <queue>
#include <set>
#include <unordered_map>

namespace mlc::mesh {

Segment Segment::line(const Vec2& from, const Vec2& to, std::string tag) {
    Segment s;
    s.kind = Kind::line;
    s.from = from;
    s.to = to;
    s.tag = std::move(tag);
    return s;
}

Segment Segment::arc(const Vec2& from, const Vec2& to, const Vec2& center, bool ccw,
                     std::string tag) {
    Segment s;
    s.kind = Kind::arc;
    s.from = from;
    s.to = to;
    s.center = center;
    s.radius = (from - center).norm();
    s.ccw = ccw;
    s.tag = std::move(tag);
    return s;
}

void SizeField::validate() const {
    MLC_CHECK(std::isfinite(max_size) && max_size > 0,
              "SizeField::max_size must be positive and finite, found " << max_size);
    MLC_CHECK(std::isfinite(min_size) && min_size >= 0 && min_size <= max_size,
              "SizeField::min_size must lie in (0, max_size = "
                  << max_size << "] (0 means max_size), found " << min_size);
    MLC_CHECK(std::isfinite(grading) && grading > 0,
              "SizeField::grading must be positive and finite, found " << grading);
    for (std::size_t i = 0; i < focus.size(); ++i)
        MLC_CHECK(focus[i].allFinite(), "SizeField::focus[" << i << "] is not finite: ("
                                                            << focus[i].x() << ", " << focus[i].y()
                                                            << ")");
}

double SizeField::operator()(const Vec2& x) const {
    if (focus.empty()) return max_size;
    double d2 = std::numeric_limits<double>::infinity();
    for (const Vec2& p : focus)
        d2 = std::min(d2, (x - p).squaredNorm());
    const double h0 = min_size > 0 ? min_size : max_size;
    return std::min(max_size, h0 + grading * std::sqrt(d2));
}

std::ostream& operator<<(std::ostream& os, const SizeField& size) {
    os << "SizeField{max_size=" << size.max_size << ", min_size=" << size.min_size
       << ", grading=" << size.grading << ", focus=[";
    for (std::size_t i = 0; i < size.focus.size(); ++i)
        os << (i ? ", " : "") << "(" << size.focus[i].x() << ", " << size.focus[i].y() << ")";
    return os << "]}";
}

namespace {

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

Vec2 to_vec(const Point& p) {
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

/// CGAL meshing criteria: a triangle is bad when its longest edge exceeds h(centroid)
/// (imperatively bad) or its smallest angle is below the shape bound. Same contract as
/// CGAL::Delaunay_mesh_size_criteria_2, with the constant size bound replaced by the field.
class SizeFieldCriteria {
public:
    using Face_handle = FaceHandle;
    using Quality = CGAL::Delaunay_mesh_size_criteria_2<CDT>::Quality;

    SizeFieldCriteria(double bound, const SizeFunction& h) : bound_(bound), h_(&h) {}

    class Is_bad {
    public:
        Is_bad(double bound, const SizeFunction* h) : bound_(bound), h_(h) {}

        CGAL::Mesh_2::Face_badness operator()(const Quality q) const {
            if (q.size() > 1) return CGAL::Mesh_2::IMPERATIVELY_BAD;
            return q.sine() < bound_ ? CGAL::Mesh_2::BAD : CGAL::Mesh_2::NOT_BAD;
        }

        CGAL::Mesh_2::Face_badness operator()(const FaceHandle& fh, Quality& q) const {
            const Point& pa = fh->vertex(0)->point();
            const Point& pb = fh->vertex(1)->point();
            const Point& pc = fh->vertex(2)->point();
            const double a = CGAL::squared_distance(pb, pc);
            const double b = CGAL::squared_distance(pc, pa);
            const double c = CGAL::squared_distance(pa, pb);
            const double l1 = std::max({a, b, c});
            const double l2 = a + b + c - l1 - std::min({a, b, c});
            const Vec2 centroid((pa.x() + pb.x() + pc.x()) / 3, (pa.y() + pb.y() + pc.y()) / 3);
            const double h = (*h_)(centroid);
            q.second = l1 / (h * h);
            if (q.size() > 1) {
                q.first = 1;
                return CGAL::Mesh_2::IMPERATIVELY_BAD;
            }
            const double area2 = CGAL::area(pa, pb, pc) * 2;
            q.first = area2 * area2 / (l1 * l2);
            return q.sine() < bound_ ? CGAL::Mesh_2::BAD : CGAL::Mesh_2::NOT_BAD;
        }

    private:
        double bound_;
        const SizeFunction* h_;
    };

    Is_bad is_bad_object() const { return Is_bad(bound_, h_); }

private:
    double bound_;
    const SizeFunction* h_;
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

std::string where(int loop, int index) {
    return "loop " + std::to_string(loop) + ", segment " + std::to_string(index);
}

std::ostream& operator<<(std::ostream& os, const Vec2& p) {
    return os << "(" << p.x() << ", " << p.y() << ")";
}

/// Intersection point of two circles nearest to p (p itself snapped to circle 1 if the circles
/// do not meet near p).
Vec2 snap_to_two_circles(const Vec2& p, const SegmentGeometry& s1, const SegmentGeometry& s2) {
    const Vec2 d = s2.c - s1.c;
    const double dist = d.norm();
    const Vec2 fallback = s1.project(p);
    if (dist == 0) return fallback;
    const double along = (s1.r * s1.r - s2.r * s2.r + dist * dist) / (2 * dist);
    const double h = std::sqrt(std::max(0.0, s1.r * s1.r - along * along));
    const Vec2 m = s1.c + along / dist * d;
    const Vec2 perp(-d.y() / dist, d.x() / dist);
    const Vec2 q1 = m + h * perp, q2 = m - h * perp;
    const Vec2 q = (q1 - p).norm() < (q2 - p).norm() ? q1 : q2;
    return (q - p).norm() <= 1e-6 * std::max(s1.r, s2.r) ? q : fallback;
}

double signed_area(const std::vector<Vec2>& x) {
    double a = 0;
    for (std::size_t k = 0; k < x.size(); ++k) {
        const Vec2& p = x[k];
        const Vec2& q = x[(k + 1) % x.size()];
        a += p.x() * q.y() - p.y() * q.x();
    }
    return a / 2;
}

/// Validates the loops and resolves each segment's end points (shared between neighbours, so
/// consecutive segments meet in exactly one vertex).
std::vector<SegmentGeometry> resolve_segments(const std::vector<std::vector<Segment>>& loops,
                                              std::vector<Circle>& circles, double& diameter) {
    MLC_CHECK(!loops.empty(), "mesh_domain: no boundary loops given; loops[0] must be the outer "
                              "boundary");
    Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (std::size_t l = 0; l < loops.size(); ++l) {
        MLC_CHECK(!loops[l].empty(), "mesh_domain: loop " << l << " has no segments");
        for (std::size_t k = 0; k < loops[l].size(); ++k) {
            const Segment& s = loops[l][k];
            const std::string w = where(static_cast<int>(l), static_cast<int>(k));
            MLC_CHECK(s.from.allFinite() && s.to.allFinite(),
                      "mesh_domain: " << w << " has a non-finite end point " << s.from << " -> "
                                      << s.to);
            lo = lo.cwiseMin(s.from).cwiseMin(s.to);
            hi = hi.cwiseMax(s.from).cwiseMax(s.to);
            if (s.kind == Segment::Kind::arc) {
                MLC_CHECK(s.center.allFinite() && std::isfinite(s.radius) && s.radius > 0,
                          "mesh_domain: " << w << " is an arc with center " << s.center
                                          << " and radius " << s.radius
                                          << "; the radius must be positive and finite");
                lo = lo.cwiseMin(s.center - Vec2::Constant(s.radius));
                hi = hi.cwiseMax(s.center + Vec2::Constant(s.radius));
            }
        }
    }
    diameter = (hi - lo).norm();
    MLC_CHECK(diameter > 0, "mesh_domain: all boundary points coincide at " << lo);
    const double tol = 1e-9 * diameter;

    std::vector<SegmentGeometry> out;
    for (std::size_t l = 0; l < loops.size(); ++l) {
        const auto& loop = loops[l];
        const std::size_t n = loop.size();
        const std::size_t first = out.size();
        for (std::size_t k = 0; k < n; ++k) {
            const Segment& s = loop[k];
            const Segment& next = loop[(k + 1) % n];
            const std::string w = where(static_cast<int>(l), static_cast<int>(k));
            const double gap = (s.to - next.from).norm();
            if (k + 1 < n)
                MLC_CHECK(gap <= tol, "mesh_domain: " << w << " ends at " << s.to << " but segment "
                                                      << k + 1 << " starts at " << next.from
                                                      << " (gap " << gap << " > tolerance " << tol
                                                      << "); consecutive segments must join");
            else
                MLC_CHECK(gap <= tol, "mesh_domain: loop "
                                          << l << " does not close: its last segment " << k
                                          << " ends at " << s.to << " but segment 0 starts at "
                                          << next.from << " (gap " << gap << " > tolerance " << tol
                                          << ")");
            SegmentGeometry g;
            g.loop = static_cast<int>(l);
            g.index = static_cast<int>(k);
            g.tag = s.tag.empty() ? "boundary" : s.tag;
            if (s.kind == Segment::Kind::arc) {
                g.arc = true;
                g.c = s.center;
                g.r = s.radius;
                for (const Vec2& p : {s.from, s.to}) {
                    const double off = std::abs((p - s.center).norm() - s.radius);
                    MLC_CHECK(off <= 1e-6 * s.radius,
                              "mesh_domain: " << w << ": end point " << p
                                              << " is not on the arc's circle (center " << s.center
                                              << ", radius " << s.radius
                                              << "): its distance from the circle is " << off
                                              << " > 1e-6 * radius; compute end points as "
                                                 "center + radius * (cos, sin)");
                }
                std::size_t ci = 0;
                while (ci < circles.size() && !((circles[ci].center - g.c).norm() <= tol &&
                                                std::abs(circles[ci].radius - g.r) <= tol))
                    ++ci;
                if (ci == circles.size()) circles.push_back(Circle{g.c, g.r});
                g.circle = static_cast<int>(ci);
            }
            out.push_back(g);
        }
        // Shared end points: segment k starts where segment k-1 ends; snap onto circles.
        std::vector<Vec2> joint(n);
        for (std::size_t k = 0; k < n; ++k) {
            const SegmentGeometry& cur = out[first + k];
            const SegmentGeometry& prev = out[first + (k + n - 1) % n];
            Vec2 p = loop[k].from;
            if (cur.arc && prev.arc && n > 1)
                p = snap_to_two_circles(p, cur, prev);
            else if (cur.arc)
                p = cur.project(p);
            else if (prev.arc)
                p = prev.project(p);
            joint[k] = p;
        }
        for (std::size_t k = 0; k < n; ++k) {
            SegmentGeometry& g = out[first + k];
            const std::string w = where(static_cast<int>(l), static_cast<int>(k));
            g.a = joint[k];
            g.b = joint[(k + 1) % n];
            const bool closed = (g.b - g.a).norm() <= tol;
            if (!g.arc) {
                MLC_CHECK(!closed, "mesh_domain: " << w << " is a line of zero length at " << g.a);
                continue;
            }
            MLC_CHECK(!closed || n == 1,
                      "mesh_domain: " << w << " is an arc that starts and ends at " << g.a
                                      << " (a full circle) but its loop has " << n
                                      << " segments; a full circle must be a loop of its own");
            g.angle0 = std::atan2(g.a.y() - g.c.y(), g.a.x() - g.c.x());
            const double angle1 = std::atan2(g.b.y() - g.c.y(), g.b.x() - g.c.x());
            const double two_pi = 2 * std::numbers::pi;
            if (closed) {
                g.sweep = loop[k].ccw ? two_pi : -two_pi;
            } else if (loop[k].ccw) {
                g.sweep = angle1 - g.angle0;
                while (g.sweep <= 0)
                    g.sweep += two_pi;
            } else {
                g.sweep = angle1 - g.angle0;
                while (g.sweep >= 0)
                    g.sweep -= two_pi;
            }
        }
        MLC_CHECK(n > 1 || out[first].arc,
                  "mesh_domain: loop " << l << " is a single line segment and encloses nothing");
    }
    return out;
}

/// Splits every segment with spacing following h (and at most max_arc_angle per arc piece):
/// n = ceil(integral of ds / h) pieces, with the points placed at equal steps of that integral.
std::vector<LoopPoints> discretize(const std::vector<SegmentGeometry>& segs, const SizeFunction& h,
                                   int n_loops) {
    std::vector<LoopPoints> loops(n_loops);
    std::size_t total = 0;
    std::vector<double> ts, cum;
    for (std::size_t s = 0; s < segs.size(); ++s) {
        const SegmentGeometry& g = segs[s];
        const double length = g.length();
        const double cap = g.arc ? g.r * max_arc_angle : std::numeric_limits<double>::infinity();
        // Refuse before marching: even the coarsest spacing would need too many points.
        MLC_CHECK(static_cast<double>(total) + length / std::min(h.max(), cap) <
                      static_cast<double>(max_boundary_points),
                  "mesh_domain: " << where(g.loop, g.index) << " is " << length
                                  << " long; at the largest spacing " << std::min(h.max(), cap)
                                  << " it alone needs more than " << max_boundary_points
                                  << " boundary points; check its coordinates or max_size");
        auto density = [&](double t) { return 1.0 / std::min(h(g.at(t)), cap); };
        // March with a quarter of the local spacing, integrating the density by trapezoids.
        ts.assign(1, 0.0);
        cum.assign(1, 0.0);
        double t = 0, f0 = density(0);
        while (t < 1) {
            const double t1 = std::min(1.0, t + 0.25 / (f0 * length));
            const double f1 = density(t1);
            cum.push_back(cum.back() + 0.5 * (f0 + f1) * (t1 - t) * length);
            ts.push_back(t1);
            t = t1;
            f0 = f1;
            MLC_CHECK(total + ts.size() / 4 < max_boundary_points,
                      "mesh_domain: the size field needs more than "
                          << max_boundary_points << " boundary points (" << where(g.loop, g.index)
                          << " alone is " << length << " long); increase SizeField::min_size");
        }
        const int n = std::max(1, static_cast<int>(std::ceil(cum.back() - 1e-6)));
        LoopPoints& lp = loops[g.loop];
        lp.x.push_back(g.a);
        lp.seg.push_back(static_cast<int>(s));
        std::size_t j = 1;
        for (int i = 1; i < n; ++i) {
            const double target = cum.back() * i / n;
            while (cum[j] < target)
                ++j;
            const double lambda = (target - cum[j - 1]) / (cum[j] - cum[j - 1]);
            lp.x.push_back(g.at(ts[j - 1] + lambda * (ts[j] - ts[j - 1])));
            lp.seg.push_back(static_cast<int>(s));
        }
        total += n;
    }
    return loops;
}

/// One constrained edge of the final triangulation with the segment it lies on.
struct SubEdge {
    VertexHandle a, b;
    int seg;
};

/// The refined triangulation with the bookkeeping that maps it back to the input segments.
struct Meshed {
    CDT tr;
    std::vector<VertexHandle> vh;                 // per flattened boundary point
    std::vector<int> next, seg;                   // per flattened boundary point
    std::vector<SubEdge> sub_edges;               // in loop order
    std::vector<std::vector<VertexHandle>> added; // per chord: mesher-added vertices, in order
    std::vector<SubEdge> line_sub_edges;          // interior lines: seg indexes the lines
};

/// Follows the constrained edges from `from` to `to` (the pieces a chord was split into by the
/// mesher), calling visit(a, b) for each piece.
template <class Visit>
void walk_chord(const CDT& tr, VertexHandle from, VertexHandle to, const Vec2& from_x,
                const Vec2& to_x, Visit&& visit) {
    const Vec2 dir = (to_x - from_x).normalized();
    VertexHandle cur = from, prev;
    for (std::size_t step = 0; cur != to; ++step) {
        MLC_CHECK(step < tr.number_of_vertices(),
                  "mesh_domain: internal error: lost the chord at " << from_x.transpose());
        VertexHandle best;
        double best_cos = 0.5;
        auto ec = tr.incident_edges(cur), done = ec;
        do {
            if (!tr.is_constrained(*ec)) continue;
            const FaceHandle f = ec->first;
            VertexHandle n = f->vertex(CDT::ccw(ec->second));
            if (n == cur) n = f->vertex(CDT::cw(ec->second));
            if (n == prev || tr.is_infinite(n)) continue;
            const double c = (to_vec(n->point()) - to_vec(cur->point())).normalized().dot(dir);
            if (c > best_cos) {
                best_cos = c;
                best = n;
            }
        } while (++ec != done);
        MLC_CHECK(best != VertexHandle(), "mesh_domain: internal error: the chord at "
                                              << from_x.transpose() << " is broken");
        visit(cur, best);
        prev = cur;
        cur = best;
    }
}

/// Inserts the boundary, checks and marks the domain (nesting level 1 = inside the outer loop,
/// outside every hole), and refines it.
void refine_domain(const std::vector<LoopPoints>& loops, const std::vector<SegmentGeometry>& segs,
                   const std::vector<LoopPoints>& lines, const SizeFunction& h, Meshed& p,
                   const StopPoll& stop) {
    std::vector<Vec2> x;
    for (const LoopPoints& lp : loops) {
        const int start = static_cast<int>(x.size()), n = static_cast<int>(lp.x.size());
        for (int k = 0; k < n; ++k) {
            x.push_back(lp.x[k]);
            p.seg.push_back(lp.seg[k]);
            p.next.push_back(start + (k + 1) % n);
        }
    }
    p.vh.resize(x.size());
    FaceHandle hint;
    for (std::size_t k = 0; k < x.size(); ++k) {
        p.vh[k] = p.tr.insert(Point(x[k].x(), x[k].y()), hint);
        hint = p.vh[k]->face();
        const int other = p.vh[k]->info().input;
        if (other >= 0) {
            const SegmentGeometry& g1 = segs[p.seg[other]];
            const SegmentGeometry& g2 = segs[p.seg[k]];
            MLC_CHECK(false, "mesh_domain: boundary point "
                                 << x[k] << " of " << where(g2.loop, g2.index)
                                 << " coincides with a point of " << where(g1.loop, g1.index)
                                 << "; loops may not touch themselves or each other");
        }
        p.vh[k]->info().input = static_cast<int>(k);
    }
    for (std::size_t k = 0; k < x.size(); ++k) {
        try {
            p.tr.insert_constraint(p.vh[k], p.vh[p.next[k]]);
        } catch (const CDT::Intersection_of_constraints_exception&) {
            const SegmentGeometry& g = segs[p.seg[k]];
            MLC_CHECK(false, "mesh_domain: " << where(g.loop, g.index) << " crosses or touches "
                                             << "another part of the boundary near " << x[k]
                                             << "; loops must be simple and disjoint");
        }
    }
    MLC_CHECK(p.tr.dimension() == 2,
              "mesh_domain: the boundary points are collinear; the domain has no area");
    // The loop constraints, which alone bound the domain (interior lines are constraints too).
    std::set<std::pair<VertexHandle, VertexHandle>> loop_edge;
    for (std::size_t k = 0; k < x.size(); ++k) {
        loop_edge.emplace(p.vh[k], p.vh[p.next[k]]);
        loop_edge.emplace(p.vh[p.next[k]], p.vh[k]);
    }
    auto is_border = [&](FaceHandle f, int i) {
        return f->is_constrained(i) &&
               loop_edge.count({f->vertex(CDT::ccw(i)), f->vertex(CDT::cw(i))}) > 0;
    };
    // Interior lines: open polylines, their ends inside the domain or at a loop point.
    std::vector<std::vector<VertexHandle>> line_vh(lines.size());
    std::map<VertexHandle, int> line_of; // vertex -> line it belongs to
    for (std::size_t l = 0; l < lines.size(); ++l) {
        const auto& lp = lines[l];
        const std::string w = "line " + std::to_string(l);
        for (std::size_t k = 0; k < lp.x.size(); ++k) {
            VertexHandle v;
            try {
                v = p.tr.insert(Point(lp.x[k].x(), lp.x[k].y()));
            } catch (const CDT::Intersection_of_constraints_exception&) {
                // The point lies inside a boundary constraint (not at one of its points).
                MLC_CHECK(false, "mesh_domain: " << w << " meets the boundary or another line at "
                                                 << lp.x[k]
                                                 << " away from their points; interior lines may "
                                                    "end on the boundary only at a segment's end");
            }
            const bool end = k == 0 || k + 1 == lp.x.size();
            MLC_CHECK(v->info().input < 0 || end,
                      "mesh_domain: " << w << " passes through the boundary point "
                                      << lp.x[k].transpose()
                                      << "; interior lines may end on the boundary only at a "
                                         "segment's end");
            const auto [it, inserted] = line_of.emplace(v, static_cast<int>(l));
            MLC_CHECK(inserted || it->second == static_cast<int>(l) || end,
                      "mesh_domain: " << w << " touches line " << it->second << " at "
                                      << lp.x[k].transpose() << " away from their ends");
            line_vh[l].push_back(v);
        }
        for (std::size_t k = 0; k + 1 < lp.x.size(); ++k) {
            try {
                p.tr.insert_constraint(line_vh[l][k], line_vh[l][k + 1]);
            } catch (const CDT::Intersection_of_constraints_exception&) {
                MLC_CHECK(false, "mesh_domain: " << w << " crosses the boundary or another line "
                                                 << "near " << lp.x[k].transpose());
            }
        }
    }

    // Nesting level of each face: number of constraints crossed from the infinite face.
    std::unordered_map<FaceHandle, int> level;
    std::queue<FaceHandle> border;
    auto flood = [&](FaceHandle start, int index) {
        std::queue<FaceHandle> q;
        level[start] = index;
        q.push(start);
        while (!q.empty()) {
            FaceHandle f = q.front();
            q.pop();
            for (int i = 0; i < 3; ++i) {
                FaceHandle n = f->neighbor(i);
                if (level.count(n)) continue;
                if (is_border(f, i)) {
                    border.push(f);
                } else {
                    level[n] = index;
                    q.push(n);
                }
            }
        }
    };
    flood(p.tr.infinite_face(), 0);
    while (!border.empty()) {
        FaceHandle f = border.front();
        border.pop();
        for (int i = 0; i < 3; ++i) {
            FaceHandle n = f->neighbor(i);
            if (is_border(f, i) && !level.count(n)) flood(n, level[f] + 1);
        }
    }
    double area = 0;
    for (auto f = p.tr.all_faces_begin(); f != p.tr.all_faces_end(); ++f) {
        const int lv = level.at(f);
        MLC_CHECK(lv <= 2, "mesh_domain: a loop lies inside a hole; loops[1..] must be holes "
                           "directly inside the outer boundary loops[0]");
        f->set_in_domain(lv == 1);
        if (lv == 1) area += p.tr.triangle(f).area();
    }
    double expected = signed_area(loops[0].x);
    const SegmentGeometry& g0 = segs[loops[0].seg[0]];
    MLC_CHECK(expected > 0, "mesh_domain: the outer boundary (loop 0) is clockwise (signed area "
                                << expected << "); list its segments counter-clockwise, starting "
                                << "with " << where(g0.loop, g0.index));
    for (std::size_t l = 1; l < loops.size(); ++l)
        expected -= std::abs(signed_area(loops[l].x));
    MLC_CHECK(std::abs(area - expected) <= 1e-8 * signed_area(loops[0].x),
              "mesh_domain: the meshed area " << area << " differs from outer minus hole areas "
                                              << expected << "; every hole must lie inside loop 0");

    for (std::size_t l = 0; l < lines.size(); ++l)
        for (std::size_t k = 0; k + 1 < line_vh[l].size(); ++k) {
            FaceHandle f;
            int i = 0;
            MLC_CHECK(p.tr.is_edge(line_vh[l][k], line_vh[l][k + 1], f, i),
                      "mesh_domain: internal error: lost interior line " << l);
            const FaceHandle n = f->neighbor(i);
            MLC_CHECK(!p.tr.is_infinite(f) && !p.tr.is_infinite(n) && f->is_in_domain() &&
                          n->is_in_domain(),
                      "mesh_domain: line " << l << " leaves the domain near "
                                           << lines[l].x[k].transpose()
                                           << "; interior lines must lie inside it");
        }

    SizeFieldCriteria criteria(shape_bound, h);
    CGAL::Delaunay_mesher_2<CDT, SizeFieldCriteria> mesher(p.tr, criteria);
    mesher.init(true); // keep our domain marks
    // refine_mesh() step by step (the same insertions in the same order), so a stop request is
    // seen: a step inserts one point, a few microseconds.
    for (std::uint64_t step = 1; mesher.try_one_step_refine_mesh(); ++step)
        if (stop && step % 2048 == 0 && stop())
            throw Interrupted("meshing stopped on request after " +
                              std::to_string(p.tr.number_of_vertices()) + " vertices");

    // Walk each input chord along the constrained edges that replaced it.
    p.added.assign(x.size(), {});
    for (std::size_t k = 0; k < x.size(); ++k) {
        const VertexHandle target = p.vh[p.next[k]];
        const Vec2 dir = (x[p.next[k]] - x[k]).normalized();
        VertexHandle cur = p.vh[k], prev;
        for (std::size_t step = 0; cur != target; ++step) {
            MLC_CHECK(step < p.tr.number_of_vertices(),
                      "mesh_domain: internal error: lost the boundary chord at " << x[k]);
            VertexHandle best;
            double best_cos = 0.5;
            auto ec = p.tr.incident_edges(cur), done = ec;
            do {
                if (!p.tr.is_constrained(*ec)) continue;
                const FaceHandle f = ec->first;
                VertexHandle n = f->vertex(CDT::ccw(ec->second));
                if (n == cur) n = f->vertex(CDT::cw(ec->second));
                if (n == prev || p.tr.is_infinite(n)) continue;
                const double c = (to_vec(n->point()) - to_vec(cur->point())).normalized().dot(dir);
                if (c > best_cos) {
                    best_cos = c;
                    best = n;
                }
            } while (++ec != done);
            MLC_CHECK(best != VertexHandle(),
                      "mesh_domain: internal error: boundary chord at " << x[k] << " is broken");
            p.sub_edges.push_back({cur, best, p.seg[k]});
            if (best != target && best->info().input < 0) p.added[k].push_back(best);
            prev = cur;
            cur = best;
        }
    }
    for (std::size_t l = 0; l < lines.size(); ++l)
        for (std::size_t k = 0; k + 1 < line_vh[l].size(); ++k)
            walk_chord(p.tr, line_vh[l][k], line_vh[l][k + 1], lines[l].x[k], lines[l].x[k + 1],
                       [&](VertexHandle a, VertexHandle b) {
                           p.line_sub_edges.push_back({a, b, static_cast<int>(l)});
                       });
}

std::uint64_t edge_key(int a, int b) {
    if (a > b) std::swap(a, b);
    return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b);
}

} // namespace

MeshPrediction predict_mesh_size(const std::vector<std::vector<Segment>>& loops,
                                 const SizeField& size) {
    size.validate();
    std::vector<Circle> circles;
    double diameter = 0;
    const std::vector<SegmentGeometry> segs = resolve_segments(loops, circles, diameter);
    // Area of each loop: the polygon of its segment ends plus, for each arc, the signed area
    // between its chord and the arc (r^2 / 2 (theta - sin theta), theta the signed sweep).
    std::vector<double> loop_area(loops.size(), 0.0);
    for (const SegmentGeometry& g : segs) {
        double a = 0.5 * (g.a.x() * g.b.y() - g.b.x() * g.a.y());
        if (g.arc) a += 0.5 * g.r * g.r * (g.sweep - std::sin(g.sweep));
        loop_area[static_cast<std::size_t>(g.loop)] += a;
    }
    MeshPrediction out;
    out.area = std::abs(loop_area[0]);
    for (std::size_t l = 1; l < loop_area.size(); ++l)
        out.area -= std::abs(loop_area[l]);
    out.area = std::max(out.area, 0.0);
    const double M = size.max_size, m = size.min_size > 0 ? size.min_size : size.max_size;
    const double g = size.grading;
    double graded = out.area / (M * M);
    if (m < M && !size.focus.empty()) {
        // The loops as one polygon set (arcs in pieces of at most 2 degrees), for the even-odd
        // inside test.
        std::vector<std::vector<Vec2>> rings(loops.size());
        for (const SegmentGeometry& sg : segs) {
            auto& ring = rings[static_cast<std::size_t>(sg.loop)];
            const int pieces =
                sg.arc ? std::max(2, static_cast<int>(
                                         std::ceil(std::abs(sg.sweep) * 90 / std::numbers::pi)))
                       : 1;
            for (int k = 0; k < pieces; ++k)
                ring.push_back(sg.at(static_cast<double>(k) / pieces));
        }
        auto inside = [&](const Vec2& q) {
            bool in = false;
            for (const auto& ring : rings)
                for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
                    const Vec2 &a = ring[i], &b = ring[j];
                    if ((a.y() > q.y()) != (b.y() > q.y()) &&
                        q.x() < (b.x() - a.x()) * (q.y() - a.y()) / (b.y() - a.y()) + a.x())
                        in = !in;
                }
            return in;
        };
        // Per focus point: the integral of 1 / h^2 - 1 / M^2 over its disc r < (M - m) / g
        // (h = m + g r) within the domain, in u = m + g r on a log scale (32 midpoints), each
        // ring's share inside the domain sampled at 32 angles. At most 2048 focus points are
        // integrated; the others count as the mean of those (an even sample of them).
        constexpr int n_u = 32, n_angle = 32;
        constexpr std::size_t max_focus = 2048;
        const std::size_t stride = (size.focus.size() + max_focus - 1) / max_focus;
        double sum = 0;
        std::size_t integrated = 0;
        for (std::size_t f = 0; f < size.focus.size(); f += stride, ++integrated) {
            const Vec2& c = size.focus[f];
            const double ds = std::log(M / m) / n_u;
            for (int i = 0; i < n_u; ++i) {
                const double u = m * std::exp((i + 0.5) * ds), r = (u - m) / g;
                int in = 0;
                for (int k = 0; k < n_angle; ++k) {
                    const double phi = 2 * std::numbers::pi * (k + 0.5) / n_angle;
                    in += inside(c + r * Vec2(std::cos(phi), std::sin(phi))) ? 1 : 0;
                }
                // 2 pi r dr (1/u^2 - 1/M^2), dr = du / g = u ds / g
                sum += static_cast<double>(in) / n_angle * 2 * std::numbers::pi * r * u / g * ds *
                       (1 / (u * u) - 1 / (M * M));
            }
        }
        graded += sum * static_cast<double>(size.focus.size()) / static_cast<double>(integrated);
    }
    out.integral = std::min(out.area / (m * m), graded);
    out.triangles = kTrianglesPerUnitIntegral * out.integral;
    return out;
}

Mesh mesh_domain(const std::vector<std::vector<Segment>>& loops, const SizeField& size,
                 const std::vector<Segment>& lines, const StopPoll& stop) {
    size.validate();
    std::vector<Circle> circles;
    double diameter = 0;
    const std::vector<SegmentGeometry> segs = resolve_segments(loops, circles, diameter);
    const SizeFunction h(size);
    const std::vector<LoopPoints> points = discretize(segs, h, static_cast<int>(loops.size()));
    // Interior lines: straight, split like the loop segments; an end within the tolerance of a
    // loop segment's end is put on it (the only boundary points they may share).
    std::vector<SegmentGeometry> lgs;
    const double tol = 1e-9 * diameter;
    Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const SegmentGeometry& g : segs) {
        const Vec2 a = g.arc ? Vec2(g.c.array() - g.r) : Vec2(g.a.cwiseMin(g.b));
        const Vec2 b = g.arc ? Vec2(g.c.array() + g.r) : Vec2(g.a.cwiseMax(g.b));
        lo = lo.cwiseMin(a);
        hi = hi.cwiseMax(b);
    }
    for (std::size_t l = 0; l < lines.size(); ++l) {
        const Segment& s = lines[l];
        MLC_CHECK(s.kind == Segment::Kind::line,
                  "mesh_domain: line " << l << " is an arc; interior lines are straight");
        MLC_CHECK(s.from.allFinite() && s.to.allFinite(),
                  "mesh_domain: line " << l << " has a non-finite end point");
        for (const Vec2* e : {&s.from, &s.to})
            MLC_CHECK(((*e - lo).array() >= -tol).all() && ((hi - *e).array() >= -tol).all(),
                      "mesh_domain: line " << l << " has its end (" << e->x() << ", " << e->y()
                                           << ") outside the loops' bounding box [" << lo.x()
                                           << ", " << hi.x() << "] x [" << lo.y() << ", " << hi.y()
                                           << "]; interior lines must lie inside it");
        SegmentGeometry g;
        g.loop = static_cast<int>(l);
        g.index = 0;
        g.a = s.from;
        g.b = s.to;
        for (const SegmentGeometry& b : segs)
            for (Vec2* e : {&g.a, &g.b})
                if ((*e - b.a).norm() <= tol) *e = b.a;
        MLC_CHECK((g.b - g.a).norm() > tol,
                  "mesh_domain: line " << l << " has zero length at " << g.a.transpose());
        g.tag = s.tag.empty() ? "line" : s.tag;
        lgs.push_back(g);
    }
    std::vector<LoopPoints> line_points = discretize(lgs, h, static_cast<int>(lgs.size()));
    for (std::size_t l = 0; l < lgs.size(); ++l)
        line_points[l].x.push_back(lgs[l].b);

    Meshed result;
    refine_domain(points, segs, line_points, h, result, stop);
    // The mesher splits boundary chords where they are encroached; on an arc, move each such
    // vertex radially onto the circle. Arc pieces span at most 15 degrees, so the move is at most
    // 13% of the distance to the nearer chord end, and the triangles around it stay close to
    // the shape bound (we measured sin^2 >= 0.2 against the bound 0.125); check_quality below
    // guards against a fold anyway.
    for (std::size_t k = 0; k < result.added.size(); ++k) {
        const SegmentGeometry& g = segs[result.seg[k]];
        if (!g.arc) continue;
        for (VertexHandle v : result.added[k]) {
            const Vec2 q = g.project(to_vec(v->point()));
            v->set_point(Point(q.x(), q.y()));
        }
    }
    CDT& tr = result.tr;

    // Vertices of in-domain triangles, numbered along a Hilbert curve for memory locality.
    std::vector<VertexHandle> used;
    for (auto f = tr.finite_faces_begin(); f != tr.finite_faces_end(); ++f) {
        if (!f->is_in_domain()) continue;
        for (int i = 0; i < 3; ++i) {
            VertexHandle v = f->vertex(i);
            if (v->info().id == -1) {
                v->info().id = -2;
                used.push_back(v);
            }
        }
    }
    std::vector<Point> pts(used.size());
    std::vector<std::size_t> order(used.size());
    for (std::size_t i = 0; i < used.size(); ++i) {
        pts[i] = used[i]->point();
        order[i] = i;
    }
    using SortTraits =
        CGAL::Spatial_sort_traits_adapter_2<K, CGAL::Pointer_property_map<Point>::type>;
    CGAL::hilbert_sort(order.begin(), order.end(), SortTraits(CGAL::make_property_map(pts)));

    Mesh out;
    out.vertices.resize(used.size());
    for (std::size_t i = 0; i < order.size(); ++i) {
        used[order[i]]->info().id = static_cast<int>(i);
        out.vertices[i] = to_vec(pts[order[i]]);
    }
    for (auto f = tr.finite_faces_begin(); f != tr.finite_faces_end(); ++f)
        if (f->is_in_domain())
            out.triangles.push_back(
                {f->vertex(0)->info().id, f->vertex(1)->info().id, f->vertex(2)->info().id});
    std::sort(out.triangles.begin(), out.triangles.end(),
              [](const auto& s, const auto& t) { return s[0] + s[1] + s[2] < t[0] + t[1] + t[2]; });

    std::vector<int> tag_of(segs.size());
    for (std::size_t s = 0; s < segs.size(); ++s)
        tag_of[s] = out.add_tag(segs[s].tag);
    out.circles = std::move(circles);
    std::unordered_map<std::uint64_t, bool> seen;
    for (const SubEdge& e : result.sub_edges) {
        FaceHandle f;
        int i = 0;
        MLC_CHECK(tr.is_edge(e.a, e.b, f, i), "mesh_domain: internal error: lost boundary edge");
        FaceHandle n = f->neighbor(i);
        const bool f_in = !tr.is_infinite(f) && f->is_in_domain();
        const bool n_in = !tr.is_infinite(n) && n->is_in_domain();
        const SegmentGeometry& g = segs[e.seg];
        MLC_CHECK(f_in != n_in, "mesh_domain: " << where(g.loop, g.index) << " near "
                                                << to_vec(e.a->point())
                                                << " does not separate the domain from outside");
        if (!f_in) {
            i = n->index(f);
            f = n;
        }
        BoundaryEdge be;
        be.v0 = f->vertex(CDT::ccw(i))->info().id;
        be.v1 = f->vertex(CDT::cw(i))->info().id;
        be.tag = tag_of[e.seg];
        be.curve = g.circle;
        MLC_CHECK(!seen[edge_key(be.v0, be.v1)],
                  "mesh_domain: internal error: boundary edge listed twice");
        seen[edge_key(be.v0, be.v1)] = true;
        out.boundary.push_back(be);
    }
    for (const SubEdge& e : result.line_sub_edges)
        out.lines.push_back(
            {e.a->info().id, e.b->info().id, out.add_tag(lgs[static_cast<size_t>(e.seg)].tag), -1});
    check_quality(out);
    return out;
}

} // namespace mlc::mesh

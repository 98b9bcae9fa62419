// SPDX-License-Identifier: MIT
// The domain mesher's boundary: segments validated and their end points resolved (arcs snapped
// onto their circles), then split into points along the size field.
#include "core/check.hpp"
#include "mesh/cgal/domain_detail.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mlc::mesh::domain {

namespace {

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

} // namespace

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

} // namespace mlc::mesh::domain

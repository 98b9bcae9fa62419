// SPDX-License-Identifier: MIT
// Domain mesher: CGAL constrained Delaunay refinement with a size-field criterion of the boundary
// points (domain_boundary.cpp), and arc vertices snapped onto their circles.
#include "mesh/cgal/domain_mesher.hpp"

#include "core/check.hpp"
#include "mesh/cgal/domain_detail.hpp"
#include "mesh/edge_key.hpp"

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

using namespace domain;

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

/// Inserts the boundary points of the loops, flattened (per point of x: its segment and the next
/// point of its loop in p), and the chords between them as constraints. Returns the points.
std::vector<Vec2> insert_boundary(const std::vector<LoopPoints>& loops,
                                  const std::vector<SegmentGeometry>& segs, Meshed& p) {
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
    return x;
}

/// Interior lines: open polylines, their ends inside the domain or at a loop point, inserted as
/// constraints. Returns each line's vertices.
std::vector<std::vector<VertexHandle>> insert_lines(const std::vector<LoopPoints>& lines,
                                                    Meshed& p) {
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
    return line_vh;
}

/// Marks the faces of the domain (nesting level 1 = inside the outer loop, outside every hole),
/// the nesting level of a face being the number of loop constraints crossed from the infinite
/// face (interior lines are constraints too, but do not bound the domain), and checks its
/// orientation and area against the loops'.
void mark_domain(const std::vector<LoopPoints>& loops, const std::vector<SegmentGeometry>& segs,
                 std::size_t n_points, Meshed& p) {
    std::set<std::pair<VertexHandle, VertexHandle>> loop_edge;
    for (std::size_t k = 0; k < n_points; ++k) {
        loop_edge.emplace(p.vh[k], p.vh[p.next[k]]);
        loop_edge.emplace(p.vh[p.next[k]], p.vh[k]);
    }
    auto is_border = [&](FaceHandle f, int i) {
        return f->is_constrained(i) &&
               loop_edge.count({f->vertex(CDT::ccw(i)), f->vertex(CDT::cw(i))}) > 0;
    };
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
}

/// Every piece of an interior line has domain faces on both sides.
void check_lines_inside(const std::vector<LoopPoints>& lines,
                        const std::vector<std::vector<VertexHandle>>& line_vh, const Meshed& p) {
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
}

/// Refines the marked domain with the size-field criteria. refine_mesh() step by step (the same
/// insertions in the same order), so a stop request is seen: a step inserts one point, a few
/// microseconds.
void run_mesher(const SizeFunction& h, Meshed& p, const StopPoll& stop) {
    SizeFieldCriteria criteria(shape_bound, h);
    CGAL::Delaunay_mesher_2<CDT, SizeFieldCriteria> mesher(p.tr, criteria);
    mesher.init(true); // keep our domain marks
    for (std::uint64_t step = 1; mesher.try_one_step_refine_mesh(); ++step)
        if (stop && step % 2048 == 0 && stop())
            throw Interrupted("meshing stopped on request after " +
                              std::to_string(p.tr.number_of_vertices()) + " vertices");
}

/// Inserts the boundary, checks and marks the domain, and refines it; then walks each input
/// chord (boundary and interior lines) along the constrained edges that replaced it.
void refine_domain(const std::vector<LoopPoints>& loops, const std::vector<SegmentGeometry>& segs,
                   const std::vector<LoopPoints>& lines, const SizeFunction& h, Meshed& p,
                   const StopPoll& stop) {
    const std::vector<Vec2> x = insert_boundary(loops, segs, p);
    const std::vector<std::vector<VertexHandle>> line_vh = insert_lines(lines, p);
    mark_domain(loops, segs, x.size(), p);
    check_lines_inside(lines, line_vh, p);
    run_mesher(h, p, stop);
    p.added.assign(x.size(), {});
    for (std::size_t k = 0; k < x.size(); ++k) {
        const VertexHandle target = p.vh[p.next[k]];
        walk_chord(p.tr, p.vh[k], target, x[k], x[p.next[k]], [&](VertexHandle a, VertexHandle b) {
            p.sub_edges.push_back({a, b, p.seg[k]});
            if (b != target && b->info().input < 0) p.added[k].push_back(b);
        });
    }
    for (std::size_t l = 0; l < lines.size(); ++l)
        for (std::size_t k = 0; k + 1 < line_vh[l].size(); ++k)
            walk_chord(p.tr, line_vh[l][k], line_vh[l][k + 1], lines[l].x[k], lines[l].x[k + 1],
                       [&](VertexHandle a, VertexHandle b) {
                           p.line_sub_edges.push_back({a, b, static_cast<int>(l)});
                       });
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
            out.cells.push_back(
                {f->vertex(0)->info().id, f->vertex(1)->info().id, f->vertex(2)->info().id});
    std::sort(out.cells.begin(), out.cells.end(),
              [](const auto& s, const auto& t) { return s[0] + s[1] + s[2] < t[0] + t[1] + t[2]; });

    std::vector<int> tag_of(segs.size());
    for (std::size_t s = 0; s < segs.size(); ++s)
        tag_of[s] = out.add_tag(segs[s].tag);
    out.shapes = std::move(circles);
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
        be.shape = g.circle;
        MLC_CHECK(!seen[detail::edge_key(be.v0, be.v1)],
                  "mesh_domain: internal error: boundary edge listed twice");
        seen[detail::edge_key(be.v0, be.v1)] = true;
        out.boundary.push_back(be);
    }
    for (const SubEdge& e : result.line_sub_edges)
        out.lines.push_back(
            {e.a->info().id, e.b->info().id, out.add_tag(lgs[static_cast<size_t>(e.seg)].tag), -1});
    check_quality(out);
    return out;
}

} // namespace mlc::mesh

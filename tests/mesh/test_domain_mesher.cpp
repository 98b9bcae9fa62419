// SPDX-License-Identifier: MIT
// Tests of the CGAL domain mesher: areas, tags, arcs on their circles, size grading, bad input.
#include "core/check.hpp"
#include "mesh/cgal/domain_mesher.hpp"
#include "mesh/mesh.hpp"
#include "tests/mesh/measures.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>

using namespace mlc;
using namespace mlc::mesh;

namespace {

constexpr double pi = std::numbers::pi;

double edge_length(const Mesh& m, const BoundaryEdge& e) {
    return (m.vertices[e.v1] - m.vertices[e.v0]).norm();
}

std::map<std::string, double> boundary_length_per_tag(const Mesh& m) {
    std::map<std::string, double> len;
    for (const BoundaryEdge& e : m.boundary)
        len[m.tag_name(e.tag)] += edge_length(m, e);
    return len;
}

/// Smallest interior angle over all triangles, in degrees.
double min_angle_deg(const Mesh& m) {
    double worst = 180;
    for (const auto& t : m.cells)
        for (int i = 0; i < 3; ++i) {
            const Vec2 a = m.vertices[t[(i + 1) % 3]] - m.vertices[t[i]];
            const Vec2 b = m.vertices[t[(i + 2) % 3]] - m.vertices[t[i]];
            worst = std::min(worst, std::acos(a.normalized().dot(b.normalized())) * 180 / pi);
        }
    return worst;
}

/// Every triangle is CCW; the boundary edges are exactly the edges with one triangle, each
/// listed once, with that triangle on its left (the edge appears in the same direction in it).
void expect_consistent_boundary(const Mesh& m) {
    std::map<std::pair<int, int>, int> directed;
    for (int t = 0; t < m.n_cells(); ++t) {
        EXPECT_GT(m.signed_measure(t), 0) << "triangle " << t;
        const auto& tri = m.cells[t];
        for (int i = 0; i < 3; ++i)
            directed[{tri[i], tri[(i + 1) % 3]}]++;
    }
    std::set<std::pair<int, int>> expected;
    for (const auto& [e, count] : directed)
        if (!directed.count({e.second, e.first})) expected.insert(e);
    std::set<std::pair<int, int>> found;
    for (const BoundaryEdge& e : m.boundary) {
        EXPECT_TRUE(found.insert({e.v0, e.v1}).second) << "boundary edge listed twice";
        EXPECT_TRUE(expected.count({e.v0, e.v1}))
            << "boundary edge " << e.v0 << "->" << e.v1 << " is not a CCW triangle edge";
    }
    EXPECT_EQ(found.size(), expected.size());
}

/// Upper bound on the area between a circle and its inscribed chords: per chord of length L,
/// the circular segment has area <= (2/3) L * L^2 / (8 r) (within a few % of exact for short L).
double sagitta_area_bound(const Mesh& m, int curve) {
    double bound = 0;
    for (const BoundaryEdge& e : m.boundary)
        if (e.shape == curve) {
            const double L = edge_length(m, e);
            bound += 1.05 * L * L * L / (12 * m.shapes[curve].radius);
        }
    return bound;
}

std::vector<Segment> unit_square() {
    return {Segment::line({0, 0}, {1, 0}, "bottom"), Segment::line({1, 0}, {1, 1}, "right"),
            Segment::line({1, 1}, {0, 1}, "top"), Segment::line({0, 1}, {0, 0}, "left")};
}

/// {x >= 0, |x - (0,1)| <= 1, y <= 1}: the lower-right quarter of the unit disc about (0,1).
std::vector<Segment> quarter_disc() {
    Segment arc;
    arc.kind = Segment::Kind::arc;
    arc.from = {0, 0};
    arc.to = {1, 1};
    arc.center = {0, 1};
    arc.radius = 1;
    arc.ccw = true;
    arc.tag = "arc";
    return {arc, Segment::line({1, 1}, {0, 1}, "top"), Segment::line({0, 1}, {0, 0}, "axis")};
}

SizeField quarter_disc_size() {
    return SizeField{.max_size = 0.1, .min_size = 0.004, .focus = {Vec2(0, 0)}};
}

} // namespace

TEST(DomainMesher, UnitSquareHasExactAreaAndTaggedSides) {
    const Mesh m = mesh_domain({unit_square()}, SizeField{.max_size = 0.1});
    EXPECT_NEAR(mesh::testing::total_area(m), 1.0, 1e-13);
    ASSERT_EQ(m.tag_names.size(), 4u);
    const auto len = boundary_length_per_tag(m);
    for (const std::string name : {"bottom", "right", "top", "left"}) {
        ASSERT_TRUE(m.find_tag(name).has_value()) << name;
        EXPECT_NEAR(len.at(name), 1.0, 1e-13) << name;
    }
    // Tag ids follow the input order.
    EXPECT_EQ(m.tag("bottom"), 0);
    EXPECT_EQ(m.tag("left"), 3);
    for (const BoundaryEdge& e : m.boundary)
        EXPECT_EQ(e.shape, -1);
    EXPECT_TRUE(m.shapes.empty());
    // Uniform field: every edge at most h; the shape bound holds (all input angles are 90).
    EXPECT_LE(m.edge_length_range().second, 0.1 * (1 + 1e-12));
    EXPECT_GE(min_angle_deg(m), 20.6);
    EXPECT_GT(m.n_cells(), 200);
    EXPECT_LT(m.n_cells(), 1000);
    expect_consistent_boundary(m);
    // Boundary vertices of "bottom" lie on y = 0.
    for (int v : m.vertices_with_tag(m.tag("bottom")))
        EXPECT_EQ(m.vertices[v].y(), 0.0);
}

TEST(DomainMesher, QuarterDiscKeepsArcVerticesOnCircleAndGradesSize) {
    const SizeField size = quarter_disc_size();
    const Mesh m = mesh_domain({quarter_disc()}, size);
    expect_consistent_boundary(m);

    ASSERT_EQ(m.shapes.size(), 1u);
    EXPECT_EQ(m.shapes[0].center, Vec2(0, 1));
    EXPECT_EQ(m.shapes[0].radius, 1.0);
    const int arc = m.tag("arc");
    const auto arc_vertices = m.vertices_with_tag(arc);
    EXPECT_GT(arc_vertices.size(), 30u);
    for (int v : arc_vertices)
        EXPECT_NEAR((m.vertices[v] - Vec2(0, 1)).norm(), 1.0, 1e-12) << "vertex " << v;
    for (const BoundaryEdge& e : m.boundary)
        EXPECT_EQ(e.shape, e.tag == arc ? 0 : -1);

    // Straight sides exact, arc longer than its chords only by the polygonal error.
    const auto len = boundary_length_per_tag(m);
    EXPECT_NEAR(len.at("top"), 1.0, 1e-13);
    EXPECT_NEAR(len.at("axis"), 1.0, 1e-13);
    EXPECT_LT(len.at("arc"), pi / 2);
    EXPECT_GT(len.at("arc"), pi / 2 - 1e-3);

    // Inscribed polygon: area below pi/4 by at most the circular segments cut off.
    const double area = mesh::testing::total_area(m);
    const double bound = sagitta_area_bound(m, 0);
    EXPECT_LE(area, pi / 4 + 1e-13);
    EXPECT_GE(area, pi / 4 - bound);
    EXPECT_LT(bound, 2e-3);

    // Sizes: fine at the focus, never above ~1.5 max_size, and following h(x) everywhere.
    int n_near = 0;
    double longest = 0;
    for (const auto& t : m.cells)
        for (int i = 0; i < 3; ++i) {
            const Vec2 a = m.vertices[t[i]], b = m.vertices[t[(i + 1) % 3]];
            const Vec2 mid = (a + b) / 2;
            const double L = (b - a).norm();
            longest = std::max(longest, L);
            if (mid.norm() < 0.01) {
                ++n_near;
                EXPECT_LT(L, 2 * size.min_size) << "edge at " << mid.transpose();
            }
            EXPECT_LE(L, 1.3 * size(mid)) << "edge at " << mid.transpose();
        }
    EXPECT_GT(n_near, 10);
    EXPECT_LE(longest, 1.5 * size.max_size);
    EXPECT_GT(longest, 0.5 * size.max_size);
    EXPECT_GE(min_angle_deg(m), 20.0);
}

TEST(DomainMesher, RingHoleIsEmpty) {
    // Outer circle r = 20 as two half arcs (an arc-arc joint), hole r = 15 as one full circle.
    const Vec2 c(0, 20);
    const std::vector<Segment> outer = {Segment::arc({0, 0}, {0, 40}, c, true, "outer"),
                                        Segment::arc({0, 40}, {0, 0}, c, true, "outer")};
    const std::vector<Segment> hole = {Segment::arc({0, 5}, {0, 5}, c, false, "inner")};
    const Mesh m = mesh_domain({outer, hole}, SizeField{.max_size = 1.0});
    expect_consistent_boundary(m);

    ASSERT_EQ(m.shapes.size(), 2u);
    for (const BoundaryEdge& e : m.boundary) {
        const Circle& circle = m.shapes.at(e.shape);
        EXPECT_EQ(circle.center, c);
        EXPECT_EQ(circle.radius, m.tag_name(e.tag) == "outer" ? 20.0 : 15.0);
        for (int v : {e.v0, e.v1})
            EXPECT_NEAR((m.vertices[v] - c).norm(), circle.radius, 1e-12 * circle.radius);
    }
    for (const auto& t : m.cells) {
        const Vec2 g = (m.vertices[t[0]] + m.vertices[t[1]] + m.vertices[t[2]]) / 3;
        EXPECT_GT((g - c).norm(), 15.0 - 0.1) << "triangle in the hole at " << g.transpose();
    }
    const int outer_curve = m.boundary[0].shape;
    const double exact = pi * (20 * 20 - 15 * 15);
    const double outer_loss = sagitta_area_bound(m, outer_curve);
    const double hole_loss = sagitta_area_bound(m, 1 - outer_curve);
    EXPECT_GE(mesh::testing::total_area(m), exact - outer_loss);
    EXPECT_LE(mesh::testing::total_area(m), exact + hole_loss);
    EXPECT_LT(outer_loss + hole_loss, 1e-2 * exact);
    EXPECT_NEAR(boundary_length_per_tag(m).at("inner"), 2 * pi * 15, 0.02);
    EXPECT_NEAR(boundary_length_per_tag(m).at("outer"), 2 * pi * 20, 0.02);

    // The hole's orientation does not matter.
    const std::vector<Segment> ccw_hole = {Segment::arc({0, 5}, {0, 5}, c, true, "inner")};
    const Mesh m2 = mesh_domain({outer, ccw_hole}, SizeField{.max_size = 1.0});
    expect_consistent_boundary(m2);
    const int outer2 = m2.boundary[0].shape;
    EXPECT_GE(mesh::testing::total_area(m2), exact - sagitta_area_bound(m2, outer2));
    EXPECT_LE(mesh::testing::total_area(m2), exact + sagitta_area_bound(m2, 1 - outer2));
}

TEST(DomainMesher, ConcaveArcStaysOnCircle) {
    // Unit square whose left side bulges into the body: a clockwise arc about (-1, 0.5).
    const Vec2 c(-1, 0.5);
    const double r = std::sqrt(1.25), theta = 2 * std::atan(0.5);
    const std::vector<Segment> loop = {
        Segment::line({0, 0}, {1, 0}, "bottom"), Segment::line({1, 0}, {1, 1}, "right"),
        Segment::line({1, 1}, {0, 1}, "top"), Segment::arc({0, 1}, {0, 0}, c, false, "notch")};
    // Refined towards the arc's apex, so the mesher splits arc chords there.
    const SizeField size{.max_size = 0.08, .min_size = 0.005, .focus = {Vec2(r - 1, 0.5)}};
    const Mesh m = mesh_domain({loop}, size);
    expect_consistent_boundary(m);
    EXPECT_GE(min_angle_deg(m), 20.0);
    const auto notch = m.vertices_with_tag(m.tag("notch"));
    EXPECT_GT(notch.size(), 30u);
    for (int v : notch)
        EXPECT_NEAR((m.vertices[v] - c).norm(), r, 1e-12);
    // Chords of a concave arc cut into the circle's disc: the polygon has a little more area.
    const double exact = 1 - r * r / 2 * (theta - std::sin(theta));
    EXPECT_GE(mesh::testing::total_area(m), exact);
    EXPECT_LE(mesh::testing::total_area(m), exact + sagitta_area_bound(m, 0));
}

TEST(DomainMesher, ManyFocusPointsFollowSizeField) {
    // Refined along the top side (a contact zone), coarse elsewhere; square hole in the middle.
    SizeField size{.max_size = 0.2, .min_size = 0.01, .grading = 0.3};
    for (int i = 0; i <= 200; ++i)
        size.focus.emplace_back(i / 200.0, 1.0);
    const std::vector<Segment> hole = {Segment::line({0.4, 0.4}, {0.4, 0.6}, "hole"),
                                       Segment::line({0.4, 0.6}, {0.6, 0.6}, "hole"),
                                       Segment::line({0.6, 0.6}, {0.6, 0.4}, "hole"),
                                       Segment::line({0.6, 0.4}, {0.4, 0.4}, "hole")};
    const Mesh m = mesh_domain({unit_square(), hole}, size);
    expect_consistent_boundary(m);
    EXPECT_NEAR(mesh::testing::total_area(m), 1.0 - 0.04, 1e-13);
    EXPECT_NEAR(boundary_length_per_tag(m).at("hole"), 0.8, 1e-13);
    for (const auto& t : m.cells)
        for (int i = 0; i < 3; ++i) {
            const Vec2 a = m.vertices[t[i]], b = m.vertices[t[(i + 1) % 3]];
            EXPECT_LE((b - a).norm(), 1.3 * size((a + b) / 2));
        }
    // The top side is split at about min_size.
    const auto top = m.vertices_with_tag(m.tag("top"));
    EXPECT_GT(top.size(), 95u);
    EXPECT_LT(top.size(), 160u);
}

TEST(DomainMesher, RefinementKeepsArcVerticesOnCircle) {
    const Mesh coarse = mesh_domain({quarter_disc()}, SizeField{.max_size = 0.2});
    const Mesh fine = refine(coarse);
    const int arc = fine.tag("arc");
    const auto arc_vertices = fine.vertices_with_tag(arc);
    EXPECT_EQ(arc_vertices.size(), 2 * coarse.vertices_with_tag(coarse.tag("arc")).size() - 1);
    for (int v : arc_vertices)
        EXPECT_NEAR((fine.vertices[v] - Vec2(0, 1)).norm(), 1.0, 1e-12) << "vertex " << v;
    EXPECT_GT(mesh::testing::total_area(fine), mesh::testing::total_area(coarse));
    EXPECT_LE(mesh::testing::total_area(fine), pi / 4);
}

TEST(DomainMesher, SizeFieldFormula) {
    const SizeField f{
        .max_size = 1.0, .min_size = 0.1, .focus = {Vec2(0, 0), Vec2(10, 0)}, .grading = 0.5};
    EXPECT_DOUBLE_EQ(f(Vec2(0, 0)), 0.1);
    EXPECT_DOUBLE_EQ(f(Vec2(0, 1)), 0.6);
    EXPECT_DOUBLE_EQ(f(Vec2(9, 0)), 0.6);
    EXPECT_DOUBLE_EQ(f(Vec2(5, 0)), 1.0);
    EXPECT_DOUBLE_EQ((SizeField{.max_size = 0.3})(Vec2(4, 4)), 0.3);
    EXPECT_DOUBLE_EQ((SizeField{.max_size = 0.3, .focus = {Vec2(0, 0)}})(Vec2(0, 0)), 0.3);
    std::ostringstream os;
    os << f;
    EXPECT_NE(os.str().find("max_size=1"), std::string::npos);
    EXPECT_NE(os.str().find("(10, 0)"), std::string::npos);
}

TEST(DomainMesher, BadInputThrows) {
    const SizeField ok{.max_size = 0.1};
    // Open loop: the last side stops short of the start.
    auto open = unit_square();
    open[3].to = {0, 0.01};
    try {
        mesh_domain({open}, ok);
        ADD_FAILURE() << "open loop accepted";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("loop 0 does not close"), std::string::npos)
            << e.what();
    }
    // Gap between two segments.
    auto gap = unit_square();
    gap[1].from = {1, 0.001};
    try {
        mesh_domain({gap}, ok);
        ADD_FAILURE() << "gap accepted";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("loop 0, segment 0"), std::string::npos) << e.what();
    }
    // Arc end point off its circle.
    auto mismatch = quarter_disc();
    mismatch[0].radius = 1.01;
    EXPECT_THROW(mesh_domain({mismatch}, ok), InvalidInput);
    auto zero_radius = quarter_disc();
    zero_radius[0].radius = 0;
    EXPECT_THROW(mesh_domain({zero_radius}, ok), InvalidInput);
    // Sizes.
    EXPECT_THROW(mesh_domain({unit_square()}, SizeField{}), InvalidInput);
    EXPECT_THROW(mesh_domain({unit_square()}, SizeField{.max_size = -1}), InvalidInput);
    EXPECT_THROW(mesh_domain({unit_square()}, SizeField{.max_size = 0.1, .min_size = 0.2}),
                 InvalidInput);
    EXPECT_THROW(mesh_domain({unit_square()}, SizeField{.max_size = 0.1, .grading = 0}),
                 InvalidInput);
    EXPECT_THROW(mesh_domain({unit_square()}, SizeField{.max_size = NAN}), InvalidInput);
    // Geometry.
    EXPECT_THROW(mesh_domain({}, ok), InvalidInput);
    EXPECT_THROW(mesh_domain({{}}, ok), InvalidInput);
    auto clockwise = unit_square();
    std::reverse(clockwise.begin(), clockwise.end());
    for (Segment& s : clockwise)
        std::swap(s.from, s.to);
    EXPECT_THROW(mesh_domain({clockwise}, ok), InvalidInput);
    const std::vector<Segment> bow_tie = {
        Segment::line({0, 0}, {1, 1}, "a"), Segment::line({1, 1}, {1, 0}, "b"),
        Segment::line({1, 0}, {0, 1}, "c"), Segment::line({0, 1}, {0, 0}, "d")};
    EXPECT_THROW(mesh_domain({bow_tie}, ok), InvalidInput);
    const std::vector<Segment> outside_hole = {Segment::line({2, 0}, {3, 0}, "h"),
                                               Segment::line({3, 0}, {3, 1}, "h"),
                                               Segment::line({3, 1}, {2, 0}, "h")};
    EXPECT_THROW(mesh_domain({unit_square(), outside_hole}, ok), InvalidInput);
    const std::vector<Segment> crossing_hole = {Segment::line({0.5, 0.5}, {1.5, 0.5}, "h"),
                                                Segment::line({1.5, 0.5}, {1.5, 0.7}, "h"),
                                                Segment::line({1.5, 0.7}, {0.5, 0.5}, "h")};
    EXPECT_THROW(mesh_domain({unit_square(), crossing_hole}, ok), InvalidInput);
    const std::vector<Segment> full_circle_in_loop = {
        Segment::arc({1, 0}, {1, 0}, {0, 0}, true, "c"),
        Segment::arc({1, 0}, {1, 0}, {0, 0}, true, "c")};
    EXPECT_THROW(mesh_domain({full_circle_in_loop}, ok), InvalidInput);
    EXPECT_THROW(mesh_domain({{Segment::line({0, 0}, {1, 0}, "l")}}, ok), InvalidInput);
}

// A line inside the loops' bounding box that leaves an L-shaped domain through its re-entrant
// side is refused when its constraint meets the boundary.
TEST(DomainMesher, ALineCrossingTheBoundaryOfAConcaveDomainIsRefused) {
    const std::vector<Segment> ell = {
        Segment::line({0, 0}, {1, 0}, "b"),       Segment::line({1, 0}, {1, 0.5}, "r"),
        Segment::line({1, 0.5}, {0.5, 0.5}, "i"), Segment::line({0.5, 0.5}, {0.5, 1}, "j"),
        Segment::line({0.5, 1}, {0, 1}, "t"),     Segment::line({0, 1}, {0, 0}, "l")};
    try {
        mesh_domain({ell}, SizeField{.max_size = 0.1},
                    {Segment::line({0.25, 0.75}, {0.75, 0.75}, "rib")});
        ADD_FAILURE() << "line leaving the domain accepted";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("line 0 crosses the boundary or another line"),
                  std::string::npos)
            << e.what();
    }
}

// A fuzzer found a scene whose interior line ran to y = 8.9e100: marching it at max_size would
// have pushed 80 million points before the size guard. Both are refused before any marching.
TEST(DomainMesher, HugeSegmentsAndFarLinesAreRefusedAtOnce) {
    const SizeField ok{.max_size = 0.25};
    try {
        mesh_domain({unit_square()}, ok, {Segment::line({0.5, 0.5}, {0.5, 8.9e100}, "rib")});
        ADD_FAILURE() << "line leaving the domain accepted";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("line 0 has its end (0.5, 8.9e+100) outside the "
                                             "loops' bounding box [0, 1] x [0, 1]"),
                  std::string::npos)
            << e.what();
    }
    // An end inside a boundary segment (not at one of its ends): CGAL refuses to split the
    // constraint, and the mesher says so (a fuzzer found it ending in std::terminate).
    try {
        mesh_domain({unit_square()}, ok, {Segment::line({0, 0.4}, {0.6, 0.5}, "rib")});
        ADD_FAILURE() << "line ending inside a boundary segment accepted";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("line 0 meets the boundary or another line at"),
                  std::string::npos)
            << e.what();
    }
    // An end on the box (a loop corner) is accepted: the tolerance keeps it.
    EXPECT_NO_THROW(mesh_domain({unit_square()}, ok, {Segment::line({0, 0}, {0.5, 0.5}, "d")}));
    // A loop so long that even max_size needs more than 20 million points.
    const double big = 1e7;
    const std::vector<Segment> huge = {
        Segment::line({0, 0}, {big, 0}, "a"), Segment::line({big, 0}, {big, big}, "b"),
        Segment::line({big, big}, {0, big}, "c"), Segment::line({0, big}, {0, 0}, "d")};
    try {
        mesh_domain({huge}, ok);
        ADD_FAILURE() << "huge loop accepted";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("loop 0, segment 0 is 1e+07 long; at the largest "
                                             "spacing 0.25 it alone needs more than 20000000"),
                  std::string::npos)
            << e.what();
    }
}

TEST(DomainMesherSlow, LargeMeshIsValid) {
    const Mesh m = mesh_domain({quarter_disc()}, SizeField{.max_size = 0.004});
    EXPECT_GT(m.n_cells(), 100000);
    expect_consistent_boundary(m);
    for (int v : m.vertices_with_tag(m.tag("arc")))
        EXPECT_NEAR((m.vertices[v] - Vec2(0, 1)).norm(), 1.0, 1e-12);
    EXPECT_NEAR(mesh::testing::total_area(m), pi / 4, sagitta_area_bound(m, 0));
}

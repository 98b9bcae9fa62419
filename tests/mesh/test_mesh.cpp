// SPDX-License-Identifier: MIT
// Structured meshes, refinement and quality checks.
#include "core/check.hpp"
#include "mesh/mesh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

using namespace mlc;

TEST(StructuredRectangle, SquareLadderCounts) {
    const auto m = mesh::structured_rectangle(Vec2(0, 0), Vec2(40, 40), 16, 16);
    EXPECT_EQ(m.n_vertices(), 17 * 17);
    EXPECT_EQ(m.n_cells(), 512);
    EXPECT_EQ(m.vertices_with_tag(m.tag("bottom")).size(), 17u);
    double area = 0;
    for (int t = 0; t < m.n_cells(); ++t)
        area += m.signed_measure(t);
    EXPECT_NEAR(area, 1600.0, 1e-10);
    EXPECT_NO_THROW(mesh::check_quality(m));
}

TEST(Refine, SplitsEveryTriangleInFourAndKeepsCoarseVertices) {
    const auto c = mesh::structured_rectangle(Vec2(0, 0), Vec2(40, 40), 16, 16);
    auto f = c;
    for (int l = 1; l <= 3; ++l) {
        const auto g = mesh::refine(f);
        EXPECT_EQ(g.n_cells(), 4 * f.n_cells());
        EXPECT_EQ(g.n_coarse_vertices, f.n_vertices());
        for (int v = 0; v < f.n_vertices(); ++v)
            EXPECT_EQ(g.vertices[static_cast<size_t>(v)], f.vertices[static_cast<size_t>(v)]);
        for (size_t k = 0; k < g.parents.size(); ++k) {
            const auto [a, b] = g.parents[k];
            const Vec2 mid =
                0.5 * (f.vertices[static_cast<size_t>(a)] + f.vertices[static_cast<size_t>(b)]);
            EXPECT_LT((g.vertices[f.vertices.size() + k] - mid).norm(), 1e-13);
        }
        EXPECT_NO_THROW(mesh::check_quality(g));
        f = g;
    }
    // Level 3 of the square ladder: (16*8+1)^2 vertices, 128 bottom edges.
    EXPECT_EQ(f.n_vertices(), 129 * 129);
    EXPECT_EQ(f.vertices_with_tag(f.tag("bottom")).size(), 129u);
}

TEST(Refine, MovesArcMidpointsOntoTheCircle) {
    // A square whose bottom edge is declared to lie on a circle of radius 5 centred above.
    auto m = mesh::structured_rectangle(Vec2(-1, 0), Vec2(2, 1), 2, 1);
    m.shapes.push_back({Vec2(0, 5), 5.0});
    for (auto& e : m.boundary)
        if (e.tag == m.tag("bottom")) e.shape = 0;
    const auto f = mesh::refine(m);
    for (const auto& e : f.boundary) {
        if (e.shape == 0 && e.v0 >= m.n_vertices()) {
            EXPECT_NEAR((f.vertices[static_cast<size_t>(e.v0)] - Vec2(0, 5)).norm(), 5.0, 1e-14);
        }
    }
}

TEST(CheckQuality, RejectsDegenerateInvertedAndDuplicate) {
    auto m = mesh::structured_rectangle(Vec2(0, 0), Vec2(1, 1), 2, 2);
    auto inverted = m;
    std::swap(inverted.cells[3][1], inverted.cells[3][2]);
    EXPECT_THROW(mesh::check_quality(inverted), InvalidInput);
    auto degenerate = m;
    degenerate.vertices[4] = Vec2(0.25, 0.0); // collinear with vertices 0 and 1
    EXPECT_THROW(mesh::check_quality(degenerate), InvalidInput);
    auto dup = m;
    dup.vertices.push_back(dup.vertices[2]);
    dup.cells.push_back({0, 1, static_cast<int>(dup.vertices.size() - 1)});
    EXPECT_THROW(mesh::check_quality(dup), InvalidInput);
    auto bad_index = m;
    bad_index.cells[0][0] = 99;
    EXPECT_THROW(mesh::check_quality(bad_index), InvalidInput);
}

TEST(CheckQuality, RefinedMeshesHaveTheirAreasChecked) {
    const auto m = mesh::refine(mesh::structured_rectangle(Vec2(0, 0), Vec2(1, 1), 2, 2));
    EXPECT_NO_THROW(mesh::check_refined_quality(m));
    auto inverted = m;
    std::swap(inverted.cells[5][1], inverted.cells[5][2]);
    EXPECT_THROW(mesh::check_refined_quality(inverted), InvalidInput);
    auto bad_index = m;
    bad_index.cells[0][2] = -1;
    EXPECT_THROW(mesh::check_refined_quality(bad_index), InvalidInput);
}

TEST(HilbertOrder, IsAPermutationThatKeepsMeshNeighboursClose) {
    // 64 x 64 squares: in index (row-major) order a vertex is 65 positions away from its upper
    // neighbour, so only the horizontal third of the mesh edges (the others are vertical and
    // diagonal) join vertices within 8 positions.
    const int nx = 64;
    const auto m = mesh::structured_rectangle(Vec2(0, 0), Vec2(2, 1), nx, nx);
    const auto order = mesh::hilbert_order(m.vertices);
    ASSERT_EQ(order.size(), m.vertices.size());
    std::vector<int> pos(order.size(), -1);
    for (size_t i = 0; i < order.size(); ++i) {
        ASSERT_GE(order[i], 0);
        ASSERT_LT(order[i], m.n_vertices());
        ASSERT_EQ(pos[static_cast<size_t>(order[i])], -1) << "vertex listed twice";
        pos[static_cast<size_t>(order[i])] = static_cast<int>(i);
    }
    auto close_fraction = [&](const std::vector<int>& position) {
        int close = 0, edges = 0;
        for (const auto& t : m.cells)
            for (int k = 0; k < 3; ++k) {
                const int a = t[static_cast<size_t>(k)], b = t[static_cast<size_t>((k + 1) % 3)];
                ++edges;
                close += std::abs(position[static_cast<size_t>(a)] -
                                  position[static_cast<size_t>(b)]) <= 8;
            }
        return static_cast<double>(close) / edges;
    };
    std::vector<int> identity(order.size());
    for (size_t i = 0; i < identity.size(); ++i)
        identity[i] = static_cast<int>(i);
    // Measured: 1/3 in index order (the horizontal edges), 0.70 along the Hilbert curve.
    EXPECT_LT(close_fraction(identity), 0.34);
    EXPECT_GT(close_fraction(pos), 0.65);
    // Degenerate inputs: one point, and all points equal (ties keep index order).
    EXPECT_EQ(mesh::hilbert_order({Vec2(1, 2)}), std::vector<int>{0});
    EXPECT_EQ(mesh::hilbert_order({Vec2(1, 2), Vec2(1, 2), Vec2(1, 2)}),
              (std::vector<int>{0, 1, 2}));
}

namespace {

// f with its vertices renumbered by a fixed shuffle and each triangle's vertices rotated: the
// same mesh in another file's order.
mesh::Mesh shuffled(const mesh::Mesh& f) {
    const int n = f.n_vertices();
    std::vector<int> to(static_cast<size_t>(n));
    for (int v = 0; v < n; ++v)
        to[static_cast<size_t>(v)] = static_cast<int>((static_cast<long>(v) * 7919 + 13) % n);
    mesh::Mesh g = f;
    g.parents.clear();
    g.n_coarse_vertices = 0;
    for (int v = 0; v < n; ++v)
        g.vertices[static_cast<size_t>(to[static_cast<size_t>(v)])] =
            f.vertices[static_cast<size_t>(v)];
    for (size_t t = 0; t < g.cells.size(); ++t) {
        const auto& a = f.cells[t];
        const size_t r = t % 3;
        for (size_t i = 0; i < 3; ++i)
            g.cells[t][i] = to[static_cast<size_t>(a[(i + r) % 3])];
    }
    for (auto* edges : {&g.boundary, &g.lines})
        for (auto& e : *edges) {
            e.v0 = to[static_cast<size_t>(e.v0)];
            e.v1 = to[static_cast<size_t>(e.v1)];
        }
    return g;
}

// The largest distance between the i-th vertices of a and b sorted by coordinates (infinite when
// their numbers differ): 0 for the same vertex set in any numbering.
double vertex_set_distance(const mesh::Mesh& a, const mesh::Mesh& b) {
    if (a.n_vertices() != b.n_vertices()) return std::numeric_limits<double>::infinity();
    auto key = [](const Vec2& p) { return std::make_pair(p.x(), p.y()); };
    std::vector<std::pair<double, double>> pa, pb;
    for (const Vec2& p : a.vertices)
        pa.push_back(key(p));
    for (const Vec2& p : b.vertices)
        pb.push_back(key(p));
    std::sort(pa.begin(), pa.end());
    std::sort(pb.begin(), pb.end());
    double d = 0.0;
    for (size_t i = 0; i < pa.size(); ++i)
        d = std::max(d, std::hypot(pa[i].first - pb[i].first, pa[i].second - pb[i].second));
    return d;
}

} // namespace

TEST(Unrefine, RecoversEveryCoarserMeshOfARefinementInAnyNumbering) {
    // 3 x 2 squares with alternating diagonals (12 triangles): itself no refinement of ours.
    auto c = mesh::structured_rectangle(Vec2(0, 0), Vec2(3, 2), 3, 2, mesh::Diagonal::alternate);
    c.attribute.assign(c.cells.size(), 0);
    c.attribute[5] = 1; // a second body id must survive
    ASSERT_FALSE(mesh::unrefine(c, 1e-12).has_value());
    const auto f2 = shuffled(mesh::refine(mesh::refine(c)));
    const auto f1 = mesh::unrefine(f2, 1e-12);
    ASSERT_TRUE(f1.has_value());
    EXPECT_EQ(f1->n_cells(), 48);
    EXPECT_EQ(f1->n_vertices(), mesh::refine(c).n_vertices());
    EXPECT_NO_THROW(mesh::check_quality(*f1));
    const auto c0 = mesh::unrefine(*f1, 1e-12);
    ASSERT_TRUE(c0.has_value());
    EXPECT_FALSE(mesh::unrefine(*c0, 1e-12).has_value());
    EXPECT_EQ(c0->n_cells(), 12);
    EXPECT_EQ(vertex_set_distance(*c0, c), 0.0);
    // Refining the recovered mesh gives the file's mesh back: vertices, boundary with its tags,
    // and the body ids (one coarse triangle of body 1, four children of it per level).
    const auto r = mesh::refine(mesh::refine(*c0));
    EXPECT_EQ(vertex_set_distance(r, f2), 0.0);
    EXPECT_EQ(r.boundary.size(), f2.boundary.size());
    for (const char* tag : {"bottom", "right", "top", "left"})
        EXPECT_EQ(r.vertices_with_tag(r.tag(tag)).size(), f2.vertices_with_tag(f2.tag(tag)).size())
            << tag;
    EXPECT_EQ(std::count(c0->attribute.begin(), c0->attribute.end(), 1), 1);
    EXPECT_EQ(std::count(f1->attribute.begin(), f1->attribute.end(), 1), 4);
}

TEST(Unrefine, KeepsArcsAndPutsTheirMidpointsBackOnTheCircle) {
    auto m = mesh::structured_rectangle(Vec2(-1, 0), Vec2(2, 1), 2, 1);
    m.shapes.push_back({Vec2(0, 5), 5.0});
    for (auto& e : m.boundary)
        if (e.tag == m.tag("bottom")) e.shape = 0;
    const auto f = mesh::refine(mesh::refine(m));
    const auto c = mesh::unrefine(mesh::unrefine(f, 1e-12).value(), 1e-12);
    ASSERT_TRUE(c.has_value());
    EXPECT_EQ(vertex_set_distance(*c, m), 0.0);
    int on_arc = 0;
    for (const auto& e : c->boundary)
        on_arc += e.shape == 0;
    EXPECT_EQ(on_arc, 2);
}

TEST(Unrefine, RefusesAMeshThatIsNoUniformRefinement) {
    const auto c =
        mesh::structured_rectangle(Vec2(0, 0), Vec2(3, 2), 3, 2, mesh::Diagonal::alternate);
    const auto f = mesh::refine(c);
    ASSERT_TRUE(mesh::unrefine(f, 1e-12).has_value());
    // A midpoint moved by 1e-6: the refinement of the recovered mesh misses it.
    auto moved = f;
    moved.vertices[static_cast<size_t>(c.n_vertices() + 3)] += Vec2(1e-6, 0.0);
    EXPECT_FALSE(mesh::unrefine(moved, 1e-10).has_value());
    EXPECT_TRUE(mesh::unrefine(moved, 1e-5).has_value()); // within a looser tolerance it is one
    // One diagonal flipped: the topology is no 1->4 split any more.
    auto flipped = f;
    bool done = false;
    for (size_t t = 0; t < flipped.cells.size() && !done; ++t)
        for (size_t u = t + 1; u < flipped.cells.size() && !done; ++u) {
            auto& A = flipped.cells[t];
            auto& B = flipped.cells[u];
            // shared edge (A[1], A[2]) = (B[2], B[1]): flip to (A[0], B[0])
            for (int i = 0; i < 3 && !done; ++i) {
                const int a0 = A[i], a1 = A[(i + 1) % 3], a2 = A[(i + 2) % 3];
                for (int j = 0; j < 3 && !done; ++j)
                    if (B[(j + 1) % 3] == a2 && B[(j + 2) % 3] == a1) {
                        const int b0 = B[j];
                        A = {a0, a1, b0};
                        B = {b0, a2, a0};
                        done = true;
                    }
            }
        }
    ASSERT_TRUE(done);
    EXPECT_FALSE(mesh::unrefine(flipped, 1e-12).has_value());
    // Triangle counts that are no multiple of 4.
    auto fewer = f;
    fewer.cells.pop_back();
    EXPECT_FALSE(mesh::unrefine(fewer, 1e-12).has_value());
}

TEST(Unrefine, JoinsInteriorLineHalvesAndRefusesHalvesWithDifferentTags) {
    // A tagged interior line along y = 1 of a 2 x 2 rectangle (4 x 4 squares after one
    // refinement): its two fine halves per coarse edge are joined back.
    auto c = mesh::structured_rectangle(Vec2(0, 0), Vec2(2, 2), 2, 2);
    const int mid = c.add_tag("middle");
    c.lines.push_back({3, 4, mid, -1}); // (0,1)-(1,1)
    c.lines.push_back({4, 5, mid, -1}); // (1,1)-(2,1)
    const auto f = mesh::refine(c);
    const auto back = mesh::unrefine(f, 1e-12);
    ASSERT_TRUE(back.has_value());
    ASSERT_EQ(back->lines.size(), 2u);
    for (const auto& e : back->lines) {
        EXPECT_EQ(e.tag, mid);
        EXPECT_EQ(back->vertices[static_cast<size_t>(e.v0)].y(), 1.0);
        EXPECT_EQ(back->vertices[static_cast<size_t>(e.v1)].y(), 1.0);
    }
    // One half of the line under another tag: no coarse edge carries both.
    auto retagged = f;
    retagged.lines[0].tag = retagged.add_tag("other");
    EXPECT_FALSE(mesh::unrefine(retagged, 1e-12).has_value());
    // The same for a boundary half, and for a child of another body.
    auto boundary = f;
    boundary.boundary[0].tag = boundary.tag("top");
    EXPECT_FALSE(mesh::unrefine(boundary, 1e-12).has_value());
    auto bodies = f;
    bodies.attribute.assign(bodies.cells.size(), 0);
    bodies.attribute[0] = 1;
    EXPECT_FALSE(mesh::unrefine(bodies, 1e-12).has_value());
}

TEST(Unrefine, ReturnsNothingWhereRefiningTheAncestorWouldThrow) {
    // Four triangles whose outer edges (a, m), (m, b) lie on the unit circle: the ancestor's
    // chord (a, b) passes through the centre, which refine refuses (an arc midpoint at its
    // centre). unrefine says "no refinement" instead of throwing.
    mesh::Mesh f;
    f.vertices = {Vec2(-1, 0),    Vec2(0, -1), Vec2(1, 0),
                  Vec2(0.5, 0.5), Vec2(0, 1),  Vec2(-0.5, 0.5)};
    // a = 0, m = 1, b = 2, bc = 3, c = 4, ca = 5
    f.cells = {{0, 1, 5}, {1, 2, 3}, {5, 3, 4}, {1, 3, 5}};
    f.shapes.push_back({Vec2(0, 0), 1.0});
    const int arc = f.add_tag("arc"), rest = f.add_tag("rest");
    f.boundary = {{0, 1, arc, 0},   {1, 2, arc, 0},   {2, 3, rest, -1},
                  {3, 4, rest, -1}, {4, 5, rest, -1}, {5, 0, rest, -1}};
    EXPECT_NO_THROW(mesh::check_quality(f));
    EXPECT_NO_THROW(EXPECT_FALSE(mesh::unrefine(f, 1e-12).has_value()));
    // Without the arc, m = (0, -1) is no midpoint of its chord: refused. At the chord's
    // midpoint (0, 0) it is an ordinary refinement of one triangle.
    for (auto& e : f.boundary)
        e.shape = -1;
    EXPECT_FALSE(mesh::unrefine(f, 1e-12).has_value());
    f.vertices[1] = Vec2(0, 0);
    const auto c = mesh::unrefine(f, 1e-12);
    ASSERT_TRUE(c.has_value());
    EXPECT_EQ(c->n_cells(), 1);
}

TEST(CheckQuality, FindsDuplicatesInEveryNeighbouringCellOfItsGrid) {
    // check_quality puts the vertices in cells of side h = 1e-9 diameter (origin: the lowest
    // corner) and compares each vertex with its own cell and the neighbouring ones. Two vertices
    // 3e-3 h apart (the tolerance is 0.1 h) placed across a cell corner or side, in each of the
    // eight directions: each pair is found, whichever cell comes first.
    auto mesh_with = [](Vec2 a, Vec2 b) {
        mesh::Mesh m;
        m.vertices = {Vec2(0, 0), Vec2(1, 0), a, b, Vec2(1, 1), Vec2(0, 1)};
        m.cells = {{0, 1, 2}, {3, 4, 5}}; // a and b in different triangles
        return m;
    };
    const mesh::Mesh probe = mesh_with(Vec2(0.5, 0.5), Vec2(0.5, 0.5));
    const double h = 1e-9 * probe.diameter();
    const double k = std::round(0.5 / h) * h; // a cell corner at (k, k)
    const double d = 1e-3 * h;
    int found = 0;
    for (int sx = -1; sx <= 1; ++sx)
        for (int sy = -1; sy <= 1; ++sy) {
            if (sx == 0 && sy == 0) continue;
            const Vec2 a(k - sx * d, k - sy * d), b(k + sx * d, k + sy * d);
            try {
                mesh::check_quality(mesh_with(a, b));
            } catch (const InvalidInput& e) {
                found +=
                    std::string(e.what()).find("duplicate vertices 2 and 3") != std::string::npos;
            }
        }
    EXPECT_EQ(found, 8);
}

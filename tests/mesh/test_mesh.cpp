// SPDX-License-Identifier: MIT
// Structured meshes, refinement and quality checks.
#include "core/check.hpp"
#include "mesh/mesh.hpp"

#include <gtest/gtest.h>

using namespace mlc;

TEST(StructuredRectangle, SquareLadderCounts) {
    const auto m = mesh::structured_rectangle(Vec2(0, 0), Vec2(40, 40), 16, 16);
    EXPECT_EQ(m.n_vertices(), 17 * 17);
    EXPECT_EQ(m.n_triangles(), 512);
    EXPECT_EQ(m.vertices_with_tag(m.tag("bottom")).size(), 17u);
    double area = 0;
    for (int t = 0; t < m.n_triangles(); ++t)
        area += m.signed_area(t);
    EXPECT_NEAR(area, 1600.0, 1e-10);
    EXPECT_NO_THROW(mesh::check_quality(m));
}

TEST(Refine, SplitsEveryTriangleInFourAndKeepsCoarseVertices) {
    const auto c = mesh::structured_rectangle(Vec2(0, 0), Vec2(40, 40), 16, 16);
    auto f = c;
    for (int l = 1; l <= 3; ++l) {
        const auto g = mesh::refine(f);
        EXPECT_EQ(g.n_triangles(), 4 * f.n_triangles());
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
    m.circles.push_back({Vec2(0, 5), 5.0});
    for (auto& e : m.boundary)
        if (e.tag == m.tag("bottom")) e.curve = 0;
    const auto f = mesh::refine(m);
    for (const auto& e : f.boundary) {
        if (e.curve == 0 && e.v0 >= m.n_vertices()) {
            EXPECT_NEAR((f.vertices[static_cast<size_t>(e.v0)] - Vec2(0, 5)).norm(), 5.0, 1e-14);
        }
    }
}

TEST(CheckQuality, RejectsDegenerateInvertedAndDuplicate) {
    auto m = mesh::structured_rectangle(Vec2(0, 0), Vec2(1, 1), 2, 2);
    auto inverted = m;
    std::swap(inverted.triangles[3][1], inverted.triangles[3][2]);
    EXPECT_THROW(mesh::check_quality(inverted), InvalidInput);
    auto degenerate = m;
    degenerate.vertices[4] = Vec2(0.25, 0.0); // collinear with vertices 0 and 1
    EXPECT_THROW(mesh::check_quality(degenerate), InvalidInput);
    auto dup = m;
    dup.vertices.push_back(dup.vertices[2]);
    dup.triangles.push_back({0, 1, static_cast<int>(dup.vertices.size() - 1)});
    EXPECT_THROW(mesh::check_quality(dup), InvalidInput);
    auto bad_index = m;
    bad_index.triangles[0][0] = 99;
    EXPECT_THROW(mesh::check_quality(bad_index), InvalidInput);
}

TEST(CheckQuality, RefinedMeshesHaveTheirAreasChecked) {
    const auto m = mesh::refine(mesh::structured_rectangle(Vec2(0, 0), Vec2(1, 1), 2, 2));
    EXPECT_NO_THROW(mesh::check_refined_quality(m));
    auto inverted = m;
    std::swap(inverted.triangles[5][1], inverted.triangles[5][2]);
    EXPECT_THROW(mesh::check_refined_quality(inverted), InvalidInput);
    auto bad_index = m;
    bad_index.triangles[0][2] = -1;
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
        for (const auto& t : m.triangles)
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

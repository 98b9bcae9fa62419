// SPDX-License-Identifier: MIT
// mesh::partition_triangles (METIS): balanced, connected parts with few cut edges, one owner per
// vertex, weights respected, reproducible; bad arguments refused.
#include "core/check.hpp"
#include "mesh/partition.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <set>

using namespace mlc;

namespace {

// Number of connected pieces of part p (triangles joined through shared edges).
int pieces(const mesh::Mesh& m, const mesh::Partition& P, int p) {
    std::map<std::pair<int, int>, std::vector<int>> by_edge;
    for (int t = 0; t < m.n_cells(); ++t)
        for (int k = 0; k < 3; ++k) {
            const auto& tri = m.cells[static_cast<size_t>(t)];
            by_edge[std::minmax(tri[k], tri[(k + 1) % 3])].push_back(t);
        }
    std::vector<int> seen(static_cast<size_t>(m.n_cells()), 0);
    int n = 0;
    for (int t0 = 0; t0 < m.n_cells(); ++t0) {
        if (P.triangle_part[static_cast<size_t>(t0)] != p || seen[static_cast<size_t>(t0)])
            continue;
        ++n;
        std::vector<int> stack{t0};
        seen[static_cast<size_t>(t0)] = 1;
        while (!stack.empty()) {
            const int t = stack.back();
            stack.pop_back();
            const auto& tri = m.cells[static_cast<size_t>(t)];
            for (int k = 0; k < 3; ++k)
                for (int u : by_edge[std::minmax(tri[k], tri[(k + 1) % 3])])
                    if (P.triangle_part[static_cast<size_t>(u)] == p &&
                        !seen[static_cast<size_t>(u)]) {
                        seen[static_cast<size_t>(u)] = 1;
                        stack.push_back(u);
                    }
        }
    }
    return n;
}

} // namespace

TEST(Partition, BalancedConnectedPartsWithFewCutEdges) {
    // The square's level-0 mesh refined twice: 16 x 16 squares -> 8192 triangles.
    const auto m =
        mesh::refine(mesh::refine(mesh::structured_rectangle(Vec2(0, 0), Vec2(40, 40), 16, 16)));
    for (int parts : {2, 3, 4, 7}) {
        SCOPED_TRACE(parts);
        const auto P = mesh::partition_triangles(m, parts);
        ASSERT_EQ(P.triangle_part.size(), static_cast<size_t>(m.n_cells()));
        std::vector<int> count(static_cast<size_t>(parts), 0);
        for (int p : P.triangle_part) {
            ASSERT_GE(p, 0);
            ASSERT_LT(p, parts);
            ++count[static_cast<size_t>(p)];
        }
        // METIS' default tolerance is 3 %.
        EXPECT_LE(P.imbalance(), 1.031);
        for (int p = 0; p < parts; ++p) {
            EXPECT_EQ(P.part_work[static_cast<size_t>(p)], count[static_cast<size_t>(p)]);
            EXPECT_EQ(pieces(m, P, p), 1) << "part " << p;
        }
        // A 64 x 64 grid of squares cut into k parts: straight cuts cost about
        // 2 x 64 x sqrt(k) triangle edges; allow twice that.
        EXPECT_GT(P.cut_edges, 0);
        EXPECT_LT(P.cut_edges, 4.0 * 64.0 * std::sqrt(static_cast<double>(parts)));
        // Every vertex has one owner, among the parts of its triangles.
        std::vector<std::set<int>> around(static_cast<size_t>(m.n_vertices()));
        for (int t = 0; t < m.n_cells(); ++t)
            for (int v : m.cells[static_cast<size_t>(t)])
                around[static_cast<size_t>(v)].insert(P.triangle_part[static_cast<size_t>(t)]);
        for (int v = 0; v < m.n_vertices(); ++v)
            EXPECT_TRUE(
                around[static_cast<size_t>(v)].count(P.vertex_owner[static_cast<size_t>(v)]));
        // Reproducible.
        EXPECT_EQ(mesh::partition_triangles(m, parts).triangle_part, P.triangle_part);
    }
}

TEST(Partition, WeightsMoveTheCut) {
    // Triangles of the left half weigh 3: two parts of equal work put fewer triangles in the
    // part that holds the left half.
    const auto m = mesh::structured_rectangle(Vec2(0, 0), Vec2(40, 40), 32, 32);
    std::vector<int> w(static_cast<size_t>(m.n_cells()), 1);
    for (int t = 0; t < m.n_cells(); ++t) {
        const auto& tri = m.cells[static_cast<size_t>(t)];
        const double x = (m.vertices[static_cast<size_t>(tri[0])].x() +
                          m.vertices[static_cast<size_t>(tri[1])].x() +
                          m.vertices[static_cast<size_t>(tri[2])].x()) /
                         3.0;
        if (x < 20.0) w[static_cast<size_t>(t)] = 3;
    }
    const auto P = mesh::partition_triangles(m, 2, w);
    EXPECT_LE(P.imbalance(), 1.031);
    EXPECT_NEAR(P.part_work[0] + P.part_work[1], 4.0 * m.n_cells() / 2.0, 1e-9);
    std::vector<int> count(2, 0);
    for (int p : P.triangle_part)
        ++count[static_cast<size_t>(p)];
    // Total work 2 n: each part 1 n; the part on the heavy side holds about n / 3 triangles.
    const int fewer = std::min(count[0], count[1]);
    EXPECT_LT(fewer, 0.45 * m.n_cells());
}

TEST(Partition, OnePartAndBadArguments) {
    const auto m = mesh::structured_rectangle(Vec2(0, 0), Vec2(1, 1), 2, 2); // 8 triangles
    const auto one = mesh::partition_triangles(m, 1);
    EXPECT_EQ(one.cut_edges, 0);
    EXPECT_DOUBLE_EQ(one.imbalance(), 1.0);
    for (int p : one.vertex_owner)
        EXPECT_EQ(p, 0);
    EXPECT_THROW(mesh::partition_triangles(m, 0), InvalidInput);
    EXPECT_THROW(mesh::partition_triangles(m, 9), InvalidInput);
    EXPECT_THROW(mesh::partition_triangles(m, 2, {1, 1, 1}), InvalidInput);
    EXPECT_THROW(mesh::partition_triangles(m, 2, std::vector<int>(8, 0)), InvalidInput);
}

// Two bodies (no triangle of one shares an edge with the other): METIS cannot make contiguous
// parts there, so partition_triangles asks for none; the parts are still balanced, and a
// connected mesh keeps connected parts (BalancedConnectedPartsWithFewCutEdges).
TEST(Partition, ADisconnectedMeshOfTwoBodiesIsPartitioned) {
    auto m = mesh::structured_rectangle(Vec2(0, 0), Vec2(1, 1), 12, 12);
    const auto upper = mesh::structured_rectangle(Vec2(0, 1), Vec2(1, 1), 11, 11);
    const int off = m.n_vertices();
    for (const auto& x : upper.vertices)
        m.vertices.push_back(x);
    for (auto t : upper.cells) {
        for (int& v : t)
            v += off;
        m.cells.push_back(t);
    }
    for (int parts : {2, 3, 4}) {
        SCOPED_TRACE(parts);
        const auto P = mesh::partition_triangles(m, parts);
        // (METIS may keep the bodies whole, 288 and 242 triangles in two parts: 1.087.)
        EXPECT_LE(P.imbalance(), 1.1);
        for (int p = 0; p < parts; ++p)
            EXPECT_GT(P.part_work[static_cast<size_t>(p)], 0);
        int total_pieces = 0;
        for (int p = 0; p < parts; ++p)
            total_pieces += pieces(m, P, p);
        EXPECT_GE(total_pieces, parts); // (a part may hold pieces of both bodies)
        EXPECT_EQ(mesh::partition_triangles(m, parts).triangle_part, P.triangle_part);
    }
}

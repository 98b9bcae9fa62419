// SPDX-License-Identifier: MIT
#include "mesh/lattice.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

using namespace mlc;
using namespace mlc::mesh;

namespace {
Mesh refined(int depth, Diagonal d = Diagonal::alternate) {
    Mesh m = structured_rectangle({0.0, 0.0}, {2.0, 1.0}, 2, 1, d);
    for (int k = 0; k < depth; ++k)
        m = refine(m);
    return m;
}
} // namespace

// Every interior point's vertex sits at A + (i/n)(B - A) + (j/n)(C - A) of its macro (A, B, C),
// exactly (dyadic coordinates), and each interior vertex is listed once.
TEST(MacroLattice, InteriorPointsSitWhereTheirLatticeCoordinatesSay) {
    const Mesh m0 = structured_rectangle({0.0, 0.0}, {2.0, 1.0}, 2, 1, Diagonal::alternate);
    for (int depth : {0, 1, 2, 3, 4}) {
        const Mesh m = refined(depth);
        const auto L = macro_lattice(m, depth);
        ASSERT_TRUE(L.has_value()) << depth;
        EXPECT_EQ(L->n, 1 << depth);
        EXPECT_EQ(L->n_macros, m0.n_cells());
        const long np = MacroLattice::interior_points(L->n);
        ASSERT_EQ(L->vertex.size(), static_cast<size_t>(np * L->n_macros));
        for (int t = 0; t < L->n_macros; ++t) {
            const auto& tri = m0.cells[static_cast<size_t>(t)];
            const Vec2 A = m0.vertices[static_cast<size_t>(tri[0])];
            const Vec2 B = m0.vertices[static_cast<size_t>(tri[1])];
            const Vec2 C = m0.vertices[static_cast<size_t>(tri[2])];
            const int n = L->n;
            for (int j = 1; j <= n - 2; ++j)
                for (int i = 1; i + j <= n - 1; ++i) {
                    const int v =
                        L->vertex[static_cast<size_t>(t * np + MacroLattice::point_index(n, i, j))];
                    const Vec2 p = A + (double(i) / n) * (B - A) + (double(j) / n) * (C - A);
                    EXPECT_EQ(m.vertices[static_cast<size_t>(v)], p)
                        << depth << " " << i << " " << j;
                }
        }
        std::vector<int> v = L->vertex;
        std::sort(v.begin(), v.end());
        EXPECT_TRUE(std::adjacent_find(v.begin(), v.end()) == v.end());
    }
}

TEST(MacroLattice, PointIndexNumbersTheInteriorRowByRow) {
    for (int n : {3, 4, 8, 64}) {
        long k = 0;
        for (int j = 1; j <= n - 2; ++j)
            for (int i = 1; i + j <= n - 1; ++i)
                EXPECT_EQ(MacroLattice::point_index(n, i, j), k++);
        EXPECT_EQ(k, MacroLattice::interior_points(n));
    }
}

// A mesh whose triangles are not in refine's order, or a depth that does not fit, has no
// lattice.
TEST(MacroLattice, NoLatticeWhenTheTrianglesAreNotRefineOrder) {
    Mesh m = refined(3);
    // Three refinements are two of the level-1 mesh, in refine's order too.
    const auto two = macro_lattice(m, 2);
    ASSERT_TRUE(two.has_value());
    EXPECT_EQ(two->n_macros, 4 * refined(0).n_cells());
    EXPECT_FALSE(macro_lattice(m, 4).has_value()); // one macro of all triangles: no lattice
    std::mt19937 rng(5);
    std::shuffle(m.cells.begin(), m.cells.end(), rng);
    EXPECT_FALSE(macro_lattice(m, 3).has_value());
}

// SPDX-License-Identifier: MIT
// Tests of Bey's 1->8 refinement: similarity classes (one on a Kuhn box, at most three per
// tetrahedron of an irregular Gmsh mesh), dihedral angles, volumes, conformity, face tags,
// parents and the predicted level sizes.
#include "mesh/io/gmsh_tet.hpp"
#include "mesh/tet_mesh.hpp"
#include "mesh/tet_refine.hpp"
#include "tests/mesh/tet_test_meshes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

using namespace mlc;
using namespace mlc::mesh;
using namespace mlc::mesh::testing;

namespace {

using Corners = std::array<Vec3, 4>;

/// Levels 0..n of the hierarchy of m.
std::vector<TetMesh> hierarchy(const TetMesh& m, int n) {
    std::vector<TetMesh> levels{m};
    for (int l = 0; l < n; ++l)
        levels.push_back(refine(levels.back()));
    return levels;
}

TetMesh gmsh_cube() {
    return read_gmsh_tet_text(msh22(distorted_cube()), "cube.msh");
}

TetMesh kuhn_box() {
    return structured_box(Vec3(0.25, -1, 0.5), Vec3(2, 2, 2), 2, 2, 2);
}

/// The children of t by a table of the form of kBeyChildren, built from coordinates alone.
std::array<Corners, 8> children(const Corners& t, const int (&table)[8][4]) {
    std::array<Vec3, 10> p;
    for (int i = 0; i < 4; ++i)
        p[i] = t[i];
    static constexpr int kEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    for (int e = 0; e < 6; ++e)
        p[4 + e] = 0.5 * (t[kEdges[e][0]] + t[kEdges[e][1]]);
    std::array<Corners, 8> out;
    for (int c = 0; c < 8; ++c)
        for (int i = 0; i < 4; ++i)
            out[c][i] = p[table[c][i]];
    return out;
}

/// The number of similarity classes among t and its descendants down to `levels`, refined by
/// `table`.
int similarity_classes(const Corners& t, const int (&table)[8][4], int levels) {
    std::vector<Corners> reps{t}, level{t};
    for (int l = 0; l < levels; ++l) {
        std::vector<Corners> next;
        for (const Corners& x : level)
            for (const Corners& c : children(x, table)) {
                next.push_back(c);
                if (std::none_of(reps.begin(), reps.end(), [&](const Corners& r) {
                        return similarity_ratio(c, r, 1e-12) > 0;
                    }))
                    reps.push_back(c);
            }
        level = std::move(next);
    }
    return static_cast<int>(reps.size());
}

/// The smallest dihedral angle of the mesh's tetrahedra.
double smallest_dihedral_angle(const TetMesh& m) {
    double smallest = std::numbers::pi;
    for (int t = 0; t < m.n_cells(); ++t) {
        const Corners x = corners(m, t);
        for (int i = 0; i < 4; ++i)
            for (int j = i + 1; j < 4; ++j) {
                int k = 0;
                while (k == i || k == j)
                    ++k;
                const int l = 6 - i - j - k;
                const Vec3 e = (x[j] - x[i]).normalized();
                const Vec3 u = (x[k] - x[i]) - (x[k] - x[i]).dot(e) * e;
                const Vec3 w = (x[l] - x[i]) - (x[l] - x[i]).dot(e) * e;
                smallest = std::min(smallest, std::acos(u.dot(w) / (u.norm() * w.norm())));
            }
    }
    return smallest;
}

} // namespace

TEST(TetRefine, ChildrenFollowBeysNumbering) {
    TetMesh m;
    m.vertices = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 2}};
    m.cells = {{0, 1, 2, 3}};
    m.attribute = {7};
    const TetMesh f = refine(m);
    ASSERT_EQ(f.n_cells(), 8);
    EXPECT_EQ(f.attribute, std::vector<int>(8, 7));
    // The midpoints in local edge order 01, 02, 03, 12, 13, 23 are vertices 4..9.
    EXPECT_EQ(f.n_coarse_vertices, 4);
    const std::vector<std::array<int, 2>> parents = {{0, 1}, {0, 2}, {0, 3},
                                                     {1, 2}, {1, 3}, {2, 3}};
    EXPECT_EQ(f.parents, parents);
    const Vec3 x01(1, 0, 0), x02(0, 1, 0), x03(0, 0, 1), x12(1, 1, 0), x13(1, 0, 1), x23(0, 1, 1);
    const std::array<Corners, 8> expected = {{{Vec3(0, 0, 0), x01, x02, x03},
                                              {x01, Vec3(2, 0, 0), x12, x13},
                                              {x02, x12, Vec3(0, 2, 0), x23},
                                              {x03, x13, x23, Vec3(0, 0, 2)},
                                              {x01, x02, x03, x13},
                                              {x01, x02, x12, x13},
                                              {x02, x03, x13, x23},
                                              {x02, x12, x13, x23}}};
    for (int c = 0; c < 8; ++c) {
        EXPECT_EQ(corners(f, c), expected[c]) << "child " << c;
        EXPECT_EQ(parent_tetrahedron(8 * 3 + c), 3);
        EXPECT_EQ(child_number(8 * 3 + c), c);
        // Children 5 and 7 are mirrored; every child has an eighth of the volume.
        EXPECT_EQ(f.signed_measure(c), (c == 5 || c == 7 ? -1 : 1) * m.signed_measure(0) / 8);
    }
}

TEST(TetRefine, KuhnChildrenAreSimilarToTheirParent) {
    const std::vector<TetMesh> levels = hierarchy(kuhn_box(), 3);
    const Corners first = corners(levels[0], 0);
    for (int l = 1; l <= 3; ++l)
        for (int c = 0; c < levels[l].n_cells(); ++c) {
            const double r = similarity_ratio(corners(levels[l], c),
                                              corners(levels[l - 1], parent_tetrahedron(c)), 1e-12);
            ASSERT_NEAR(r, 0.5, 1e-12) << "level " << l << " tetrahedron " << c;
            ASSERT_NEAR(similarity_ratio(corners(levels[l], c), first, 1e-12), std::ldexp(1.0, -l),
                        1e-12);
        }
    // A Kuhn tetrahedron's dihedral angles are 45, 60 and 90 degrees, on every level.
    for (const TetMesh& m : levels)
        EXPECT_NEAR(smallest_dihedral_angle(m), std::numbers::pi / 4, 1e-12);
}

TEST(TetRefine, AtMostThreeSimilarityClassesPerStartTetrahedron) {
    const TetMesh m0 = gmsh_cube();
    const std::vector<TetMesh> levels = hierarchy(m0, 3);
    for (int s = 0; s < m0.n_cells(); ++s) {
        // The mesh's descendants of s are 8^l s .. 8^l (s + 1) - 1 on level l.
        std::vector<Corners> reps{corners(m0, s)};
        for (int l = 1, n = 8; l <= 3; ++l, n *= 8)
            for (int c = n * s; c < n * (s + 1); ++c) {
                const Corners x = corners(levels[l], c);
                if (std::none_of(reps.begin(), reps.end(), [&](const Corners& r) {
                        return similarity_ratio(x, r, 1e-12) > 0;
                    }))
                    reps.push_back(x);
            }
        // Three for an irregular tetrahedron (the corner children keep its class).
        EXPECT_EQ(reps.size(), 3u) << "start tetrahedron " << s;
        EXPECT_EQ(similarity_classes(corners(m0, s), kBeyChildren, 3), 3);
        // The same children with corner child 1 listed from its own corner, (x1, x01, x12,
        // x13): its children cut its octahedron along another diagonal, and the classes
        // multiply (nine).
        static constexpr int kCornerFirst[8][4] = {{0, 4, 5, 6}, {1, 4, 7, 8}, {5, 7, 2, 9},
                                                   {6, 8, 9, 3}, {4, 5, 6, 8}, {4, 5, 7, 8},
                                                   {5, 6, 8, 9}, {5, 7, 8, 9}};
        EXPECT_EQ(similarity_classes(corners(m0, s), kCornerFirst, 3), 9);
    }
}

TEST(TetRefine, SmallestDihedralAngleDoesNotFallFromLevelOne) {
    const std::vector<TetMesh> levels = hierarchy(gmsh_cube(), 3);
    std::vector<double> angle;
    for (const TetMesh& m : levels)
        angle.push_back(smallest_dihedral_angle(m));
    EXPECT_GT(angle[1], 0.1);
    for (int l = 2; l <= 3; ++l)
        EXPECT_GE(angle[l], angle[l - 1] - 1e-12) << "level " << l;
}

TEST(TetRefine, VolumesVerticesAndFaceTagsAreKept) {
    for (const TetMesh& m0 : {gmsh_cube(), kuhn_box()}) {
        const std::vector<TetMesh> levels = hierarchy(m0, 3);
        for (int l = 1; l <= 3; ++l) {
            const TetMesh &c = levels[l - 1], &f = levels[l];
            for (int t = 0; t < c.n_cells(); ++t) {
                double sum = 0;
                for (int k = 0; k < 8; ++k) {
                    const double v = f.signed_measure(8 * t + k);
                    EXPECT_EQ(v > 0, (c.signed_measure(t) > 0) != (k == 5 || k == 7));
                    sum += std::abs(v);
                }
                ASSERT_NEAR(sum, std::abs(c.signed_measure(t)),
                            1e-14 * std::abs(c.signed_measure(t)));
            }
            // Coarse vertices keep their index; a new one is its parents' midpoint.
            ASSERT_EQ(f.n_coarse_vertices, c.n_vertices());
            for (int v = 0; v < f.n_vertices(); ++v) {
                if (v < c.n_vertices()) {
                    ASSERT_EQ(f.vertices[v], c.vertices[v]);
                } else {
                    const auto& p = f.parents[v - c.n_vertices()];
                    ASSERT_LT(p[0], p[1]);
                    ASSERT_EQ(f.vertices[v], 0.5 * (c.vertices[p[0]] + c.vertices[p[1]]));
                }
            }
            // Boundary face f's children 4 f .. 4 f + 3 carry its tag, cover it and face out.
            ASSERT_EQ(f.boundary.size(), 4 * c.boundary.size());
            EXPECT_EQ(f.tag_names, c.tag_names);
            for (std::size_t b = 0; b < c.boundary.size(); ++b) {
                const auto& pv = c.boundary[b].v;
                const Vec3 n = (c.vertices[pv[1]] - c.vertices[pv[0]])
                                   .cross(c.vertices[pv[2]] - c.vertices[pv[0]]);
                double area = 0;
                for (int k = 0; k < 4; ++k) {
                    const BoundaryFace& child = f.boundary[4 * b + k];
                    EXPECT_EQ(child.tag, c.boundary[b].tag);
                    const Vec3 nk = (f.vertices[child.v[1]] - f.vertices[child.v[0]])
                                        .cross(f.vertices[child.v[2]] - f.vertices[child.v[0]]);
                    EXPECT_NEAR(nk.cross(n).norm(), 0.0, 1e-14 * n.squaredNorm());
                    EXPECT_GT(nk.dot(n), 0);
                    area += nk.norm();
                }
                EXPECT_NEAR(area, n.norm(), 1e-14 * n.norm());
            }
        }
    }
    // On the box, a side's tag holds the side's vertices of the finer grid.
    const TetMesh fine = hierarchy(kuhn_box(), 2).back();
    const std::vector<int> xmin = fine.vertices_with_tag(fine.tag("xmin"));
    EXPECT_EQ(xmin.size(), 9u * 9u);
    for (int v : xmin)
        EXPECT_EQ(fine.vertices[v].x(), 0.25);
}

TEST(TetRefine, ConformingLevelsOfThePredictedSizes) {
    for (const TetMesh& m0 : {gmsh_cube(), kuhn_box()}) {
        const std::vector<TetMesh> levels = hierarchy(m0, 3);
        const std::vector<TetLevelSize> sizes = predict_tet_level_sizes(m0, 3);
        ASSERT_EQ(sizes.size(), 4u);
        for (int l = 0; l <= 3; ++l) {
            const TetMesh& m = levels[l];
            // Every face of one or two tetrahedra, the boundary a closed manifold, no fold.
            EXPECT_NO_THROW(check_quality(m)) << "level " << l;
            const double faces = static_cast<double>(count_faces(m));
            EXPECT_EQ(sizes[l].level, l);
            EXPECT_EQ(sizes[l].vertices, m.n_vertices());
            EXPECT_EQ(sizes[l].edges, static_cast<double>(tet_edges(m).edges.size()));
            EXPECT_EQ(sizes[l].faces, faces);
            EXPECT_EQ(sizes[l].tetrahedra, m.n_cells());
            EXPECT_EQ(sizes[l].tagged_faces, static_cast<double>(m.boundary.size()));
            // Faces of one tetrahedron: 4 T = 2 F_interior + F_boundary.
            EXPECT_EQ(sizes[l].boundary_faces, 2 * faces - 4 * m.n_cells());
            EXPECT_EQ(sizes[l].boundary_faces, std::pow(4, l) * sizes[0].boundary_faces);
            EXPECT_GT(sizes[l].bytes, 24 * sizes[l].vertices + 16 * sizes[l].tetrahedra);
        }
    }
    // A Kuhn box of 2 x 2 x 2 cells: 12 x 4 faces of its sides on level 0.
    EXPECT_EQ(predict_tet_level_sizes(kuhn_box(), 0)[0].boundary_faces, 48);
}

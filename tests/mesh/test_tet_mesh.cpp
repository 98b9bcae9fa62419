// SPDX-License-Identifier: MIT
// Tests of the tetrahedral mesh: the Kuhn box, the Gmsh reader in both formats, and every
// quality check on a mesh that has its defect.
#include "core/check.hpp"
#include "mesh/io/gmsh_tet.hpp"
#include "mesh/tet_mesh.hpp"
#include "tests/mesh/measures.hpp"
#include "tests/mesh/tet_test_meshes.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <tuple>
#include <unistd.h>

using namespace mlc;
using namespace mlc::mesh;
using namespace mlc::mesh::testing;

namespace {

/// The union of two meshes, with vertices at equal coordinates merged.
TetMesh merge(const TetMesh& a, const TetMesh& b) {
    TetMesh m = a;
    std::map<std::tuple<double, double, double>, int> at;
    for (int v = 0; v < a.n_vertices(); ++v)
        at[{a.vertices[v].x(), a.vertices[v].y(), a.vertices[v].z()}] = v;
    std::vector<int> index(b.vertices.size());
    for (int v = 0; v < b.n_vertices(); ++v) {
        const auto [it, inserted] = at.try_emplace(
            {b.vertices[v].x(), b.vertices[v].y(), b.vertices[v].z()}, m.n_vertices());
        if (inserted) m.vertices.push_back(b.vertices[v]);
        index[v] = it->second;
    }
    for (auto k : b.cells) {
        for (int& v : k)
            v = index[v];
        m.cells.push_back(k);
    }
    return m;
}

/// The boundary faces as (sorted vertices, tag name).
std::set<std::pair<std::array<int, 3>, std::string>> faces_of(const TetMesh& m) {
    std::set<std::pair<std::array<int, 3>, std::string>> s;
    for (const auto& f : m.boundary) {
        std::array<int, 3> v = f.v;
        std::sort(v.begin(), v.end());
        s.insert({v, m.tag_name(f.tag)});
    }
    return s;
}

} // namespace

TEST(TetBox, CountsTagsAndKuhnPaths) {
    const Vec3 corner(-1, 0.5, 2), size(3, 2, 1);
    const TetMesh m = structured_box(corner, size, 3, 4, 2);
    EXPECT_EQ(m.n_vertices(), 4 * 5 * 3);
    EXPECT_EQ(m.n_cells(), 6 * 3 * 4 * 2);
    EXPECT_EQ(m.boundary.size(), 4u * (3 * 4 + 4 * 2 + 2 * 3));
    EXPECT_NEAR(mesh::testing::total_volume(m), 6.0, 1e-13);
    EXPECT_EQ(m.vertices[(2 * 5 + 3) * 4 + 1], corner + Vec3(1, 1.5, 1)); // vertex (1, 3, 2)
    // Every tetrahedron runs along a Kuhn path: three steps along three different axes.
    const Vec3 h(1, 0.5, 0.5);
    for (const auto& k : m.cells) {
        std::set<int> axes;
        for (int s = 0; s < 3; ++s) {
            const Vec3 d = m.vertices[k[s + 1]] - m.vertices[k[s]];
            int axis = -1;
            for (int a = 0; a < 3; ++a)
                if (std::abs(d[a] - h[a]) < 1e-14)
                    axis = a;
                else
                    EXPECT_NEAR(d[a], 0.0, 1e-14);
            axes.insert(axis);
        }
        EXPECT_EQ(axes, (std::set<int>{0, 1, 2}));
    }
    // Each side's tag holds the vertices of that side, and its faces cover its area.
    const char* names[3][2] = {{"xmin", "xmax"}, {"ymin", "ymax"}, {"zmin", "zmax"}};
    for (int axis = 0; axis < 3; ++axis)
        for (int high = 0; high < 2; ++high) {
            const int tag = m.tag(names[axis][high]);
            const double plane = corner[axis] + high * size[axis];
            const int n[3] = {3, 4, 2};
            const std::vector<int> v = m.vertices_with_tag(tag);
            EXPECT_EQ(static_cast<int>(v.size()),
                      (n[(axis + 1) % 3] + 1) * (n[(axis + 2) % 3] + 1));
            for (int i : v)
                EXPECT_DOUBLE_EQ(m.vertices[i][axis], plane);
            double area = 0;
            for (const auto& f : m.boundary)
                if (f.tag == tag) {
                    const Vec3 normal = (m.vertices[f.v[1]] - m.vertices[f.v[0]])
                                            .cross(m.vertices[f.v[2]] - m.vertices[f.v[0]]);
                    EXPECT_GT(normal[axis] * (high ? 1 : -1), 0) << names[axis][high];
                    area += 0.5 * normal.norm();
                }
            EXPECT_NEAR(area, size[(axis + 1) % 3] * size[(axis + 2) % 3], 1e-13);
        }
    EXPECT_NO_THROW(check_quality(m));
    // Edges: along the axes, one diagonal per square, one per cell.
    const int axis_edges = 3 * 5 * 3 + 4 * 4 * 3 + 4 * 5 * 2;
    const int diagonals = 3 * 4 * 3 + 4 * 4 * 2 + 3 * 5 * 2 + 3 * 4 * 2;
    EXPECT_EQ(static_cast<int>(tet_edges(m).edges.size()), axis_edges + diagonals);
}

TEST(TetBox, RefusesBadArguments) {
    expect_invalid([] { structured_box(Vec3::Zero(), Vec3(1, 1, 1), 0, 1, 1); },
                   {"at least one cell each way, got 0 x 1 x 1"});
    expect_invalid([] { structured_box(Vec3::Zero(), Vec3(1, -1, 1), 1, 1, 1); },
                   {"positive size, got 1 x -1 x 1"});
    expect_invalid([] { structured_box(Vec3::Zero(), Vec3(1, 1, 1), 2000, 2000, 2000); },
                   {"more than an int index can address"});
}

TEST(TetGmsh, ReadsBothFormats) {
    const MshSpec spec = distorted_cube();
    for (const std::string& text : {msh22(spec), msh41(spec)}) {
        const TetMesh m = read_gmsh_tet_text(text, "cube.msh");
        ASSERT_EQ(m.n_vertices(), 8);
        for (int v = 0; v < 8; ++v)
            EXPECT_EQ(m.vertices[v], spec.nodes[v]);
        ASSERT_EQ(m.n_cells(), 5);
        for (int t = 0; t < 5; ++t) {
            for (int i = 0; i < 4; ++i)
                EXPECT_EQ(m.cells[t][i], spec.tets[t].second[i] - 1);
            EXPECT_GT(m.signed_measure(t), 0);
        }
        EXPECT_EQ(m.attribute, (std::vector<int>{3, 3, 3, 3, 4}));
        const std::set<std::pair<std::array<int, 3>, std::string>> expected = {
            {{0, 1, 2}, "bottom"}, {{1, 2, 3}, "bottom"}, {{4, 5, 7}, "top"},
            {{4, 6, 7}, "top"},    {{0, 2, 4}, "tag5"},   {{2, 4, 6}, "tag5"}};
        EXPECT_EQ(faces_of(m), expected);
        // check_quality ran, so every face points out of the body (the bottom's were turned).
        EXPECT_NO_THROW(check_quality(m));
        const Vec3 n = (m.vertices[m.boundary[0].v[1]] - m.vertices[m.boundary[0].v[0]])
                           .cross(m.vertices[m.boundary[0].v[2]] - m.vertices[m.boundary[0].v[0]]);
        EXPECT_LT(n.z(), 0);
        // One body out of two: the core alone, its own vertices renumbered in file order.
        const TetMesh core = read_gmsh_tet_text(text, "cube.msh", "core");
        ASSERT_EQ(core.n_cells(), 1);
        EXPECT_EQ(core.cells[0], (std::array<int, 4>{0, 1, 2, 3}));
        EXPECT_EQ(core.vertices[3], spec.nodes[7]);
        EXPECT_TRUE(core.boundary.empty()); // no tagged triangle is a face of the core
        // The shell alone: its four corners touch each other along edges only.
        expect_invalid([&] { read_gmsh_tet_text(text, "cube.msh", "shell"); },
                       {"cube.msh: non-manifold boundary: the edge (1, 2) from (1.1, 0, 0.05) to "
                        "(0, 0.9, 0) lies on 4 boundary faces (of tetrahedron 0 (the element on "
                        "line"});
    }
}

TEST(TetGmsh, ReadsAFile) {
    const std::filesystem::path file = std::filesystem::path(::testing::TempDir()) /
                                       ("mlc_tet_cube_" + std::to_string(::getpid()) + ".msh");
    std::ofstream(file) << msh41(distorted_cube());
    const TetMesh core = read_gmsh_tet(file, "core");
    std::filesystem::remove(file);
    ASSERT_EQ(core.n_cells(), 1);
    EXPECT_EQ(core.attribute, std::vector<int>{4});
    expect_invalid([&] { read_gmsh_tet(file); }, {"cannot open '" + file.string() + "'"});
}

TEST(TetGmsh, RefusesBadFiles) {
    const MshSpec good = distorted_cube();
    expect_invalid([&] { read_gmsh_tet_text(msh41(good), "cube.msh", "steel"); },
                   {"cube.msh: no physical volume 'steel'; expected one of: 'shell' 'core'"});
    // A tetrahedron listed with negative volume: inverted. Its element is on line 32.
    MshSpec inverted = good;
    std::swap(inverted.tets[2].second[0], inverted.tets[2].second[1]);
    expect_invalid([&] { read_gmsh_tet_text(msh22(inverted), "cube.msh"); },
                   {"cube.msh:32: inverted tetrahedron 2 (the element on line 32, nodes 2 6 5 8)",
                    "expected a positive volume"});
    MshSpec duplicated = good;
    duplicated.tets.push_back(good.tets[1]);
    expect_invalid([&] { read_gmsh_tet_text(msh22(duplicated), "cube.msh"); },
                   {"duplicated element: tetrahedron 1 (the element on line 31, nodes",
                    "and tetrahedron 5 (the element on line 35, nodes"});
    // Node 1 moved into the plane of nodes 2, 3, 5: the corner tetrahedron 0 is flat.
    MshSpec flat = good;
    const Vec3 a = good.nodes[1], b = good.nodes[2], c = good.nodes[4];
    flat.nodes[0] = (a + b + c) / 3;
    expect_invalid([&] { read_gmsh_tet_text(msh41(flat), "cube.msh"); },
                   {"flat tetrahedron: tetrahedron 0 (the element on line", "expected more than"});
    MshSpec hexahedron = good;
    std::string text = msh22(hexahedron);
    text.replace(text.find("$EndElements"), 0, "12 5 2 3 3 1 2 4 3 5 6 8 7\n");
    text.replace(text.find("\n11\n") + 1, 2, "12");
    expect_invalid([&] { read_gmsh_tet_text(text, "cube.msh"); },
                   {"cube.msh:35: element type 5 (8-node hexahedron) is not supported"});
    MshSpec planar = good;
    planar.tets.clear();
    expect_invalid([&] { read_gmsh_tet_text(msh22(planar), "cube.msh"); },
                   {"no 4-node tetrahedra found"});
}

TEST(TetQuality, NamesTheBadElement) {
    // Three tetrahedra on one face: two above it, one below.
    TetMesh three;
    three.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.2, 0.2, 2}, {0, 0, -1}};
    three.cells = {{0, 1, 2, 3}, {0, 1, 2, 4}, {0, 1, 2, 5}};
    expect_invalid([&] { check_quality(three); },
                   {"a face shared by 3 tetrahedra: the face (0, 1, 2) at (0, 0, 0), (1, 0, 0), "
                    "(0, 1, 0) belongs to tetrahedron 0, tetrahedron 1, tetrahedron 2",
                    "expected at most two"});
    // Two of them: both above their common face, one folded over the other.
    TetMesh folded = three;
    folded.cells.pop_back();
    expect_invalid([&] { check_quality(folded); },
                   {"inverted tetrahedron: tetrahedron 1 (vertices 0, 1, 2, 4", "and tetrahedron 0",
                    "lie on the same side of their common face (0, 1, 2)"});
    // An interior vertex of a box pushed through a face of its neighbours folds elements.
    TetMesh pushed = structured_box(Vec3::Zero(), Vec3(2, 2, 2), 2, 2, 2);
    pushed.vertices[13] = Vec3(1.5, 0.2, 1.0);
    expect_invalid([&] { check_quality(pushed); },
                   {"inverted tetrahedron: tetrahedron 11 (vertices 1, 10, 13, 14 at (1, 0, 0), "
                    "(1, 0, 1), (1.5, 0.2, 1), (2, 1, 1)) and tetrahedron 1 lie on the same side "
                    "of their common face (1, 10, 13)"});
    // A flat one named by the caller's namer.
    TetMesh flat = structured_box(Vec3::Zero(), Vec3(1, 1, 1), 1, 1, 1);
    flat.cells[4] = {0, 1, 2, 3};
    expect_invalid([&] { check_quality(flat, [](int t) { return "cell #" + std::to_string(t); }); },
                   {"flat tetrahedron: cell #4 (vertices 0, 1, 2, 3 at (0, 0, 0), (1, 0, 0), "
                    "(0, 1, 0), (1, 1, 0)) has volume 0"});
    TetMesh twice = structured_box(Vec3::Zero(), Vec3(1, 1, 1), 1, 1, 1);
    twice.cells.push_back({7, 0, 1, 3});
    expect_invalid([&] { check_quality(twice); },
                   {"duplicated element: tetrahedron 0 (vertices 0, 1, 3, 7", "and tetrahedron 6"});
    // Two cubes touching along an edge, and at a corner.
    const TetMesh a = structured_box(Vec3::Zero(), Vec3(1, 1, 1), 1, 1, 1);
    const TetMesh along = merge(a, structured_box(Vec3(1, 1, 0), Vec3(1, 1, 1), 1, 1, 1));
    expect_invalid([&] { check_quality(along); },
                   {"non-manifold boundary: the edge (3, 7) from (1, 1, 0) to (1, 1, 1) lies on 4 "
                    "boundary faces",
                    "expected two: parts of the mesh touch only along this edge"});
    const TetMesh corner = merge(a, structured_box(Vec3(1, 1, 1), Vec3(1, 1, 1), 1, 1, 1));
    expect_invalid([&] { check_quality(corner); },
                   {"non-manifold boundary: vertex 7 at (1, 1, 1) joins separate sheets",
                    "touch only at this point"});
    // Tagged faces: one turned into the body, one that is not a boundary face.
    TetMesh turned = a;
    std::swap(turned.boundary[3].v[0], turned.boundary[3].v[1]);
    expect_invalid(
        [&] { check_quality(turned); },
        {"tagged 'xmax' has its normal (v1 - v0) x (v2 - v0) pointing into tetrahedron"});
    TetMesh inside = a;
    inside.boundary.push_back({{0, 3, 7}, 0});
    expect_invalid(
        [&] { check_quality(inside); },
        {"boundary face (0, 3, 7) tagged 'xmin' is a face of 2 tetrahedra; expected one"});
    TetMesh out_of_range = a;
    out_of_range.cells[2][3] = 8;
    expect_invalid([&] { check_quality(out_of_range); },
                   {"tetrahedron 2 refers to vertex 8 but the mesh has 8 vertices"});
    TetMesh attributes = a;
    attributes.attribute = {1, 2};
    expect_invalid([&] { check_quality(attributes); },
                   {"2 tetrahedron attributes for 6 tetrahedra"});
}

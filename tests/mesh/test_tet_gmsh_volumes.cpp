// SPDX-License-Identifier: MIT
// Tests of the Gmsh tetrahedral reader's physical volumes: bodies for all tetrahedra or none, a
// tetrahedron outside every physical volume named by its element, a volume selected by name, and
// physical curves read as tagged lines.
#include "mesh/io/gmsh_tet.hpp"
#include "mesh/tet_refine.hpp"
#include "tests/mesh/tet_test_meshes.hpp"

#include <gtest/gtest.h>

using namespace mlc;
using namespace mlc::mesh;
namespace tmesh = mlc::mesh::testing;

TEST(TetGmshVolumes, ATetrahedronInNoPhysicalVolumeIsNamed) {
    tmesh::MshSpec spec = tmesh::distorted_cube();
    spec.tets[2].first = 0; // the third tetrahedron (line 32 of the 2.2 text) in no volume
    tmesh::expect_invalid([&] { read_gmsh_tet_text(tmesh::msh22(spec), "cube.msh"); },
                          {"cube.msh:32: tetrahedron 2 (the element on line 32, nodes",
                           "is in no physical volume, but 4 of the 5 tetrahedra are (in 'shell' "
                           "'core')"});
    // Selecting one volume by name reads its tetrahedra alone.
    const TetMesh core = read_gmsh_tet_text(tmesh::msh22(spec), "cube.msh", "core");
    EXPECT_EQ(core.n_cells(), 1);
    EXPECT_EQ(core.attribute, std::vector<int>{4});
    // No tetrahedron in a physical volume: all are body 0 (no attributes).
    for (auto& t : spec.tets)
        t.first = 0;
    const TetMesh none = read_gmsh_tet_text(tmesh::msh22(spec), "cube.msh");
    EXPECT_EQ(none.n_cells(), 5);
    EXPECT_TRUE(none.attribute.empty());
}

TEST(TetGmshVolumes, PhysicalCurvesBecomeTaggedLinesThatRefinementSplits) {
    tmesh::MshSpec spec = tmesh::distorted_cube();
    // The bottom edge from node 1 to node 2 (vertices 0 and 1), named, and the edge 1-3 unnamed.
    spec.lines = {{6, {1, 2}}, {7, {1, 3}}, {6, {2, 1}}}; // the repeat is kept once
    spec.names.push_back("1 6 \"edge\"");
    for (const std::string& text : {tmesh::msh22(spec), tmesh::msh41(spec)}) {
        const TetMesh m = read_gmsh_tet_text(text, "cube.msh");
        ASSERT_EQ(m.lines.size(), 2u);
        const int edge = m.tag("edge");
        EXPECT_EQ(m.lines[0].vertices(), (std::array<int, 2>{0, 1}));
        EXPECT_EQ(m.lines[0].tag, edge);
        EXPECT_EQ(m.lines[1].vertices(), (std::array<int, 2>{0, 2}));
        EXPECT_EQ(m.lines[1].tag, m.tag("tag7"));
        EXPECT_FALSE(m.is_boundary_tag(edge)); // a line tag, on no face
        EXPECT_EQ(m.vertices_on_tag(edge), (std::vector<int>{0, 1}));
        // Each refinement halves the line's edges; the midpoints are on it.
        TetMesh f = m;
        for (int l = 1; l <= 2; ++l) {
            f = refine(f);
            check_quality(f);
            const std::vector<int> on = f.vertices_on_tag(edge);
            ASSERT_EQ(on.size(), static_cast<size_t>((1 << l) + 1)) << "level " << l;
            const Vec3 a = m.vertices[0], b = m.vertices[1];
            for (int v : on) {
                const Vec3 x = f.vertices[static_cast<size_t>(v)];
                EXPECT_LT((x - a).cross(b - a).norm(), 1e-14) << "vertex " << v;
            }
        }
    }
    // A curve that is no edge of a tetrahedron (the cube's main diagonal) is refused by name.
    spec.lines = {{6, {1, 8}}};
    tmesh::expect_invalid([&] { read_gmsh_tet_text(tmesh::msh22(spec), "cube.msh"); },
                          {"cube.msh: line 0 of tag 'edge' from vertex 0 to vertex 7",
                           "is no edge of a tetrahedron"});
}

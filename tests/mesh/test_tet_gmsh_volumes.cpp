// SPDX-License-Identifier: MIT
// Tests of the Gmsh tetrahedral reader's physical volumes: bodies for all tetrahedra or none, a
// tetrahedron outside every physical volume named by its element, and a volume selected by name.
#include "mesh/io/gmsh_tet.hpp"
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

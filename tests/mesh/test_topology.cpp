// SPDX-License-Identifier: MIT
// Meshes that lie: duplicated elements, edges of more than two triangles and hanging nodes
// (T-junctions) are refused by check_quality (mesh/topology.hpp) with the elements named; the
// Gmsh files of tests/data/mesh reproduce them on real scenes.
#include "core/check.hpp"
#include "mesh/io/gmsh.hpp"
#include "mesh/mesh.hpp"
#include "mesh/topology.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

using namespace mlc;
using namespace mlc::mesh;

namespace {

std::filesystem::path data(const std::string& name) {
    return std::filesystem::path(MLC_TEST_DATA_DIR) / "mesh" / name;
}

/// The message check_quality throws for m, or "" when it accepts it.
std::string refusal(const Mesh& m) {
    try {
        check_quality(m);
    } catch (const InvalidInput& e) {
        return e.what();
    }
    return "";
}

/// The unit square [0, 1]^2 in two triangles, shifted by `at`, with attribute `body`.
void add_square(Mesh& m, const Vec2& at, int body) {
    const int b = m.n_vertices();
    for (const Vec2& p : {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)})
        m.vertices.push_back(at + p);
    m.cells.push_back({b, b + 1, b + 2});
    m.cells.push_back({b, b + 2, b + 3});
    m.attribute.push_back(body);
    m.attribute.push_back(body);
}

/// Two unit squares: [0, 1]^2 in two triangles and, at x0 .. x0 + 1, one split into four
/// triangles around its centre with a vertex at the middle (x0, 0.5) of its left side.
Mesh square_beside_fan(double x0, int left_body, int right_body) {
    Mesh m;
    add_square(m, Vec2(0, 0), left_body);
    const int b = m.n_vertices();
    for (const Vec2& p :
         {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1), Vec2(0, 0.5), Vec2(0.5, 0.5)})
        m.vertices.push_back(Vec2(x0, 0) + p);
    // corners b .. b+3, side midpoint b+4, centre b+5
    for (const std::array<int, 3>& t :
         std::initializer_list<std::array<int, 3>>{{b, b + 1, b + 5},
                                                   {b + 1, b + 2, b + 5},
                                                   {b + 2, b + 3, b + 5},
                                                   {b + 3, b + 4, b + 5},
                                                   {b + 4, b, b + 5}}) {
        m.cells.push_back(t);
        m.attribute.push_back(right_body);
    }
    return m;
}

} // namespace

TEST(MeshTopology, DuplicatedTriangleAtTheHertzContactPointIsRefused) {
    // The built-in hertz_gmsh mesh with element 46 (nodes 1 4 45, at the contact point (0, 0))
    // listed twice, its nodes rotated.
    try {
        read_gmsh(data("hertz_gmsh_duplicate.msh"));
        FAIL() << "accepted";
    } catch (const InvalidInput& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("hertz_gmsh_duplicate.msh: duplicated element: triangle 0 (the "
                           "element on line 232, nodes 1 4 45) and triangle 295 (the element on "
                           "line 527, nodes 45 1 4) have the same vertices, vertex 0 (0, 0)"),
                  std::string::npos)
            << msg;
        EXPECT_EQ(msg.find("[check"), std::string::npos) << msg; // no internal location
    }
}

TEST(MeshTopology, TJunctionInASquareMeshIsRefused) {
    try {
        read_gmsh(data("t_junction.msh"));
        FAIL() << "accepted";
    } catch (const InvalidInput& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("t_junction.msh: hanging node (T-junction): vertex 9 (1, 0.5) lies "
                           "inside the edge from vertex 1 (1, 0) to vertex 4 (1, 1) of triangle 0 "
                           "(the element on line 37, nodes 1 2 5)"),
                  std::string::npos)
            << msg;
    }
}

TEST(MeshTopology, HangingNodeAndItsConformingRepair) {
    // [0, 2] x [0, 1]: the left square in two triangles, the right one in four around its
    // centre (1.5, 0.5), one of them with the vertex (1, 0.5) on the left square's side.
    Mesh m;
    m.vertices = {Vec2(0, 0),   Vec2(1, 0), Vec2(1, 1), Vec2(0, 1),
                  Vec2(1, 0.5), Vec2(2, 0), Vec2(2, 1), Vec2(1.5, 0.5)};
    m.cells = {{0, 1, 2}, {0, 2, 3}, {1, 5, 7}, {5, 6, 7}, {6, 2, 7}, {2, 4, 7}, {4, 1, 7}};
    EXPECT_NE(refusal(m).find("hanging node (T-junction): vertex 4 (1, 0.5) lies inside the edge "
                              "from vertex 1 (1, 0) to vertex 2 (1, 1) of triangle 0"),
              std::string::npos)
        << refusal(m);
    // The left square split at the vertex: conforming.
    Mesh fixed = m;
    fixed.cells[0] = {0, 1, 4};
    fixed.cells[1] = {0, 4, 3};
    fixed.cells.push_back({4, 2, 3});
    EXPECT_EQ(refusal(fixed), "");
}

TEST(MeshTopology, TouchingBodiesAndTheTolerance) {
    // Two bodies may touch along non-matching edges (a two-body contact interface).
    EXPECT_EQ(refusal(square_beside_fan(1.0, 0, 1)), "");
    // One body: a vertex 1e-3 of the edge's length away from it is no hanging node...
    EXPECT_EQ(refusal(square_beside_fan(1.0 + 1e-3, 0, 0)), "");
    // ...1e-8 away, outside or inside, it is (kHangingNodeTol = 1e-6 of the edge's length).
    for (double x0 : {1.0 + 1e-8, 1.0 - 1e-8})
        EXPECT_NE(refusal(square_beside_fan(x0, 0, 0)).find("hanging node (T-junction): vertex 8"),
                  std::string::npos)
            << refusal(square_beside_fan(x0, 0, 0));
    // Scaled by 1e6 and moved far from the origin, the same answers (all tolerances relative).
    for (double x0 : {1.0 + 1e-3, 1.0 + 1e-8}) {
        Mesh big = square_beside_fan(x0, 0, 0);
        for (Vec2& v : big.vertices)
            v = 1e6 * v + Vec2(3e7, -2e7);
        EXPECT_EQ(refusal(big).find("hanging node") != std::string::npos, x0 < 1.0 + 1e-6);
    }
}

TEST(MeshTopology, DuplicatedAndNonManifoldTrianglesAreNamed) {
    Mesh m;
    m.vertices = {Vec2(0, 0), Vec2(1, 0), Vec2(0.5, 1), Vec2(0.5, -1), Vec2(0.5, 2)};
    m.cells = {{0, 1, 2}, {1, 0, 3}};
    EXPECT_EQ(refusal(m), "");
    Mesh dup = m;
    dup.cells.push_back({2, 0, 1}); // triangle 0 again, rotated
    EXPECT_NE(refusal(dup).find("duplicated element: triangle 0 and triangle 2 have the same "
                                "vertices, vertex 0 (0, 0), vertex 1 (1, 0) and vertex 2 (0.5, 1)"),
              std::string::npos)
        << refusal(dup);
    Mesh fold = m;
    fold.cells.push_back({0, 1, 4}); // a third triangle on the edge (0, 1), over triangle 0
    EXPECT_NE(refusal(fold).find("non-manifold edge: the edge from vertex 0 (0, 0) to vertex 1 "
                                 "(1, 0) is shared by 3 triangles (triangle 0, triangle 1 and "
                                 "triangle 2)"),
              std::string::npos)
        << refusal(fold);
}

TEST(MeshTopology, StructuredAndRefinedMeshesPass) {
    for (Diagonal d : {Diagonal::right, Diagonal::left, Diagonal::alternate}) {
        const Mesh m = structured_rectangle(Vec2(0, 0), Vec2(3, 1), 30, 10, d);
        EXPECT_NO_THROW(check_topology(m));
        EXPECT_NO_THROW(check_topology(refine(refine(m))));
    }
    // The built-in hertz_gmsh mesh (graded: edges 0.025 to 0.15) passes.
    EXPECT_NO_THROW(read_gmsh(std::filesystem::path(MLC_TEST_DATA_DIR) / ".." / ".." / "scenes" /
                              "hertz_gmsh.msh"));
}

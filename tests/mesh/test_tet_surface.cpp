// SPDX-License-Identifier: MIT
// Tests of curved boundary faces of tetrahedral meshes: vertices created on a sphere or a
// cylinder are moved onto it, a vertex off the declared surface and a move that inverts an
// element are refused.
#include "mesh/tet_mesh.hpp"
#include "mesh/tet_refine.hpp"
#include "tests/mesh/measures.hpp"
#include "tests/mesh/tet_test_meshes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

using namespace mlc;
using namespace mlc::mesh;
using namespace mlc::mesh::testing;

namespace {

/// Appends the face (a, b, c) tagged `tag`, its normal turned away from vertex `inside`.
void add_face(TetMesh& m, std::array<int, 3> v, int inside, int tag) {
    const Vec3& a = m.vertices[v[0]];
    if ((m.vertices[v[1]] - a).cross(m.vertices[v[2]] - a).dot(m.vertices[inside] - a) > 0)
        std::swap(v[1], v[2]);
    m.boundary.push_back({v, tag});
}

/// The unit ball as an octahedron: the centre and the six points +-e_i, eight tetrahedra, the
/// eight outer faces tagged "ball".
TetMesh octahedron() {
    TetMesh m;
    m.vertices = {Vec3::Zero(),   Vec3::UnitX(), -Vec3::UnitX(), Vec3::UnitY(),
                  -Vec3::UnitY(), Vec3::UnitZ(), -Vec3::UnitZ()};
    const int ball = m.add_tag("ball");
    for (int a : {1, 2})
        for (int b : {3, 4})
            for (int c : {5, 6}) {
                m.cells.push_back({0, a, b, c});
                add_face(m, {a, b, c}, 0, ball);
            }
    return m;
}

/// The largest distance from `s` of a vertex of `tag`.
double largest_offset(const TetMesh& m, const std::string& tag, const CurvedSurface& s) {
    double d = 0;
    for (int v : m.vertices_with_tag(m.tag(tag)))
        d = std::max(d, s.distance(m.vertices[v]));
    return d;
}

} // namespace

TEST(TetSurface, NewVerticesGoOntoTheSphere) {
    TetMesh m = octahedron();
    const CurvedSurface sphere{CurvedSurface::Kind::sphere, Vec3::Zero(), Vec3::UnitZ(), 1.0};
    attach_surface(m, "ball", sphere);
    ASSERT_EQ(m.shapes.size(), 1u);
    for (const auto& f : m.boundary)
        EXPECT_EQ(f.shape, 0);
    const std::vector<TetLevelSize> sizes = predict_tet_level_sizes(m, 3);
    std::vector<double> error{4 * std::numbers::pi / 3 - mesh::testing::total_volume(m)};
    for (int l = 1; l <= 3; ++l) {
        m = refine(m);
        EXPECT_NO_THROW(check_quality(m)) << "level " << l;
        EXPECT_LE(largest_offset(m, "ball", sphere), 1e-15);
        EXPECT_EQ(m.n_vertices(), sizes[l].vertices);
        for (const auto& f : m.boundary)
            EXPECT_EQ(f.shape, 0);
        error.push_back(4 * std::numbers::pi / 3 - mesh::testing::total_volume(m));
        // The volume grows towards the ball's, its error falling about fourfold per level once
        // the octahedron's (a coarse start) has been refined away.
        EXPECT_GT(error[l], 0);
        EXPECT_GT(error[l - 1] / error[l], l == 1 ? 2.0 : 3.0) << "level " << l;
        EXPECT_LT(error[l - 1] / error[l], 5.0) << "level " << l;
    }
}

TEST(TetSurface, NewVerticesGoOntoTheCylinder) {
    // The box [-1, 1]^2 x [0, 1] with its side vertices pushed onto the unit circle.
    TetMesh m = structured_box(Vec3(-1, -1, 0), Vec3(2, 2, 1), 2, 2, 1);
    for (Vec3& p : m.vertices)
        if (std::max(std::abs(p.x()), std::abs(p.y())) == 1.0) p.head<2>().normalize();
    const CurvedSurface cylinder{CurvedSurface::Kind::cylinder, Vec3(0, 0, 5), Vec3(0, 0, 2), 1.0};
    for (const char* side : {"xmin", "xmax", "ymin", "ymax"})
        attach_surface(m, side, cylinder);
    EXPECT_EQ(m.shapes[0].axis, Vec3::UnitZ());
    for (int l = 1; l <= 2; ++l) {
        m = refine(m);
        EXPECT_NO_THROW(check_quality(m)) << "level " << l;
        for (const char* side : {"xmin", "xmax", "ymin", "ymax"})
            EXPECT_LE(largest_offset(m, side, m.shapes[0]), 1e-15) << side;
        // The rim's new vertices stay in the planes of the ends.
        for (int v : m.vertices_with_tag(m.tag("zmin")))
            EXPECT_EQ(m.vertices[v].z(), 0.0);
        for (int v : m.vertices_with_tag(m.tag("zmax")))
            EXPECT_EQ(m.vertices[v].z(), 1.0);
    }
    // 32 sides around a circle on level 2: the polygon's area 16 sin(2 pi / 32).
    EXPECT_NEAR(mesh::testing::total_volume(m), 16 * std::sin(2 * std::numbers::pi / 32), 1e-13);
}

TEST(TetSurface, RefusesABadDeclarationOrAnInvertingMove) {
    TetMesh box = structured_box(Vec3::Zero(), Vec3(1, 1, 1), 1, 1, 1);
    const CurvedSurface sphere{CurvedSurface::Kind::sphere, Vec3::Zero(), Vec3::UnitZ(), 1.0};
    expect_invalid([&] { attach_surface(box, "rim", sphere); },
                   {"no boundary tag 'rim' to put on a curved surface; expected one of: xmax, "
                    "xmin, ymax, ymin, zmax, zmin"});
    expect_invalid([&] { attach_surface(box, "xmin", sphere); },
                   {"vertex 0 at (0, 0, 0) of tag 'xmin' lies 1 off the sphere (center (0, 0, 0), "
                    "radius 1); expected on it"});
    CurvedSurface flat = sphere;
    flat.radius = 0;
    expect_invalid([&] { attach_surface(box, "xmin", flat); }, {"needs a positive radius, got 0"});
    const CurvedSurface no_axis{CurvedSurface::Kind::cylinder, Vec3::Zero(), Vec3::Zero(), 1.0};
    expect_invalid([&] { attach_surface(box, "xmin", no_axis); },
                   {"the cylinder of tag 'xmin' needs a nonzero axis direction"});
    // A tetrahedron outside the unit sphere with a face on it (a cavity) and its fourth vertex
    // near that face: the face's midpoints, moved onto the sphere, pass that vertex.
    TetMesh cavity;
    cavity.vertices = {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ(), Vec3(0.4, 0.4, 0.4)};
    cavity.cells = {{0, 1, 2, 3}};
    add_face(cavity, {0, 1, 2}, 3, cavity.add_tag("cavity"));
    EXPECT_NO_THROW(check_quality(cavity));
    attach_surface(cavity, "cavity", sphere);
    expect_invalid([&] { refine(cavity); },
                   {"on the sphere (center (0, 0, 0), radius 1) of tag 'cavity' inverts "
                    "tetrahedron ",
                    "of coarse tetrahedron 0): its volume becomes -",
                    "refine the start mesh near the curved boundary"});
    // Farther from the face, the same move is fine.
    cavity.vertices[3] = Vec3(1, 1, 1);
    EXPECT_NO_THROW(check_quality(refine(cavity)));
}

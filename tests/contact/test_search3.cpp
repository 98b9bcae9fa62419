// SPDX-License-Identifier: MIT
// 3D contact search: the closest point of a triangle (inside, on an edge, at a vertex) with
// exact barycentric coordinates and distances; the normals of a box's faces, edges and corners
// (the angle-weighted rule); a flat non-matching interface between two stacked boxes (every
// node found, weights reproducing linear fields, g0 = 0), its rim and its refinement; a faceted
// sphere (g0 the distance to the facet plane); node on node on matching boxes; the AABB tree
// against a brute-force scan; the refusals.
#include "contact/search3.hpp"
#include "core/check.hpp"
#include "mesh/tet_mesh.hpp"
#include "mesh/tet_refine.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <string>

using namespace mlc;
using contact::TriangleFeature;
using mesh::Vec3;

namespace {

/// The message of the InvalidInput `f` throws, without the " [check ...]" place that follows.
std::string search3_refusal(const std::function<void()>& f) {
    try {
        f();
    } catch (const InvalidInput& e) {
        const std::string what = e.what();
        return what.substr(0, what.find(" [check `"));
    }
    return "(no InvalidInput thrown)";
}

/// Appends `body` to `m`: its vertices, cells and boundary faces, the tags renamed
/// `prefix` + name. Returns the index of its first vertex in `m`.
int search3_append(mesh::TetMesh& m, const mesh::TetMesh& body, const std::string& prefix) {
    const int offset = m.n_vertices();
    m.vertices.insert(m.vertices.end(), body.vertices.begin(), body.vertices.end());
    for (auto c : body.cells) {
        for (int& v : c)
            v += offset;
        m.cells.push_back(c);
    }
    for (auto f : body.boundary) {
        for (int& v : f.v)
            v += offset;
        f.tag = m.add_tag(prefix + body.tag_name(f.tag));
        m.boundary.push_back(f);
    }
    return offset;
}

/// Two boxes stacked: the lower [0, 1]^2 x [0, 1] with n_low x n_low x 1 cells, the upper
/// [dx, dx + 1] x [0, 1] x [1 + gap, 1.5 + gap] with n_up x n_up x 1 cells; tags "lower_zmax",
/// "upper_zmin", ... `upper_offset` receives the index of the upper box's first vertex.
mesh::TetMesh search3_stack(int n_low, int n_up, double gap = 0.0, double dx = 0.0,
                            int* upper_offset = nullptr) {
    mesh::TetMesh m;
    search3_append(m, mesh::structured_box(Vec3::Zero(), Vec3(1, 1, 1), n_low, n_low, 1), "lower_");
    const int off = search3_append(
        m, mesh::structured_box(Vec3(dx, 0, 1 + gap), Vec3(1, 1, 0.5), n_up, n_up, 1), "upper_");
    if (upper_offset) *upper_offset = off;
    return m;
}

/// The unit ball as an octahedron (the centre and +-e_i, eight tetrahedra, the outer faces
/// tagged "ball", oriented outward), on the unit sphere, refined `levels` times.
mesh::TetMesh search3_ball(int levels) {
    mesh::TetMesh m;
    m.vertices = {Vec3::Zero(),   Vec3::UnitX(), -Vec3::UnitX(), Vec3::UnitY(),
                  -Vec3::UnitY(), Vec3::UnitZ(), -Vec3::UnitZ()};
    const int ball = m.add_tag("ball");
    for (int a : {1, 2})
        for (int b : {3, 4})
            for (int c : {5, 6}) {
                m.cells.push_back({0, a, b, c});
                std::array<int, 3> v{a, b, c};
                const Vec3& x = m.vertices[static_cast<size_t>(a)];
                if ((m.vertices[static_cast<size_t>(b)] - x)
                        .cross(m.vertices[static_cast<size_t>(c)] - x)
                        .dot(-x) > 0)
                    std::swap(v[1], v[2]);
                m.boundary.push_back({v, ball});
            }
    mesh::attach_surface(m, "ball",
                         {mesh::CurvedSurface::Kind::sphere, Vec3::Zero(), Vec3::UnitZ(), 1.0});
    for (int l = 0; l < levels; ++l)
        m = mesh::refine(m);
    return m;
}

/// The index over the faces of `m` tagged `tag`.
contact::FacetIndex3 search3_index(const mesh::TetMesh& m, const std::string& tag) {
    return contact::FacetIndex3(m.vertices, contact::target_facets3(m, m.tag(tag)));
}

/// sum_j w_j f(x_j) for element e.
double search3_apply(const contact::ContactElement3& e, const mesh::TetMesh& m,
                     const std::function<double(const Vec3&)>& f) {
    double s = 0.0;
    for (int j = 0; j < e.n_nodes(); ++j)
        s += e.weight[static_cast<size_t>(j)] *
             f(m.vertices[static_cast<size_t>(e.vertex[static_cast<size_t>(j)])]);
    return s;
}

} // namespace

TEST(Search3, ProjectionInsideATriangleHasExactBarycentricsAndDistance) {
    const Vec3 a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
    const auto p = contact::project_on_triangle(Vec3(0.5, 0.5, 0.3), a, b, c);
    EXPECT_EQ(p.where, TriangleFeature::interior);
    EXPECT_EQ(p.feature, -1);
    EXPECT_EQ(p.bary[0], 0.5);
    EXPECT_EQ(p.bary[1], 0.25);
    EXPECT_EQ(p.bary[2], 0.25);
    EXPECT_EQ(p.point, Vec3(0.5, 0.5, 0.0));
    EXPECT_DOUBLE_EQ(p.distance, 0.3);
    EXPECT_DOUBLE_EQ(p.g0, 0.3);
    EXPECT_EQ(p.n, Vec3::UnitZ());
    // Below the triangle: the gap is negative, the distance not.
    const auto q = contact::project_on_triangle(Vec3(0.5, 1.0, -0.2), a, b, c);
    EXPECT_EQ(q.where, TriangleFeature::interior);
    EXPECT_EQ(q.bary[0], 0.25);
    EXPECT_EQ(q.bary[1], 0.25);
    EXPECT_EQ(q.bary[2], 0.5);
    EXPECT_DOUBLE_EQ(q.g0, -0.2);
    EXPECT_DOUBLE_EQ(q.distance, 0.2);
}

TEST(Search3, ProjectionOnEachEdgeHasAZeroCoordinateOppositeIt) {
    const Vec3 a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
    // Edge ab (opposite vertex 2): the closest point (1, 0, 0).
    const auto p2 = contact::project_on_triangle(Vec3(1, -1, 0.5), a, b, c);
    EXPECT_EQ(p2.where, TriangleFeature::edge);
    EXPECT_EQ(p2.feature, 2);
    EXPECT_EQ(p2.bary[0], 0.5);
    EXPECT_EQ(p2.bary[1], 0.5);
    EXPECT_EQ(p2.bary[2], 0.0);
    EXPECT_EQ(p2.point, Vec3(1, 0, 0));
    EXPECT_DOUBLE_EQ(p2.distance, std::sqrt(1.25));
    EXPECT_DOUBLE_EQ(p2.g0, 0.5); // the distance to the plane (the triangle's own normal)
    // Edge ca (opposite vertex 1): the closest point (0, 0.5, 0) = 0.75 a + 0.25 c.
    const auto p1 = contact::project_on_triangle(Vec3(-1, 0.5, 0.2), a, b, c);
    EXPECT_EQ(p1.where, TriangleFeature::edge);
    EXPECT_EQ(p1.feature, 1);
    EXPECT_EQ(p1.bary[0], 0.75);
    EXPECT_EQ(p1.bary[1], 0.0);
    EXPECT_EQ(p1.bary[2], 0.25);
    EXPECT_EQ(p1.point, Vec3(0, 0.5, 0));
    EXPECT_DOUBLE_EQ(p1.distance, std::sqrt(1.04));
    // Edge bc (opposite vertex 0): the closest point (1, 1, 0).
    const auto p0 = contact::project_on_triangle(Vec3(1.5, 1.5, -0.25), a, b, c);
    EXPECT_EQ(p0.where, TriangleFeature::edge);
    EXPECT_EQ(p0.feature, 0);
    EXPECT_EQ(p0.bary[0], 0.0);
    EXPECT_EQ(p0.bary[1], 0.5);
    EXPECT_EQ(p0.bary[2], 0.5);
    EXPECT_DOUBLE_EQ(p0.distance, 0.75);
    EXPECT_DOUBLE_EQ(p0.g0, -0.25);
    // Exactly over an edge counts as the edge.
    const auto on = contact::project_on_triangle(Vec3(0.5, 0, 1), a, b, c);
    EXPECT_EQ(on.where, TriangleFeature::edge);
    EXPECT_EQ(on.feature, 2);
    EXPECT_EQ(on.bary[1], 0.25);
}

TEST(Search3, ProjectionAtEachVertexIsThatVertex) {
    const Vec3 a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
    const std::array<Vec3, 3> x{Vec3(-1, -1, 1), Vec3(3, -0.5, 0), Vec3(-0.5, 3, 0.1)};
    const std::array<Vec3, 3> corner{a, b, c};
    for (int k = 0; k < 3; ++k) {
        const auto p = contact::project_on_triangle(x[k], a, b, c);
        EXPECT_EQ(p.where, TriangleFeature::vertex) << k;
        EXPECT_EQ(p.feature, k);
        for (int j = 0; j < 3; ++j)
            EXPECT_EQ(p.bary[j], j == k ? 1.0 : 0.0) << k << " " << j;
        EXPECT_EQ(p.point, corner[k]);
        EXPECT_DOUBLE_EQ(p.distance, (x[k] - corner[k]).norm());
        EXPECT_DOUBLE_EQ(p.g0, x[k].z());
    }
}

TEST(Search3, ProjectionOnASkewTriangleSumsToOneAndIsTheClosestPoint) {
    // The closest point is where the gradient of |x - p|^2 is normal to the triangle: inside,
    // x - p is along the normal.
    const Vec3 a(0.1, -0.3, 0.7), b(1.3, 0.2, 0.4), c(0.4, 1.1, 1.5);
    const Vec3 x(0.6, 0.4, 1.6);
    const auto p = contact::project_on_triangle(x, a, b, c);
    ASSERT_EQ(p.where, TriangleFeature::interior);
    EXPECT_NEAR(p.bary[0] + p.bary[1] + p.bary[2], 1.0, 1e-15);
    const Vec3 n = (b - a).cross(c - a).normalized();
    EXPECT_LE(((x - p.point) - p.g0 * n).norm(), 1e-15);
    EXPECT_NEAR(p.g0, n.dot(x - a), 1e-15);
    EXPECT_NEAR(p.distance, std::abs(n.dot(x - a)), 1e-15);
    EXPECT_LE((p.point - (p.bary[0] * a + p.bary[1] * b + p.bary[2] * c)).norm(), 1e-15);
}

TEST(Search3, DegenerateTriangleIsRefusedNamingItsCorners) {
    EXPECT_EQ(search3_refusal([] {
                  contact::project_on_triangle(Vec3::Zero(), Vec3(0, 0, 0), Vec3(1, 1, 1),
                                               Vec3(2, 2, 2));
              }),
              "contact search: a target triangle has zero area, its corners (0, 0, 0), (1, 1, 1), "
              "(2, 2, 2)");
    const std::vector<Vec3> v{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(2, 0, 0)};
    EXPECT_EQ(search3_refusal([&] {
                  contact::FacetIndex3(v, {{{0, 1, 2}}, {{0, 1, 3}}});
              }),
              "contact search: target facet (0, 1, 3) is degenerate (zero area): vertex 0 at (0, "
              "0, 0), vertex 1 at (1, 0, 0), vertex 3 at (2, 0, 0)");
    EXPECT_EQ(search3_refusal([&] { contact::FacetIndex3(v, {}); }),
              "contact search: no target facet to search");
    EXPECT_EQ(search3_refusal([&] {
                  contact::FacetIndex3(v, {{{0, 1, 4}}});
              }),
              "contact search: facet (0, 1, 4) refers to a vertex out of range (4 vertices)");
}

TEST(Search3, BoxFacesAreOrientedOutward) {
    const auto m = mesh::structured_box(Vec3(1, 2, 3), Vec3(2, 1, 0.5), 3, 2, 2);
    const std::array<std::pair<const char*, Vec3>, 6> sides{{{"xmin", -Vec3::UnitX()},
                                                             {"xmax", Vec3::UnitX()},
                                                             {"ymin", -Vec3::UnitY()},
                                                             {"ymax", Vec3::UnitY()},
                                                             {"zmin", -Vec3::UnitZ()},
                                                             {"zmax", Vec3::UnitZ()}}};
    for (const auto& [tag, normal] : sides) {
        const auto index = search3_index(m, tag);
        ASSERT_GT(index.facets().size(), 0u) << tag;
        for (int i = 0; i < static_cast<int>(index.facets().size()); ++i)
            EXPECT_LE((index.facet_normal(i) - normal).norm(), 1e-15) << tag << " facet " << i;
    }
    // xmax has 2 x 2 squares (y, z) of 0.5 x 0.25, two triangles each.
    EXPECT_EQ(contact::target_facets3(m, m.tag("xmax")).size(), 8u);
}

TEST(Search3, BoxEdgesAndCornersTakeTheAngleWeightedNormal) {
    // The whole boundary of the unit cube as the target. Whatever the diagonals, the faces meet
    // each corner with a right angle each: the corner's normal is (1, 1, 1) / sqrt 3 (a plain
    // mean of the triangles' normals would depend on how many triangles meet there).
    auto m = mesh::structured_box(Vec3::Zero(), Vec3(1, 1, 1), 2, 2, 2);
    const int all = m.add_tag("all");
    for (auto& f : m.boundary)
        f.tag = all;
    const auto index = search3_index(m, "all");
    // Corner (1, 1, 1), from outside: the vertex normal and the gap along it.
    const Vec3 x(1.2, 1.5, 1.1);
    const auto corner = index.closest(x, 1.0);
    ASSERT_TRUE(corner);
    EXPECT_EQ(corner->where, TriangleFeature::vertex);
    EXPECT_EQ(corner->point, Vec3(1, 1, 1));
    EXPECT_LE((corner->n - Vec3(1, 1, 1).normalized()).norm(), 1e-15);
    EXPECT_NEAR(corner->g0, 0.8 / std::sqrt(3.0), 1e-15);
    EXPECT_NEAR(corner->distance, std::sqrt(0.3), 1e-15);
    // Every corner (i, j, k) in {0, 2}^3 of the 2 x 2 x 2 cells: the faces meet it with one or
    // two triangles each (at (1, 0, 0): one of zmin, one of ymin, two of xmax, where the plain
    // mean of the triangle normals would lean to (2, -1, -1)), always (+-1, +-1, +-1) / sqrt 3.
    for (int k : {0, 2})
        for (int j : {0, 2})
            for (int i : {0, 2}) {
                const int v = (k * 3 + j) * 3 + i;
                const Vec3 expect = Vec3(i - 1, j - 1, k - 1).normalized();
                EXPECT_LE((index.vertex_normal(v) - expect).norm(), 1e-15) << "vertex " << v;
            }
    // The edge x = y = 1: the mean of the normals of xmax and ymax.
    const auto edge = index.closest(Vec3(1.3, 1.4, 0.75), 1.0);
    ASSERT_TRUE(edge);
    EXPECT_EQ(edge->where, TriangleFeature::edge);
    EXPECT_LE((edge->point - Vec3(1, 1, 0.75)).norm(), 1e-15);
    EXPECT_LE((edge->n - Vec3(1, 1, 0).normalized()).norm(), 1e-15);
    EXPECT_NEAR(edge->g0, 0.7 / std::sqrt(2.0), 1e-15);
    EXPECT_NEAR(edge->distance, 0.5, 1e-15);
    // Inside the box near its top: the top's normal, a negative gap (penetration).
    const auto inside = index.closest(Vec3(0.3, 0.6, 0.9), 1.0);
    ASSERT_TRUE(inside);
    EXPECT_EQ(inside->where, TriangleFeature::interior);
    EXPECT_LE((inside->n - Vec3::UnitZ()).norm(), 1e-15);
    EXPECT_NEAR(inside->g0, -0.1, 1e-15);
    // A point on an inner edge of a flat face (a square's diagonal): the face's normal.
    const auto diag = index.closest(Vec3(0.25, 0.25, 1.3), 1.0);
    ASSERT_TRUE(diag);
    EXPECT_LE((diag->n - Vec3::UnitZ()).norm(), 1e-15);
    EXPECT_NEAR(diag->g0, 0.3, 1e-15);
    // The local size: the longest edge of the face triangles, the diagonal of a 0.5 square.
    EXPECT_NEAR(index.local_size(Vec3(0.3, 0.6, 1.2)), std::sqrt(0.5), 1e-15);
}

TEST(Search3, FlatNonMatchingInterfaceFindsEveryNodeAndReproducesLinearFields) {
    // Lower box 3 x 3 cells across, upper box 4 x 4 cells, touching at z = 1.
    const auto m = search3_stack(3, 4);
    const auto contactors = m.vertices_with_tag(m.tag("lower_zmax"));
    ASSERT_EQ(contactors.size(), 16u);
    const auto reference = search3_index(m, "upper_zmin");
    const auto res = contact::node_on_facet_search3(m, contactors, m.tag("upper_zmin"), reference,
                                                    0.5, 0.3, 10.0, 2);
    EXPECT_TRUE(res.not_found.empty());
    ASSERT_EQ(res.elements.size(), contactors.size());
    const auto f = [](const Vec3& x) { return 1.0 + 2.0 * x.x() - 3.0 * x.y() + 5.0 * x.z(); };
    for (size_t i = 0; i < contactors.size(); ++i) {
        const auto& e = res.elements[i];
        EXPECT_EQ(e.vertex[0], contactors[i]);
        EXPECT_EQ(e.n_nodes(), 4);
        double sum = 0.0;
        for (int j = 0; j < e.n_nodes(); ++j)
            sum += e.weight[static_cast<size_t>(j)];
        EXPECT_NEAR(sum, 0.0, 1e-15) << "node " << contactors[i];
        for (int j = 1; j < 4; ++j) {
            EXPECT_LE(e.weight[static_cast<size_t>(j)], 0.0);
            EXPECT_GE(e.weight[static_cast<size_t>(j)], -1.0);
        }
        // sum_j w_j f(x_j) = f(x_c) - f(projection) = 0: the planes coincide.
        EXPECT_NEAR(search3_apply(e, m, f), 0.0, 1e-14) << "node " << contactors[i];
        for (int k = 0; k < 3; ++k)
            EXPECT_NEAR(search3_apply(e, m, [k](const Vec3& x) { return x[k]; }), 0.0, 1e-15);
        EXPECT_LE((e.n - Vec3(0, 0, -1)).norm(), 1e-15);
        EXPECT_NEAR(e.g0, 0.0, 1e-15);
        EXPECT_LE((e.t.col(0).cross(e.t.col(1)) - e.n).norm(), 1e-15);
        EXPECT_EQ(e.pair, 2);
        EXPECT_DOUBLE_EQ(e.mu, 0.3);
        EXPECT_DOUBLE_EQ(e.r, 10.0);
    }
}

TEST(Search3, FlatInterfaceWithAGapGivesItAlongTheNormal) {
    const auto m = search3_stack(3, 4, 0.01);
    const auto contactors = m.vertices_with_tag(m.tag("lower_zmax"));
    const auto reference = search3_index(m, "upper_zmin");
    const auto res = contact::node_on_facet_search3(m, contactors, m.tag("upper_zmin"), reference,
                                                    0.5, 0.0, 1.0, 0);
    ASSERT_EQ(res.elements.size(), 16u);
    for (const auto& e : res.elements) {
        EXPECT_NEAR(e.g0, 0.01, 1e-15);
        // sum_j w_j x_j = x_c - p = g0 n.
        for (int k = 0; k < 3; ++k)
            EXPECT_NEAR(search3_apply(e, m, [k](const Vec3& x) { return x[k]; }), 0.01 * e.n[k],
                        1e-15);
    }
}

TEST(Search3, NodesBeyondTheRimOfTheTargetAreNotFound) {
    // The upper box shifted by 0.5 in x: the lower nodes at x = 0 and 1/3 lie beyond its rim
    // (not found, in input order), those at x = 2/3 and 1 under it (x = 1: under its inside).
    const auto m = search3_stack(3, 4, 0.0, 0.5);
    const auto contactors = m.vertices_with_tag(m.tag("lower_zmax"));
    const auto reference = search3_index(m, "upper_zmin");
    const auto res = contact::node_on_facet_search3(m, contactors, m.tag("upper_zmin"), reference,
                                                    2.0, 0.0, 1.0, 0);
    std::vector<int> expect_missing, expect_found;
    for (int c : contactors)
        (m.vertices[static_cast<size_t>(c)].x() < 0.5 ? expect_missing : expect_found).push_back(c);
    ASSERT_EQ(expect_missing.size(), 8u);
    EXPECT_EQ(res.not_found, expect_missing);
    ASSERT_EQ(res.elements.size(), expect_found.size());
    for (size_t i = 0; i < expect_found.size(); ++i)
        EXPECT_EQ(res.elements[i].vertex[0], expect_found[i]);
    // On the rim itself (the upper box's edge x = 0.5 on a contactor's line) a node counts as
    // under it: the lower box with 2 cells has nodes at x = 0.5.
    const auto m2 = search3_stack(2, 4, 0.0, 0.5);
    const auto c2 = m2.vertices_with_tag(m2.tag("lower_zmax"));
    const auto res2 = contact::node_on_facet_search3(
        m2, c2, m2.tag("upper_zmin"), search3_index(m2, "upper_zmin"), 2.0, 0.0, 1.0, 0);
    EXPECT_EQ(res2.elements.size(), 6u); // x = 0.5 and 1
    EXPECT_EQ(res2.not_found.size(), 3u);
}

TEST(Search3, ContactNodesNestUnderRefinementWithTheLevelZeroReference) {
    // Level 1 of the stacked boxes, the decision on the level-0 facets: every top node of the
    // lower box is a contact node, and the elements reproduce linear fields.
    const auto m0 = search3_stack(3, 4);
    const auto m1 = mesh::refine(m0);
    const auto reference = search3_index(m0, "upper_zmin");
    const auto contactors = m1.vertices_with_tag(m1.tag("lower_zmax"));
    ASSERT_EQ(contactors.size(), 49u);
    const auto res = contact::node_on_facet_search3(m1, contactors, m1.tag("upper_zmin"), reference,
                                                    0.5, 0.0, 1.0, 0);
    EXPECT_TRUE(res.not_found.empty());
    ASSERT_EQ(res.elements.size(), 49u);
    for (const auto& e : res.elements) {
        for (int j = 1; j < 4; ++j) // targets of level 1 (the upper box's refined faces)
            EXPECT_EQ(m1.vertices[static_cast<size_t>(e.vertex[static_cast<size_t>(j)])].z(), 1.0);
        EXPECT_NEAR(search3_apply(e, m1, [](const Vec3& x) { return 4.0 * x.x() + x.y(); }), 0.0,
                    1e-14);
    }
}

TEST(Search3, CurvedTargetGivesTheDistanceToTheFacetPlane) {
    const auto ball = search3_ball(2);
    const auto facets = contact::target_facets3(ball, ball.tag("ball"));
    ASSERT_EQ(facets.size(), 128u);
    // Contactor vertices off each facet's centroid along its normal, outside (+0.05) and inside
    // (-0.01): the closest point is the centroid, g0 the distance to the facet's plane.
    auto m = ball;
    std::vector<int> contactors;
    std::vector<std::pair<size_t, double>> expect; // facet, offset
    for (size_t i = 0; i < facets.size(); ++i) {
        const auto& v = facets[i].v;
        const Vec3 a = m.vertices[static_cast<size_t>(v[0])];
        const Vec3 b = m.vertices[static_cast<size_t>(v[1])];
        const Vec3 c = m.vertices[static_cast<size_t>(v[2])];
        const Vec3 n = (b - a).cross(c - a).normalized();
        EXPECT_GT(n.dot(a + b + c), 0.0) << "facet " << i << " faces inward";
        for (double offset : {0.05, -0.01}) {
            contactors.push_back(m.n_vertices());
            m.vertices.push_back((a + b + c) / 3.0 + offset * n);
            expect.emplace_back(i, offset);
        }
    }
    const auto reference = search3_index(m, "ball");
    const auto res =
        contact::node_on_facet_search3(m, contactors, m.tag("ball"), reference, 1.0, 0.0, 1.0, 0);
    EXPECT_TRUE(res.not_found.empty());
    ASSERT_EQ(res.elements.size(), contactors.size());
    for (size_t k = 0; k < contactors.size(); ++k) {
        const auto& e = res.elements[k];
        const auto& [i, offset] = expect[k];
        for (size_t j = 0; j < 3; ++j) {
            EXPECT_EQ(e.vertex[j + 1], facets[i].v[j]) << "contactor " << k;
            EXPECT_NEAR(e.weight[j + 1], -1.0 / 3.0, 1e-14) << "contactor " << k;
        }
        EXPECT_NEAR(e.g0, offset, 1e-15) << "contactor " << k;
        EXPECT_LE((e.n - reference.facet_normal(static_cast<int>(i))).norm(), 1e-15);
    }
    // Over the octahedron's vertex e_z, which four symmetric facets share: the vertex normal
    // is e_z, the gap the height above it.
    const auto top = reference.closest(Vec3(0, 0, 1.2), 1.0);
    ASSERT_TRUE(top);
    EXPECT_EQ(top->where, TriangleFeature::vertex);
    EXPECT_EQ(top->point, Vec3::UnitZ());
    EXPECT_LE((top->n - Vec3::UnitZ()).norm(), 1e-15);
    EXPECT_NEAR(top->g0, 0.2, 1e-15);
}

TEST(Search3, NodeOnNodeOnMatchingBoxesPairsEachNodeWithItsTwin) {
    int off = 0;
    const auto m = search3_stack(3, 3, 0.0, 0.0, &off);
    const auto contactors = m.vertices_with_tag(m.tag("lower_zmax"));
    const auto res =
        contact::node_on_node_search3(m, contactors, m.tag("upper_zmin"), 0.1, 0.2, 5.0, 1);
    EXPECT_TRUE(res.not_found.empty());
    ASSERT_EQ(res.elements.size(), 16u);
    for (size_t k = 0; k < contactors.size(); ++k) {
        const auto& e = res.elements[k];
        const int c = contactors[k];
        // Lower vertex (i, j, 1) is c = (4 + j) 4 + i; its twin the upper (i, j, 0).
        const int i = c % 4, j = (c / 4) % 4;
        EXPECT_EQ(c, 16 + 4 * j + i);
        EXPECT_EQ(e.n_nodes(), 2);
        EXPECT_EQ(e.vertex[0], c);
        EXPECT_EQ(e.vertex[1], off + 4 * j + i);
        EXPECT_EQ(e.weight[0], 1.0);
        EXPECT_EQ(e.weight[1], -1.0);
        EXPECT_LE((e.n - Vec3(0, 0, -1)).norm(), 1e-15);
        EXPECT_EQ(e.g0, 0.0);
        EXPECT_EQ(e.pair, 1);
    }
    // A gap of 0.001 is within the tolerance (0.1 of a third): g0 = 0.001 along n = -e_z.
    const auto gap = search3_stack(3, 3, 0.001);
    const auto res_gap =
        contact::node_on_node_search3(gap, contactors, gap.tag("upper_zmin"), 0.1, 0.0, 1.0, 0);
    ASSERT_EQ(res_gap.elements.size(), 16u);
    for (const auto& e : res_gap.elements)
        EXPECT_NEAR(e.g0, 0.001, 1e-15);
    // Shifted by 0.1 in x (0.3 of a cell): nothing within the tolerance.
    const auto shifted = search3_stack(3, 3, 0.0, 0.1);
    const auto res_shifted = contact::node_on_node_search3(
        shifted, contactors, shifted.tag("upper_zmin"), 0.1, 0.0, 1.0, 0);
    EXPECT_TRUE(res_shifted.elements.empty());
    EXPECT_EQ(res_shifted.not_found, contactors);
}

TEST(Search3, TreeAgreesWithABruteForceScan) {
    // The faceted sphere (closed: no rim) and pseudo-random points around it.
    const auto m = search3_ball(2);
    const auto facets = contact::target_facets3(m, m.tag("ball"));
    const contact::FacetIndex3 index(m.vertices, facets);
    std::mt19937 gen(12345);
    std::uniform_real_distribution<double> coord(-1.4, 1.4);
    int found = 0, unique = 0;
    for (int s = 0; s < 400; ++s) {
        const Vec3 x(coord(gen), coord(gen), coord(gen));
        const double radius = 0.3;
        std::vector<std::pair<double, int>> all;
        for (int i = 0; i < static_cast<int>(facets.size()); ++i) {
            const auto& e = index.corners(i);
            all.emplace_back(contact::project_on_triangle(x, e[0], e[1], e[2]).distance, i);
        }
        std::sort(all.begin(), all.end());
        std::vector<int> within;
        for (const auto& [d, i] : all)
            if (d <= radius) within.push_back(i);
        std::sort(within.begin(), within.end());
        EXPECT_EQ(index.within(x, radius), within) << "point " << s;
        const auto hit = index.closest(x, radius);
        ASSERT_EQ(hit.has_value(), all[0].first <= radius) << "point " << s;
        if (!hit) continue;
        ++found;
        EXPECT_NEAR(hit->distance, all[0].first, 1e-12) << "point " << s;
        if (all[1].first - all[0].first > 1e-9) {
            ++unique;
            EXPECT_EQ(hit->facet, all[0].second) << "point " << s;
            EXPECT_EQ(index.local_size(x),
                      [&] {
                          const auto& e = index.corners(all[0].second);
                          return std::max(
                              {(e[1] - e[0]).norm(), (e[2] - e[1]).norm(), (e[0] - e[2]).norm()});
                      }())
                << "point " << s;
        }
    }
    // The sample covers both outcomes.
    EXPECT_GT(found, 50);
    EXPECT_LT(found, 400);
    EXPECT_GT(unique, 40);
}

TEST(Search3, SkippedVertexIsNotItsOwnTarget) {
    // A contactor vertex that is a corner of target facets finds the nearest other facet only.
    const auto m = mesh::structured_box(Vec3::Zero(), Vec3(1, 1, 1), 1, 1, 1);
    const auto index = search3_index(m, "zmax");
    // Vertex 4 = (0, 0, 1) is a corner of both zmax triangles: skipping it leaves none.
    EXPECT_FALSE(index.closest(m.vertices[4], 1.0, 4));
    EXPECT_TRUE(index.closest(m.vertices[4], 1.0));
}

TEST(Search3, MissingTargetTagAndBadElementsAreRefused) {
    auto m = mesh::structured_box(Vec3::Zero(), Vec3(1, 1, 1), 1, 1, 1);
    const int none = m.add_tag("nothing");
    const auto reference = search3_index(m, "zmax");
    EXPECT_EQ(search3_refusal([&] {
                  contact::node_on_facet_search3(m, {0}, none, reference, 1.0, 0.0, 1.0, 0);
              }),
              "contact search: the mesh has no boundary face tagged 'nothing' to search");
    EXPECT_EQ(
        search3_refusal([&] { contact::node_on_node_search3(m, {0}, none, 0.1, 0.0, 1.0, 0); }),
        "contact search: the mesh has no boundary face tagged 'nothing' to search");
    const contact::Facet3 f{{1, 2, 3}};
    EXPECT_EQ(search3_refusal([&] {
                  contact::node_on_facet3(0, f, {0.5, 0.6, -0.1}, Vec3::UnitZ(), 0.0, 0.0, 1.0, 0);
              }),
              "node_on_facet3: barycentric coordinates must lie in [0, 1], found (0.5, 0.6, -0.1)");
    EXPECT_EQ(search3_refusal([&] {
                  contact::node_on_facet3(2, f, {0.5, 0.5, 0.0}, Vec3::UnitZ(), 0.0, 0.0, 1.0, 0);
              }),
              "node_on_facet3: contactor vertex 2 is a corner of its facet");
    EXPECT_EQ(
        search3_refusal([&] { contact::node_on_node<3>(0, 1, Vec3(0, 0, 2), 0.0, 0.0, 1.0, 0); }),
        "node_on_node: the normal must have unit length, found |n| = 2");
    EXPECT_EQ(search3_refusal([&] {
                  contact::node_on_facet3(0, contact::Facet3{{1, 1, 3}}, {0.2, 0.3, 0.5},
                                          Vec3::UnitZ(), 0.0, 0.0, 1.0, 0);
              }),
              "node_on_facet_weighted: target vertex 1 repeats");
    // A well-formed element: weights (1, -bary), the frame of tangent_basis.
    const auto e = contact::node_on_facet3(0, f, {0.2, 0.3, 0.5}, Vec3::UnitX(), 0.1, 0.4, 3.0, 5);
    EXPECT_EQ(e.n_nodes(), 4);
    EXPECT_EQ(e.weight[1], -0.2);
    EXPECT_EQ(e.weight[2], -0.3);
    EXPECT_EQ(e.weight[3], -0.5);
    EXPECT_EQ(e.vertex[3], 3);
    EXPECT_EQ(e.t, contact::tangent_basis<3>(Vec3::UnitX()));
    EXPECT_EQ(e.n_multipliers(), 3);
    const auto nn = contact::node_on_node<3>(0, 1, Vec3::UnitY(), 0.2, 0.0, 3.0, 5);
    EXPECT_EQ(nn.vertex, (std::vector<int>{0, 1}));
    EXPECT_EQ(nn.weight, (std::vector<double>{1.0, -1.0}));
    EXPECT_EQ(nn.t, contact::tangent_basis<3>(Vec3::UnitY()));
    EXPECT_EQ(nn.g0, 0.2);
    EXPECT_EQ(nn.n_multipliers(), 1);
}

TEST(Search3, IndexOfOneFacetAnswersLikeTheProjection) {
    // One triangle: CGAL's tree treats a single primitive apart.
    const std::vector<Vec3> v{Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 2, 0)};
    const contact::FacetIndex3 index(v, {{{0, 1, 2}}});
    EXPECT_DOUBLE_EQ(index.local_size(Vec3(5, 5, 5)), std::sqrt(8.0));
    EXPECT_DOUBLE_EQ(index.max_size(), std::sqrt(8.0));
    const auto hit = index.closest(Vec3(0.5, 0.5, 0.3), 1.0);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->facet, 0);
    EXPECT_EQ(hit->bary[0], 0.5);
    EXPECT_DOUBLE_EQ(hit->g0, 0.3);
    // Every edge is on the rim: beyond it nothing is found, even within the radius.
    EXPECT_TRUE(index.is_rim_edge(0, 1));
    EXPECT_FALSE(index.closest(Vec3(1, -0.1, 0.1), 1.0));
    EXPECT_FALSE(index.closest(Vec3(0.5, 0.5, 1.3), 1.0)); // too far
    EXPECT_EQ(index.within(Vec3(1, -0.1, 0.1), 1.0), std::vector<int>{0});
}

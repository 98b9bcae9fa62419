// SPDX-License-Identifier: MIT
// Whole-mesh transformations: a half domain mirrored about a vertical line, bodies merged.
#include "core/check.hpp"
#include "mesh/mesh.hpp"
#include "mesh/transform.hpp"

#include <gtest/gtest.h>

using namespace mlc;

namespace {

/// The right half [1, 3] x [0, 1] of a domain symmetric about x = 1: 2 x 1 squares, vertex
/// (i, j) at index 3 j + i, attribute 3, the "right" edge on a circle (geometry irrelevant here).
mesh::Mesh right_half() {
    auto h = mesh::structured_rectangle(Vec2(1, 0), Vec2(2, 1), 2, 1);
    h.attribute.assign(h.cells.size(), 3);
    h.shapes.push_back({Vec2(2.5, 0.5), 0.75});
    for (auto& e : h.boundary)
        if (e.tag == h.tag("right")) e.shape = 0;
    return h;
}

/// Whether the directed edge (a, b) is an edge of a triangle in that direction (then the triangle,
/// counter-clockwise, lies to its left).
bool has_directed_edge(const mesh::Mesh& m, int a, int b) {
    for (const auto& t : m.cells)
        for (int k = 0; k < 3; ++k)
            if (t[static_cast<size_t>(k)] == a && t[static_cast<size_t>((k + 1) % 3)] == b)
                return true;
    return false;
}

} // namespace

TEST(MirrorAboutX, ImagesVerticesTrianglesCirclesAndEdges) {
    const auto h = right_half();
    const auto m = mesh::mirror_about_x(h, 1.0);
    // The 6 vertices kept in place, the 4 off the line (1, 2, 4, 5) mirrored in that order.
    ASSERT_EQ(m.n_vertices(), 10);
    for (int v = 0; v < 6; ++v)
        EXPECT_EQ(m.vertices[static_cast<size_t>(v)], h.vertices[static_cast<size_t>(v)]);
    EXPECT_EQ(m.vertices[6], Vec2(0, 0));
    EXPECT_EQ(m.vertices[7], Vec2(-1, 0));
    EXPECT_EQ(m.vertices[8], Vec2(0, 1));
    EXPECT_EQ(m.vertices[9], Vec2(-1, 1));
    // Triangles doubled, all counter-clockwise, total area twice the half's (2 each).
    ASSERT_EQ(m.n_cells(), 8);
    double area = 0.0;
    for (int t = 0; t < m.n_cells(); ++t) {
        EXPECT_GT(m.signed_measure(t), 0.0) << "triangle " << t;
        area += m.signed_measure(t);
    }
    EXPECT_DOUBLE_EQ(area, 4.0);
    for (int t = 0; t < 4; ++t)
        EXPECT_EQ(m.cells[static_cast<size_t>(t)], h.cells[static_cast<size_t>(t)]);
    EXPECT_EQ(m.attribute, std::vector<int>(8, 3));
    // The circle is mirrored after the original.
    ASSERT_EQ(m.shapes.size(), 2u);
    EXPECT_EQ(m.shapes[1].center, Vec2(-0.5, 0.5));
    EXPECT_EQ(m.shapes[1].radius, 0.75);
    // Boundary: the "left" edge lies on the mirror line and is dropped; the 5 others are kept,
    // each followed by its reversed image with the same tag.
    EXPECT_EQ(m.tag_names, h.tag_names);
    ASSERT_EQ(m.boundary.size(), 10u);
    size_t k = 0;
    for (const auto& e : h.boundary) {
        if (e.tag == h.tag("left")) continue;
        const auto& kept = m.boundary[k];
        const auto& img = m.boundary[k + 1];
        EXPECT_EQ(kept.v0, e.v0);
        EXPECT_EQ(kept.v1, e.v1);
        EXPECT_EQ(kept.tag, e.tag);
        EXPECT_EQ(kept.shape, e.shape);
        EXPECT_EQ(img.tag, e.tag);
        EXPECT_EQ(img.shape, e.shape >= 0 ? 1 : -1);
        // The image runs from the mirror of v1 to the mirror of v0.
        const Vec2 a = m.vertices[static_cast<size_t>(img.v0)];
        const Vec2 b = m.vertices[static_cast<size_t>(img.v1)];
        const Vec2 a0 = h.vertices[static_cast<size_t>(e.v1)];
        const Vec2 b0 = h.vertices[static_cast<size_t>(e.v0)];
        EXPECT_EQ(a, Vec2(2.0 - a0.x(), a0.y()));
        EXPECT_EQ(b, Vec2(2.0 - b0.x(), b0.y()));
        k += 2;
    }
    for (const auto& e : m.boundary)
        EXPECT_TRUE(has_directed_edge(m, e.v0, e.v1)) << "edge " << e.v0 << " -> " << e.v1;
    // The mirrored bottom edges: (0,0) -> (1,0) becomes (0,0)' = vertex 6 ... see the layout.
    EXPECT_EQ(m.vertices_with_tag(m.tag("bottom")), (std::vector<int>{0, 1, 2, 6, 7}));
    EXPECT_EQ(m.vertices_with_tag(m.tag("right")), (std::vector<int>{2, 5, 7, 9}));
    EXPECT_TRUE(m.vertices_with_tag(m.tag("left")).empty());
}

TEST(MirrorAboutX, RejectsBothSidesAndNoVertexOnTheLine) {
    const auto h = right_half();
    EXPECT_THROW(mesh::mirror_about_x(h, 2.0), InvalidInput); // the line cuts the domain
    EXPECT_THROW(mesh::mirror_about_x(h, 0.5), InvalidInput); // no vertex on the line
}

TEST(MergeInto, RenumbersVerticesCirclesAndMergesTagsByName) {
    mesh::Mesh all;
    const auto a = mesh::structured_rectangle(Vec2(0, 0), Vec2(1, 1), 1, 1);
    mesh::merge_into(all, a, 0);
    EXPECT_EQ(all.n_vertices(), 4);
    EXPECT_EQ(all.n_cells(), 2);
    EXPECT_EQ(all.attribute, (std::vector<int>{0, 0}));
    EXPECT_EQ(all.boundary.size(), 4u);

    // A second body above the first: 2 x 1 squares, a circle, one new tag and its own attribute
    // (which merge_into replaces by the body number).
    auto b = mesh::structured_rectangle(Vec2(0, 1), Vec2(2, 1), 2, 1);
    b.attribute.assign(b.cells.size(), 7);
    b.shapes.push_back({Vec2(1, 3), 1.0});
    const int contact = b.add_tag("contact");
    for (auto& e : b.boundary)
        if (e.tag == b.tag("bottom")) {
            e.tag = contact;
            e.shape = 0;
        }
    all.shapes.push_back({Vec2(5, 5), 2.0}); // one circle already in `all`
    mesh::merge_into(all, b, 1);

    ASSERT_EQ(all.n_vertices(), 4 + 6);
    ASSERT_EQ(all.n_cells(), 2 + 4);
    for (int v = 0; v < 6; ++v)
        EXPECT_EQ(all.vertices[static_cast<size_t>(4 + v)], b.vertices[static_cast<size_t>(v)]);
    for (size_t t = 0; t < b.cells.size(); ++t)
        for (size_t k = 0; k < 3; ++k)
            EXPECT_EQ(all.cells[2 + t][k], b.cells[t][k] + 4);
    EXPECT_EQ(all.attribute, (std::vector<int>{0, 0, 1, 1, 1, 1}));
    ASSERT_EQ(all.shapes.size(), 2u);
    EXPECT_EQ(all.shapes[1].center, Vec2(1, 3));
    // Tags: bottom/right/top/left keep their ids 0..3, "contact" gets 4.
    EXPECT_EQ(all.tag_names.size(), 5u);
    EXPECT_EQ(all.tag("contact"), 4);
    for (const auto& name : {"bottom", "right", "top", "left"})
        EXPECT_EQ(all.tag(name), a.tag(name));
    ASSERT_EQ(all.boundary.size(), 4u + b.boundary.size());
    for (size_t k = 0; k < b.boundary.size(); ++k) {
        const auto& e = all.boundary[4 + k];
        const auto& eb = b.boundary[k];
        EXPECT_EQ(e.v0, eb.v0 + 4);
        EXPECT_EQ(e.v1, eb.v1 + 4);
        EXPECT_EQ(all.tag_name(e.tag), b.tag_name(eb.tag));
        EXPECT_EQ(e.shape, eb.shape >= 0 ? 1 : -1);
    }
    EXPECT_EQ(all.vertices_with_tag(all.tag("contact")), (std::vector<int>{4, 5, 6}));
    // Vertices (0,1) and (1,1) of the two bodies coincide but stay distinct: two bodies.
    EXPECT_NO_THROW(mesh::check_quality(all));
}

// SPDX-License-Identifier: MIT
// Contact search: closest facet, barycentric alpha, gap and frame on hand-made facets; node on
// node on a matching interface; contactor nodes that find nothing are reported.
#include "contact/search.hpp"
#include "core/check.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace mlc;

namespace {

/// A target polyline v0 = (2, 0) -> v1 = (1, 0) -> v2 = (0, 1) (the target body below-left, so
/// the outward normals are (0, 1) and (1, 1)/sqrt 2), plus contactor vertices 3.. at `pts`.
/// Only what the search reads is filled in (vertices, tagged boundary edges).
mesh::Mesh two_facets(const std::vector<Vec2>& pts) {
    mesh::Mesh m;
    m.vertices = {Vec2(2, 0), Vec2(1, 0), Vec2(0, 1)};
    for (const auto& p : pts)
        m.vertices.push_back(p);
    const int target = m.add_tag("target");
    m.boundary.push_back({0, 1, target, -1});
    m.boundary.push_back({1, 2, target, -1});
    return m;
}

std::vector<int> contactor_ids(int n) {
    std::vector<int> c;
    for (int i = 0; i < n; ++i)
        c.push_back(3 + i);
    return c;
}

} // namespace

TEST(ContactSearch, ProjectionOnAFacetGivesAlphaGapAndNormalExactly) {
    const auto p = contact::project_on_facet(Vec2(1.25, 0.3), Vec2(2, 0), Vec2(1, 0));
    EXPECT_DOUBLE_EQ(p.alpha, 0.75);
    EXPECT_DOUBLE_EQ(p.g0, 0.3);
    EXPECT_DOUBLE_EQ(p.distance, 0.3);
    EXPECT_DOUBLE_EQ(p.n.x(), 0.0);
    EXPECT_DOUBLE_EQ(p.n.y(), 1.0);
    // Beyond the end b: alpha clamped to 1, the gap is the distance to the facet's line.
    const auto q = contact::project_on_facet(Vec2(0.5, -0.2), Vec2(2, 0), Vec2(1, 0));
    EXPECT_DOUBLE_EQ(q.alpha, 1.0);
    EXPECT_DOUBLE_EQ(q.g0, -0.2);
    EXPECT_NEAR(q.distance, std::hypot(0.5, 0.2), 1e-15);
    EXPECT_THROW(contact::project_on_facet(Vec2(0, 0), Vec2(1, 1), Vec2(1, 1)), InvalidInput);
}

TEST(ContactSearch, NodeOnFacetElementsOnAHandMadePairOfFacets) {
    // Contactor 3 above facet (v0, v1); contactor 4 off the oblique facet (v1, v2).
    const auto m = two_facets({Vec2(1.25, 0.3), Vec2(0.25, 1.0)});
    const contact::FacetIndex reference(m.vertices, contact::target_facets(m, m.tag("target")));
    const auto res = contact::node_on_facet_search(m, contactor_ids(2), m.tag("target"), reference,
                                                   2.0, 0.3, 10.0, 7);
    ASSERT_EQ(res.elements.size(), 2u);
    EXPECT_TRUE(res.not_found.empty());
    const auto& a = res.elements[0];
    EXPECT_EQ(a.n_nodes(), 3);
    EXPECT_EQ(a.vertex[0], 3);
    EXPECT_EQ(a.vertex[1], 0);
    EXPECT_EQ(a.vertex[2], 1);
    // alpha = 0.75: weights (1, -(1 - alpha), -alpha).
    EXPECT_DOUBLE_EQ(a.weight[0], 1.0);
    EXPECT_DOUBLE_EQ(a.weight[1], -0.25);
    EXPECT_DOUBLE_EQ(a.weight[2], -0.75);
    EXPECT_DOUBLE_EQ(a.g0, 0.3);
    EXPECT_DOUBLE_EQ(a.n.y(), 1.0);
    EXPECT_DOUBLE_EQ(a.t.x(), 1.0); // t = (n_y, -n_x)
    EXPECT_EQ(a.pair, 7);
    EXPECT_DOUBLE_EQ(a.mu, 0.3);
    EXPECT_DOUBLE_EQ(a.r, 10.0);
    const auto& b = res.elements[1];
    EXPECT_EQ(b.vertex[1], 1);
    EXPECT_EQ(b.vertex[2], 2);
    // Relative to v1: (-0.75, 1), along d = (-1, 1): alpha = 1.75 / 2; n = (1, 1)/sqrt 2.
    EXPECT_NEAR(b.weight[2], -0.875, 1e-15);
    EXPECT_NEAR(b.weight[1], -0.125, 1e-15);
    EXPECT_NEAR(b.g0, 0.25 / std::sqrt(2.0), 1e-15);
    EXPECT_NEAR(b.n.x(), 1.0 / std::sqrt(2.0), 1e-15);
    EXPECT_NEAR(b.n.y(), 1.0 / std::sqrt(2.0), 1e-15);
    EXPECT_NEAR(b.t.x(), b.n.y(), 0.0);
    EXPECT_NEAR(b.t.y(), -b.n.x(), 0.0);
    // The relative displacement of a rigid translation vanishes: sum of weights = 0.
    EXPECT_NEAR(b.weight[0] + b.weight[1] + b.weight[2], 0.0, 1e-15);
}

TEST(ContactSearch, PenetratingNodeHasANegativeGap) {
    const auto m = two_facets({Vec2(1.5, -0.1)});
    const contact::FacetIndex reference(m.vertices, contact::target_facets(m, m.tag("target")));
    const auto res =
        contact::node_on_facet_search(m, {3}, m.tag("target"), reference, 2.0, 0.0, 1.0, 0);
    ASSERT_EQ(res.elements.size(), 1u);
    EXPECT_DOUBLE_EQ(res.elements[0].g0, -0.1);
    EXPECT_DOUBLE_EQ(res.elements[0].weight[2], -0.5);
}

TEST(ContactSearch, NodesBeyondEveryFacetAreReportedNotDropped) {
    // 3: far away (outside the radius); 4: beyond the free end v0 = (2, 0) of the target
    // boundary at zero height (within the radius, but over no facet); 5: a regular node.
    const auto m = two_facets({Vec2(8, 9), Vec2(2.3, 0.0), Vec2(1.5, 0.1)});
    const contact::FacetIndex reference(m.vertices, contact::target_facets(m, m.tag("target")));
    const auto res = contact::node_on_facet_search(m, contactor_ids(3), m.tag("target"), reference,
                                                   2.0, 0.0, 1.0, 0);
    ASSERT_EQ(res.not_found.size(), 2u);
    EXPECT_EQ(res.not_found[0], 3);
    EXPECT_EQ(res.not_found[1], 4);
    ASSERT_EQ(res.elements.size(), 1u);
    EXPECT_EQ(res.elements[0].vertex[0], 5);
}

TEST(ContactSearch, ConvexCornerOfTheTargetKeepsTheClampedProjection) {
    // Target (2, 0) -> (1, 0) -> (0, -1), body below: a convex corner at (1, 0). A point above
    // and left of it projects beyond both facets' extents, onto the shared vertex: kept, clamped
    // (alpha 1 on the first facet, the tie going to the lower index), g0 = distance to the line.
    mesh::Mesh m;
    m.vertices = {Vec2(2, 0), Vec2(1, 0), Vec2(0, -1), Vec2(0.9, 0.3)};
    const int tag = m.add_tag("target");
    m.boundary.push_back({0, 1, tag, -1});
    m.boundary.push_back({1, 2, tag, -1});
    const contact::FacetIndex index(m.vertices, contact::target_facets(m, tag));
    const auto hit = index.closest(Vec2(0.9, 0.3), 10.0);
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->facet, 0);
    EXPECT_DOUBLE_EQ(hit->alpha, 1.0);
    EXPECT_DOUBLE_EQ(hit->g0, 0.3);
    EXPECT_NEAR(hit->distance, std::hypot(0.1, 0.3), 1e-15);
    // A facet incident to the skipped vertex is never returned.
    const auto skip = index.closest(Vec2(1.5, 0.1), 10.0, 0);
    ASSERT_TRUE(skip.has_value());
    EXPECT_EQ(skip->facet, 1);
    // The local size is the length of the facet with the nearest midpoint.
    EXPECT_DOUBLE_EQ(index.local_size(Vec2(1.6, 0.0)), 1.0);
    EXPECT_DOUBLE_EQ(index.local_size(Vec2(0.4, -0.6)), std::sqrt(2.0));
}

TEST(ContactSearch, RadiusIsExactAgainstABruteForceScan) {
    // Many facets of very different lengths: the Kd-tree on midpoints must find the same
    // closest facet as a scan over all of them.
    mesh::Mesh m;
    const int tag = m.add_tag("t");
    double x = 0;
    for (int i = 0; i <= 40; ++i) {
        m.vertices.emplace_back(-x, 0.1 * std::sin(x));
        x += (i % 7 == 0) ? 1.5 : 0.05 * (1 + i % 3);
    }
    for (int i = 0; i < 40; ++i)
        m.boundary.push_back({i, i + 1, tag, -1});
    const contact::FacetIndex index(m.vertices, contact::target_facets(m, tag));
    ASSERT_GT(x, 11.0);
    for (int k = 0; k < 200; ++k) { // x inside the polyline's extent: never beyond its ends
        const Vec2 q(-0.5 - 0.05 * k, 0.2 * std::cos(k));
        double best = 1e300;
        for (int i = 0; i < 40; ++i)
            best = std::min(best, contact::project_on_facet(q, m.vertices[static_cast<size_t>(i)],
                                                            m.vertices[static_cast<size_t>(i + 1)])
                                      .distance);
        const auto hit = index.closest(q, 0.5);
        if (best <= 0.5) {
            ASSERT_TRUE(hit.has_value()) << "query " << k;
            EXPECT_NEAR(hit->distance, best, 1e-14) << "query " << k;
        } else {
            EXPECT_FALSE(hit.has_value()) << "query " << k;
        }
    }
}

TEST(ContactSearch, NodeOnNodeMatchesCoincidentVerticesWithAveragedNormal) {
    // Target v0 -> v1 -> v2 as above; contactors at v1 (a corner: normals (0,1) and (1,1)/sqrt2
    // averaged) and at v2 + 1e-9 (within the relative tolerance), and one unmatched.
    const auto m = two_facets({Vec2(1, 0), Vec2(1e-9, 1), Vec2(0.5, 0.5)});
    const auto res =
        contact::node_on_node_search(m, contactor_ids(3), m.tag("target"), 1e-6, 0.3, 1.0, 0);
    ASSERT_EQ(res.elements.size(), 2u);
    ASSERT_EQ(res.not_found.size(), 1u);
    EXPECT_EQ(res.not_found[0], 5);
    const auto& a = res.elements[0];
    EXPECT_EQ(a.n_nodes(), 2);
    EXPECT_EQ(a.vertex[1], 1);
    EXPECT_DOUBLE_EQ(a.weight[1], -1.0);
    const Vec2 expected = (Vec2(0, 1) + Vec2(1, 1) / std::sqrt(2.0)).normalized();
    EXPECT_NEAR((a.n - expected).norm(), 0.0, 1e-15);
    EXPECT_NEAR(a.g0, 0.0, 1e-15);
    const auto& b = res.elements[1];
    EXPECT_EQ(b.vertex[1], 2);
    EXPECT_NEAR(b.n.x(), 1.0 / std::sqrt(2.0), 1e-15);
    EXPECT_NEAR(b.g0, 1e-9 / std::sqrt(2.0), 1e-20);
}

TEST(ContactSearch, BadInputThrows) {
    const auto m = two_facets({Vec2(1.5, 0.1)});
    EXPECT_THROW(contact::FacetIndex(m.vertices, {}), InvalidInput);
    EXPECT_THROW(contact::FacetIndex(m.vertices, {{0, 9}}), InvalidInput);
    EXPECT_THROW(contact::node_on_facet(3, 0, 1, 1.5, Vec2(0, 1), 0, 0, 1, 0), InvalidInput);
    EXPECT_THROW(contact::node_on_facet(3, 0, 1, 0.5, Vec2(0, 2), 0, 0, 1, 0), InvalidInput);
    EXPECT_THROW(contact::node_on_node(3, 3, Vec2(0, 1), 0, 0, 1, 0), InvalidInput);
    mesh::Mesh none = m;
    const int other = none.add_tag("other");
    const contact::FacetIndex reference(m.vertices, contact::target_facets(m, m.tag("target")));
    EXPECT_THROW(contact::node_on_facet_search(none, {3}, other, reference, 2.0, 0, 1, 0),
                 InvalidInput);
}

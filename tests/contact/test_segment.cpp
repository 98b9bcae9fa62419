// SPDX-License-Identifier: MIT
// Segment-integrated (mortar-type, lumped) node-on-facet weights on a hand-made non-matching
// pair: weights (1, -M_ik / D_i) with D_i = int N_i ds and M_ik = int N_i N_k ds computed by hand,
// their sum zero, and the renormalisation by the covered part at an end of the target.
#include "contact/search.hpp"
#include "core/check.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

using namespace mlc;

namespace {

/// Target (body below) v0 = (2, 0) -> v1 = (1.2, 0) -> v2 = (0, 0): facets [1.2, 2] and [0, 1.2]
/// of y = 0, outward normal (0, 1). Contactor (body above) v6 = (-0.2, 0.1) -> v3 = (0.4, 0.1)
/// -> v4 = (1, 0.1) -> v5 = (1.6, 0.16): edges of length 0.6, 0.6 and L2 = |(0.6, 0.06)| (tilted,
/// so that ds along the contactor is L2 / 0.6 times dx there). v6 lies beyond the target's end.
mesh::Mesh non_matching_pair() {
    mesh::Mesh m;
    m.vertices = {Vec2(2, 0),     Vec2(1.2, 0),    Vec2(0, 0),     Vec2(0.4, 0.1),
                  Vec2(1.0, 0.1), Vec2(1.6, 0.16), Vec2(-0.2, 0.1)};
    const int target = m.add_tag("target");
    const int contactor = m.add_tag("contactor");
    m.boundary.push_back({0, 1, target, -1});
    m.boundary.push_back({1, 2, target, -1});
    m.boundary.push_back({6, 3, contactor, -1});
    m.boundary.push_back({3, 4, contactor, -1});
    m.boundary.push_back({4, 5, contactor, -1});
    return m;
}

std::map<int, double> target_weights(const contact::ContactElement& e) {
    std::map<int, double> w;
    for (int j = 1; j < e.n_nodes(); ++j)
        w[e.vertex[static_cast<size_t>(j)]] = e.weight[static_cast<size_t>(j)];
    return w;
}

} // namespace

TEST(SegmentWeights, EqualMikOverDiComputedByHandAndSumToZero) {
    const auto m = non_matching_pair();
    const contact::FacetIndex reference(m.vertices, contact::target_facets(m, m.tag("target")));
    const auto res =
        contact::node_on_facet_search(m, {3, 4, 6}, m.tag("target"), reference, 2.0, 0.3, 10.0, 2,
                                      contact::FacetIntegration::segment, m.tag("contactor"));
    ASSERT_EQ(res.elements.size(), 2u);
    ASSERT_EQ(res.not_found.size(), 1u);
    EXPECT_EQ(res.not_found[0], 6); // beyond the end of the target
    for (const auto& e : res.elements) {
        double sum = 0;
        for (int j = 0; j < e.n_nodes(); ++j)
            sum += e.weight[static_cast<size_t>(j)];
        EXPECT_NEAR(sum, 0.0, 1e-14);
        EXPECT_DOUBLE_EQ(e.weight[0], 1.0);
        // Frame and gap as for the nodal variant: the facet under the node.
        EXPECT_DOUBLE_EQ(e.n.y(), 1.0);
        EXPECT_DOUBLE_EQ(e.t.x(), 1.0);
        EXPECT_NEAR(e.g0, 0.1, 1e-15);
        EXPECT_EQ(e.pair, 2);
        EXPECT_DOUBLE_EQ(e.mu, 0.3);
        EXPECT_DOUBLE_EQ(e.r, 10.0);
    }

    // Node v4 at x = 1: N_4 = 1 - |x - 1| / 0.6 on [0.4, 1.6]; target hats N_2 = (1.2 - x) / 1.2
    // and N_1 = x / 1.2 on [0, 1.2], N_1 = (2 - x) / 0.8 and N_0 = (x - 1.2) / 0.8 on [1.2, 2].
    // By hand (integrals in x, the right edge scaled by f = L2 / 0.6):
    //   M_42 = 1/10 + f 2/135, M_41 = 1/5 + f 71/270, M_40 = f 1/45, D_4 = 3/10 + f 3/10.
    const auto& e4 = res.elements[1];
    ASSERT_EQ(e4.vertex[0], 4);
    ASSERT_EQ(e4.n_nodes(), 4);
    const double f = std::hypot(0.6, 0.06) / 0.6;
    const double D4 = 0.3 + 0.3 * f;
    auto w4 = target_weights(e4);
    ASSERT_EQ(w4.size(), 3u);
    EXPECT_NEAR(w4[2], -(1.0 / 10 + f * 2.0 / 135) / D4, 1e-14);
    EXPECT_NEAR(w4[1], -(1.0 / 5 + f * 71.0 / 270) / D4, 1e-14);
    EXPECT_NEAR(w4[0], -(f / 45) / D4, 1e-14);
    // Not the nodal weights (alpha = 1/6 on the facet (v1, v2): -5/6 at v1, -1/6 at v2).
    EXPECT_GT(std::abs(w4[1] + 5.0 / 6.0), 0.05);

    // Node v3 at x = 0.4: N_3 = (x + 0.2) / 0.6 on [-0.2, 0.4], (1 - x) / 0.6 on [0.4, 1]. Only
    // [0, 1] lies over the target: D_3 = 0.6 but the covered part is 17/30, and the weights are
    // renormalised by it: M_32 = 197/540, M_31 = 109/540 (sum 17/30).
    const auto& e3 = res.elements[0];
    ASSERT_EQ(e3.vertex[0], 3);
    ASSERT_EQ(e3.n_nodes(), 3);
    auto w3 = target_weights(e3);
    ASSERT_EQ(w3.size(), 2u);
    EXPECT_NEAR(w3[2], -197.0 / 306.0, 1e-14);
    EXPECT_NEAR(w3[1], -109.0 / 306.0, 1e-14);

    // Dual: psi_4 = 3 N_4 - 1 on each edge in place of N_4 in M (v4's support lies entirely over
    // the target). By hand: M_42 = 1/20 + f/36, M_41 = 1/4 + f 11/36, M_40 = -f/30 (the same
    // sums per edge, 3/10 and f 3/10, as with N_4). v3 is only partly over the target: it keeps
    // the segment weights.
    const auto dual =
        contact::node_on_facet_search(m, {3, 4}, m.tag("target"), reference, 2.0, 0.3, 10.0, 2,
                                      contact::FacetIntegration::dual, m.tag("contactor"));
    ASSERT_EQ(dual.elements.size(), 2u);
    auto d4 = target_weights(dual.elements[1]);
    ASSERT_EQ(d4.size(), 3u);
    EXPECT_NEAR(d4[2], -(1.0 / 20 + f / 36) / D4, 1e-14);
    EXPECT_NEAR(d4[1], -(1.0 / 4 + f * 11.0 / 36) / D4, 1e-14);
    EXPECT_NEAR(d4[0], (f / 30) / D4, 1e-14);
    EXPECT_NEAR(d4[0] + d4[1] + d4[2], -1.0, 1e-14);
    auto d3 = target_weights(dual.elements[0]);
    EXPECT_NEAR(d3[2], -197.0 / 306.0, 1e-14);
    EXPECT_NEAR(d3[1], -109.0 / 306.0, 1e-14);

    // The nodal variant on the same pair keeps the papers' weights.
    const auto nodal = contact::node_on_facet_search(m, {4}, m.tag("target"), reference, 2.0, 0.3,
                                                     10.0, 2, contact::FacetIntegration::nodal);
    ASSERT_EQ(nodal.elements.size(), 1u);
    EXPECT_EQ(nodal.elements[0].n_nodes(), 3);
    EXPECT_NEAR(nodal.elements[0].weight[1], -5.0 / 6.0, 1e-15);
    EXPECT_NEAR(nodal.elements[0].weight[2], -1.0 / 6.0, 1e-15);
}

TEST(SegmentWeights, BadInputIsRejected) {
    const auto m = non_matching_pair();
    const contact::FacetIndex reference(m.vertices, contact::target_facets(m, m.tag("target")));
    // Segment integration needs the contactor edges.
    EXPECT_THROW(contact::node_on_facet_search(m, {4}, m.tag("target"), reference, 2.0, 0.0, 1.0, 0,
                                               contact::FacetIntegration::segment),
                 InvalidInput);
    // Weights that do not sum to -1, a repeated target.
    EXPECT_THROW(
        contact::node_on_facet_weighted(4, {0, 1}, {-0.5, -0.4}, Vec2(0, 1), 0.0, 0.0, 1.0, 0),
        InvalidInput);
    EXPECT_THROW(
        contact::node_on_facet_weighted(4, {0, 0}, {-0.5, -0.5}, Vec2(0, 1), 0.0, 0.0, 1.0, 0),
        InvalidInput);
    // No target, or targets and weights that differ in number.
    EXPECT_THROW(contact::node_on_facet_weighted(4, {}, {}, Vec2(0, 1), 0.0, 0.0, 1.0, 0),
                 InvalidInput);
    EXPECT_THROW(contact::node_on_facet_weighted(4, {0, 1}, {-1.0}, Vec2(0, 1), 0.0, 0.0, 1.0, 0),
                 InvalidInput);
}

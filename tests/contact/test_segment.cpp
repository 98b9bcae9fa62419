// SPDX-License-Identifier: MIT
// Segment-integrated (mortar-type, lumped) node-on-facet weights on a hand-made non-matching
// pair: weights (1, -M_ik / D_i) with D_i = int N_i ds and M_ik = int N_i N_k ds computed by hand,
// their sum zero, and the renormalisation by the covered part at an end of the target; an element
// with twenty target vertices against the closed forms of its relative displacement, residual
// and tangent.
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

TEST(SegmentWeights, ElementWithTwentyTargetsEvaluatesAndLinearizesInClosedForm) {
    // Contactor vertex 0, targets k = 1 .. 20 with weights w_k = -k / 210 (sum -1), the normal
    // n = (0.6, 0.8) and so t = (n_y, -n_x) = (0.8, -0.6).
    constexpr int m = 20;
    std::vector<int> targets;
    std::vector<double> w;
    for (int k = 1; k <= m; ++k) {
        targets.push_back(k);
        w.push_back(-k / 210.0);
    }
    const Vec2 n(0.6, 0.8);
    const double g0 = 0.05, mu = 0.5, r = 10.0;
    const auto e = contact::node_on_facet_weighted(0, targets, w, n, g0, mu, r, 3);
    ASSERT_EQ(e.n_nodes(), m + 1);
    ASSERT_EQ(e.vertex.size(), e.weight.size());
    EXPECT_EQ(e.vertex[0], 0);
    EXPECT_EQ(e.weight[0], 1.0);
    double sum = 0.0;
    for (int j = 1; j <= m; ++j) {
        EXPECT_EQ(e.vertex[static_cast<size_t>(j)], j);
        sum += e.weight[static_cast<size_t>(j)];
    }
    EXPECT_NEAR(sum, -1.0, 1e-15);
    EXPECT_EQ(e.t, Vec2(0.8, -0.6));
    EXPECT_EQ(e.n, n);

    // u_0 = (0.3, -0.2), u_k = (a k, b k^2), u_prev = 0: with sum k^2 = 2870, sum k^3 = 44100,
    // u_rel = u_0 - (a 2870, b 44100) / 210.
    const double a = 1e-3, b = 1e-4;
    Vector u = Vector::Zero(2 * (m + 1));
    u.segment<2>(0) = Vec2(0.3, -0.2);
    for (int k = 1; k <= m; ++k)
        u.segment<2>(2 * k) = Vec2(a * k, b * k * k);
    const Vec2 du = Vec2(0.3, -0.2) - Vec2(a * 2870.0, b * 44100.0) / 210.0;
    const double d_n = g0 + n.dot(du), d_t = e.t.dot(du);
    // Every displacement free; the contactor carries (lambda_t, lambda_n).
    std::vector<std::array<bool, 2>> fixed(m + 1, {false, false});
    std::vector<int> extra(m + 1, 0);
    extra[0] = 2;
    const fem::DofMap dofs(fixed, extra);
    const int ld = dofs.extra_dof(0);
    Vector x = Vector::Zero(dofs.n_dofs());
    x[ld] = 0.0;       // lambda_t
    x[ld + 1] = -10.0; // lambda_n: sigma = (r d_t, -10 + r d_n), inside the cone (stick)
    const auto s = contact::evaluate(e, u, Vector::Zero(u.size()), x, ld);
    EXPECT_NEAR(s.d_n, d_n, 1e-15);
    EXPECT_NEAR(s.d_t[0], d_t, 1e-15);
    ASSERT_EQ(s.proj.status, contact::Status::stick);
    EXPECT_NEAR(s.proj.phi[0], r * d_t, 1e-14);
    EXPECT_NEAR(s.proj.phi[1], -10.0 + r * d_n, 1e-14);
    EXPECT_EQ(s.proj.M, Eigen::Matrix2d::Identity());

    // The residual: w_j (t Phi_t + n Phi_n) at vertex j, and R_lambda = -(lambda - Phi) / r.
    Vector R = Vector::Zero(dofs.n_dofs());
    contact::add_residual(e, s, dofs, ld, R);
    const Vec2 force = (r * d_t) * e.t + (-10.0 + r * d_n) * n;
    for (int j = 0; j <= m; ++j) {
        const double wj = j == 0 ? 1.0 : -j / 210.0;
        for (int c = 0; c < 2; ++c)
            EXPECT_NEAR(R[dofs.u_dof(j, c)], wj * force[c], 1e-14) << "vertex " << j;
    }
    EXPECT_NEAR(R[ld], d_t, 1e-15);     // -(0 - r d_t) / r
    EXPECT_NEAR(R[ld + 1], d_n, 1e-15); // -(-10 - (-10 + r d_n)) / r

    // The tangent with M = I (stick): G M G^T = I, so uu = r w_j w_k delta_ab, u-lambda w_j G,
    // lambda-u its transpose, lambda-lambda (M - I) / r = 0; every pair of the element's
    // (2 (m + 1) + 2) unknowns appears once.
    const int size = static_cast<int>(dofs.n_dofs());
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(size, size);
    int calls = 0;
    contact::for_each_tangent_entry(e, s.proj.M, dofs, ld, [&](int i, int j, double v) {
        J(i, j) += v;
        ++calls;
    });
    EXPECT_EQ(calls, (2 * (m + 1) + 2) * (2 * (m + 1) + 2));
    Eigen::Matrix2d G;
    G.col(0) = e.t;
    G.col(1) = n;
    Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(size, size);
    for (int j = 0; j <= m; ++j) {
        const double wj = j == 0 ? 1.0 : -j / 210.0;
        for (int c = 0; c < 2; ++c) {
            const int row = dofs.u_dof(j, c);
            for (int k = 0; k <= m; ++k) {
                const double wk = k == 0 ? 1.0 : -k / 210.0;
                expected(row, dofs.u_dof(k, c)) = r * wj * wk;
            }
            for (int q = 0; q < 2; ++q) {
                expected(row, ld + q) = wj * G(c, q);
                expected(ld + q, row) = wj * G(c, q);
            }
        }
    }
    EXPECT_LE((J - expected).cwiseAbs().maxCoeff(), 1e-14);
}

// SPDX-License-Identifier: MIT
// Two bodies in 3D (levels/solve3 with node-on-facet and node-on-node pairs): the patch test of
// stack3d (two stacked blocks, non-matching meshes, uniform pressure) exact with the segment and
// dual weights on levels 0-2 by the exact and the multigrid solvers and not with the nodal
// weights, the matching interface by node on node, shear3d (the loads balanced, the slip zone
// growing, the multigrid's iterations, the symmetry plane's pinned tangent), and the refusals of
// the two-body keys.
#include "core/check.hpp"
#include "levels/solve3.hpp"
#include "scene/scene.hpp"
#include "scene/scene3.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace mlc {
namespace {

using mesh::Vec3;

constexpr double kStackE = 1.0, kStackNu = 0.3, kStackP = 0.01;

// stack3d with its contact pair's `integration` and `element` replaced, on `levels` levels.
levels::ElasticProblem3 stack(int levels, contact::FacetIntegration integration,
                              levels::ContactElementKind element =
                                  levels::ContactElementKind::node_on_facet) {
    auto p = scene::load_scene3("stack3d");
    p.levels = levels;
    p.contacts.at(0).integration = integration;
    p.contacts.at(0).element = element;
    return p;
}

// The largest deviation of the contact pressure -lambda_n / area from kStackP, relative to kStackP, and of
// the displacements from the exact u = (nu p x, nu p y, -p z) / E, relative to p (the largest
// exact displacement is 2 p / E).
struct PatchErrors {
    double pressure = 0.0, displacement = 0.0;
    int closed = 0;
};
PatchErrors patch_errors(const levels::ElasticProblem3& p, const levels::RunResult3& r) {
    PatchErrors e;
    const auto& L = r.finest();
    const auto areas = levels::contact_areas(p, L);
    for (size_t k = 0; k < r.nodes.size(); ++k) {
        e.pressure = std::max(e.pressure, std::abs(-r.nodes[k].lambda_n / areas[k] - kStackP) / kStackP);
        e.closed += r.nodes[k].status != contact::Status::gap;
    }
    for (int v = 0; v < L.mesh.n_vertices(); ++v) {
        const Vec3& x = L.mesh.vertices[static_cast<size_t>(v)];
        const Vec3 exact(kStackNu * kStackP * x.x() / kStackE, kStackNu * kStackP * x.y() / kStackE, -kStackP * x.z() / kStackE);
        e.displacement = std::max(
            e.displacement, (r.u_full.segment<3>(3 * v) - exact).cwiseAbs().maxCoeff() / kStackP);
    }
    return e;
}

TEST(TwoBody3, Stack3dPatchTestExactWithSegmentAndDualWeightsOnLevels0To2) {
    for (auto integration : {contact::FacetIntegration::segment, contact::FacetIntegration::dual})
        for (auto m : {levels::Method3::schur, levels::Method3::mg})
            for (int l = 0; l <= 2; ++l) {
                if (m == levels::Method3::mg && l == 0) continue;
                SCOPED_TRACE(std::string(contact::to_string(integration)) + " " +
                             levels::to_string(m) + " level " + std::to_string(l));
                const auto p = stack(l, integration);
                levels::SolveOptions3 so;
                so.upper = m;
                so.krylov_rel_tol = 1e-12;
                const auto r = levels::solve(p, so);
                ASSERT_TRUE(r.converged) << r.failure;
                // Every vertex of the upper block's bottom is a contact node: (5 2^l + 1)^2.
                const int n = 5 * (1 << l) + 1;
                EXPECT_EQ(static_cast<int>(r.nodes.size()), n * n);
                const auto e = patch_errors(p, r);
                EXPECT_EQ(e.closed, n * n);
                EXPECT_LE(e.pressure, 1e-8);
                EXPECT_LE(e.displacement, 1e-8);
            }
}

TEST(TwoBody3, Stack3dColdMultigridSolvesTheTwoBodyNewtonSystems) {
    // Coarse to fine, the exact solution interpolates exactly and the upper levels need no
    // Newton iteration; cold, level 2 solves its Newton systems by GMRES + mg (Galerkin
    // operators of the two-body Jacobian) from zero.
    const auto p = stack(2, contact::FacetIntegration::segment);
    levels::SolveOptions3 so;
    so.coarse_to_fine = false;
    so.krylov_rel_tol = 1e-12;
    const auto r = levels::solve(p, so);
    ASSERT_TRUE(r.converged) << r.failure;
    const auto& its = r.steps.at(0).linear_iterations_per_newton;
    ASSERT_FALSE(its.empty());
    for (int k : its) {
        EXPECT_GT(k, 0);
        EXPECT_LE(k, 25);
    }
    const auto e = patch_errors(p, r);
    EXPECT_LE(e.pressure, 1e-8);
    EXPECT_LE(e.displacement, 1e-8);
}

TEST(TwoBody3, Stack3dNodalWeightsMissThePatchTestOnNonMatchingMeshes) {
    const auto p = stack(0, contact::FacetIntegration::nodal);
    const auto r = levels::solve(p);
    ASSERT_TRUE(r.converged) << r.failure;
    const auto e = patch_errors(p, r);
    // The nodal weights pass the contactor's forces to the target by interpolation, which is no
    // consistent load on non-matching meshes: the pressure is off by percents.
    EXPECT_GT(e.pressure, 1e-3);
}

TEST(TwoBody3, MatchingBlocksByNodeOnNodeAreExact) {
    // The upper block meshed like the lower one: the interface matches, node on node.
    auto text = std::string(R"(
[scene]
name = "matching"
dimension = 3
levels = 1
[[body]]
E = 1.0
nu = 0.3
mesh = { type = "box", corner = [0, 0, 0], size = [1, 1, 1], divisions = [3, 3, 2] }
tags = { zmin = "base", zmax = "lower_top", xmin = "sym_x", ymin = "sym_y" }
[[body]]
E = 1.0
nu = 0.3
mesh = { type = "box", corner = [0, 0, 1], size = [1, 1, 1], divisions = [3, 3, 2] }
tags = { zmin = "upper_bottom", zmax = "platen", xmin = "sym_x", ymin = "sym_y" }
[[load]]
tag = "platen"
pressure = 0.01
[[support]]
tag = "base"
uz = 0.0
[[support]]
tag = "sym_x"
ux = 0.0
[[support]]
tag = "sym_y"
uy = 0.0
[[contact]]
contactor = "upper_bottom"
target = "lower_top"
element = "node_on_node"
mu = 0.3
)");
    const auto p = scene::parse_scene3(text, "matching.toml");
    ASSERT_EQ(p.contacts.size(), 1u);
    EXPECT_EQ(p.contacts[0].element, levels::ContactElementKind::node_on_node);
    const auto r = levels::solve(p);
    ASSERT_TRUE(r.converged) << r.failure;
    ASSERT_EQ(r.nodes.size(), 49u); // (3 * 2 + 1)^2 on level 1
    for (const auto& e : r.finest().contacts)
        ASSERT_EQ(e.n_nodes(), 2);
    const auto e = patch_errors(p, r);
    EXPECT_LE(e.pressure, 1e-8);
    EXPECT_LE(e.displacement, 1e-8);
    // Frictional and stuck: no tangential force where nothing slides.
    for (const auto& n : r.nodes)
        EXPECT_LE(n.lambda_t.norm(), 1e-8 * std::abs(n.lambda_n));
}

// The contact force on the contactor in global axes, summed over its nodes: -(n lambda_n +
// T lambda_t) at each (the run report's resultant).
Vec3 contact_resultant(const std::vector<levels::ContactNodeState3>& nodes) {
    Vec3 F = Vec3::Zero();
    for (const auto& n : nodes)
        F -= n.n * n.lambda_n + n.t * n.lambda_t;
    return F;
}

TEST(TwoBody3, Shear3dBalancesItsLoadsAndItsSlipZoneGrowsWithThePush) {
    auto p = scene::load_scene3("shear3d");
    p.levels = 1;
    const auto r = levels::solve(p);
    ASSERT_TRUE(r.converged) << r.failure;
    ASSERT_EQ(r.step_nodes.size(), 5u);
    // The upper block is held by the contact alone along x and z: the contact force on it
    // balances the push (40 MPa x 20 x 20 at the last step, 0 at the first) and the pressure
    // (50 MPa x 40 x 20) at every step.
    const double push[] = {0.0, 4000.0, 8000.0, 12000.0, 16000.0}, press = 40000.0;
    int slipping_before = -1;
    for (size_t k = 0; k < 5; ++k) {
        const Vec3 F = contact_resultant(r.step_nodes[k]);
        EXPECT_NEAR(F.x(), -push[k], 1e-8 * press) << "step " << k + 1;
        EXPECT_NEAR(F.z(), press, 1e-8 * press) << "step " << k + 1;
        int slipping = 0;
        for (const auto& n : r.step_nodes[k])
            slipping += n.status != contact::Status::stick;
        EXPECT_GE(slipping, slipping_before) << "step " << k + 1;
        slipping_before = slipping;
    }
    // 153 contact nodes on level 1: most stick under the pressure alone, most no longer do
    // once the push reaches 0.8 of the friction limit.
    const auto& first = r.step_nodes.front();
    ASSERT_EQ(first.size(), 153u);
    EXPECT_LE(slipping_before, 153);
    EXPECT_GE(slipping_before, 153 / 3);
    // The multigrid of level 1 (GMRES + mg on the Galerkin operators of the two-body Jacobian).
    std::vector<int> its;
    for (const auto& st : r.level_steps.at(1))
        its.insert(its.end(), st.report.linear_iterations_per_newton.begin(),
                   st.report.linear_iterations_per_newton.end());
    ASSERT_FALSE(its.empty());
    std::sort(its.begin(), its.end());
    EXPECT_LE(its[its.size() / 2], 15);
    EXPECT_LE(its.back(), 25);
}

TEST(TwoBody3, Shear3dSymmetryPlanePinsTheTangentAcrossItAtItsContactNodes) {
    // The contact nodes on y = 0 hold uy; their segment patches reach target vertices off the
    // plane, which leave uy free. The contactor's support decides: t1 along y is pinned and
    // its multiplier vanishes; the nodes off the plane are not pinned.
    auto p = scene::load_scene3("shear3d");
    p.levels = 0;
    const auto r = levels::solve(p);
    ASSERT_TRUE(r.converged) << r.failure;
    const auto& L = r.finest();
    int on_plane = 0, reaching_off = 0;
    for (size_t k = 0; k < L.contacts.size(); ++k) {
        const auto& e = L.contacts[k];
        const Vec3& x = L.mesh.vertices[static_cast<size_t>(e.vertex[0])];
        if (x.y() != 0.0) {
            EXPECT_EQ(e.pinned, 0) << "vertex " << e.vertex[0];
            continue;
        }
        ++on_plane;
        EXPECT_EQ(e.pinned, contact::ContactElement3::kPinnedT1) << "vertex " << e.vertex[0];
        EXPECT_NEAR(std::abs(e.t.col(0).y()), 1.0, 1e-14);
        EXPECT_EQ(r.nodes[k].lambda_t[0], 0.0);
        for (int j = 1; j < e.n_nodes(); ++j)
            if (e.weight[static_cast<size_t>(j)] != 0.0 &&
                L.mesh.vertices[static_cast<size_t>(e.vertex[static_cast<size_t>(j)])].y() > 0.0) {
                ++reaching_off;
                break;
            }
    }
    EXPECT_EQ(on_plane, 9); // 8 cells of the upper block along x on level 0
    EXPECT_EQ(reaching_off, on_plane);
}

// stack3d's text with `from` replaced by `to` (once).
std::string stack_text(const std::string& from, const std::string& to) {
    std::string t = scene::builtin_scene_text("stack3d");
    const auto i = t.find(from);
    EXPECT_NE(i, std::string::npos) << from;
    return t.replace(i, from.size(), to);
}

void expect_refused(const std::string& text, const std::string& what) {
    try {
        (void)scene::parse_scene3(text, "s.toml");
        ADD_FAILURE() << "not refused: " << what;
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
}

TEST(TwoBody3, TwoBodyKeysAreRefusedWithTheirReason) {
    expect_refused(stack_text("target = \"lower_top\"", "target = \"roof\""),
                   "s.toml:63: [[contact]]: unknown target tag 'roof'");
    expect_refused(stack_text("target = \"lower_top\"", "target = \"upper_bottom\""),
                   "the target tag is the contactor tag");
    expect_refused(stack_text("element = \"node_on_facet\"", "element = \"node_on_node\""),
                   "applies to element = \"node_on_facet\" only");
    expect_refused(stack_text("element = \"node_on_facet\"", "element = \"mortar\""),
                   ".element must be \"node_on_facet\" or \"node_on_node\", found \"mortar\"");
    expect_refused(stack_text("mu = 0.0", "mu = 0.0\nobstacle = { type = \"plane\", point = "
                                          "[0, 0, 0], normal = [0, 0, 1] }"),
                   "takes an obstacle (rigid) or a target tag (two bodies), not both");
    expect_refused(stack_text("mu = 0.0", "mu = 0.0\nsearch_radius = -1.0"),
                   ".search_radius must be > 0");
    expect_refused(stack_text("tags = { zmin = \"base\"", "tags = { zmin2 = \"base\""),
                   "the body's mesh has no tag 'zmin2'");
}

} // namespace
} // namespace mlc

// SPDX-License-Identifier: MIT
// The size of a domain mesh predicted before meshing (predict_mesh_size) against the meshes made,
// and the stop request polled while meshing (mesh_domain's StopPoll).
#include "core/check.hpp"
#include "mesh/cgal/domain_mesher.hpp"
#include "mesh/mesh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

using namespace mlc;
using namespace mlc::mesh;

namespace {

std::vector<std::vector<Segment>> square(double side) {
    return {{Segment::line({0, 0}, {side, 0}, "bottom"),
             Segment::line({side, 0}, {side, side}, "right"),
             Segment::line({side, side}, {0, side}, "top"),
             Segment::line({0, side}, {0, 0}, "left")}};
}

/// The hertz scene's quarter disc: the arc from (0, 0) to (1, 1) about (0, 1), the top, the axis.
std::vector<std::vector<Segment>> quarter_disc_loops() {
    return {{Segment::arc({0, 0}, {1, 1}, {0, 1}, true, "surface"),
             Segment::line({1, 1}, {0, 1}, "top"), Segment::line({0, 1}, {0, 0}, "axis")}};
}

SizeField field(double max_size, double min_size, std::vector<Vec2> focus, double grading) {
    SizeField f;
    f.max_size = max_size;
    f.min_size = min_size;
    f.focus = std::move(focus);
    f.grading = grading;
    return f;
}

} // namespace

TEST(MeshPrediction, AreasAreExact) {
    EXPECT_NEAR(predict_mesh_size(square(2), field(0.1, 0, {}, 0.25)).area, 4.0, 1e-14);
    EXPECT_NEAR(predict_mesh_size(quarter_disc_loops(), field(0.1, 0, {}, 0.25)).area,
                std::numbers::pi / 4, 1e-14);
    // A square with a round hole: 4 - pi r^2.
    auto loops = square(2);
    loops.push_back({Segment::arc({1.5, 1}, {1.5, 1}, {1, 1}, false, "hole")});
    const MeshPrediction p = predict_mesh_size(loops, field(0.1, 0, {}, 0.25));
    EXPECT_NEAR(p.area, 4 - std::numbers::pi * 0.25, 1e-13);
    // Uniform: the integral is A / h^2 exactly.
    EXPECT_NEAR(p.integral, (4 - std::numbers::pi * 0.25) / 0.01, 1e-9);
    EXPECT_DOUBLE_EQ(p.triangles, kTrianglesPerUnitIntegral * p.integral);
}

TEST(MeshPrediction, GradedIntegralAgainstItsClosedForm) {
    // A focus point in the middle of a square far larger than its disc r < (M - m) / g: the
    // whole disc adds 2 pi / g^2 (ln(M / m) - 1 + m / M) to A / M^2.
    const double M = 1, m = 0.01, g = 0.5;
    const SizeField f = field(M, m, {{50, 50}}, g);
    const double closed =
        1e4 / (M * M) + 2 * std::numbers::pi / (g * g) * (std::log(M / m) - 1 + m / M);
    EXPECT_NEAR(predict_mesh_size(square(100), f).integral, closed, 2e-3 * closed);
    // At a corner of the square a quarter of the disc is inside.
    const SizeField corner = field(M, m, {{0, 0}}, g);
    const double quarter =
        1e4 / (M * M) + 0.25 * 2 * std::numbers::pi / (g * g) * (std::log(M / m) - 1 + m / M);
    EXPECT_NEAR(predict_mesh_size(square(100), corner).integral, quarter, 2e-3 * quarter);
}

TEST(MeshPrediction, AtOrAboveTheMeshedCountAndWithinOneAndAHalfTimesIt) {
    struct Case {
        std::vector<std::vector<Segment>> loops;
        SizeField size;
    };
    const std::vector<Case> cases = {
        {square(1), field(0.05, 0, {}, 0.25)},
        {square(1), field(0.1, 0.005, {{0.5, 0}}, 0.25)},
        {quarter_disc_loops(), field(0.1, 0.004, {{0, 0}}, 0.12)}, // the hertz scene
        {quarter_disc_loops(), field(0.02, 0, {}, 0.25)},
        {{{Segment::arc({1, 0}, {1, 0}, {0, 0}, true, "circle")}},
         field(0.1, 0.01, {{0, 0}, {0.5, 0}}, 0.3)},
    };
    for (size_t i = 0; i < cases.size(); ++i) {
        const double predicted = predict_mesh_size(cases[i].loops, cases[i].size).triangles;
        const double made = mesh_domain(cases[i].loops, cases[i].size).n_cells();
        EXPECT_GE(predicted, made) << "case " << i;
        EXPECT_LE(predicted, 1.5 * made) << "case " << i;
    }
}

TEST(MeshPrediction, BadGeometryIsRefusedAsByTheMesher) {
    EXPECT_THROW(predict_mesh_size({}, field(0.1, 0, {}, 0.25)), InvalidInput);
    EXPECT_THROW(predict_mesh_size(square(1), field(-1, 0, {}, 0.25)), InvalidInput);
}

TEST(MeshStop, APollThatSaysStopThrowsInterruptedAndOneThatNeverDoesChangesNothing) {
    const auto loops = quarter_disc_loops();
    const SizeField size = field(0.01, 0.002, {{0, 0}}, 0.2);
    int polls = 0;
    EXPECT_THROW(mesh_domain(loops, size, {}, [&] { return ++polls == 3; }), Interrupted);
    EXPECT_EQ(polls, 3);
    polls = 0;
    const Mesh with = mesh_domain(loops, size, {}, [&] { return ++polls < 0; });
    EXPECT_GT(polls, 3); // polled all along the meshing
    const Mesh without = mesh_domain(loops, size);
    ASSERT_EQ(with.n_vertices(), without.n_vertices());
    EXPECT_EQ(with.vertices, without.vertices);
    EXPECT_EQ(with.cells, without.cells);
}

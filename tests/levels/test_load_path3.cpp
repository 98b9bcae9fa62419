// SPDX-License-Identifier: MIT
// Loading paths of 3D problems (scene/scene3, levels/elastic3d_levels, levels/solve3): an
// elastic box along a two-point path is the superposition of proportional problems, a block on
// a rigid plane pressed and then sheared through a prescribed top displacement slips and stays in
// equilibrium, and the scene's per-point lists are checked as in 2D.
#include "core/check.hpp"
#include "fem/assembly.hpp"
#include "levels/solve3.hpp"
#include "scene/scene3.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace mlc {
namespace {

using mesh::Vec3;

/// Replaces the one occurrence of `from` in `text` by `to`.
std::string replaced(std::string text, const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
}

/// The message of the InvalidInput parse_scene3 throws on `text` ("" when it parses).
std::string error_of(const std::string& text) {
    try {
        scene::parse_scene3(text, "t.toml");
    } catch (const InvalidInput& e) {
        return e.what();
    }
    return "";
}

/// Expects `message` to be `want` followed only by MLC_CHECK's " [check ...]" note, if any.
void expect_message(const std::string& message, const std::string& want) {
    EXPECT_EQ(message.substr(0, want.size()), want);
    const std::string rest = message.substr(std::min(want.size(), message.size()));
    EXPECT_TRUE(rest.empty() || rest.rfind(" [check ", 0) == 0) << message;
}

/// The 1-based line of the first occurrence of `what` in `text`.
int line_of(const std::string& text, const std::string& what) {
    const auto at = text.find(what);
    EXPECT_NE(at, std::string::npos) << what;
    return 1 +
           static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

// A unit box held on its bottom (every component) and on its top (uz = `top_uz`, a number or a
// list), with the [[load]] tables `load_keys` and the body's `body_force` line, on 2 levels.
std::string elastic_box(const std::string& load_keys, const std::string& top_uz,
                        const std::string& body_force, int steps) {
    return "[scene]\nname = \"box\"\ndimension = 3\nlevels = 1\nload_steps = " +
           std::to_string(steps) + "\n[[body]]\nE = 1.0\nnu = 0.3\n" + body_force +
           "mesh = { type = \"box\", corner = [0.0, 0.0, 0.0], size = [1.0, 1.0, 1.0], "
           "divisions = [2, 2, 2] }\n"
           "[[support]]\ntag = \"zmin\"\nux = 0.0\nuy = 0.0\nuz = 0.0\n"
           "[[support]]\ntag = \"zmax\"\nuz = " +
           top_uz + "\n" + load_keys;
}

constexpr double kD = 0.01, kP = 0.02;
const std::string kBodyForce = "body_force = [0.0, 0.003, -0.005]\n";

levels::RunResult3 solve_lu(const levels::ElasticProblem3& p, bool extrapolate = true) {
    levels::SolveOptions3 so;
    so.level0 = so.upper = levels::Method3::lu;
    so.extrapolate = extrapolate;
    return levels::solve(p, so);
}

// Step 1..4 of 4 along the path (s = 0.25 .. 1): the load with factors [1, 1] is at 0.5, 1, 1, 1
// of its full value, the top's uz = [0, -d] at 0, 0, -d/2, -d, the body force (no factors) at s.
// The problem is linear without contact, so each step's displacements are a(s) A + b(s) B +
// s C, A, B and C the solutions of the load alone (top held at uz = 0), the top's -d alone, and
// the body force alone.
TEST(LoadPath3, ElasticBoxAlongATwoPointPathIsTheSuperpositionOfProportionalProblems) {
    const std::string load = "[[load]]\ntag = \"xmax\"\npressure = 0.02\n";
    const auto path = scene::parse_scene3(
        elastic_box(load + "factors = [1.0, 1.0]\n", "[0.0, -0.01]", kBodyForce, 4), "path.toml");
    ASSERT_EQ(path.n_path_points(), 2);
    const auto A = scene::parse_scene3(elastic_box(load, "0.0", "", 1), "a.toml");
    const auto B = scene::parse_scene3(elastic_box("", "-0.01", "", 1), "b.toml");
    const auto C = scene::parse_scene3(elastic_box("", "0.0", kBodyForce, 1), "c.toml");
    ASSERT_EQ(A.n_path_points(), 1);
    ASSERT_DOUBLE_EQ(path.loads[0].pressure, kP);

    // The level evaluates the path: the top's prescribed uz and the nodal loads.
    const levels::Level3 L = levels::build_level(path, path.mesh0);
    const int top = L.mesh.nearest_vertex(Vec3(0.5, 0.5, 1.0));
    for (const auto& [s, uz] : {std::pair{0.25, 0.0}, std::pair{0.5, 0.0},
                                std::pair{0.75, -0.5 * kD}, std::pair{1.0, -kD}}) {
        EXPECT_EQ(L.u_fixed_at(s)[3 * top + 2], uz) << "s = " << s;
        EXPECT_EQ(L.u_fixed_at(s)[3 * top], 0.0) << "s = " << s;
    }
    // The pressure on xmax (area 1) and the body force (volume 1) resultants along x and y.
    auto resultant = [&](double s) {
        const Vector F = L.f_nodal_at(s);
        Vec3 r = Vec3::Zero();
        for (int v = 0; v < L.mesh.n_vertices(); ++v)
            r += F.segment<3>(3 * v);
        return r;
    };
    EXPECT_NEAR(resultant(0.25).x(), -0.5 * kP, 1e-15);
    EXPECT_NEAR(resultant(0.75).x(), -kP, 1e-15);
    EXPECT_NEAR(resultant(0.25).y(), 0.25 * 0.003, 1e-15);
    EXPECT_NEAR(resultant(0.75).y(), 0.75 * 0.003, 1e-15);
    // The last path point is the assembled full load.
    EXPECT_EQ(L.f_at(1.0), L.elastic.f);
    EXPECT_EQ(L.u_fixed_at(1.0), L.u_fixed);

    const auto ra = solve_lu(A), rb = solve_lu(B), rc = solve_lu(C);
    ASSERT_TRUE(ra.converged && rb.converged && rc.converged);
    const double a[4] = {0.5, 1.0, 1.0, 1.0}, b[4] = {0.0, 0.0, 0.5, 1.0};
    for (const bool extrapolate : {true, false}) {
        SCOPED_TRACE(extrapolate ? "secant predictor" : "no predictor");
        const auto r = solve_lu(path, extrapolate);
        ASSERT_TRUE(r.converged) << r.failure;
        ASSERT_EQ(r.step_u_full.size(), 4u);
        for (int k = 0; k < 4; ++k) {
            const double s = 0.25 * (k + 1);
            const Vector want = a[k] * ra.u_full + b[k] * rb.u_full + s * rc.u_full;
            EXPECT_LE((r.step_u_full[static_cast<size_t>(k)] - want).norm(), 1e-10 * want.norm())
                << "step " << k + 1;
        }
        // The predictor between path points (steps 2 and 4) is exact: those steps converge at the
        // check, on both levels; step 3 crosses the path point s = 0.5 and iterates.
        for (int l = 0; l <= 1; ++l) {
            const auto& st = r.level_steps[static_cast<size_t>(l)];
            ASSERT_EQ(st.size(), 4u);
            EXPECT_GE(st[0].report.iterations, 1) << "level " << l;
            EXPECT_GE(st[2].report.iterations, 1) << "level " << l;
            if (extrapolate) {
                EXPECT_EQ(st[1].report.iterations, 0) << "level " << l;
                EXPECT_EQ(st[3].report.iterations, 0) << "level " << l;
            } else {
                EXPECT_GE(st[1].report.iterations, 1) << "level " << l;
                EXPECT_GE(st[3].report.iterations, 1) << "level " << l;
            }
        }
        // Step 3 on level 0 starts from the secant 2 x_2 - x_1 of the unknowns (K x_j = f at s_j)
        // or from x_2, the prescribed values being step 3's either way: its first residual is
        // ||K x_start - f(0.75)|| over the larger of ||K x_start|| and ||f(0.75)||.
        const levels::Level3& L0 = r.hierarchy.levels[0];
        const Vector f3 = L0.f_at(0.75);
        const Vector Kx =
            extrapolate ? Vector(2.0 * L0.f_at(0.5) - L0.f_at(0.25)) : Vector(L0.f_at(0.5));
        const double want = (Kx - f3).norm() / std::max(Kx.norm(), f3.norm());
        const auto& step3 = r.level_steps[0][2].report;
        ASSERT_FALSE(step3.residuals.empty());
        EXPECT_NEAR(step3.residuals[0], want, 1e-8 * want);
    }
}

// A block on the rigid plane z = 0 with friction, pressed by a pressure on its top in step 1 and
// then, the pressure kept, its top moved along x by a prescribed ux in step 2 (ux = [0, d_t]).
const std::string kSlide = R"([scene]
name = "slide"
dimension = 3
load_steps = 2
levels = 1

[[body]]
name = "block"
E = 1.0
nu = 0.3
mesh = { type = "box", corner = [0.0, 0.0, 0.0], size = [1.0, 1.0, 0.5], divisions = [2, 2, 1] }

[[load]]
tag = "zmax"
pressure = 0.01
factors = [1.0, 1.0]

[[support]]
tag = "zmax"
ux = [0.0, 2e-3]

[[contact]]
name = "floor"
contactor = "zmin"
mu = 0.3
obstacle = { type = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }
)";

// Per axis: the loads, the floor's force on the block (minus the multipliers in global
// components) and the reactions of the prescribed components (K u - F there) sum to zero.
TEST(LoadPath3, BlockPressedThenShearedSlipsAndBalancesItsLoadsAndReactions) {
    const auto p = scene::parse_scene3(kSlide, "slide.toml");
    ASSERT_EQ(p.n_path_points(), 2);
    const auto r = levels::solve(p);
    ASSERT_TRUE(r.converged) << r.failure;
    ASSERT_EQ(r.step_nodes.size(), 2u);
    const levels::Level3& L = r.finest();
    int slip[2] = {0, 0}, leading = 0;
    Vec3 floor_force[2];
    for (int k = 0; k < 2; ++k) {
        const double s = 0.5 * (k + 1);
        const Vector& u = r.step_u_full[static_cast<size_t>(k)];
        // The top's prescribed ux of this step.
        const int top = L.mesh.nearest_vertex(Vec3(0.5, 0.5, 0.5));
        EXPECT_EQ(u[3 * top], k == 0 ? 0.0 : 2e-3);
        const Vector F = L.f_nodal_at(s);
        const Vector Ku = fem::internal_forces(L.mesh, L.materials, u);
        Vec3 loads = Vec3::Zero(), reactions = Vec3::Zero(), floor = Vec3::Zero(),
             magnitude = Vec3::Zero();
        for (int v = 0; v < L.mesh.n_vertices(); ++v)
            for (int c = 0; c < 3; ++c) {
                loads[c] += F[3 * v + c];
                magnitude[c] += std::abs(F[3 * v + c]);
            }
        for (const auto& n : r.step_nodes[static_cast<size_t>(k)]) {
            const Vec3 f =
                -(n.t.col(0) * n.lambda_t[0] + n.t.col(1) * n.lambda_t[1] + n.n * n.lambda_n);
            floor += f;
            magnitude += f.cwiseAbs();
            if (n.status == contact::Status::slip) ++slip[k];
            // Step 2: the edge x = 1, ahead of the shear, slips forward (+x) over the floor.
            const Vec3 slip_increment = n.t * n.d_t;
            if (k == 1 && n.x.x() == 1.0) {
                EXPECT_EQ(n.status, contact::Status::slip) << "node at y = " << n.x.y();
                EXPECT_GT(slip_increment.x(), 0.05 * 2e-3) << "node at y = " << n.x.y();
                ++leading;
            }
        }
        // Reactions where a component is prescribed: K u - F there (no contact node there).
        for (int v = 0; v < L.mesh.n_vertices(); ++v)
            for (int c = 0; c < 3; ++c)
                if (L.fixed[static_cast<size_t>(v)][static_cast<size_t>(c)]) {
                    ASSERT_LT(L.contact_of_vertex[static_cast<size_t>(v)], 0);
                    const double rv = Ku[3 * v + c] - F[3 * v + c];
                    reactions[c] += rv;
                    magnitude[c] += std::abs(rv);
                }
        for (int c = 0; c < 3; ++c)
            EXPECT_LE(std::abs(loads[c] + floor[c] + reactions[c]), 1e-8 * magnitude.maxCoeff())
                << "step " << k + 1 << " axis " << c;
        // The pressure 0.01 on the unit top, carried by the floor in both steps.
        EXPECT_NEAR(floor.z(), 0.01, 1e-8 * 0.01) << "step " << k + 1;
        floor_force[k] = floor;
    }
    // Step 2 shears the block: the floor resists along -x, the nodes ahead slip (and those at
    // x = 0 no longer all do: partial slip), and the friction force lies inside the Coulomb cone
    // of the whole contact.
    EXPECT_EQ(leading, 5);
    EXPECT_GT(slip[1], 0);
    EXPECT_LT(slip[1], static_cast<int>(r.nodes.size()));
    EXPECT_LT(floor_force[1].x(), -0.1 * 0.3 * 0.01);
    EXPECT_LE(floor_force[1].head<2>().norm(), 0.3 * 0.01 * (1 + 1e-9));
    EXPECT_LT(std::abs(floor_force[0].x()), std::abs(floor_force[1].x()));
}

TEST(LoadPath3, ThePathMovesTheTopWithoutExtrapolatingItsPrescribedValues) {
    // load_steps = 4 on the two-point path: step 3 crosses s = 0.5, where ux starts to move.
    // With and without the predictor, coarse to fine and cold, every step ends at the same
    // state, the top's ux at its prescribed value.
    auto p = scene::parse_scene3(kSlide, "slide.toml");
    p.load_steps = 4;
    std::vector<levels::RunResult3> runs;
    for (const bool c2f : {true, false})
        for (const bool extrapolate : {true, false}) {
            levels::SolveOptions3 so;
            so.coarse_to_fine = c2f;
            so.extrapolate = extrapolate;
            so.krylov_rel_tol = 1e-12;
            runs.push_back(levels::solve(p, so));
            ASSERT_TRUE(runs.back().converged) << runs.back().failure;
        }
    const levels::Level3& L = runs[0].finest();
    const int top = L.mesh.nearest_vertex(Vec3(0.5, 0.5, 0.5));
    const double ux[4] = {0.0, 0.0, 1e-3, 2e-3};
    for (const auto& r : runs)
        for (int k = 0; k < 4; ++k) {
            const Vector& u = r.step_u_full[static_cast<size_t>(k)];
            EXPECT_EQ(u[3 * top], ux[k]) << "step " << k + 1;
            const Vector& u0 = runs[0].step_u_full[static_cast<size_t>(k)];
            EXPECT_LE((u - u0).cwiseAbs().maxCoeff(), 1e-7 * u0.cwiseAbs().maxCoeff())
                << "step " << k + 1;
        }
}

// ---------------------------------------------------------------------------------------------
// The scene's lists.

TEST(LoadPath3, ListsOfAnotherLengthAreRefusedAtTheirLineWithThe2DMessage) {
    // A support's list against a load's factors.
    std::string text = replaced(kSlide, "ux = [0.0, 2e-3]", "ux = [0.0, 1e-3, 2e-3]");
    expect_message(error_of(text),
                   "t.toml:" + std::to_string(line_of(text, "ux = [0.0, 1e-3")) +
                       ": support on 'zmax' (ux) has 3 path values but another list has 2; every "
                       "per-step list must have the same length");
    // Two components of one support.
    text = replaced(kSlide, "ux = [0.0, 2e-3]", "ux = [0.0, 2e-3]\nuy = [0.0]");
    expect_message(error_of(text),
                   "t.toml:" + std::to_string(line_of(text, "uy = [0.0]")) +
                       ": support on 'zmax' (uy) has 1 path values but another list "
                       "has 2; every per-step list must have the same length");
    // A line support's list against a load's factors.
    text = replaced(kSlide, "[[contact]]",
                    "[[support]]\nline = [[0.0, 0.0, 0.5], [1.0, 0.0, 0.5]]\nuy = [0.0, 0.0, "
                    "0.0]\n\n[[contact]]");
    expect_message(
        error_of(text),
        "t.toml:" + std::to_string(line_of(text, "uy = [0.0, 0.0, 0.0]")) +
            ": support along a line (uy) has 3 path values but another list has 2; every "
            "per-step list must have the same length");
    // The same lists of one length parse.
    EXPECT_EQ(error_of(replaced(kSlide, "ux = [0.0, 2e-3]", "ux = [0.0, 2e-3]\nuy = [0.0, 0.0]")),
              "");
}

TEST(LoadPath3, AListWhereANumberIsExpectedAndKeysWithoutA3DMeaningAreRefused) {
    // pressure takes a number (the path's values go in factors).
    std::string text = replaced(kSlide, "pressure = 0.01", "pressure = [0.01, 0.01]");
    expect_message(error_of(text), "t.toml:" + std::to_string(line_of(text, "pressure = [")) +
                                       ": [[load]].pressure must be a number, found an array");
    // factors is a list.
    text = replaced(kSlide, "factors = [1.0, 1.0]", "factors = 1.0");
    expect_message(error_of(text), "t.toml:" + std::to_string(line_of(text, "factors = 1.0")) +
                                       ": [[load]].factors must be a non-empty array of numbers");
    text = replaced(kSlide, "ux = [0.0, 2e-3]", "ux = []");
    expect_message(error_of(text), "t.toml:" + std::to_string(line_of(text, "ux = []")) +
                                       ": [[support]].ux must be a non-empty array of numbers");
    // A support is not released along a 3D path.
    text = replaced(kSlide, "ux = [0.0, 2e-3]", "ux = [0.0, 2e-3]\nactive = [true, false]");
    expect_message(
        error_of(text),
        "t.toml:" + std::to_string(line_of(text, "active")) +
            ": [[support]].active is 2D-only: a 3D scene ([scene] dimension = 3) has no "
            "active (a 3D support holds in every load step: releasing it along the loading "
            "path, which rebuilds the levels between steps, is 2D-only)");
}

TEST(LoadPath3, TheProblemChecksItsListsAsThe2DProblem) {
    auto p = scene::parse_scene3(kSlide, "slide.toml");
    p.validate();
    auto q = p;
    q.loads[0].factors = {1.0, 1.0, 1.0};
    try {
        q.validate();
        ADD_FAILURE() << "validate accepted lists of lengths 3 and 2";
    } catch (const InvalidInput& e) {
        expect_message(e.what(), "support on 'zmax' (ux) has 2 path values but another list has 3; "
                                 "every per-step list must have the same length");
    }
    q = p;
    q.supports[0].u[0] = 1.0; // not the last entry of its list
    try {
        q.validate();
        ADD_FAILURE() << "validate accepted ux != its list's last entry";
    } catch (const InvalidInput& e) {
        expect_message(e.what(), "support on 'zmax': ux must equal the last entry of its per-point "
                                 "list");
    }
    // Without lists: one path point, the proportional loading.
    q = p;
    q.loads[0].factors.clear();
    q.supports[0].u_path[0].clear();
    EXPECT_EQ(q.n_path_points(), 1);
    q.validate();
}

} // namespace
} // namespace mlc

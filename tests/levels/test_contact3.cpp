// SPDX-License-Identifier: MIT
// 3D contact runs (levels/solve3): a block on a frictionless rigid plane under uniform pressure
// (the exact P1 solution: uniform pressure, linear displacements) on levels 0-2 with every
// Newton-system solver, the multiplier transfer's conservation, coarse-to-fine against cold, and
// a frictional case whose Newton must converge in 3D slip.
#include "core/check.hpp"
#include "levels/solve3.hpp"
#include "mesh/tet_mesh.hpp"
#include "scene/scene3.hpp"

#include <algorithm>

#include <gtest/gtest.h>

#include <cmath>

namespace mlc {
namespace {

using mesh::Vec3;

constexpr double kE = 1.0, kNu = 0.3, kP = 0.01;

// A unit cube on the rigid plane z = 0 (frictionless unless mu > 0), pressed by kP on its top,
// held by ux = 0 on x = 0 and uy = 0 on y = 0 only.
levels::ElasticProblem3 punch(int levels, double mu = 0.0, int n = 2) {
    levels::ElasticProblem3 p;
    p.name = "punch";
    p.mesh0 = mesh::structured_box(Vec3::Zero(), Vec3::Ones(), n, n, n);
    levels::Body3 b;
    b.name = "block";
    b.material.E = kE;
    b.material.nu = kNu;
    p.bodies = {b};
    levels::FaceLoad3 load;
    load.tag = "zmax";
    load.pressure = kP;
    p.loads = {load};
    levels::Support3 sx, sy;
    sx.tag = "xmin";
    sx.u[0] = 0.0;
    sy.tag = "ymin";
    sy.u[1] = 0.0;
    p.supports = {sx, sy};
    levels::ContactPair3 c;
    c.name = "floor";
    c.contactor = "zmin";
    c.obstacle.kind = contact::BasicObstacle<3>::Kind::plane;
    c.obstacle.point = Vec3::Zero();
    c.obstacle.normal = Vec3::UnitZ();
    c.mu = mu;
    c.r = 0.1 * kE / n;
    p.contacts = {c};
    p.levels = levels;
    return p;
}

// Pressure -lambda_n / area at every contact node equals kP, and the displacements are the
// exact u = (nu p x, nu p y, -p z) / E, both to `tol` relative.
void expect_exact_punch(const levels::ElasticProblem3& p, const levels::RunResult3& r,
                        double tol) {
    ASSERT_TRUE(r.converged) << r.failure;
    const auto& L = r.finest();
    const auto areas = levels::contact_areas(p, L);
    ASSERT_EQ(r.nodes.size(), L.contacts.size());
    ASSERT_GT(r.nodes.size(), 0u);
    for (size_t e = 0; e < r.nodes.size(); ++e) {
        EXPECT_NEAR(-r.nodes[e].lambda_n / areas[e], kP, tol * kP) << "node " << e;
        EXPECT_NE(r.nodes[e].status, contact::Status::gap);
    }
    double err = 0.0;
    for (int v = 0; v < L.mesh.n_vertices(); ++v) {
        const Vec3& x = L.mesh.vertices[static_cast<size_t>(v)];
        const Vec3 exact(kNu * kP * x.x() / kE, kNu * kP * x.y() / kE, -kP * x.z() / kE);
        err = std::max(err, (r.u_full.segment<3>(3 * v) - exact).cwiseAbs().maxCoeff());
    }
    EXPECT_LE(err, tol * kP);
}

TEST(Contact3, PunchUniformPressureExactOnLevels0To2EverySolver) {
    for (auto m : {levels::Method3::schur, levels::Method3::lu, levels::Method3::mg})
        for (int l = 0; l <= 2; ++l) {
            SCOPED_TRACE(std::string(levels::to_string(m)) + " level " + std::to_string(l));
            const auto p = punch(l);
            levels::SolveOptions3 so;
            so.upper = m;
            if (m != levels::Method3::mg) so.level0 = m;
            so.krylov_rel_tol = 1e-12;
            expect_exact_punch(p, levels::solve(p, so), 1e-10);
        }
}

TEST(Contact3, MultiplierTransferConservesTheTotalForce) {
    const auto p = punch(1);
    const auto H = levels::build_hierarchy(p, 1);
    const auto& C = H.levels[0];
    const auto& F = H.levels[1];
    const levels::MultiplierTransfer3 q(C, F, levels::contactor_faces(p, C),
                                        levels::contactor_faces(p, F));
    // Arbitrary normal multipliers on the coarse nodes; the fine ones must sum to the same force.
    Vector xc = Vector::Zero(C.n_unknowns()), xf = Vector::Zero(F.n_unknowns());
    double total = 0.0;
    for (size_t e = 0; e < C.contacts.size(); ++e) {
        const double v = -1.0 - 0.37 * static_cast<double>(e) + 0.01 * static_cast<double>(e * e);
        xc[C.lambda_dof[e]] = v;
        total += v;
    }
    q.apply(xc, xf);
    double fine_total = 0.0;
    for (size_t e = 0; e < F.contacts.size(); ++e)
        fine_total += xf[F.lambda_dof[e]];
    EXPECT_NEAR(fine_total, total, 1e-12 * std::abs(total));
    // The multigrid's T carries the same multiplier block.
    const SparseMatrix T = levels::full_prolongation3(H.transfers[0].T, q);
    const Vector xt = T * xc;
    for (size_t e = 0; e < F.contacts.size(); ++e)
        EXPECT_NEAR(xt[F.lambda_dof[e]], xf[F.lambda_dof[e]], 1e-14);
}

TEST(Contact3, CoarseToFinePredictsThePunchStatusesAndNeedsFewerFinestIterations) {
    const auto p = punch(2);
    levels::SolveOptions3 warm, cold;
    cold.coarse_to_fine = false;
    const auto rw = levels::solve(p, warm);
    const auto rc = levels::solve(p, cold);
    ASSERT_TRUE(rw.converged && rc.converged);
    const auto& top = rw.level_steps.back().front();
    EXPECT_TRUE(top.predicted);
    EXPECT_DOUBLE_EQ(top.agreement(), 1.0);
    EXPECT_LE(rw.steps.front().iterations, rc.steps.front().iterations);
    // The same answer either way.
    EXPECT_LE((rw.u_full - rc.u_full).cwiseAbs().maxCoeff(), 1e-10 * kP);
}

TEST(Contact3, FrictionalPunchConvergesWithSlipAndTheCoulombDisc) {
    // With friction the bottom's lateral expansion is resisted: nodes near the centre stick,
    // those at the edges slip outwards. Every converged node satisfies |lambda_t| <= mu |lambda_n|,
    // with equality in slip, and the slip direction is a unit vector.
    // No supports: friction alone holds the block in its plane (the symmetry supports would meet
    // the contact frame in one tangent only, which frictional 3D nodes refuse).
    const double mu = 0.2;
    auto p = punch(1, mu);
    p.supports.clear();
    for (auto m : {levels::Method3::schur, levels::Method3::lu, levels::Method3::mg}) {
    SCOPED_TRACE(levels::to_string(m));
    levels::SolveOptions3 so;
    so.level0 = m == levels::Method3::mg ? levels::Method3::schur : m;
    so.upper = m;
    so.krylov_rel_tol = 1e-12;
    const auto r = levels::solve(p, so);
    ASSERT_TRUE(r.converged) << r.failure;
    int slip = 0, stick = 0;
    for (const auto& n : r.nodes) {
        const double lt = n.lambda_t.norm(), ln = std::abs(n.lambda_n);
        EXPECT_LE(lt, mu * ln * (1 + 1e-9) + 1e-15);
        if (n.status == contact::Status::slip) {
            ++slip;
            EXPECT_NEAR(lt, mu * ln, 1e-8 * ln);
            EXPECT_NEAR(n.slip_direction.norm(), 1.0, 1e-12);
        } else if (n.status == contact::Status::stick) {
            ++stick;
        }
    }
    EXPECT_GT(slip, 0);
    EXPECT_GT(stick + slip, 0);
    // Vertical equilibrium: the floor carries the load kP on the unit top face.
    double fz = 0.0;
    for (const auto& n : r.nodes)
        fz -= (n.t.col(0) * n.lambda_t[0] + n.t.col(1) * n.lambda_t[1] + n.n * n.lambda_n).z();
    EXPECT_NEAR(fz, kP, 1e-9 * kP);
    }
}

// The secant predictor on block3d, level 1: the loading is proportional and no status or slip
// direction changes from step to step, so the solution is linear in the load factor and the
// extrapolated start of steps 2-5 is exact: those steps converge at the check, on every level,
// coarse to fine and cold. Without the predictor every step takes Newton iterations (3D slip is
// not piecewise linear), and both give the same answer.
TEST(Contact3, SecantPredictorExactUnderProportionalLoading) {
    auto p = scene::load_scene3("block3d");
    p.levels = 1;
    for (const bool c2f : {true, false}) {
        levels::SolveOptions3 with, without;
        with.coarse_to_fine = without.coarse_to_fine = c2f;
        without.extrapolate = false;
        const auto rw = levels::solve(p, with);
        const auto ro = levels::solve(p, without);
        ASSERT_TRUE(rw.converged) << rw.failure;
        ASSERT_TRUE(ro.converged) << ro.failure;
        for (int l = c2f ? 0 : 1; l <= 1; ++l) {
            const auto& sw = rw.level_steps[static_cast<size_t>(l)];
            const auto& so = ro.level_steps[static_cast<size_t>(l)];
            ASSERT_EQ(sw.size(), 5u);
            EXPECT_GT(sw[0].report.iterations, 0) << "level " << l;
            for (size_t k = 1; k < sw.size(); ++k) {
                EXPECT_EQ(sw[k].report.iterations, 0) << "level " << l << " step " << k + 1;
                EXPECT_GT(so[k].report.iterations, 0) << "level " << l << " step " << k + 1;
            }
        }
        const double us = ro.u_full.cwiseAbs().maxCoeff();
        EXPECT_LE((rw.u_full - ro.u_full).cwiseAbs().maxCoeff(), 1e-8 * us);
        const double xs = ro.x.cwiseAbs().maxCoeff();
        EXPECT_LE((rw.x - ro.x).cwiseAbs().maxCoeff(), 1e-8 * xs);
    }
}

// The 3D plan: schur on level 0 when it fits, lu when only lu fits, mg above; --linear forces
// one exact solver everywhere; a plan that does not fit is refused.
TEST(Contact3, PlanChoosesTheLevel0SolverBySizeAndMemory) {
    auto p = scene::load_scene3("block3d");
    p.levels = 2;
    auto sizes = levels::predict_elastic3_sizes(p, p.levels);
    const levels::MemoryLimit none{};
    auto plan = levels::plan_contact3(sizes, std::nullopt, none);
    EXPECT_EQ(plan.level0, levels::Method3::schur);
    EXPECT_EQ(plan.upper, levels::Method3::mg);
    EXPECT_EQ(plan.why, "level 0 schur (60 contact components), gmres + mg above");
    plan = levels::plan_contact3(sizes, levels::Method3::schur, none);
    EXPECT_EQ(plan.level0, levels::Method3::schur);
    EXPECT_EQ(plan.upper, levels::Method3::schur);
    // schur's dense systems of level 0 alone beyond the limit: lu instead, when lu fits.
    sizes.front().multipliers = 1000;
    const double with_schur =
        levels::estimate_contact3_bytes(sizes, levels::Method3::schur, levels::Method3::mg);
    const double with_lu =
        levels::estimate_contact3_bytes(sizes, levels::Method3::lu, levels::Method3::mg);
    ASSERT_LT(with_lu, with_schur);
    levels::MemoryLimit between;
    between.bytes = 0.5 * (with_lu + with_schur);
    between.source = "test";
    plan = levels::plan_contact3(sizes, std::nullopt, between);
    EXPECT_EQ(plan.level0, levels::Method3::lu);
    EXPECT_EQ(plan.why, "level 0 lu (1000 contact components: schur's dense systems do not fit), "
                        "gmres + mg above");
    plan = levels::plan_contact3(sizes, std::nullopt, none);
    EXPECT_EQ(plan.level0, levels::Method3::schur);
    levels::MemoryLimit tiny;
    tiny.bytes = 0.5 * with_lu;
    tiny.source = "test";
    EXPECT_THROW(levels::plan_contact3(sizes, std::nullopt, tiny), mlc::InvalidInput);
}

// The sparse LU's memory on block3d (docs/results/contact3d.md#results-contact3d-lu-memory):
// `run block3d --levels 3 --linear lu` peaks at 3.57 GiB and level 2 at 104 MiB; the estimate
// covers both (the old rule, twice a Cholesky factor, gave 1.0 GiB on level 3).
TEST(Contact3, SparseLuEstimateCoversTheMeasuredPeaks) {
    auto p = scene::load_scene3("block3d");
    const double mib = 1024.0 * 1024.0;
    for (const auto& [level, peak] : {std::pair{2, 104.0 * mib}, std::pair{3, 3.57 * 1024 * mib}}) {
        const auto sizes = levels::predict_elastic3_sizes(p, level);
        const double est =
            levels::estimate_contact3_bytes(sizes, levels::Method3::lu, levels::Method3::lu);
        EXPECT_GE(est, 0.95 * peak) << "level " << level;
        EXPECT_LE(est, 1.5 * peak) << "level " << level;
    }
}

} // namespace
} // namespace mlc

namespace mlc {
namespace {

// block3d (the square test in 3D, mu = 1, 5 steps) on level 2: GMRES + mg takes a median of at
// most 12 and at most 20 iterations per Newton system on every level >= 1, and coarse-to-fine
// takes at most half the finest level's Newton iterations of the cold solve, with the same
// answer.
TEST(Contact3, Block3dMultigridIterationsAndCoarseToFineAgainstCold) {
    auto p = scene::load_scene3("block3d");
    p.levels = 2;
    levels::SolveOptions3 warm, cold;
    cold.coarse_to_fine = false;
    const auto rw = levels::solve(p, warm);
    const auto rc = levels::solve(p, cold);
    ASSERT_TRUE(rw.converged) << rw.failure;
    ASSERT_TRUE(rc.converged) << rc.failure;
    for (int l = 1; l <= 2; ++l) {
        std::vector<int> its;
        for (const auto& st : rw.level_steps[static_cast<size_t>(l)])
            its.insert(its.end(), st.report.linear_iterations_per_newton.begin(),
                       st.report.linear_iterations_per_newton.end());
        ASSERT_FALSE(its.empty());
        std::sort(its.begin(), its.end());
        EXPECT_LE(its[its.size() / 2], 12) << "level " << l;
        EXPECT_LE(its.back(), 20) << "level " << l;
        EXPECT_GT(its.front(), 0) << "level " << l;
    }
    int warm_its = 0, cold_its = 0;
    for (const auto& s : rw.steps)
        warm_its += s.iterations;
    for (const auto& s : rc.steps)
        cold_its += s.iterations;
    EXPECT_LE(2 * warm_its, cold_its);
    const double scale = rc.u_full.cwiseAbs().maxCoeff();
    EXPECT_LE((rw.u_full - rc.u_full).cwiseAbs().maxCoeff(), 1e-8 * scale);
    // Slip nodes in 3D: some, with unit slip directions.
    int slip = 0;
    for (const auto& n : rw.nodes)
        if (n.status == contact::Status::slip) {
            ++slip;
            EXPECT_NEAR(n.slip_direction.norm(), 1.0, 1e-12);
        }
    EXPECT_GT(slip, 0);
}

} // namespace
} // namespace mlc

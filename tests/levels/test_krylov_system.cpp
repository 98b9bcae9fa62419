// SPDX-License-Identifier: MIT
// Krylov Newton-system solvers with the papers' preconditioners on two levels of the square:
// one fine Newton system of the multilevel Newton, solved by CGS with ILU(0), CF, SORCF and EBE,
// against the exact condensed ("schur") solve.
#include "contact/element.hpp"
#include "core/check.hpp"
#include "levels/hierarchy.hpp"
#include "levels/krylov_system.hpp"
#include "levels/level.hpp"
#include "levels/newton.hpp"
#include "mesh/mesh.hpp"
#include "scene/scene.hpp"
#include "transfer/transfer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>

using namespace mlc;
using namespace mlc::levels;

namespace {

// Levels 0 and 1 of the built-in square (mu = 1, five load steps). The coarse level is solved
// through every load step by Newton with the exact "schur" solver; the fine Newton system is the
// first one of the multilevel Newton at the last step: J(M_h) dx = -R(x_h0) at the interpolated
// state x_h0 = T x_H, with M_h the statuses there.
struct TwoLevels {
    Problem problem;
    Level coarse, fine;
    transfer::LevelTransfer transfer;
    std::unique_ptr<NewtonSystemSolver> coarse_solver; // exact, for the CF context
    std::vector<Eigen::Matrix2d> coarse_M, fine_M;
    Vector b, dx_ref;
    std::unique_ptr<JacobianAssembler> J;

    TwoLevels() {
        problem = scene::load_scene("square");
        coarse = build_level(problem, problem.mesh0);
        fine = build_level(problem, mesh::refine(problem.mesh0));
        transfer =
            transfer::build_transfer(fine.mesh, coarse.dofs, fine.dofs,
                                     levels::contact_nodes(coarse), levels::contact_nodes(fine));
        ContactNewton newton_c(
            coarse, problem.newton,
            make_newton_system_solver(coarse, {.method = solvers::Method::schur}));
        Vector x = Vector::Zero(coarse.n_unknowns());
        Vector u_prev = Vector::Zero(2 * coarse.mesh.n_vertices()), u_full;
        const int N = problem.load_steps;
        for (int step = 1; step <= N; ++step) {
            const double s = static_cast<double>(step) / N;
            const StepReport rep = newton_c.solve(s, u_prev, x);
            EXPECT_TRUE(rep.converged) << "coarse step " << step << ": " << rep.message;
            if (step == N) break;
            coarse.dofs.expand(x, s * coarse.u_fixed, u_full);
            u_prev = u_full;
        }
        Vector R;
        double scale = 0.0;
        newton_c.residual(1.0, u_prev, x, R, nullptr, &coarse_M, &scale);
        coarse_solver = make_newton_system_solver(coarse, {.method = solvers::Method::schur});

        ContactNewton newton_f(fine, problem.newton,
                               make_newton_system_solver(fine, {.method = solvers::Method::schur}));
        Vector x_f, u_prev_f;
        transfer.prolongate(x, x_f);
        transfer.interpolate_nodal(u_prev, u_prev_f);
        newton_f.residual(1.0, u_prev_f, x_f, R, nullptr, &fine_M, &scale);
        b = -R;
        auto schur = make_newton_system_solver(fine, {.method = solvers::Method::schur});
        schur->solve(fine_M, b, dx_ref);
        J = std::make_unique<JacobianAssembler>(fine);
        J->assemble(fine_M);
    }

    LevelBelow below() {
        LevelBelow c;
        c.coarse = &coarse;
        c.transfer = &transfer;
        c.solver = coarse_solver.get();
        return c;
    }
};

TwoLevels& two_levels() {
    static TwoLevels t;
    return t;
}

struct Outcome {
    SolveResult result;
    double true_rel = 0.0, err = 0.0;
    std::string name;
};

Outcome solve_with(const std::string& krylov, const std::string& pc, double rel_tol = 1e-9) {
    TwoLevels& t = two_levels();
    const LevelBelow below = t.below();
    LinearSolverSpec spec{.method = solvers::Method::krylov,
                          .krylov = solvers::parse_krylov(krylov),
                          .pc = solvers::parse_pc(pc),
                          .rel_tol = rel_tol};
    auto solver = make_newton_system_solver(t.fine, spec, &below);
    solver->set_coarse_statuses(t.coarse_M);
    Outcome o;
    Vector dx = Vector::Zero(t.b.size());
    o.result = solver->solve(t.fine_M, t.b, dx);
    o.true_rel = (t.b - t.J->matrix() * dx).norm() / t.b.norm();
    o.err = (dx - t.dx_ref).norm() / t.dx_ref.norm();
    o.name = solver->name();
    return o;
}

} // namespace

TEST(KrylovSystem, TheFineSystemIsAGenuineContactSystem) {
    TwoLevels& t = two_levels();
    EXPECT_EQ(t.coarse.n_contact_nodes(), 16);
    EXPECT_EQ(t.fine.n_contact_nodes(), 32);
    // Both stick and slip statuses (zero multiplier diagonals, non-symmetric J).
    int stick = 0, slip = 0;
    for (const auto& M : t.fine_M) {
        if (M.isIdentity()) ++stick;
        if (M(0, 0) == 0.0 && M(1, 1) == 1.0) ++slip;
    }
    EXPECT_GT(stick, 0);
    EXPECT_GT(slip, 0);
    EXPECT_GT(t.b.norm(), 0.0);
    // The reference solve is exact.
    EXPECT_LT((t.b - t.J->matrix() * t.dx_ref).norm(), 1e-10 * t.b.norm());
}

TEST(KrylovSystem, ElementMatricesSumToTheJacobian) {
    TwoLevels& t = two_levels();
    std::vector<smoothers::ElementMatrix> els = elastic_element_matrices(t.fine);
    EXPECT_EQ(static_cast<int>(els.size()), t.fine.mesh.n_cells());
    for (size_t e = 0; e < t.fine.contacts.size(); ++e) {
        smoothers::ElementMatrix c;
        contact_element_matrix(t.fine, e, t.fine_M[e], c);
        EXPECT_TRUE(c.is_contact);
        EXPECT_EQ(c.dofs.size(), 4u); // u_x, u_y, lambda_t, lambda_n (mu = 1)
        els.push_back(c);
    }
    std::vector<Triplet> trip;
    for (const auto& e : els)
        for (size_t a = 0; a < e.dofs.size(); ++a)
            for (size_t b = 0; b < e.dofs.size(); ++b)
                trip.emplace_back(e.dofs[a], e.dofs[b],
                                  e.A(static_cast<Index>(a), static_cast<Index>(b)));
    SparseMatrix S(t.fine.n_unknowns(), t.fine.n_unknowns());
    S.setFromTriplets(trip.begin(), trip.end());
    const SparseMatrix D = S - t.J->matrix();
    EXPECT_LT(D.norm(), 1e-12 * t.J->matrix().norm());
}

TEST(JacobianAssembler, IsKPlusTheContactTangentsAndReassemblesInPlace) {
    // The pattern is merged row by row from K's and the contact entries' (multiplier rows and
    // the contact nodes' displacement rows gain columns K lacks); the values are K's plus the
    // tangents at the given statuses. Reassembling at other statuses resets exactly the rows
    // contact touches: the result equals a fresh assembler's, bit for bit.
    TwoLevels& t = two_levels();
    const Level& L = t.fine;
    std::vector<Triplet> trip;
    const SparseMatrix& K = L.elastic.K;
    for (int i = 0; i < K.outerSize(); ++i)
        for (SparseMatrix::InnerIterator it(K, i); it; ++it)
            trip.emplace_back(i, static_cast<int>(it.col()), it.value());
    for (size_t e = 0; e < L.contacts.size(); ++e)
        contact::for_each_tangent_entry(
            L.contacts[e], t.fine_M[e], L.dofs, L.lambda_dof[e],
            [&](int r, int c, double v) { trip.emplace_back(r, c, v); });
    SparseMatrix ref(L.n_unknowns(), L.n_unknowns());
    ref.setFromTriplets(trip.begin(), trip.end());
    ASSERT_GT(ref.nonZeros(), K.nonZeros()); // contact adds entries outside K's pattern

    JacobianAssembler a(L);
    a.assemble(std::vector<Eigen::Matrix2d>(L.contacts.size(), Eigen::Matrix2d::Identity()));
    a.assemble(std::vector<Eigen::Matrix2d>(L.contacts.size(), Eigen::Matrix2d::Zero()));
    a.assemble(t.fine_M);
    const SparseMatrix& J = a.matrix();
    ASSERT_EQ(J.nonZeros(), ref.nonZeros());
    for (Index i = 0; i <= J.rows(); ++i)
        ASSERT_EQ(J.outerIndexPtr()[i], ref.outerIndexPtr()[i]) << i;
    for (Index k = 0; k < J.nonZeros(); ++k)
        ASSERT_EQ(J.innerIndexPtr()[k], ref.innerIndexPtr()[k]) << k;
    const SparseMatrix D = J - ref;
    const double kmax = Eigen::Map<const Vector>(K.valuePtr(), K.nonZeros()).cwiseAbs().maxCoeff();
    EXPECT_LE(Eigen::Map<const Vector>(D.valuePtr(), D.nonZeros()).cwiseAbs().maxCoeff(),
              1e-14 * kmax);

    JacobianAssembler fresh(L);
    fresh.assemble(t.fine_M);
    for (Index k = 0; k < J.nonZeros(); ++k)
        ASSERT_EQ(J.valuePtr()[k], fresh.matrix().valuePtr()[k]) << k;
}

TEST(KrylovSystem, ElementsRestrictedToTheFirstUnknownsSumToTheLeadingBlock) {
    // EBE on one process's diagonal block: the elements restricted to the unknowns
    // [0, n) sum to J's leading n x n block, for any n; elements with none of them are dropped.
    TwoLevels& t = two_levels();
    std::vector<smoothers::ElementMatrix> all = elastic_element_matrices(t.fine);
    for (size_t e = 0; e < t.fine.contacts.size(); ++e) {
        smoothers::ElementMatrix c;
        contact_element_matrix(t.fine, e, t.fine_M[e], c);
        all.push_back(c);
    }
    const Index N = t.fine.n_unknowns();
    for (const Index n : {N, N / 2 + 1, N / 3, Index{5}}) {
        std::vector<smoothers::ElementMatrix> els = all;
        restrict_elements(els, n);
        size_t touching = 0;
        for (const auto& e : all)
            touching += std::any_of(e.dofs.begin(), e.dofs.end(), [n](int d) { return d < n; });
        EXPECT_EQ(els.size(), touching) << n;
        std::vector<Triplet> trip;
        for (const auto& e : els) {
            ASSERT_EQ(e.A.rows(), static_cast<Index>(e.dofs.size()));
            for (size_t a = 0; a < e.dofs.size(); ++a) {
                ASSERT_LT(e.dofs[a], n);
                for (size_t b = 0; b < e.dofs.size(); ++b)
                    trip.emplace_back(e.dofs[a], e.dofs[b],
                                      e.A(static_cast<Index>(a), static_cast<Index>(b)));
            }
        }
        SparseMatrix S(n, n);
        S.setFromTriplets(trip.begin(), trip.end());
        const SparseMatrix B = t.J->matrix().topLeftCorner(n, n);
        EXPECT_LT(SparseMatrix(S - B).norm(), 1e-12 * t.J->matrix().norm()) << n;
        EXPECT_GT(B.norm(), 0) << n;
    }
}

TEST(KrylovSystem, EveryPreconditionerSolvesTheFineSystem) {
    for (const std::string pc : {"ilu:0", "cf", "sorcf", "ebe", "ebe:variant=c5"}) {
        const Outcome o = solve_with("cgs", pc);
        EXPECT_TRUE(o.result.converged) << pc << ": " << o.result;
        EXPECT_LT(o.true_rel, 1e-8) << pc;
        EXPECT_LT(o.err, 1e-6) << pc;
        std::cout << "    cgs + " << o.name << ": " << o.result.iterations << " iterations, "
                  << "true rel. residual " << o.true_rel << ", error " << o.err << "\n";
    }
}

TEST(KrylovSystem, CoarseFineVariantsSolveTheFineSystem) {
    // CF is much stronger than ILU(0): the coarse operator carries the low frequencies.
    const Outcome ilu = solve_with("cgs", "ilu:0");
    const Outcome cf = solve_with("cgs", "cf");
    EXPECT_LT(cf.result.iterations, ilu.result.iterations / 3);
    for (const std::string pc : {"cf:coarse=solver", "cf:scale=none", "sorcf:omega=1.2,block=1",
                                 "ebe:variant=c5,unit=contact"}) {
        const Outcome o = solve_with("cgs", pc);
        EXPECT_TRUE(o.result.converged) << pc << ": " << o.result;
        EXPECT_LT(o.true_rel, 1e-8) << pc;
        EXPECT_LT(o.err, 1e-6) << pc;
    }
    // C5's correction of the gathered diagonal matters: C4 needs many more iterations (or fails).
    EXPECT_LT(solve_with("cgs", "ebe:variant=c5").result.iterations,
              solve_with("cgs", "ebe:variant=c4").result.iterations);
    // The coarse LU and the coarse Newton-system solver are the same exact A_H^{-1}.
    EXPECT_EQ(solve_with("cgs", "cf:coarse=solver").result.iterations, cf.result.iterations);
    // The paper's inner CGS makes the preconditioner vary: outer CGS and GMRES (which assume a
    // fixed one) fail, BiCGStab copes when the inner solve is tight enough (at 1e-6 it copes or
    // stagnates by the last bits of the coarse factorization, which depend on the processor).
    const Outcome inner = solve_with("bicgstab", "cf:inner=cgs,tol=1e-8");
    EXPECT_TRUE(inner.result.converged) << inner.result;
    EXPECT_LT(inner.true_rel, 1e-8);
}

TEST(KrylovSystem, LevelAwarePreconditionersCheckTheirInput) {
    TwoLevels& t = two_levels();
    const LinearSolverSpec cf{.method = solvers::Method::krylov, .pc = solvers::parse_pc("cf")};
    try {
        make_newton_system_solver(t.fine, cf, nullptr);
        ADD_FAILURE() << "cf without a coarse context must throw";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("cf needs the level below"), std::string::npos)
            << e.what();
    }
    const LevelBelow empty;
    EXPECT_THROW(
        make_newton_system_solver(
            t.fine, {.method = solvers::Method::krylov, .pc = solvers::parse_pc("sorcf")}, &empty),
        InvalidInput);
    const LevelBelow ctx = t.below();
    for (const std::string pc : {"cf:inner=ilu", "cf:scale=half", "cf:coarse=amg", "cf:omega=1",
                                 "sorcf:block=2", "sorcf:omega=2", "ebe:variant=c2", "ebe:omega=1"})
        EXPECT_THROW(
            make_newton_system_solver(
                t.fine, {.method = solvers::Method::krylov, .pc = solvers::parse_pc(pc)}, &ctx),
            InvalidInput)
            << pc;
    // EBE needs no coarse level.
    EXPECT_NO_THROW(make_newton_system_solver(
        t.fine, {.method = solvers::Method::krylov, .pc = solvers::parse_pc("ebe")}, nullptr));
}

TEST(KrylovSystem, TheCoarseStatusesArePassedByTheDriver) {
    // The coarse-to-fine driver builds the solver before the coarse level is solved and passes
    // the coarse statuses afterwards (set_coarse_statuses), at every load step.
    TwoLevels& t = two_levels();
    const LevelBelow below = t.below();
    auto solver = make_newton_system_solver(
        t.fine, {.method = solvers::Method::krylov, .pc = solvers::parse_pc("cf"), .rel_tol = 1e-9},
        &below);
    Vector dx;
    EXPECT_THROW(solver->solve(t.fine_M, t.b, dx), InvalidInput);
    EXPECT_THROW(solver->set_coarse_statuses({Eigen::Matrix2d::Identity()}), InvalidInput);
    solver->set_coarse_statuses(t.coarse_M);
    dx.setZero(t.b.size());
    const SolveResult first = solver->solve(t.fine_M, t.b, dx);
    EXPECT_TRUE(first.converged);
    EXPECT_LT((dx - t.dx_ref).norm(), 1e-6 * t.dx_ref.norm());
    // Same statuses again: nothing is reassembled, the same iterations.
    dx.setZero(t.b.size());
    const SolveResult again = solver->solve(t.fine_M, t.b, dx);
    EXPECT_EQ(again.iterations, first.iterations);
    EXPECT_LT(again.setup_seconds, first.setup_seconds);
    // Other coarse statuses (all stuck): the coarse LU is refactored, CF is a different
    // preconditioner but still converges.
    solver->set_coarse_statuses(
        std::vector<Eigen::Matrix2d>(t.coarse_M.size(), Eigen::Matrix2d::Identity()));
    dx.setZero(t.b.size());
    const SolveResult stuck = solver->solve(t.fine_M, t.b, dx);
    EXPECT_TRUE(stuck.converged);
    EXPECT_GT(stuck.iterations, first.iterations);
}

// SPDX-License-Identifier: MIT
// Krylov methods x preconditioners on manufactured problems (x* = 1), plus the failure paths:
// NaN input, breakdown, max_iter, b = 0, history and true residuals.
#include "core/check.hpp"
#include "core/parallel.hpp"
#include "smoothers/block_sor.hpp"
#include "solvers/direct.hpp"
#include "solvers/factory.hpp"
#include "solvers/krylov.hpp"
#include "tests/smoothers/matrices.hpp"

#include <gtest/gtest.h>

#include <sstream>
#include <tuple>

using namespace mlc;
using namespace mlc::solvers;

namespace {

struct Problem {
    std::string name;
    SparseMatrix A;
    std::vector<Index> vertex_starts; // for block SOR on the saddle-point matrix
};

const std::vector<Problem>& problems() {
    static const std::vector<Problem> p = [] {
        std::vector<Problem> v;
        v.push_back({"laplace_1d", testmat::laplace_1d(40), {}});
        v.push_back({"laplace_2d", testmat::laplace_2d(8), {}});
        v.push_back({"convection_diffusion", testmat::convection_diffusion(), {}});
        std::vector<Index> vs;
        SparseMatrix S = testmat::contact_saddle(12, &vs);
        v.push_back({"contact_saddle", S, vs});
        return v;
    }();
    return p;
}

// Preconditioner for a spec; "sor"/"ssor" use vertex(+multiplier) blocks on the saddle point.
std::unique_ptr<Preconditioner> make_for(const std::string& spec, const Problem& p) {
    if ((spec == "sor" || spec == "ssor") && !p.vertex_starts.empty())
        return std::make_unique<smoothers::BlockSOR>(smoothers::BlockSORParams{
            .omega = 1.2,
            .sweep = spec == "sor" ? smoothers::Sweep::forward : smoothers::Sweep::symmetric,
            .block_starts = p.vertex_starts});
    if (spec == "sor" || spec == "ssor") return make_preconditioner(spec + ":omega=1.2");
    return make_preconditioner(spec);
}

using Combo = std::tuple<Krylov, std::string, int>;

// Every method x preconditioner x problem, except forward SOR on the tridiagonal matrix with
// CGS and BiCG: C^{-1} A is defective there (Krylov.DefectiveSorPreconditionedTridiagonal).
std::vector<Combo> combos() {
    std::vector<Combo> c;
    for (Krylov k : {Krylov::cgs, Krylov::bicg, Krylov::bicgstab, Krylov::gmres})
        for (const char* spec : {"none", "diag", "ilu:0", "ilu:1", "sor", "ssor", "lu"})
            for (int p = 0; p < static_cast<int>(problems().size()); ++p) {
                const bool defective = std::string(spec) == "sor" &&
                                       problems()[p].name == "laplace_1d" &&
                                       (k == Krylov::cgs || k == Krylov::bicg);
                if (!defective) c.emplace_back(k, spec, p);
            }
    return c;
}

class KrylovSweep : public ::testing::TestWithParam<Combo> {};

} // namespace

TEST_P(KrylovSweep, ConvergesToOnesWithTrueResidual) {
    const auto& [method, spec, pi] = GetParam();
    const Problem& p = problems()[static_cast<size_t>(pi)];
    const Index n = p.A.rows();
    const Vector ones = Vector::Ones(n);
    const Vector b = p.A * ones;
    auto M = make_for(spec, p);
    M->setup(p.A);
    KrylovParams params{.rel_tol = 1e-10, .max_iter = 2000, .restart = 30};
    Vector x; // empty: zero initial guess
    const SolveResult r = solve(method, p.A, *M, b, x, params);
    ASSERT_TRUE(r.converged) << r;
    EXPECT_EQ(r.reason, StopReason::converged);
    EXPECT_GT(r.iterations, 0);
    const double true_res = (b - p.A * x).norm();
    EXPECT_NEAR(r.final_residual, true_res, 1e-14 * b.norm());
    EXPECT_NEAR(r.relative_residual, true_res / b.norm(), 1e-14);
    EXPECT_LE(r.relative_residual, 1e-10);
    EXPECT_NEAR(r.initial_residual, b.norm(), 1e-12 * b.norm());
    EXPECT_LE((x - ones).norm(), 1e-6 * ones.norm()) << r;
}

INSTANTIATE_TEST_SUITE_P(AllMethodsAllPreconditioners, KrylovSweep, ::testing::ValuesIn(combos()),
                         [](const ::testing::TestParamInfo<Combo>& pinfo) {
                             std::string spec = std::get<1>(pinfo.param);
                             for (char& ch : spec)
                                 if (ch == ':') ch = '_';
                             return std::string(to_string(std::get<0>(pinfo.param))) + "_" + spec +
                                    "_" +
                                    problems()[static_cast<size_t>(std::get<2>(pinfo.param))].name;
                         });

TEST(Krylov, CgsWithExactLUConvergesInOneOrTwoIterations) {
    for (const auto& p : problems()) {
        SparseLUPreconditioner lu;
        lu.setup(p.A);
        const Vector b = p.A * Vector::Ones(p.A.rows());
        Vector x = Vector::Zero(p.A.rows());
        const SolveResult r = cgs(MatrixOperator(p.A), lu, b, x, KrylovParams{.rel_tol = 1e-12});
        EXPECT_TRUE(r.converged) << p.name << ": " << r;
        EXPECT_LE(r.iterations, 2) << p.name;
        EXPECT_GE(r.iterations, 1) << p.name;
    }
}

// cg (the reductions a communicator needs, like the others) on an SPD matrix reaches the exact
// solution in at most n iterations; on an indefinite saddle point it reports the breakdown.
TEST(Krylov, CgSolvesASpdSystemAndRefusesAnIndefiniteMatrix) {
    const SparseMatrix A = testmat::laplace_2d(12);
    const auto M = make_preconditioner("diag");
    M->setup(A);
    const Vector xs = testmat::pseudo_random(A.rows());
    const Vector b = A * xs;
    Vector x;
    const SolveResult r = cg(MatrixOperator(A), *M, b, x, KrylovParams{.rel_tol = 1e-12});
    ASSERT_TRUE(r.converged) << r;
    EXPECT_LE(r.iterations, A.rows());
    EXPECT_LE(r.relative_residual, 1e-12);
    EXPECT_LE((x - xs).norm(), 1e-9 * xs.norm());
    std::vector<Index> vs;
    const SparseMatrix S = testmat::contact_saddle(12, &vs);
    const auto I = make_preconditioner("none");
    Vector x3;
    const SolveResult r3 =
        cg(MatrixOperator(S), *I, S * Vector::Ones(S.rows()), x3, KrylovParams{.rel_tol = 1e-10});
    EXPECT_FALSE(r3.converged);
    EXPECT_EQ(r3.reason, StopReason::breakdown) << r3;
}

TEST(Krylov, DefectiveSorPreconditionedTridiagonal) {
    // Forward Gauss-Seidel on tridiag(-1, 2, -1): the iteration matrix has eigenvalue 0 with a
    // Jordan block of size about n/2, so C^{-1} A is far from normal (eigenvector condition
    // number ~1e16). Lanczos-based CGS and BiCG lose biorthogonality and do not converge; they
    // must still return, with an honest reason and the true residual. BiCGStab and GMRES cope.
    const SparseMatrix A = testmat::laplace_1d(40);
    auto M = make_preconditioner("sor:omega=1.2");
    M->setup(A);
    const Vector b = A * Vector::Ones(A.rows());
    const KrylovParams params{.rel_tol = 1e-10, .max_iter = 300, .restart = 30};
    for (Krylov k : {Krylov::cgs, Krylov::bicg, Krylov::bicgstab, Krylov::gmres}) {
        Vector x;
        const SolveResult r = solve(k, A, *M, b, x, params);
        EXPECT_LE(r.iterations, params.max_iter) << k;
        if (x.allFinite()) {
            EXPECT_NEAR(r.final_residual, (b - A * x).norm(), 1e-8 * r.final_residual) << k;
        }
        EXPECT_EQ(r.converged, r.reason == StopReason::converged) << k;
        EXPECT_EQ(r.converged, r.relative_residual <= 1e-10) << k << ": " << r;
        if (k == Krylov::bicgstab || k == Krylov::gmres) {
            EXPECT_TRUE(r.converged) << k << ": " << r;
        }
    }
}

TEST(Krylov, NonZeroInitialGuessAndAbsoluteTolerance) {
    const SparseMatrix A = testmat::convection_diffusion();
    const MatrixOperator op(A);
    IdentityPreconditioner I;
    const Vector b = A * Vector::Ones(A.rows());
    for (Krylov k : {Krylov::cgs, Krylov::bicg, Krylov::bicgstab, Krylov::gmres}) {
        Vector x = testmat::pseudo_random(A.rows());
        const Vector x0 = x;
        const SolveResult r =
            solve(k, op, I, b, x, KrylovParams{.rel_tol = 0.0, .abs_tol = 1e-6 * b.norm()});
        EXPECT_TRUE(r.converged) << k << ": " << r;
        EXPECT_NEAR(r.initial_residual, (b - A * x0).norm(), 1e-12 * b.norm());
        EXPECT_LE(r.final_residual, 1e-6 * b.norm()) << k;
    }
}

TEST(Krylov, NaNInRightHandSideThrows) {
    const SparseMatrix A = testmat::laplace_1d(5);
    IdentityPreconditioner I;
    Vector b = Vector::Ones(5);
    b[2] = std::nan("");
    for (Krylov k : {Krylov::cgs, Krylov::bicg, Krylov::bicgstab, Krylov::gmres}) {
        Vector x;
        EXPECT_THROW(solve(k, A, I, b, x, {}), SolverBreakdown) << k;
    }
    b[2] = std::numeric_limits<double>::infinity();
    Vector x;
    EXPECT_THROW(solve(Krylov::gmres, A, I, b, x, {}), SolverBreakdown);
}

TEST(Krylov, ZeroInnerProductReturnsBreakdown) {
    // A = [[0, 1], [1, 0]], b = e1: (r0, A r0) = 0, so CGS, BiCG and BiCGStab break down at
    // once; GMRES does not (A is nonsingular) and solves it in two steps.
    const SparseMatrix A = testmat::from_triplets(2, {{0, 1, 1.0}, {1, 0, 1.0}});
    IdentityPreconditioner I;
    const Vector b = Vector::Unit(2, 0);
    for (Krylov k : {Krylov::cgs, Krylov::bicg, Krylov::bicgstab}) {
        Vector x;
        const SolveResult r = solve(k, A, I, b, x, {});
        EXPECT_FALSE(r.converged) << k;
        EXPECT_EQ(r.reason, StopReason::breakdown) << k;
        EXPECT_FALSE(r.message.empty()) << k;
        EXPECT_LE(r.iterations, 1) << k;
        EXPECT_NEAR(r.final_residual, (b - A * x).norm(), 1e-15) << k;
    }
    Vector x;
    const SolveResult g = gmres(MatrixOperator(A), I, b, x, {});
    EXPECT_TRUE(g.converged) << g;
    EXPECT_EQ(g.iterations, 2);
    EXPECT_NEAR(x[1], 1.0, 1e-14);
}

TEST(Krylov, GmresOnSingularSystemReturnsBreakdown) {
    // A = diag(1, 0), b = e2 is not in the range of A.
    const SparseMatrix A = testmat::from_triplets(2, {{0, 0, 1.0}, {1, 1, 0.0}});
    IdentityPreconditioner I;
    Vector x;
    const SolveResult r = gmres(MatrixOperator(A), I, Vector::Unit(2, 1), x, {});
    EXPECT_FALSE(r.converged);
    EXPECT_EQ(r.reason, StopReason::breakdown);
    EXPECT_NE(r.message.find("gmres"), std::string::npos) << r.message;
}

TEST(Krylov, MaxIterReturnsNotConverged) {
    const SparseMatrix A = testmat::laplace_2d(10);
    IdentityPreconditioner I;
    const Vector b = A * Vector::Ones(A.rows());
    for (Krylov k : {Krylov::cgs, Krylov::bicg, Krylov::bicgstab, Krylov::gmres}) {
        Vector x;
        const SolveResult r = solve(k, A, I, b, x, KrylovParams{.max_iter = 3, .restart = 2});
        EXPECT_FALSE(r.converged) << k;
        EXPECT_EQ(r.reason, StopReason::max_iter) << k;
        EXPECT_EQ(r.iterations, 3) << k;
        EXPECT_NEAR(r.final_residual, (b - A * x).norm(), 1e-13 * b.norm()) << k;
        if (k == Krylov::gmres) {
            EXPECT_LT(r.final_residual, r.initial_residual); // GMRES is monotone
        }
    }
    Vector x;
    const SolveResult r0 = solve(Krylov::cgs, A, I, b, x, KrylovParams{.max_iter = 0});
    EXPECT_EQ(r0.reason, StopReason::max_iter);
    EXPECT_EQ(r0.iterations, 0);
    EXPECT_EQ(x, Vector::Zero(A.rows()));
}

TEST(Krylov, UnattainableToleranceEndsAtMaxIter) {
    // rel_tol below round-off: the recursive residuals may claim convergence, the true residual
    // cannot follow; every method must stop (max_iter or breakdown) and report honestly.
    const SparseMatrix A = testmat::convection_diffusion();
    auto M = make_preconditioner("ilu:0");
    M->setup(A);
    const Vector xs = testmat::pseudo_random(A.rows(), 9); // not exactly representable in b
    const Vector b = A * xs;
    for (Krylov k : {Krylov::cgs, Krylov::bicg, Krylov::bicgstab, Krylov::gmres}) {
        Vector x;
        const SolveResult r =
            solve(k, A, *M, b, x, KrylovParams{.rel_tol = 1e-20, .max_iter = 150});
        // Converged only if x reproduces b to the last bit (tolerance ~1e-19).
        EXPECT_EQ(r.converged, r.final_residual <= 1e-20 * b.norm()) << k << ": " << r;
        EXPECT_EQ(r.converged, r.reason == StopReason::converged) << k;
        EXPECT_LE(r.iterations, 150) << k;
        EXPECT_NEAR(r.final_residual, (b - A * x).norm(), 1e-14 * b.norm()) << k;
        EXPECT_LE((x - xs).norm(), 1e-10 * xs.norm()) << k << ": " << r;
    }
}

TEST(Krylov, ZeroRightHandSideGivesZeroSolution) {
    const SparseMatrix A = testmat::laplace_1d(6);
    IdentityPreconditioner I;
    for (Krylov k : {Krylov::cgs, Krylov::bicg, Krylov::bicgstab, Krylov::gmres}) {
        Vector x = Vector::Ones(6);
        const SolveResult r = solve(k, A, I, Vector::Zero(6), x, {});
        EXPECT_TRUE(r.converged) << k;
        EXPECT_EQ(r.iterations, 0) << k;
        EXPECT_EQ(r.final_residual, 0.0) << k;
        EXPECT_EQ(x, Vector::Zero(6)) << k;
    }
}

TEST(Krylov, RecordsHistory) {
    const SparseMatrix A = testmat::laplace_2d(6);
    const Vector b = A * Vector::Ones(A.rows());
    auto M = make_preconditioner("ilu:0");
    M->setup(A);
    for (Krylov k : {Krylov::cgs, Krylov::bicg, Krylov::bicgstab, Krylov::gmres}) {
        Vector x;
        const SolveResult r = solve(k, A, *M, b, x, KrylovParams{.record_history = true});
        ASSERT_TRUE(r.converged) << k;
        ASSERT_EQ(r.history.size(), static_cast<size_t>(r.iterations) + 1) << k;
        EXPECT_DOUBLE_EQ(r.history.front(), r.initial_residual) << k;
        EXPECT_LE(r.history.back(), 1e-8 * b.norm() * 1.0001) << k;
        Vector y;
        EXPECT_TRUE(solve(k, A, *M, b, y, KrylovParams{}).history.empty()) << k;
    }
}

namespace {
// A preconditioner without a transpose.
class NoTranspose final : public Preconditioner {
public:
    void setup(const SparseMatrix&) override {}
    void apply(const Vector& r, Vector& z) const override { z = r; }
    std::string name() const override { return "no-transpose"; }
};
} // namespace

TEST(Krylov, BicgNeedsTransposes) {
    const SparseMatrix A = testmat::laplace_1d(5);
    NoTranspose M;
    Vector x;
    try {
        bicg(MatrixOperator(A), M, Vector::Ones(5), x, {});
        FAIL() << "expected InvalidInput";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("no-transpose"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(cgs(MatrixOperator(A), M, Vector::Ones(5), x, {}).converged);
}

TEST(Krylov, RejectsBadInput) {
    const SparseMatrix A = testmat::laplace_1d(5);
    IdentityPreconditioner I;
    Vector x;
    EXPECT_THROW(solve(Krylov::cgs, A, I, Vector::Ones(4), x, {}), InvalidInput);
    x = Vector::Ones(3);
    EXPECT_THROW(solve(Krylov::gmres, A, I, Vector::Ones(5), x, {}), InvalidInput);
    x.resize(0);
    EXPECT_THROW(solve(Krylov::cgs, A, I, Vector::Ones(5), x, KrylovParams{.rel_tol = -1}),
                 InvalidInput);
    EXPECT_THROW(KrylovParams{.max_iter = -1}.validate(), InvalidInput);
    EXPECT_THROW(KrylovParams{.restart = 0}.validate(), InvalidInput);
    EXPECT_THROW(KrylovParams{.abs_tol = std::nan("")}.validate(), InvalidInput);
    EXPECT_NO_THROW(KrylovParams{}.validate());
}

TEST(Krylov, ParsesNamesAndPrintsParams) {
    EXPECT_EQ(parse_krylov("cgs"), Krylov::cgs);
    EXPECT_EQ(parse_krylov("bicg"), Krylov::bicg);
    EXPECT_EQ(parse_krylov("bicgstab"), Krylov::bicgstab);
    EXPECT_EQ(parse_krylov("gmres"), Krylov::gmres);
    try {
        parse_krylov("cg");
        FAIL() << "expected InvalidInput";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("bicgstab"), std::string::npos);
    }
    std::ostringstream os;
    os << KrylovParams{};
    for (const char* f :
         {"rel_tol=1e-08", "abs_tol=0", "max_iter=1000", "restart=50", "record_history=false"})
        EXPECT_NE(os.str().find(f), std::string::npos) << os.str();
}

TEST(Krylov, ASlowSolveIsGivenUpOnlyWhenItsRateMissesTheBudget) {
    // Unpreconditioned CG-like methods on a 2D Laplacian of 60 x 60 need a few hundred
    // iterations for 1e-10: with a budget of 60 the projection at iteration 50 exceeds it and
    // the solve stops there (reason max_iter, the message says why); with a budget far above
    // the need, or none, the solve runs to convergence with the same iteration count.
    const SparseMatrix A = testmat::laplace_2d(60);
    const MatrixOperator op(A);
    IdentityPreconditioner I;
    const Vector b = A * Vector::Ones(A.rows());
    for (Krylov k : {Krylov::cgs, Krylov::bicgstab, Krylov::gmres}) {
        Vector x0, x1, x2;
        const KrylovParams base{.rel_tol = 1e-10, .max_iter = 5000};
        const SolveResult free = solve(k, op, I, b, x0, base);
        ASSERT_TRUE(free.converged) << k << ": " << free;
        ASSERT_GT(free.iterations, 60) << k;
        KrylovParams tight = base;
        tight.give_up_budget = 60;
        const SolveResult cut = solve(k, op, I, b, x1, tight);
        EXPECT_FALSE(cut.converged) << k;
        EXPECT_EQ(cut.reason, StopReason::max_iter) << k;
        EXPECT_LE(cut.iterations, 100) << k; // at the first check, 50 (GMRES: its restart)
        EXPECT_NE(cut.message.find("given up at iteration"), std::string::npos) << cut.message;
        KrylovParams loose = base;
        loose.give_up_budget = 100 * free.iterations;
        const SolveResult same = solve(k, op, I, b, x2, loose);
        EXPECT_TRUE(same.converged) << k;
        EXPECT_EQ(same.iterations, free.iterations) << k;
        EXPECT_EQ((x2 - x0).norm(), 0.0) << k;
    }
    KrylovParams bad;
    bad.give_up_budget = -1;
    EXPECT_THROW(bad.validate(), InvalidInput);
}

namespace {
// Textbook right-preconditioned BiCGStab with the identity preconditioner in whole-vector Eigen
// statements (the form of bicgstab before its elementwise statements ran over the threads),
// without the half-step exit: the iterates of `iterations` full steps from x = 0.
Vector reference_bicgstab(const SparseMatrix& A, const Vector& b, int iterations) {
    const Index n = b.size();
    Vector x = Vector::Zero(n), r = b - A * x, rh = r, p = Vector::Zero(n), v = Vector::Zero(n),
           t(n);
    double rho_old = 1.0, alpha = 1.0, omega = 1.0;
    for (int it = 0; it < iterations; ++it) {
        const double rho = rh.dot(r);
        const double beta = (rho / rho_old) * (alpha / omega);
        p = r + beta * (p - omega * v);
        v = A * p;
        alpha = rho / rh.dot(v);
        r -= alpha * v;
        t = A * r;
        omega = t.dot(r) / t.squaredNorm();
        x += alpha * p + omega * r;
        r -= omega * t;
        rho_old = rho;
    }
    return x;
}
} // namespace

TEST(Krylov, BicgstabOverTheThreadsIsTheWholeVectorIterationBitForBit) {
    // 90 000 unknowns: the elementwise statements run as three chunks over two threads. Each
    // entry is computed as the whole-vector expression computes it, so after 60 iterations
    // (stopped by max_iter, far from the tolerance) x is the reference's to the last bit (a
    // wrong chunk offset, a missed chunk or a statement moved across a reduction changes it),
    // at two threads and at one. The same solve run to its tolerance meets it (at two threads
    // only: its thousand iterations are most of this test's time under the sanitizers).
    const SparseMatrix A = testmat::laplace_2d(300, 1.5);
    const MatrixOperator op(A);
    IdentityPreconditioner I;
    const Vector b = A * testmat::pseudo_random(A.rows());
    const Vector ref = reference_bicgstab(A, b, 60);
    for (int threads : {2, 1}) {
        parallel::set_num_threads(threads);
        Vector x;
        const SolveResult r = bicgstab(op, I, b, x, {.rel_tol = 1e-14, .max_iter = 60});
        EXPECT_EQ(r.reason, StopReason::max_iter) << r;
        EXPECT_EQ(r.iterations, 60);
        EXPECT_EQ((x - ref).cwiseAbs().maxCoeff(), 0.0) << "threads " << threads;
        if (threads != 2) continue;
        Vector y;
        const SolveResult full = bicgstab(op, I, b, y, {.rel_tol = 1e-6, .max_iter = 4000});
        ASSERT_TRUE(full.converged) << full;
        EXPECT_LE((b - A * y).norm(), 1e-6 * b.norm());
    }
    parallel::set_num_threads(0);
}

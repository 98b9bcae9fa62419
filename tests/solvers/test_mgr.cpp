// SPDX-License-Identifier: MIT
// hypre MGR (solvers/hypre/mgr.hpp) on real Newton systems of the square: F = displacements,
// C = multipliers; our CGS with it reaches the tolerance, checked on the true residual.
#include "core/check.hpp"
#include "levels/newton_system.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"
#include "solvers/factory.hpp"
#include "solvers/hypre/boomeramg.hpp"
#include "solvers/hypre/mgr.hpp"
#include "solvers/krylov.hpp"

#include <gtest/gtest.h>

using namespace mlc;

namespace {

struct CapturedSystem {
    SparseMatrix J;
    Vector b;
    int stick = 0;
};

// Forwards to the run's solver and keeps a copy of every Newton system it is given.
class Capture final : public levels::ForwardingSystemSolver {
public:
    Capture(std::unique_ptr<levels::NewtonSystemSolver> inner, const levels::Level& L,
            std::vector<CapturedSystem>& out)
        : levels::ForwardingSystemSolver(std::move(inner)), jac_(L), out_(out) {}
    SolveResult solve(const std::vector<Eigen::Matrix2d>& M, const Vector& b, Vector& dx,
                      double forcing) override {
        jac_.assemble(M);
        CapturedSystem s{jac_.matrix(), b, 0};
        for (const auto& m : M)
            s.stick += m(0, 0) == 1.0 && m(1, 1) == 1.0;
        out_.push_back(std::move(s));
        return inner().solve(M, b, dx, forcing);
    }

private:
    levels::JacobianAssembler jac_;
    std::vector<CapturedSystem>& out_;
};

// The finest level's Newton systems of the square at `level` (coarse-to-fine, schur).
std::vector<CapturedSystem> square_systems(int level, std::vector<int>& functions) {
    auto p = scene::load_scene("square");
    p.levels = level;
    std::vector<CapturedSystem> systems;
    levels::SolveOptions so;
    levels::SolverWrapper wrap(
        [&](int l, const levels::Level& L, std::unique_ptr<levels::NewtonSystemSolver> s)
            -> std::unique_ptr<levels::NewtonSystemSolver> {
            if (l != level) return s;
            functions.assign(static_cast<size_t>(L.n_unknowns()), solvers::kMultiplierFunction);
            for (int v = 0; v < L.dofs.n_vertices(); ++v)
                for (int c = 0; c < 2; ++c)
                    if (const int i = L.dofs.u_dof(v, c); i >= 0)
                        functions[static_cast<size_t>(i)] = c;
            return std::make_unique<Capture>(std::move(s), L, systems);
        });
    const auto r = levels::solve(p, so, &wrap);
    EXPECT_TRUE(r.converged) << r.failure;
    return systems;
}

} // namespace

TEST(MGR, PreconditionedCgsReachesTheToleranceOnTheSquaresNewtonSystems) {
    if (!solvers::have_hypre()) GTEST_SKIP() << "built without hypre";
    std::vector<int> functions;
    const auto systems = square_systems(2, functions);
    ASSERT_GE(systems.size(), 5u);
    solvers::LevelData data;
    data.has_multipliers = true;
    data.unknown_functions = [&]() { return functions; };
    int with_stick = 0;
    for (const auto& s : systems) {
        with_stick += s.stick > 0;
        auto pc = solvers::make_preconditioner("mgr", &data);
        pc->setup(s.J);
        solvers::KrylovParams kp;
        kp.rel_tol = 1e-8;
        kp.max_iter = 200;
        Vector x = Vector::Zero(s.b.size());
        const SolveResult r = solvers::cgs(MatrixOperator(s.J), *pc, s.b, x, kp);
        EXPECT_TRUE(r.converged) << r;
        const double rel = (s.b - s.J * x).norm() / s.b.norm();
        EXPECT_LE(rel, 1e-8);
        EXPECT_LT(r.iterations, 60) << "MGR needs 20-30 CGS iterations here";
    }
    EXPECT_GT(with_stick, 0) << "the systems have stuck nodes (zero multiplier diagonals)";
}

TEST(MGR, RefusesASystemWithoutMultipliersAndBadOptions) {
    if (!solvers::have_hypre()) GTEST_SKIP() << "built without hypre";
    EXPECT_THROW(solvers::MGRPreconditioner({0, 1, 0, 1}), InvalidInput);
    EXPECT_THROW(solvers::MGRPreconditioner({0, 1, 5}), InvalidInput);
    solvers::LevelData data;
    data.has_multipliers = true;
    data.unknown_functions = []() { return std::vector<int>{0, 1, solvers::kMultiplierFunction}; };
    EXPECT_THROW(solvers::make_preconditioner("mgr:frelax=ilu", &data), InvalidInput);
    EXPECT_THROW(solvers::make_preconditioner("mgr:interp=99", &data), InvalidInput);
    EXPECT_THROW(solvers::make_preconditioner("mgr:theta=2", &data), InvalidInput);
    EXPECT_NO_THROW(solvers::make_preconditioner("mgr:smooth=1,smoother=16", &data));
}

TEST(MGR, AvailableExactlyWhenBuiltWithHypre) {
    // With hypre the preconditioner is built; without it, the message says why not.
    if (solvers::have_hypre()) {
        EXPECT_NO_THROW(solvers::MGRPreconditioner pc({0, 1, solvers::kMultiplierFunction}));
        // A 3D vertex: x, y and z, then a multiplier.
        EXPECT_NO_THROW(solvers::MGRPreconditioner pc({0, 1, 2, solvers::kMultiplierFunction}));
        return;
    }
    try {
        solvers::MGRPreconditioner pc({0, 1, solvers::kMultiplierFunction});
        ADD_FAILURE() << "built without hypre";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("mgr (hypre MGR) is not available"), std::string::npos)
            << e.what();
    }
}

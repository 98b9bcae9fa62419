// SPDX-License-Identifier: MIT
/// @file What the Krylov Newton-system solvers of 2D and 3D levels share (levels/krylov_system.cpp,
/// levels/krylov_system3.cpp): the level below's Jacobian at its converged statuses, factored for
/// CF and SORCF, and the level below's exact solver as their coarse solve. Internal to mlc_levels.
#pragma once

#include "core/check.hpp"
#include "levels/newton_system.hpp"
#include "solvers/coarse_fine.hpp"
#include "solvers/direct.hpp"
#include "solvers/hypre/mgr.hpp"
#include "solvers/pc_spec.hpp"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace mlc::levels::detail {

/// A Newton-system solver at fixed statuses used as a preconditioner: the exact coarse solve when
/// the coarse Jacobian cannot be factored by sparse LU (`name` says so). `M` is read at each
/// apply: the caller's coarse statuses, which must outlive this object.
template <int dim> class CoarseSolverAsPreconditioner final : public Preconditioner {
public:
    CoarseSolverAsPreconditioner(BasicNewtonSystemSolver<dim>& solver,
                                 const std::vector<StatusMatrix<dim>>& M)
        : solver_(&solver), M_(M) {}
    void setup(const SparseMatrix&) override {}
    void apply(const Vector& r, Vector& z) const override {
        z.setZero(r.size());
        const SolveResult res = solver_->solve(M_, r, z);
        if (!res.converged)
            throw SolverBreakdown("the coarse solve (" + solver_->name() +
                                  ") did not converge: " + res.message);
    }
    std::string name() const override { return solver_->name(); }

private:
    BasicNewtonSystemSolver<dim>* solver_;
    const std::vector<StatusMatrix<dim>>& M_;
};

/// CF's coarse=solver: the level below's own solver called at the coarse statuses `M` (read at
/// each call; both must outlive the result). A solve that does not converge throws
/// SolverBreakdown.
template <int dim>
solvers::CoarseSolve coarse_solver_call(BasicNewtonSystemSolver<dim>& solver,
                                        const std::vector<StatusMatrix<dim>>& M) {
    return [&solver, &M](const Vector& r, Vector& z) {
        z.setZero(r.size());
        const SolveResult res = solver.solve(M, r, z);
        if (!res.converged)
            throw SolverBreakdown("CF: the coarse solve (" + solver.name() +
                                  ") did not converge: " + res.message);
    };
}

/// The level below's Jacobian at the statuses the driver passed (set_statuses: its converged
/// ones), for the preconditioners that solve on the level below: assembled again and factored
/// when the statuses changed (refresh). The factorization is a sparse LU (lu_call: CF and SORCF
/// with coarse=lu) or the caller's (the 2D two-level mg's coarse operator). When it breaks down
/// (a singular Jacobian, as for the tangential multiplier of a stuck node whose tangential
/// displacement is prescribed: a zero row and column), the level below's own exact solver is the
/// coarse solve from then on, and note() says so. `coarse` and `solver` must outlive this object.
template <int dim> class CoarseJacobian {
public:
    using Statuses = std::vector<StatusMatrix<dim>>;
    /// Sets the caller's operator from the assembled Jacobian (may throw SolverBreakdown).
    using Factor = std::function<void(const SparseMatrix&)>;
    /// Takes the exact solve that replaces a factorization that broke down.
    using TakeFallback = std::function<void(std::unique_ptr<Preconditioner>)>;

    CoarseJacobian(const BasicLevel<dim>& coarse, BasicNewtonSystemSolver<dim>& solver)
        : coarse_(coarse), solver_(solver) {}

    void set_statuses(const Statuses& M) {
        MLC_CHECK(M.size() == coarse_.contacts.size(),
                  "set_coarse_statuses: " << M.size() << " status matrices for "
                                          << coarse_.contacts.size()
                                          << " contact elements of the level below");
        M_ = M;
    }
    /// The statuses passed last; `who` (the preconditioner) is named when none were.
    const Statuses& statuses(const solvers::PcSpec& who) const {
        MLC_CHECK(M_.size() == coarse_.contacts.size(),
                  who << ": the coarse statuses hold " << M_.size() << " status matrices for "
                      << coarse_.contacts.size()
                      << " coarse contact elements; solve the level below first and pass its "
                         "converged statuses (set_coarse_statuses)");
        return M_;
    }
    /// CF/SORCF's coarse=solver: the level below's own solver at the statuses passed last
    /// (read at each call).
    solvers::CoarseSolve solver_call() { return coarse_solver_call(solver_, M_); }

    /// CF/SORCF's coarse=lu: the sparse LU of the Jacobian (after a breakdown, the exact solve).
    solvers::CoarseSolve lu_call() {
        if (!jac_) jac_ = std::make_unique<BasicJacobianAssembler<dim>>(coarse_);
        if (!lu_) lu_ = std::make_unique<solvers::SparseLUPreconditioner>();
        return [this](const Vector& r, Vector& z) {
            if (exact_)
                exact_->apply(r, z);
            else
                lu_->apply(r, z);
        };
    }

    /// Assembles and factors at the statuses when they changed since the last factorization:
    /// by the LU of lu_call, or by `factor` when given (then `take` receives the exact solve of
    /// a breakdown). Nothing to do when neither the LU nor `factor` is in use, or after a
    /// breakdown.
    void refresh(const solvers::PcSpec& who, const Factor& factor = nullptr,
                 const TakeFallback& take = nullptr) {
        const Statuses& M = statuses(who);
        if (factor && !jac_) jac_ = std::make_unique<BasicJacobianAssembler<dim>>(coarse_);
        if (!jac_ || !fallback_.empty() || (factored_ && M == M_used_)) return;
        jac_->assemble(M);
        try {
            if (factor)
                factor(jac_->matrix());
            else if (!factored_)
                lu_->setup(jac_->matrix());
            else
                lu_->update_values(jac_->matrix());
            factored_ = true;
            M_used_ = M;
        } catch (const SolverBreakdown&) {
            fallback_ = solver_.name();
            auto exact = std::make_unique<CoarseSolverAsPreconditioner<dim>>(solver_, M_);
            if (take)
                take(std::move(exact));
            else
                exact_ = std::move(exact);
        }
    }

    /// What a solver's name adds after a breakdown (empty before).
    std::string note() const {
        return fallback_.empty()
                   ? std::string()
                   : " (coarse LU singular, coarse solve by the level below's " + fallback_ + ")";
    }

private:
    const BasicLevel<dim>& coarse_;
    BasicNewtonSystemSolver<dim>& solver_;
    Statuses M_;
    std::unique_ptr<BasicJacobianAssembler<dim>> jac_;
    std::unique_ptr<solvers::SparseLUPreconditioner> lu_;
    bool factored_ = false;
    Statuses M_used_; // the statuses of the last factorization
    std::unique_ptr<Preconditioner> exact_;
    std::string fallback_; // the level below's solver after a breakdown
};

/// The solver functions of a level's unknowns for hypre's MGR: the component (0 .. dim-1) of a
/// displacement, solvers::kMultiplierFunction for a multiplier.
template <int dim> std::vector<int> unknown_functions(const BasicLevel<dim>& level) {
    std::vector<int> f(static_cast<size_t>(level.n_unknowns()), solvers::kMultiplierFunction);
    for (int v = 0; v < level.dofs.n_vertices(); ++v)
        for (int c = 0; c < dim; ++c)
            if (const int i = level.dofs.u_dof(v, c); i >= 0) f[static_cast<size_t>(i)] = c;
    return f;
}

} // namespace mlc::levels::detail

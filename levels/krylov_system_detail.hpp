// SPDX-License-Identifier: MIT
/// @file What the Krylov Newton-system solvers of 2D and 3D levels share (levels/krylov_system.cpp,
/// levels/krylov_system3.cpp): the level below's exact solver as the coarse solve of CF and SORCF.
/// Internal to mlc_levels.
#pragma once

#include "core/check.hpp"
#include "levels/newton_system.hpp"
#include "solvers/coarse_fine.hpp"

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

} // namespace mlc::levels::detail

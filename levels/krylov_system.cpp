// SPDX-License-Identifier: MIT
// Krylov + preconditioner on the assembled contact Jacobian.
#include "levels/krylov_system.hpp"

#include "core/check.hpp"
#include "core/timer.hpp"
#include "solvers/factory.hpp"
#include "solvers/krylov.hpp"

namespace mlc::levels {

namespace {

class KrylovSystemSolver final : public NewtonSystemSolver {
public:
    KrylovSystemSolver(const Level& level, const LinearSolverSpec& spec)
        : spec_(spec), jac_(level), method_(solvers::parse_krylov(spec.krylov)),
          pc_(solvers::make_preconditioner(spec.pc)) {
        params_.rel_tol = spec.rel_tol;
        params_.max_iter = spec.max_iter;
        params_.restart = spec.restart;
        params_.validate();
    }

    SolveResult solve(const std::vector<Eigen::Matrix2d>& M, const Vector& b, Vector& dx) override {
        jac_.assemble(M);
        const double t0 = wall_seconds();
        if (first_) {
            pc_->setup(jac_.matrix());
            first_ = false;
        } else {
            pc_->update_values(jac_.matrix());
        }
        const double t1 = wall_seconds();
        if (dx.size() != b.size()) dx = Vector::Zero(b.size());
        SolveResult r = solvers::solve(method_, jac_.matrix(), *pc_, b, dx, params_);
        r.setup_seconds = t1 - t0;
        return r;
    }
    std::string name() const override { return spec_.krylov + "+" + pc_->name(); }

private:
    LinearSolverSpec spec_;
    JacobianAssembler jac_;
    solvers::Krylov method_;
    std::unique_ptr<Preconditioner> pc_;
    solvers::KrylovParams params_;
    bool first_ = true;
};

} // namespace

std::unique_ptr<NewtonSystemSolver> make_krylov_system_solver(const Level& level,
                                                              const LinearSolverSpec& spec,
                                                              const CoarseContext* context) {
    (void)context;
    return std::make_unique<KrylovSystemSolver>(level, spec);
}

} // namespace mlc::levels

// SPDX-License-Identifier: MIT
// The Newton systems of a 3D level by a Krylov method with a preconditioner of the registry: the
// preconditioners of the matrix alone, CF and SORCF on the split of the level below, and hypre's
// MGR.
#include "levels/krylov_system.hpp"
#include "levels/krylov_system_detail.hpp"

#include "core/check.hpp"
#include "core/timer.hpp"
#include "solvers/direct.hpp"
#include "solvers/factory.hpp"
#include "solvers/hypre/mgr.hpp"
#include "solvers/krylov.hpp"

#include <algorithm>
#include <cmath>

namespace mlc::levels {

solvers::CoarseFineSplit coarse_fine_split3(const Level3& fine, const Level3& coarse,
                                            const SparseMatrix& P_vertex,
                                            const SparseMatrix& T_full,
                                            solvers::MultiplierScale scale) {
    MLC_CHECK(P_vertex.rows() == fine.mesh.n_vertices() &&
                  P_vertex.cols() == coarse.mesh.n_vertices(),
              "coarse_fine_split3: the vertex prolongation is " << P_vertex.rows() << " x "
                                                                << P_vertex.cols());
    MLC_CHECK(T_full.rows() == fine.n_unknowns() && T_full.cols() == coarse.n_unknowns(),
              "coarse_fine_split3: the transfer is " << T_full.rows() << " x " << T_full.cols()
                                                     << ", expected " << fine.n_unknowns() << " x "
                                                     << coarse.n_unknowns());
    // The coarse vertex of each fine vertex that is one: a row of P with the single entry 1.
    std::vector<int> coarse_vertex(static_cast<size_t>(fine.mesh.n_vertices()), -1);
    for (Index v = 0; v < P_vertex.outerSize(); ++v) {
        SparseMatrix::InnerIterator it(P_vertex, v);
        if (!it) continue;
        const int c = static_cast<int>(it.col());
        const double w = it.value();
        if (!++it && w == 1.0) coarse_vertex[static_cast<size_t>(v)] = c;
    }
    solvers::CoarseFineSplit s;
    s.n_coarse = coarse.n_unknowns();
    std::vector<char> taken(static_cast<size_t>(coarse.n_unknowns()), 0);
    for (Index i = 0; i < fine.n_unknowns(); ++i) {
        const int v = fine.dofs.vertex_of(i);
        const int c = coarse_vertex[static_cast<size_t>(v)];
        int dof = -1;
        double q = 1.0;
        if (c >= 0 && fine.dofs.is_displacement(i)) {
            for (int k = 0; k < 3; ++k)
                if (fine.dofs.u_dof(v, k) == i) dof = coarse.dofs.u_dof(c, k);
        } else if (c >= 0) {
            // A multiplier of a node on a coarse vertex: the coarse multiplier of that vertex
            // its row of T weighs most (the same component, as the frames of one vertex on two
            // levels differ little), with that weight q.
            double best = 0.0;
            for (SparseMatrix::InnerIterator it(T_full, i); it; ++it)
                if (!coarse.dofs.is_displacement(it.col()) && std::abs(it.value()) > best &&
                    coarse.dofs.vertex_of(it.col()) == c) {
                    best = std::abs(it.value());
                    dof = static_cast<int>(it.col());
                    q = it.value();
                }
            if (q <= 0.0) dof = -1;
        }
        if (dof >= 0 && !taken[static_cast<size_t>(dof)]) {
            taken[static_cast<size_t>(dof)] = 1;
            s.coarse_set.push_back(static_cast<int>(i));
            s.coarse_dof.push_back(dof);
            const bool multiplier = !fine.dofs.is_displacement(i);
            const bool scaled = multiplier && scale != solvers::MultiplierScale::none;
            s.prolong_scale.push_back(scaled ? q : 1.0);
            s.restrict_scale.push_back(!scaled                                   ? 1.0
                                       : scale == solvers::MultiplierScale::qt   ? q
                                       : scale == solvers::MultiplierScale::qinv ? 1.0 / q
                                                                                 : 1.0);
        } else {
            s.fine_set.push_back(static_cast<int>(i));
        }
    }
    // One diagonal block per fine vertex (its displacements and multipliers are contiguous).
    int last = -1;
    for (size_t k = 0; k < s.fine_set.size(); ++k) {
        const int v = fine.dofs.vertex_of(s.fine_set[k]);
        if (v != last) s.fine_block_starts.push_back(static_cast<Index>(k));
        last = v;
    }
    s.validate(fine.n_unknowns());
    return s;
}

namespace {

using Matrix3 = StatusMatrix<3>;

using CoarseSolver3 = detail::CoarseSolverAsPreconditioner<3>;

class KrylovSystemSolver3 final : public NewtonSystemSolver3 {
public:
    KrylovSystemSolver3(const Level3& level, const LinearSolverSpec& spec, const LevelBelow3* below)
        : level_(level), spec_(spec), jac_(level) {
        params_.rel_tol = spec.rel_tol;
        params_.max_iter = spec.max_iter;
        params_.restart = spec.restart;
        params_.give_up_budget = spec.give_up_budget;
        params_.validate();
        const solvers::PreconditionerEntry* entry = spec.pc.entry;
        MLC_CHECK(entry != nullptr, "a 3D Krylov solve needs a preconditioner");
        const std::string why = spec.pc.dimension_reason(3);
        MLC_CHECK(why.empty(), why);
        MLC_CHECK(spec.pc.name() != "mg",
                  "internal error: mg on a 3D level is the Galerkin multigrid's solver");
        if (entry->needs_level_below) {
            MLC_CHECK(below != nullptr && below->coarse && below->P_vertex && below->T_full &&
                          below->solver,
                      spec.pc.name() << " needs the level below: use it with --levels >= 1 "
                                        "(level 0 is solved exactly)");
            below_ = below;
        }
        const solvers::LevelData data = level_data();
        pc_ = solvers::make_preconditioner(spec.pc, &data);
    }

    using NewtonSystemSolver3::solve;
    SolveResult solve(const std::vector<Matrix3>& M, const Vector& b, Vector& dx,
                      double forcing) override {
        MLC_CHECK(forcing >= 0 && forcing < 1,
                  "forcing term must lie in [0, 1), found " << forcing);
        const double t0 = wall_seconds();
        prepare(M);
        const double t1 = wall_seconds();
        if (dx.size() != b.size()) dx = Vector::Zero(b.size());
        solvers::KrylovParams params = params_;
        params.rel_tol = std::max(params_.rel_tol, forcing);
        SolveResult r = solvers::solve(spec_.krylov, jac_.matrix(), *pc_, b, dx, params);
        r.setup_seconds = t1 - t0;
        r.assembly_seconds = assembly_seconds_;
        r.solve_seconds = wall_seconds() - t1;
        return r;
    }

    std::string name() const override {
        return std::string(solvers::to_string(spec_.krylov)) + " + " + spec_.pc.text() +
               (coarse_fallback_.empty()
                    ? ""
                    : " (coarse LU singular, coarse solve by the level below's " +
                          coarse_fallback_ + ")");
    }

    void set_coarse_statuses(const std::vector<Matrix3>& M) override {
        if (below_ == nullptr) return;
        MLC_CHECK(M.size() == below_->coarse->contacts.size(),
                  "set_coarse_statuses: " << M.size() << " status matrices for "
                                          << below_->coarse->contacts.size()
                                          << " contact elements of the level below");
        coarse_M_ = M;
    }

    void prepare(const std::vector<Matrix3>& M) override {
        MLC_CHECK(M.size() == level_.contacts.size(),
                  "prepare: " << M.size() << " status matrices for " << level_.contacts.size()
                              << " contact elements");
        if (below_ != nullptr) refresh_coarse();
        assembly_seconds_ = 0.0;
        if (!first_ && M == last_M_) return;
        const double t0 = wall_seconds();
        jac_.assemble(M);
        assembly_seconds_ = wall_seconds() - t0;
        if (first_)
            pc_->setup(jac_.matrix());
        else
            pc_->update_values(jac_.matrix());
        first_ = false;
        last_M_ = M;
    }

private:
    // What the registry's builders may use: the unknowns' functions (mgr) and, for CF and
    // SORCF, the split of this level by the level below and the coarse solve.
    solvers::LevelData level_data() {
        solvers::LevelData d;
        d.has_multipliers = !level_.contacts.empty();
        d.unknown_functions = [this]() { // 0 / 1 / 2: u_x / u_y / u_z; else a multiplier
            std::vector<int> f(static_cast<size_t>(level_.n_unknowns()),
                               solvers::kMultiplierFunction);
            for (int v = 0; v < level_.dofs.n_vertices(); ++v)
                for (int c = 0; c < 3; ++c)
                    if (const int i = level_.dofs.u_dof(v, c); i >= 0)
                        f[static_cast<size_t>(i)] = c;
            return f;
        };
        if (below_ == nullptr) return d;
        d.has_level_below = true;
        d.coarse_fine_split = [this](solvers::MultiplierScale scale) {
            return coarse_fine_split3(level_, *below_->coarse, *below_->P_vertex, *below_->T_full,
                                      scale);
        };
        d.coarse_lu = [this]() -> solvers::CoarseSolve {
            if (!coarse_lu_) {
                coarse_jac_ = std::make_unique<BasicJacobianAssembler<3>>(*below_->coarse);
                coarse_lu_ = std::make_unique<solvers::SparseLUPreconditioner>();
            }
            return [this](const Vector& r, Vector& z) {
                if (coarse_exact_)
                    coarse_exact_->apply(r, z);
                else
                    coarse_lu_->apply(r, z);
            };
        };
        d.coarse_solver = detail::coarse_solver_call(*below_->solver, coarse_M_);
        return d;
    }

    // The coarse LU of CF/SORCF (coarse=lu) at the coarse statuses the driver passed,
    // refactored when they changed; the level below's own solver when it is singular.
    void refresh_coarse() {
        MLC_CHECK(coarse_M_.size() == below_->coarse->contacts.size(),
                  spec_.pc << ": the coarse statuses hold " << coarse_M_.size()
                           << " status matrices for " << below_->coarse->contacts.size()
                           << " coarse contact elements; solve the level below first and pass "
                              "its converged statuses (set_coarse_statuses)");
        if (!coarse_jac_ || coarse_exact_ || (coarse_factored_ && coarse_M_ == coarse_M_used_))
            return;
        coarse_jac_->assemble(coarse_M_);
        try {
            if (!coarse_factored_)
                coarse_lu_->setup(coarse_jac_->matrix());
            else
                coarse_lu_->update_values(coarse_jac_->matrix());
            coarse_factored_ = true;
            coarse_M_used_ = coarse_M_;
        } catch (const SolverBreakdown&) {
            coarse_fallback_ = below_->solver->name();
            coarse_exact_ = std::make_unique<CoarseSolver3>(*below_->solver, coarse_M_);
        }
    }

    const Level3& level_;
    LinearSolverSpec spec_;
    BasicJacobianAssembler<3> jac_;
    std::unique_ptr<Preconditioner> pc_;
    solvers::KrylovParams params_;
    bool first_ = true;
    std::vector<Matrix3> last_M_;
    double assembly_seconds_ = 0.0;
    const LevelBelow3* below_ = nullptr;
    std::vector<Matrix3> coarse_M_;
    std::unique_ptr<BasicJacobianAssembler<3>> coarse_jac_;
    std::unique_ptr<solvers::SparseLUPreconditioner> coarse_lu_;
    bool coarse_factored_ = false;
    std::vector<Matrix3> coarse_M_used_;
    std::unique_ptr<Preconditioner> coarse_exact_;
    std::string coarse_fallback_;
};

} // namespace

std::unique_ptr<NewtonSystemSolver3> make_krylov_system_solver(const Level3& level,
                                                               const LinearSolverSpec& spec,
                                                               const LevelBelow3* below) {
    return std::make_unique<KrylovSystemSolver3>(level, spec, below);
}

} // namespace mlc::levels

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

class KrylovSystemSolver3 final : public NewtonSystemSolver3 {
public:
    KrylovSystemSolver3(const Level3& level, const LinearSolverSpec& spec, const LevelBelow3* below)
        : level_(level), spec_(spec), jac_(level), params_(spec.krylov_params()) {
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
            coarse_ = std::make_unique<detail::CoarseJacobian<3>>(*below->coarse, *below->solver);
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
               (coarse_ ? coarse_->note() : std::string());
    }

    void set_coarse_statuses(const std::vector<Matrix3>& M) override {
        if (coarse_) coarse_->set_statuses(M);
    }

    void prepare(const std::vector<Matrix3>& M) override {
        MLC_CHECK(M.size() == level_.contacts.size(),
                  "prepare: " << M.size() << " status matrices for " << level_.contacts.size()
                              << " contact elements");
        if (coarse_) coarse_->refresh(spec_.pc);
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
        d.unknown_functions = [this]() { return detail::unknown_functions(level_); };
        if (below_ == nullptr) return d;
        d.has_level_below = true;
        d.coarse_fine_split = [this](solvers::MultiplierScale scale) {
            return coarse_fine_split3(level_, *below_->coarse, *below_->P_vertex, *below_->T_full,
                                      scale);
        };
        d.coarse_lu = [this]() { return coarse_->lu_call(); };
        d.coarse_solver = coarse_->solver_call();
        return d;
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
    // The level below's Jacobian for CF/SORCF (null without the level below).
    std::unique_ptr<detail::CoarseJacobian<3>> coarse_;
};

} // namespace

std::unique_ptr<NewtonSystemSolver3> make_krylov_system_solver(const Level3& level,
                                                               const LinearSolverSpec& spec,
                                                               const LevelBelow3* below) {
    return std::make_unique<KrylovSystemSolver3>(level, spec, below);
}

} // namespace mlc::levels

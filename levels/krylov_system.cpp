// SPDX-License-Identifier: MIT
// Krylov + preconditioner on the assembled contact Jacobian, with the level-aware CF, SORCF and
// EBE preconditioners built from the level (and the level below).
#include "levels/krylov_system.hpp"
#include "levels/krylov_system_detail.hpp"

#include "core/check.hpp"
#include "core/timer.hpp"
#include "fem/elasticity.hpp"
#include "solvers/direct.hpp"
#include "solvers/factory.hpp"
#include "solvers/hypre/mgr.hpp"
#include "solvers/krylov.hpp"
#include "solvers/mg.hpp"
#include "solvers/sorcf.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <set>
#include <sstream>

namespace mlc::levels {

namespace {

// The smoother blocks of a level: one per vertex, its displacements and multipliers.
std::vector<Index> level_vertex_blocks(const Level& L) {
    std::vector<int> owner(static_cast<size_t>(L.n_unknowns()));
    for (Index i = 0; i < L.n_unknowns(); ++i)
        owner[static_cast<size_t>(i)] = L.dofs.vertex_of(i);
    return solvers::vertex_block_starts(owner);
}

class KrylovSystemSolver final : public NewtonSystemSolver {
public:
    KrylovSystemSolver(const Level& level, const LinearSolverSpec& spec, const LevelBelow* below)
        : level_(level), spec_(spec), jac_(level), method_(spec.krylov),
          params_(spec.krylov_params()) {
        if (below != nullptr && below->available()) {
            below_ = below;
            coarse_ = std::make_unique<detail::CoarseJacobian<2>>(*below->coarse, *below->solver);
        }
        const solvers::PreconditionerEntry* entry = spec.pc.entry;
        const solvers::LevelData data = level_data(entry);
        pc_ = solvers::make_preconditioner(spec.pc, &data);
        // Only the level-aware entries need the level below's statuses; mg also needs its
        // operators filled (rediscretized) or computes them (Galerkin).
        mg_ = dynamic_cast<solvers::Multigrid*>(pc_.get());
        if (mg_ != nullptr)
            mg_mode_ = mg_->coarse_operators() == solvers::CoarseOperators::galerkin
                           ? MgMode::galerkin
                       : data.below_multigrid != nullptr ? MgMode::above
                                                         : MgMode::two_level;
        uses_coarse_statuses_ = below_ != nullptr && entry != nullptr && entry->needs_level_below &&
                                mg_mode_ != MgMode::galerkin;
    }

    SolveResult solve(const std::vector<Eigen::Matrix2d>& M, const Vector& b, Vector& dx,
                      double forcing) override {
        MLC_CHECK(M.size() == level_.contacts.size(),
                  "Newton system: " << M.size() << " status matrices for " << level_.contacts.size()
                                    << " contact elements");
        MLC_CHECK(forcing >= 0 && forcing < 1,
                  "forcing term must lie in [0, 1), found " << forcing);
        const double t0 = wall_seconds();
        prepare(M);
        const double t1 = wall_seconds();
        if (dx.size() != b.size()) dx = Vector::Zero(b.size());
        solvers::KrylovParams params = params_;
        params.rel_tol = std::max(params_.rel_tol, forcing);
        // The preconditioner says which product goes with it (mg: the unrolled one or its
        // lattice stencils); the others keep Eigen's in-order one, so their published iteration
        // counts stay bit-for-bit reproducible.
        const std::unique_ptr<LinearOperator> op = pc_->krylov_operator(jac_.matrix());
        SolveResult r = op ? solvers::solve(method_, *op, *pc_, b, dx, params)
                           : solvers::solve(method_, jac_.matrix(), *pc_, b, dx, params);
        r.setup_seconds = t1 - t0;
        r.assembly_seconds = assembly_seconds_;
        return r;
    }
    std::string name() const override {
        return std::string(solvers::to_string(spec_.krylov)) + "+" + pc_->name() +
               (coarse_ ? coarse_->note() : std::string());
    }

    void set_coarse_statuses(const std::vector<Eigen::Matrix2d>& M) override {
        if (coarse_) coarse_->set_statuses(M);
    }

    // Assembles J(M) and sets the preconditioner up, unless M is the last call's (as when the
    // level above's multigrid asks for this level's operator at its converged statuses).
    void prepare(const std::vector<Eigen::Matrix2d>& M) override {
        MLC_CHECK(M.size() == level_.contacts.size(),
                  "prepare: " << M.size() << " status matrices for " << level_.contacts.size()
                              << " contact elements");
        if (uses_coarse_statuses_) refresh_coarse();
        assembly_seconds_ = 0.0;
        if (first_ || M != last_M_) {
            const double t0 = wall_seconds();
            jac_.assemble(M);
            assembly_seconds_ = wall_seconds() - t0;
            if (!ebe_elements_.empty())
                for (size_t e = 0; e < level_.contacts.size(); ++e)
                    contact_element_matrix(level_, e, M[e], ebe_elements_[ebe_n_elastic_ + e]);
            if (first_)
                pc_->setup(jac_.matrix());
            else
                pc_->update_values(jac_.matrix());
            first_ = false;
            last_M_ = M;
        }
    }

    const solvers::Multigrid* multigrid() const override { return mg_; }

private:
    enum class MgMode { none, above, two_level, galerkin };

    // What the registry's builders may use from this level and the level below.
    solvers::LevelData level_data(const solvers::PreconditionerEntry* entry) {
        solvers::LevelData d;
        d.has_multipliers = !level_.contacts.empty();
        d.elements = [this]() {
            if (ebe_elements_.empty()) {
                ebe_elements_ = elastic_element_matrices(level_);
                ebe_n_elastic_ = ebe_elements_.size();
                ebe_elements_.resize(ebe_n_elastic_ + level_.contacts.size());
            }
            return &ebe_elements_;
        };
        d.unknown_functions = [this]() { return detail::unknown_functions(level_); };
        d.aggregation = [this]() { return aggregation_input(level_); };
        if (below_ == nullptr || entry == nullptr || !entry->needs_level_below) return d;
        d.has_level_below = true;
        d.coarse_fine_split = [this](solvers::MultiplierScale scale) {
            return coarse_fine_split(level_, *below_->coarse, *below_->transfer, scale);
        };
        d.coarse_lu = [this]() { return coarse_->lu_call(); };
        d.coarse_solver = coarse_->solver_call();
        d.top.T = &below_->transfer->T;
        d.top.R = &below_->transfer->R;
        d.top.block_starts = level_vertex_blocks(level_);
        // The levels from the lowest one solved up to this one, coarsest first.
        std::vector<const Level*> lv{&level_};
        std::vector<const transfer::LevelTransfer*> tr{below_->transfer};
        for (const LevelBelow* c = below_; c != nullptr; c = c->below) {
            lv.push_back(c->coarse);
            tr.push_back(c->below != nullptr && c->below->available() ? c->below->transfer
                                                                      : nullptr);
            if (c->below == nullptr || !c->below->available()) break;
        }
        d.hierarchy_from_level0 = lv.back()->mesh.n_coarse_vertices == 0;
        d.top_lattice = [this]() { return level_.lattice; };
        d.hierarchy = [lv, tr]() {
            std::vector<solvers::MultigridLevelData> h;
            for (size_t k = lv.size(); k-- > 0;) {
                solvers::MultigridLevelData m;
                if (tr[k] != nullptr) {
                    m.T = &tr[k]->T;
                    m.R = &tr[k]->R;
                }
                m.block_starts = level_vertex_blocks(*lv[k]);
                h.push_back(std::move(m));
            }
            return h;
        };
        const auto& T = below_->transfer->T;
        MLC_CHECK(T.rows() == level_.n_unknowns() && T.cols() == below_->coarse->n_unknowns(),
                  "the transfer is " << T.rows() << " x " << T.cols() << ", expected "
                                     << level_.n_unknowns() << " x "
                                     << below_->coarse->n_unknowns());
        d.below_multigrid = below_->solver->multigrid();
        return d;
    }

    // The coarse statuses given by the driver (set_coarse_statuses): the level below's operator
    // in the multigrid is refreshed (its own solver's, or the coarse Jacobian assembled and
    // factored on the two-level mg's level 0), and CF/SORCF's coarse LU is refactored when they
    // changed.
    void refresh_coarse() {
        const solvers::PcSpec& who = spec_.pc;
        if (mg_mode_ == MgMode::above) {
            // The level below's own multigrid level, at its converged statuses.
            below_->solver->prepare(coarse_->statuses(who));
            return;
        }
        if (mg_mode_ != MgMode::two_level) {
            coarse_->refresh(who);
            return;
        }
        coarse_->refresh(
            who, [this](const SparseMatrix& J) { mg_->set_operator(0, J); },
            [this](std::unique_ptr<Preconditioner> exact) {
                mg_->set_coarse_solver(std::move(exact));
            });
    }

    const Level& level_;
    LinearSolverSpec spec_;
    JacobianAssembler jac_;
    solvers::Krylov method_;
    std::unique_ptr<Preconditioner> pc_;
    solvers::KrylovParams params_;
    bool first_ = true;
    std::vector<Eigen::Matrix2d> last_M_; // statuses of the last assembly
    double assembly_seconds_ = 0.0;       // of the last prepare
    // The level below (null without one) and its Jacobian at the converged statuses
    // (set_coarse_statuses): CF/SORCF with coarse=lu and the two-level mg's level 0.
    const LevelBelow* below_ = nullptr;
    bool uses_coarse_statuses_ = false;
    std::unique_ptr<detail::CoarseJacobian<2>> coarse_;
    // mg: the multigrid (pc_) and how its coarse operators are filled.
    solvers::Multigrid* mg_ = nullptr;
    MgMode mg_mode_ = MgMode::none;
    // EBE: elastic element matrices first, then one per contact element (refreshed per solve).
    std::vector<smoothers::ElementMatrix> ebe_elements_;
    size_t ebe_n_elastic_ = 0;
};

} // namespace

std::unique_ptr<NewtonSystemSolver> make_krylov_system_solver(const Level& level,
                                                              const LinearSolverSpec& spec,
                                                              const LevelBelow* below) {
    return std::make_unique<KrylovSystemSolver>(level, spec, below);
}

solvers::AggregationInput aggregation_input(const Level& L) {
    solvers::AggregationInput in;
    in.K = &L.elastic.K;
    const auto n = static_cast<size_t>(L.n_unknowns());
    in.vertex.resize(n);
    in.kind.assign(n, solvers::UnknownKind::ux);
    for (Index i = 0; i < L.n_unknowns(); ++i)
        in.vertex[static_cast<size_t>(i)] = L.dofs.vertex_of(i);
    for (int v = 0; v < L.dofs.n_vertices(); ++v)
        if (const int i = L.dofs.u_dof(v, 1); i >= 0)
            in.kind[static_cast<size_t>(i)] = solvers::UnknownKind::uy;
    // Rigid modes about the centroid (for conditioning): (1, 0), (0, 1), (-(y - yc), x - xc).
    Vec2 c(0.0, 0.0);
    for (const auto& p : L.mesh.vertices)
        c += p;
    c /= std::max(1, L.mesh.n_vertices());
    in.near_null = Eigen::MatrixXd::Zero(L.n_unknowns(), 3);
    for (int v = 0; v < L.dofs.n_vertices(); ++v) {
        const Vec2 d = L.mesh.vertices[static_cast<size_t>(v)] - c;
        if (const int i = L.dofs.u_dof(v, 0); i >= 0) {
            in.near_null(i, 0) = 1.0;
            in.near_null(i, 2) = -d.y();
        }
        if (const int i = L.dofs.u_dof(v, 1); i >= 0) {
            in.near_null(i, 1) = 1.0;
            in.near_null(i, 2) = d.x();
        }
    }
    for (size_t e = 0; e < L.contacts.size(); ++e) {
        const int m = L.contacts[e].n_multipliers();
        for (int k = 0; k < m; ++k)
            in.kind[static_cast<size_t>(L.lambda_dof[e] + k)] =
                k + 1 == m ? solvers::UnknownKind::lambda_n : solvers::UnknownKind::lambda_t;
    }
    return in;
}

std::vector<smoothers::ElementMatrix> elastic_element_matrices(const Level& level) {
    const auto& m = level.mesh;
    std::vector<smoothers::ElementMatrix> out;
    out.reserve(static_cast<size_t>(m.n_cells()));
    for (int t = 0; t < m.n_cells(); ++t) {
        const auto& tri = m.cells[static_cast<size_t>(t)];
        const auto ke = fem::element_stiffness(
            m.vertices[static_cast<size_t>(tri[0])], m.vertices[static_cast<size_t>(tri[1])],
            m.vertices[static_cast<size_t>(tri[2])], fem::material_of(m, level.materials, t));
        std::vector<int> local;
        smoothers::ElementMatrix el;
        for (int i = 0; i < 6; ++i)
            if (const int d = level.dofs.u_dof(tri[static_cast<size_t>(i / 2)], i % 2); d >= 0) {
                local.push_back(i);
                el.dofs.push_back(d);
            }
        if (local.empty()) continue;
        const auto ne = static_cast<Index>(local.size());
        el.A.resize(ne, ne);
        for (Index a = 0; a < ne; ++a)
            for (Index b = 0; b < ne; ++b)
                el.A(a, b) = ke(local[static_cast<size_t>(a)], local[static_cast<size_t>(b)]);
        out.push_back(std::move(el));
    }
    return out;
}

void restrict_elements(std::vector<smoothers::ElementMatrix>& elements, Index n) {
    size_t kept = 0;
    for (auto& el : elements) {
        std::vector<Index> keep;
        for (size_t a = 0; a < el.dofs.size(); ++a)
            if (el.dofs[a] < n) keep.push_back(static_cast<Index>(a));
        if (keep.empty()) continue;
        if (keep.size() < el.dofs.size()) {
            const auto ne = static_cast<Index>(keep.size());
            smoothers::ElementMatrix r;
            r.is_contact = el.is_contact;
            r.A.resize(ne, ne);
            for (Index a = 0; a < ne; ++a) {
                r.dofs.push_back(el.dofs[static_cast<size_t>(keep[static_cast<size_t>(a)])]);
                for (Index b = 0; b < ne; ++b)
                    r.A(a, b) = el.A(keep[static_cast<size_t>(a)], keep[static_cast<size_t>(b)]);
            }
            el = std::move(r);
        }
        if (&elements[kept] != &el) elements[kept] = std::move(el);
        ++kept;
    }
    elements.resize(kept);
}

void contact_element_matrix(const Level& level, size_t e, const Eigen::Matrix2d& M,
                            smoothers::ElementMatrix& out) {
    MLC_CHECK(e < level.contacts.size(), "contact_element_matrix: element "
                                             << e << " out of range (" << level.contacts.size()
                                             << " contact elements)");
    const auto& el = level.contacts[e];
    const int l0 = level.lambda_dof[e];
    if (out.dofs.empty() || !out.is_contact) {
        out.dofs.clear();
        contact::for_each_tangent_entry(el, M, level.dofs, l0, [&](int row, int col, double) {
            for (int d : {row, col})
                if (std::find(out.dofs.begin(), out.dofs.end(), d) == out.dofs.end())
                    out.dofs.push_back(d);
        });
        out.is_contact = true;
        out.A.resize(static_cast<Index>(out.dofs.size()), static_cast<Index>(out.dofs.size()));
    }
    out.A.setZero();
    auto local = [&](int d) {
        return static_cast<Index>(std::find(out.dofs.begin(), out.dofs.end(), d) -
                                  out.dofs.begin());
    };
    contact::for_each_tangent_entry(el, M, level.dofs, l0, [&](int row, int col, double v) {
        out.A(local(row), local(col)) += v;
    });
}

solvers::CoarseFineSplit coarse_fine_split(const Level& fine, const Level& coarse,
                                           const transfer::LevelTransfer& transfer,
                                           solvers::MultiplierScale scale) {
    solvers::CoarseFineSplit s;
    s.coarse_set = transfer.coarse_set;
    s.fine_set = transfer.fine_set;
    s.coarse_dof = transfer.coarse_dof;
    s.n_coarse = coarse.n_unknowns();
    s.validate(fine.n_unknowns());
    const size_t nc = s.coarse_set.size();
    s.restrict_scale.assign(nc, 1.0);
    s.prolong_scale.assign(nc, 1.0);
    const bool have_T = transfer.T.rows() == fine.n_unknowns() && transfer.T.nonZeros() > 0;
    for (size_t k = 0; k < nc; ++k) {
        if (fine.dofs.is_displacement(s.coarse_set[k]) || scale == solvers::MultiplierScale::none)
            continue;
        const double q = have_T ? transfer.T.coeff(s.coarse_set[k], s.coarse_dof[k]) : 0.5;
        MLC_CHECK(q > 0.0, "coarse_fine_split: the transfer has no Q entry at fine unknown "
                               << s.coarse_set[k] << " (coarse " << s.coarse_dof[k] << ")");
        s.prolong_scale[k] = q;
        if (scale == solvers::MultiplierScale::qt) s.restrict_scale[k] = q;
        if (scale == solvers::MultiplierScale::qinv) s.restrict_scale[k] = 1.0 / q;
    }
    // One diagonal block per fine vertex (its displacements and multipliers are contiguous).
    int last = -1;
    for (size_t k = 0; k < s.fine_set.size(); ++k) {
        const int v = fine.dofs.vertex_of(s.fine_set[k]);
        if (v != last) s.fine_block_starts.push_back(static_cast<Index>(k));
        last = v;
    }
    return s;
}

} // namespace mlc::levels

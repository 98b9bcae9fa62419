// SPDX-License-Identifier: MIT
// Krylov + preconditioner on the assembled contact Jacobian, with the level-aware CF, SORCF and
// EBE preconditioners built from the level (and the level below).
#include "levels/krylov_system.hpp"

#include "core/check.hpp"
#include "core/timer.hpp"
#include "fem/elasticity.hpp"
#include "solvers/direct.hpp"
#include "solvers/factory.hpp"
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

// Typed access to the options of a level-aware spec; unknown keys are errors.
class Options {
public:
    explicit Options(const solvers::PreconditionerSpec& spec) : spec_(spec) {}
    std::string get_string(const std::string& key, const std::string& fallback) {
        used_.insert(key);
        const auto it = spec_.options.find(key);
        return it == spec_.options.end() ? fallback : it->second;
    }
    double get_double(const std::string& key, double fallback) {
        const std::string s = get_string(key, "");
        if (s.empty()) return fallback;
        double v = 0.0;
        const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
        MLC_CHECK(ec == std::errc() && ptr == s.data() + s.size() && std::isfinite(v),
                  "option " << key << "=" << s << " of preconditioner '" << spec_.name
                            << "' is not a number");
        return v;
    }
    int get_int(const std::string& key, int fallback) {
        const std::string s = get_string(key, "");
        if (s.empty()) return fallback;
        int v = 0;
        const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
        MLC_CHECK(ec == std::errc() && ptr == s.data() + s.size(),
                  "option " << key << "=" << s << " of preconditioner '" << spec_.name
                            << "' is not an integer");
        return v;
    }
    void finish() const {
        for (const auto& [key, value] : spec_.options) {
            if (used_.count(key)) continue;
            std::ostringstream keys;
            for (const auto& k : used_)
                keys << (keys.tellp() > 0 ? ", " : "") << k;
            MLC_CHECK(false, "unknown option '" << key << "' for preconditioner '" << spec_.name
                                                << "'; valid options: " << keys.str());
        }
    }

private:
    const solvers::PreconditionerSpec& spec_;
    std::set<std::string> used_;
};

// A Newton-system solver (at fixed statuses) used as a preconditioner: the exact coarse solve
// when the coarse Jacobian cannot be factored by sparse LU.
class CoarseSolverAsPreconditioner final : public Preconditioner {
public:
    CoarseSolverAsPreconditioner(NewtonSystemSolver& solver, const std::vector<Eigen::Matrix2d>& M)
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
    NewtonSystemSolver* solver_;
    const std::vector<Eigen::Matrix2d>& M_; // the context's coarse statuses, read at each apply
};

class KrylovSystemSolver final : public NewtonSystemSolver {
public:
    KrylovSystemSolver(const Level& level, const LinearSolverSpec& spec,
                       const CoarseContext* context)
        : level_(level), spec_(spec), jac_(level), method_(solvers::parse_krylov(spec.krylov)) {
        params_.rel_tol = spec.rel_tol;
        params_.max_iter = spec.max_iter;
        params_.restart = spec.restart;
        params_.validate();
        const solvers::PreconditionerSpec parsed = solvers::parse_preconditioner_spec(spec.pc);
        if (parsed.name == "cf" || parsed.name == "sorcf")
            build_coarse_fine(parsed, context);
        else if (parsed.name == "ebe")
            build_ebe(parsed);
        else if (parsed.name == "mg")
            build_mg(parsed, context);
        else if (parsed.name == "amg" && !level.contacts.empty())
            MLC_CHECK(false,
                      "amg (hypre BoomerAMG) preconditions the elastic block only (symmetric "
                      "positive definite); the contact Jacobian has zero multiplier "
                      "diagonals: use --pc mg, or compare on the elastic block with "
                      "`mlcontact bench elastic`");
        else
            pc_ = solvers::make_preconditioner(spec.pc);
    }

    SolveResult solve(const std::vector<Eigen::Matrix2d>& M, const Vector& b, Vector& dx) override {
        MLC_CHECK(M.size() == level_.contacts.size(),
                  "Newton system: " << M.size() << " status matrices for " << level_.contacts.size()
                                    << " contact elements");
        const double t0 = wall_seconds();
        prepare(M);
        const double t1 = wall_seconds();
        if (dx.size() != b.size()) dx = Vector::Zero(b.size());
        // mg: the unrolled mat-vec (MatVec::unrolled); the others keep Eigen's in-order one,
        // so their published iteration counts stay bit-for-bit reproducible.
        solvers::KrylovParams params = params_;
        params.rel_tol = std::max(params_.rel_tol, forcing_);
        SolveResult r =
            mg_ ? solvers::solve(method_, MatrixOperator(jac_.matrix(), MatVec::unrolled), *pc_, b,
                                 dx, params)
                : solvers::solve(method_, jac_.matrix(), *pc_, b, dx, params);
        r.setup_seconds = t1 - t0;
        r.assembly_seconds = assembly_seconds_;
        return r;
    }
    std::string name() const override {
        return spec_.krylov + "+" + pc_->name() +
               (coarse_exact_ ? " (coarse LU singular, coarse solve by the level below's " +
                                    coarse_exact_->name() + ")"
                              : "");
    }
    void set_forcing(double eta) override {
        MLC_CHECK(eta >= 0 && eta < 1, "forcing term must lie in [0, 1), found " << eta);
        forcing_ = eta;
    }

    const Preconditioner* preconditioner_for(const std::vector<Eigen::Matrix2d>& M) override {
        MLC_CHECK(M.size() == level_.contacts.size(),
                  "preconditioner_for: " << M.size() << " status matrices for "
                                         << level_.contacts.size() << " contact elements");
        prepare(M);
        return pc_.get();
    }

private:
    // Assembles J(M) and sets the preconditioner up, unless M is the last call's.
    void prepare(const std::vector<Eigen::Matrix2d>& M) {
        if (ctx_ != nullptr) refresh_coarse();
        // The same statuses as the last call (e.g. this solver serving as the coarse solve of
        // the level above, once per preconditioner application): J and C are unchanged.
        assembly_seconds_ = 0.0;
        if (first_ || M != last_M_) {
            const double t0 = wall_seconds();
            jac_.assemble(M);
            assembly_seconds_ = wall_seconds() - t0;
            if (!ebe_elements_.empty())
                for (size_t e = 0; e < level_.contacts.size(); ++e)
                    contact_element_matrix(level_, e, M[e], ebe_elements_[ebe_n_elastic_ + e]);
            if (!galerkin_.empty()) build_galerkin(); // the coarse operators from this J
            if (first_)
                pc_->setup(jac_.matrix());
            else
                pc_->update_values(jac_.matrix());
            first_ = false;
            last_M_ = M;
        }
    }

    // The coarse statuses are read from the context at every solve (the driver updates them
    // after each coarse load step); with coarse=lu the coarse Jacobian is refactored when they
    // changed.
    void refresh_coarse() {
        if (!galerkin_.empty()) return; // the coarse operators come from this level's J
        const auto& cM = ctx_->coarse_M;
        MLC_CHECK(cM.size() == ctx_->coarse->contacts.size(),
                  "CF: the coarse context has " << cM.size() << " status matrices for "
                                                << ctx_->coarse->contacts.size()
                                                << " coarse contact elements; solve the level "
                                                   "below first and set CoarseContext::coarse_M");
        if (mg_) {
            // The level below's own V-cycle at its converged statuses when it has one (which
            // makes the cycle recursive down to level 1); else (level 0, solved by a direct
            // method) a sparse LU of its Jacobian here.
            const Preconditioner* below = ctx_->coarse_solver->preconditioner_for(cM);
            if (dynamic_cast<const solvers::MultigridCycle*>(below) != nullptr) {
                mg_coarse_ = below;
            } else {
                if (!coarse_lu_) {
                    coarse_jac_ = std::make_unique<JacobianAssembler>(*ctx_->coarse);
                    coarse_lu_ = std::make_unique<solvers::SparseLUPreconditioner>();
                }
                mg_coarse_ = coarse_lu_.get();
            }
        }
        if (coarse_lu_ && !coarse_exact_ && (!coarse_factored_ || cM != coarse_M_used_)) {
            coarse_jac_->assemble(cM);
            try {
                if (!coarse_factored_)
                    coarse_lu_->setup(coarse_jac_->matrix());
                else
                    coarse_lu_->update_values(coarse_jac_->matrix());
                coarse_factored_ = true;
                coarse_M_used_ = cM;
            } catch (const SolverBreakdown&) {
                // The coarse Jacobian is singular at these statuses (for instance the
                // tangential multiplier of a stuck node whose tangential displacement is
                // prescribed: a zero row and column). The level below's own exact solver
                // (schur) copes with it: from now on it is the coarse solve, and the name
                // says so.
                coarse_exact_ = std::make_unique<CoarseSolverAsPreconditioner>(*ctx_->coarse_solver,
                                                                               ctx_->coarse_M);
            }
        }
        if (mg_ && coarse_exact_ && mg_coarse_ == coarse_lu_.get())
            mg_coarse_ = coarse_exact_.get();
    }

    // The coarse correction of CF/SORCF with coarse=lu: the LU, or the fallback above.
    void coarse_lu_apply(const Vector& r, Vector& z) const {
        if (coarse_exact_)
            coarse_exact_->apply(r, z);
        else
            coarse_lu_->apply(r, z);
    }

    void build_coarse_fine(const solvers::PreconditionerSpec& parsed,
                           const CoarseContext* context) {
        MLC_CHECK(context != nullptr && context->available(),
                  parsed.name << " needs the level below: use with --levels >= 1 and the "
                                 "coarse-to-fine solve");
        ctx_ = context;
        Options o(parsed);
        const MultiplierScale scale = parse_multiplier_scale(o.get_string("scale", "q"));
        const std::string coarse = o.get_string("coarse", "lu");
        MLC_CHECK(coarse == "solver" || coarse == "lu",
                  "option coarse=" << coarse << " of " << parsed.name << ": valid solver, lu");
        solvers::CoarseSolve coarse_solve;
        if (coarse == "lu") {
            coarse_jac_ = std::make_unique<JacobianAssembler>(*ctx_->coarse);
            coarse_lu_ = std::make_unique<solvers::SparseLUPreconditioner>();
            coarse_solve = [this](const Vector& r, Vector& z) { coarse_lu_apply(r, z); };
        } else {
            coarse_solve = [this](const Vector& r, Vector& z) {
                z.setZero(r.size());
                const SolveResult res = ctx_->coarse_solver->solve(ctx_->coarse_M, r, z);
                if (!res.converged)
                    throw SolverBreakdown("CF: the coarse solve (" + ctx_->coarse_solver->name() +
                                          ") did not converge: " + res.message);
            };
        }
        solvers::CoarseFineSplit split =
            coarse_fine_split(level_, *ctx_->coarse, *ctx_->transfer, scale);
        if (parsed.name == "cf") {
            solvers::CoarseFineParams p;
            p.inner = solvers::parse_inner_solve(o.get_string("inner", "lu"));
            p.inner_tol = o.get_double("tol", p.inner_tol);
            p.inner_max_iter = o.get_int("maxit", p.inner_max_iter);
            o.finish();
            pc_ = solvers::make_coarse_fine(std::move(split), std::move(coarse_solve), p);
        } else {
            solvers::SorcfParams p;
            p.omega = o.get_double("omega", p.omega);
            const int block = o.get_int("block", 0);
            MLC_CHECK(block == 0 || block == 1,
                      "option block=" << block << " of sorcf: valid 0 (scalar D*), 1 (blocks)");
            p.block = block == 1;
            o.finish();
            pc_ = solvers::make_sorcf(std::move(split), std::move(coarse_solve), p);
        }
    }

    void build_mg(const solvers::PreconditionerSpec& parsed, const CoarseContext* context) {
        MLC_CHECK(context != nullptr && context->available(),
                  "mg needs the level below: use with --levels >= 1 and the coarse-to-fine solve");
        ctx_ = context;
        Options o(parsed);
        solvers::MultigridParams p;
        p.pre_sweeps = o.get_int("pre", p.pre_sweeps);
        p.post_sweeps = o.get_int("post", p.post_sweeps);
        p.omega = o.get_double("omega", p.omega);
        const std::string coarse = o.get_string("coarse", "rediscretize");
        MLC_CHECK(coarse == "rediscretize" || coarse == "galerkin",
                  "option coarse=" << coarse << " of mg: valid rediscretize, galerkin");
        o.finish();
        const auto& T = ctx_->transfer->T;
        MLC_CHECK(T.rows() == level_.n_unknowns() && T.cols() == ctx_->coarse->n_unknowns(),
                  "mg: the transfer is " << T.rows() << " x " << T.cols() << ", expected "
                                         << level_.n_unknowns() << " x "
                                         << ctx_->coarse->n_unknowns());
        mg_ = true;
        pc_ = std::make_unique<solvers::MultigridCycle>(
            T, ctx_->transfer->R, [this](const Vector& r, Vector& z) { mg_coarse_->apply(r, z); },
            level_vertex_blocks(level_), p);
        if (coarse == "galerkin") {
            // One entry per level below, down to level 0: the level, its transfer from the
            // level under it, its Galerkin operator and (above level 0) its cycle.
            for (const CoarseContext* c = ctx_; c != nullptr; c = c->below) {
                GalerkinLevel g;
                g.level = c->coarse;
                g.R = &c->transfer->R;
                g.T = &c->transfer->T;
                galerkin_.push_back(std::move(g));
            }
            MLC_CHECK(galerkin_.back().level->mesh.n_coarse_vertices == 0,
                      "mg:coarse=galerkin needs every level below in the coarse-to-fine solve");
            // galerkin_[k] is level l-1-k with T from it to level l-k; the cycle of level l-1-k
            // thus prolongates with galerkin_[k+1].T.
            for (size_t k = 0; k + 1 < galerkin_.size(); ++k) {
                const GalerkinLevel& under = galerkin_[k + 1];
                galerkin_[k].cycle = std::make_unique<solvers::MultigridCycle>(
                    *under.T, *under.R,
                    [this, k](const Vector& r, Vector& z) {
                        if (k + 2 < galerkin_.size())
                            galerkin_[k + 1].cycle->apply(r, z);
                        else
                            galerkin_lu_.apply(r, z);
                    },
                    level_vertex_blocks(*galerkin_[k].level), p);
            }
            mg_coarse_ = galerkin_.size() > 1
                             ? static_cast<const Preconditioner*>(galerkin_[0].cycle.get())
                             : &galerkin_lu_;
        }
    }

    // Galerkin coarse operators down the chain from this level's J (A of galerkin_[0] is R J T
    // with this level's transfer, then R A T level by level); the cycles are set up on them
    // and level 0's is factored.
    void build_galerkin() {
        const SparseMatrix* A = &jac_.matrix();
        for (size_t k = 0; k < galerkin_.size(); ++k) {
            const SparseMatrix RA = *galerkin_[k].R * (*A);
            galerkin_[k].A = RA * *galerkin_[k].T;
            galerkin_[k].A.makeCompressed();
            A = &galerkin_[k].A;
        }
        for (size_t k = galerkin_.size(); k-- > 0;) {
            if (k + 1 == galerkin_.size())
                galerkin_lu_.setup(galerkin_[k].A);
            else
                galerkin_[k].cycle->setup(galerkin_[k].A);
        }
    }

    void build_ebe(const solvers::PreconditionerSpec& parsed) {
        Options o(parsed);
        smoothers::EBEParams p;
        p.variant = smoothers::parse_ebe_variant(o.get_string("variant", "c1"));
        const std::string unit = o.get_string("unit", "multipliers");
        MLC_CHECK(unit == "contact" || unit == "multipliers",
                  "option unit=" << unit << " of ebe: valid contact, multipliers");
        p.unit_scaling = unit == "contact" ? smoothers::UnitScaling::contact_unknowns
                                           : smoothers::UnitScaling::multipliers;
        o.finish();
        ebe_elements_ = elastic_element_matrices(level_);
        ebe_n_elastic_ = ebe_elements_.size();
        ebe_elements_.resize(ebe_n_elastic_ + level_.contacts.size());
        pc_ = std::make_unique<smoothers::EBE>(ebe_elements_, p);
    }

    const Level& level_;
    LinearSolverSpec spec_;
    JacobianAssembler jac_;
    solvers::Krylov method_;
    std::unique_ptr<Preconditioner> pc_;
    solvers::KrylovParams params_;
    double forcing_ = 0.0; // inexact Newton: looser tolerance of the next solves (set_forcing)
    bool first_ = true;
    std::vector<Eigen::Matrix2d> last_M_; // statuses of the last assembly
    double assembly_seconds_ = 0.0;       // of the last prepare
    // CF / SORCF
    const CoarseContext* ctx_ = nullptr; // borrowed, read at every solve
    std::unique_ptr<JacobianAssembler> coarse_jac_;
    std::unique_ptr<solvers::SparseLUPreconditioner> coarse_lu_;
    bool coarse_factored_ = false;
    // When the coarse LU broke down: the level below's exact solver as coarse solve.
    std::unique_ptr<Preconditioner> coarse_exact_;
    std::vector<Eigen::Matrix2d> coarse_M_used_;
    // MG: the coarse correction (the level below's cycle, or coarse_lu_), set at every solve.
    bool mg_ = false;
    const Preconditioner* mg_coarse_ = nullptr;
    // MG with coarse=galerkin: one entry per level below (the level below first).
    struct GalerkinLevel {
        const Level* level = nullptr;
        const SparseMatrix* R = nullptr; // restriction to this level from the one above
        const SparseMatrix* T = nullptr; // prolongation from this level to the one above
        SparseMatrix A;                  // its Galerkin operator
        std::unique_ptr<solvers::MultigridCycle> cycle; // above level 0
    };
    std::vector<GalerkinLevel> galerkin_;
    solvers::SparseLUPreconditioner galerkin_lu_;
    // EBE: elastic element matrices first, then one per contact element (refreshed per solve).
    std::vector<smoothers::ElementMatrix> ebe_elements_;
    size_t ebe_n_elastic_ = 0;
};

} // namespace

std::unique_ptr<NewtonSystemSolver> make_krylov_system_solver(const Level& level,
                                                              const LinearSolverSpec& spec,
                                                              const CoarseContext* context) {
    return std::make_unique<KrylovSystemSolver>(level, spec, context);
}

std::vector<smoothers::ElementMatrix> elastic_element_matrices(const Level& level) {
    const auto& m = level.mesh;
    std::vector<smoothers::ElementMatrix> out;
    out.reserve(static_cast<size_t>(m.n_triangles()));
    for (int t = 0; t < m.n_triangles(); ++t) {
        const auto& tri = m.triangles[static_cast<size_t>(t)];
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

MultiplierScale parse_multiplier_scale(std::string_view name) {
    if (name == "q") return MultiplierScale::q;
    if (name == "none") return MultiplierScale::none;
    if (name == "qt") return MultiplierScale::qt;
    if (name == "qinv") return MultiplierScale::qinv;
    MLC_CHECK(false, "unknown multiplier scale '" << name << "'; valid: q, none, qt, qinv");
    return MultiplierScale::q;
}

solvers::CoarseFineSplit coarse_fine_split(const Level& fine, const Level& coarse,
                                           const transfer::LevelTransfer& transfer,
                                           MultiplierScale scale) {
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
        if (fine.dofs.is_displacement(s.coarse_set[k]) || scale == MultiplierScale::none) continue;
        const double q = have_T ? transfer.T.coeff(s.coarse_set[k], s.coarse_dof[k]) : 0.5;
        MLC_CHECK(q > 0.0, "coarse_fine_split: the transfer has no Q entry at fine unknown "
                               << s.coarse_set[k] << " (coarse " << s.coarse_dof[k] << ")");
        s.prolong_scale[k] = q;
        if (scale == MultiplierScale::qt) s.restrict_scale[k] = q;
        if (scale == MultiplierScale::qinv) s.restrict_scale[k] = 1.0 / q;
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

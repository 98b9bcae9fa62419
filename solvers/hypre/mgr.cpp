// SPDX-License-Identifier: MIT
// hypre MGR on the contact Newton system: F = displacements (BoomerAMG on A_FF), C = multipliers.
#include "solvers/hypre/mgr.hpp"

#include "core/check.hpp"
#include "core/timer.hpp"
#include "smoothers/matrix_checks.hpp"
#include "solvers/hypre/ij_system.h"

#include <algorithm>
#include <mpi.h>

#include <cmath>
#include <sstream>

namespace mlc::solvers {

void MGRParams::validate() const {
    MLC_CHECK(f_relax == 0 || f_relax == 2 || (f_relax >= 3 && f_relax <= 8) || f_relax == 13 ||
                  f_relax == 14 || f_relax == 18,
              "MGR: F-relaxation type must be 2 (AMG) or a relaxation type 0, 3-8, 13, 14, 18; "
              "found "
                  << f_relax);
    MLC_CHECK(f_sweeps >= 1, "MGR: F-relaxation sweeps must be >= 1, found " << f_sweeps);
    MLC_CHECK(interp_type >= 0 && interp_type <= 12,
              "MGR: interpolation type must be in 0..12, found " << interp_type);
    MLC_CHECK(restrict_type >= 0 && restrict_type <= 14,
              "MGR: restriction type must be in 0..14, found " << restrict_type);
    MLC_CHECK(coarse_method >= 0 && coarse_method <= 4,
              "MGR: coarse grid method must be in 0..4, found " << coarse_method);
    MLC_CHECK(global_smooth_iters >= 0,
              "MGR: global smoothing iterations must be >= 0, found " << global_smooth_iters);
    MLC_CHECK(global_smooth_type >= 0 && global_smooth_type <= 16,
              "MGR: global smoother type must be in 0..16, found " << global_smooth_type);
    f_amg.validate();
    c_amg.validate();
}

std::ostream& operator<<(std::ostream& os, const MGRParams& p) {
    return os << "MGRParams{f_relax=" << p.f_relax << ", f_sweeps=" << p.f_sweeps
              << ", interp_type=" << p.interp_type << ", restrict_type=" << p.restrict_type
              << ", coarse_method=" << p.coarse_method
              << ", global_smooth_iters=" << p.global_smooth_iters
              << ", global_smooth_type=" << p.global_smooth_type << ", f_amg=" << p.f_amg
              << ", c_amg=" << p.c_amg << "}";
}

// The matrix in hypre, the MGR solver and the two BoomerAMG solvers it is given (MGR does not
// destroy solvers it is given: they are destroyed here, after it).
struct MGRPreconditioner::Impl : hypre_detail::IJSystem {
    HYPRE_Solver mgr = nullptr, f_amg = nullptr, c_amg = nullptr;
    // Arrays MGR keeps pointers to (the point markers) or may: kept alive with the solver.
    std::vector<HYPRE_Int> marker;
    HYPRE_Int n_coarse_per_level = 1;
    HYPRE_Int coarse_label = 1;
    HYPRE_Int* coarse_labels = &coarse_label;
    HYPRE_Int level_frelax = 2, level_sweeps = 1, cg_method = 0;

    explicit Impl(const SparseMatrix& M) : IJSystem(M) {}
    ~Impl() {
        if (mgr) HYPRE_MGRDestroy(mgr);
        if (f_amg) HYPRE_BoomerAMGDestroy(f_amg);
        if (c_amg) HYPRE_BoomerAMGDestroy(c_amg);
    }
};

MGRPreconditioner::MGRPreconditioner(std::vector<int> unknown_function, MGRParams params)
    : function_(std::move(unknown_function)), params_(params) {
    params_.validate();
    ensure_hypre_initialized();
    size_t n_c = 0;
    for (size_t i = 0; i < function_.size(); ++i) {
        MLC_CHECK((function_[i] >= 0 && function_[i] <= 2) || function_[i] == kMultiplierFunction,
                  "MGR: unknown " << i << " has function " << function_[i]
                                  << "; valid 0, 1, 2 (displacement components), "
                                  << kMultiplierFunction << " (multiplier)");
        n_c += function_[i] == kMultiplierFunction;
    }
    MLC_CHECK(n_c > 0, "mgr (hypre MGR) reduces onto the contact multipliers: this system has "
                       "none (no contact candidates); use --pc mg or amg");
    MLC_CHECK(n_c < function_.size(), "mgr: the system has no displacement unknowns");
}

MGRPreconditioner::~MGRPreconditioner() = default;

void MGRPreconditioner::setup(const SparseMatrix& A) {
    smoothers::check_setup_matrix(A, "MGRPreconditioner::setup");
    MLC_CHECK(static_cast<size_t>(A.rows()) == function_.size(),
              "MGR: the matrix has " << A.rows() << " rows, the unknown functions "
                                     << function_.size());
    impl_.reset();
    const double t0 = wall_seconds();
    auto h = std::make_unique<Impl>(A);
    copy_seconds_ = wall_seconds() - t0;
    const MGRParams& p = params_;
    h->marker.resize(function_.size());
    std::vector<int> f_func;
    f_func.reserve(function_.size());
    for (size_t i = 0; i < function_.size(); ++i) {
        const bool c = function_[i] == kMultiplierFunction;
        h->marker[i] = c ? 1 : 0;
        if (!c) f_func.push_back(function_[i]);
    }
    HYPRE_MGRCreate(&h->mgr);
    // Labels: 0 displacement (F), 1 multiplier (kept as C); one reduction level.
    HYPRE_MGRSetCpointsByPointMarkerArray(h->mgr, 2, 1, &h->n_coarse_per_level, &h->coarse_labels,
                                          h->marker.data());
    HYPRE_MGRSetNonCpointsToFpoints(h->mgr, 1);
    HYPRE_MGRSetMaxCoarseLevels(h->mgr, 1);
    h->level_frelax = p.f_relax == 2 ? 2 : p.f_relax;
    HYPRE_MGRSetLevelFRelaxType(h->mgr, &h->level_frelax);
    if (p.f_relax == 2) {
        // Our BoomerAMG on A_FF: systems AMG with each F row's displacement component.
        // Systems AMG over the displacement components present: x, y (2D) or x, y, z (3D).
        BoomerAMGParams fp = p.f_amg;
        fp.num_functions = 1 + *std::max_element(f_func.begin(), f_func.end());
        h->f_amg =
            hypre_detail::create_boomeramg(fp, true, f_func, static_cast<HYPRE_Int>(f_func.size()));
        HYPRE_MGRSetFSolver(h->mgr, reinterpret_cast<HYPRE_PtrToParSolverFcn>(HYPRE_BoomerAMGSolve),
                            reinterpret_cast<HYPRE_PtrToParSolverFcn>(HYPRE_BoomerAMGSetup),
                            h->f_amg);
    } else {
        h->level_sweeps = p.f_sweeps;
        HYPRE_MGRSetLevelNumRelaxSweeps(h->mgr, &h->level_sweeps);
    }
    HYPRE_MGRSetInterpType(h->mgr, p.interp_type);
    HYPRE_MGRSetRestrictType(h->mgr, p.restrict_type);
    h->cg_method = p.coarse_method;
    HYPRE_MGRSetCoarseGridMethod(h->mgr, &h->cg_method);
    if (p.global_smooth_iters > 0) {
        HYPRE_MGRSetMaxGlobalSmoothIters(h->mgr, p.global_smooth_iters);
        HYPRE_MGRSetGlobalSmoothType(h->mgr, p.global_smooth_type);
    }
    h->c_amg = hypre_detail::create_boomeramg(p.c_amg, true, {}, 0);
    HYPRE_MGRSetCoarseSolver(
        h->mgr, reinterpret_cast<HYPRE_PtrToParSolverFcn>(HYPRE_BoomerAMGSolve),
        reinterpret_cast<HYPRE_PtrToParSolverFcn>(HYPRE_BoomerAMGSetup), h->c_amg);
    HYPRE_MGRSetMaxIter(h->mgr, 1);
    HYPRE_MGRSetTol(h->mgr, 0.0);
    HYPRE_MGRSetPrintLevel(h->mgr, 0);
    HYPRE_ClearAllErrors();
    HYPRE_MGRSetup(h->mgr, h->A, h->b, h->x);
    const HYPRE_Int err = HYPRE_GetError();
    HYPRE_ClearAllErrors();
    if ((err & ~HYPRE_ERROR_CONV) != 0) {
        std::ostringstream os;
        os << "hypre MGR setup failed (hypre error code " << err << ")";
        throw SolverBreakdown(os.str());
    }
    impl_ = std::move(h);
}

void MGRPreconditioner::apply(const Vector& r, Vector& z) const {
    MLC_CHECK(impl_ != nullptr, "MGRPreconditioner: call setup first");
    smoothers::check_size(r, impl_->n, "MGRPreconditioner::apply", "r");
    z.setZero(r.size());
    impl_->set_vector(impl_->ij_b, r);
    impl_->set_vector(impl_->ij_x, z);
    HYPRE_MGRSolve(impl_->mgr, impl_->A, impl_->b, impl_->x);
    HYPRE_ClearAllErrors(); // max_iter 1 "not converged" is the preconditioner's normal exit
    impl_->get_vector(impl_->ij_x, z);
}

SolveResult MGRPreconditioner::solve_fgmres(const SparseMatrix& A, const Vector& b, Vector& x,
                                            double rel_tol, int max_iter, int restart) const {
    MLC_CHECK(impl_ != nullptr, "MGRPreconditioner::solve_fgmres: call setup first");
    smoothers::check_size(b, impl_->n, "MGRPreconditioner::solve_fgmres", "b");
    MLC_CHECK(A.rows() == impl_->n, "MGRPreconditioner::solve_fgmres: the matrix has "
                                        << A.rows() << " rows, the setup " << impl_->n);
    MLC_CHECK(rel_tol > 0 && rel_tol < 1, "solve_fgmres: rel_tol must be in (0, 1)");
    MLC_CHECK(max_iter >= 1 && restart >= 1, "solve_fgmres: max_iter and restart must be >= 1");
    if (x.size() != b.size()) x = Vector::Zero(b.size());
    SolveResult res;
    res.initial_residual = (b - A * x).norm();
    Impl& h = *impl_;
    h.set_vector(h.ij_b, b);
    h.set_vector(h.ij_x, x);
    HYPRE_Solver gm = nullptr;
    HYPRE_ParCSRFlexGMRESCreate(MPI_COMM_SELF, &gm);
    HYPRE_FlexGMRESSetKDim(gm, restart);
    HYPRE_FlexGMRESSetTol(gm, rel_tol);
    HYPRE_FlexGMRESSetAbsoluteTol(gm, 0.0);
    HYPRE_FlexGMRESSetMaxIter(gm, max_iter);
    HYPRE_FlexGMRESSetPrintLevel(gm, 0);
    // MGR is set up already (setup() is timed on its own): FlexGMRES's setup call is a no-op.
    HYPRE_PtrToParSolverFcn no_setup = [](HYPRE_Solver, HYPRE_ParCSRMatrix, HYPRE_ParVector,
                                          HYPRE_ParVector) -> HYPRE_Int { return 0; };
    HYPRE_ParCSRFlexGMRESSetPrecond(gm, HYPRE_MGRSolve, no_setup, h.mgr);
    HYPRE_ParCSRFlexGMRESSetup(gm, h.A, h.b, h.x);
    const double t0 = wall_seconds();
    HYPRE_ParCSRFlexGMRESSolve(gm, h.A, h.b, h.x);
    res.solve_seconds = wall_seconds() - t0;
    HYPRE_ClearAllErrors();
    HYPRE_Int its = 0;
    HYPRE_FlexGMRESGetNumIterations(gm, &its);
    HYPRE_ParCSRFlexGMRESDestroy(gm);
    h.get_vector(h.ij_x, x);
    res.iterations = static_cast<int>(its);
    res.final_residual = x.allFinite() ? (b - A * x).norm() : HUGE_VAL;
    const double bn = b.norm();
    res.relative_residual = bn > 0 ? res.final_residual / bn : res.final_residual;
    res.converged = res.relative_residual <= rel_tol;
    res.reason = res.converged ? StopReason::converged : StopReason::max_iter;
    if (its > 0 && res.initial_residual > 0 && std::isfinite(res.final_residual))
        res.average_rate = std::pow(res.final_residual / res.initial_residual, 1.0 / its);
    return res;
}

std::string MGRPreconditioner::name() const {
    std::ostringstream os;
    os << "mgr(F=u:" << (params_.f_relax == 2 ? "amg" : "relax" + std::to_string(params_.f_relax))
       << ",C=lambda:amg";
    if (params_.interp_type != 2) os << ",interp=" << params_.interp_type;
    if (params_.restrict_type != 0) os << ",restrict=" << params_.restrict_type;
    if (params_.coarse_method != 0) os << ",cg=" << params_.coarse_method;
    if (params_.global_smooth_iters != 1 || params_.global_smooth_type != 16)
        os << ",smooth=" << params_.global_smooth_iters
           << ",smoother=" << params_.global_smooth_type;
    os << ")";
    return os.str();
}

} // namespace mlc::solvers

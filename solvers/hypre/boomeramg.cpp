// SPDX-License-Identifier: MIT
// hypre BoomerAMG (one V-cycle as a Preconditioner) and hypre PCG + BoomerAMG.
#include "solvers/hypre/boomeramg.hpp"

#include "solvers/hypre/ij_system.h"
#include "solvers/hypre/par_matrix.hpp"

#include "core/check.hpp"
#include "core/timer.hpp"
#include "smoothers/matrix_checks.hpp"

#include <HYPRE.h>
#include <HYPRE_krylov.h>
#include <HYPRE_parcsr_ls.h>
#include <_hypre_parcsr_ls.h> // SetSmoothInterpVectors, SetInterpRefine
#include <_hypre_parcsr_mv.h>
#include <mpi.h>
#ifdef HYPRE_USING_OPENMP
#include <omp.h>
#endif

#include <cmath>
#include <cstdlib>
#include <numeric>
#include <sstream>
#include <vector>

namespace mlc::solvers {

void BoomerAMGParams::validate() const {
    MLC_CHECK(num_functions >= 1, "BoomerAMG: num_functions must be >= 1, found " << num_functions);
    MLC_CHECK(nodal >= 0, "BoomerAMG: nodal must be >= 0, found " << nodal);
    MLC_CHECK(strong_threshold > 0 && strong_threshold < 1,
              "BoomerAMG: strong_threshold must be in (0, 1), found " << strong_threshold);
    MLC_CHECK(p_max_elmts >= 0, "BoomerAMG: p_max_elmts must be >= 0, found " << p_max_elmts);
    MLC_CHECK(agg_num_levels >= 0, "BoomerAMG: agg_num_levels must be >= 0, found " << agg_num_levels);
    MLC_CHECK(interp_vec_variant >= 0 && interp_vec_variant <= 3,
              "BoomerAMG: interp_vec_variant must be in 0..3, found " << interp_vec_variant);
    MLC_CHECK(interp_vec_variant == 0 || nodal > 0,
              "BoomerAMG: interpolation vectors need nodal coarsening (nodal >= 1)");
    MLC_CHECK(nodal_diag >= 0 && interp_vec_q_max >= 0 && smooth_interp_vectors >= 0 &&
                  interp_refine >= 0,
              "BoomerAMG: nodal_diag, interp_vec_q_max, smooth_interp_vectors and interp_refine "
              "must be >= 0");
}

int hypre_threads() {
#ifdef HYPRE_USING_OPENMP
    return omp_get_max_threads();
#else
    return 1;
#endif
}

std::ostream& operator<<(std::ostream& os, const BoomerAMGParams& p) {
    return os << "BoomerAMGParams{num_functions=" << p.num_functions << ", nodal=" << p.nodal
              << ", strong_threshold=" << p.strong_threshold << ", coarsen_type=" << p.coarsen_type
              << ", interp_type=" << p.interp_type << ", p_max_elmts=" << p.p_max_elmts
              << ", relax_type=" << p.relax_type << ", agg_num_levels=" << p.agg_num_levels
              << ", nodal_diag=" << p.nodal_diag << ", interp_vec_variant=" << p.interp_vec_variant
              << ", interp_vec_q_max=" << p.interp_vec_q_max
              << ", smooth_interp_vectors=" << p.smooth_interp_vectors
              << ", interp_refine=" << p.interp_refine << "}";
}

bool have_hypre() { return true; }

namespace {

void finalize_hypre() {
    HYPRE_Finalize();
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
}

} // namespace

void ensure_hypre_initialized() {
    static const bool done = [] {
        int initialized = 0;
        MPI_Initialized(&initialized);
        if (!initialized) {
            int argc = 0;
            char** argv = nullptr;
            MLC_CHECK(MPI_Init(&argc, &argv) == MPI_SUCCESS, "BoomerAMG: MPI_Init failed");
        }
        HYPRE_Init();
        std::atexit(finalize_hypre);
        return true;
    }();
    (void)done;
}

namespace hypre_detail {

IJSystem::IJSystem(const SparseMatrix& M) {
    ensure_hypre_initialized();
    n = static_cast<HYPRE_Int>(M.rows());
    const HYPRE_BigInt last = n - 1;
    HYPRE_IJMatrixCreate(MPI_COMM_SELF, 0, last, 0, last, &ij_A);
    HYPRE_IJMatrixSetObjectType(ij_A, HYPRE_PARCSR);
    std::vector<HYPRE_Int> ncols(static_cast<size_t>(n));
    for (HYPRE_Int i = 0; i < n; ++i)
        ncols[static_cast<size_t>(i)] = M.outerIndexPtr()[i + 1] - M.outerIndexPtr()[i];
    HYPRE_IJMatrixSetRowSizes(ij_A, ncols.data());
    HYPRE_IJMatrixInitialize(ij_A);
    rows.resize(static_cast<size_t>(n));
    std::iota(rows.begin(), rows.end(), HYPRE_BigInt{0});
    std::vector<HYPRE_BigInt> cols(M.innerIndexPtr(), M.innerIndexPtr() + M.nonZeros());
    HYPRE_IJMatrixSetValues(ij_A, n, ncols.data(), rows.data(), cols.data(), M.valuePtr());
    HYPRE_IJMatrixAssemble(ij_A);
    HYPRE_IJMatrixGetObject(ij_A, reinterpret_cast<void**>(&A));
    for (auto* v : {&ij_b, &ij_x}) {
        HYPRE_IJVectorCreate(MPI_COMM_SELF, 0, last, v);
        HYPRE_IJVectorSetObjectType(*v, HYPRE_PARCSR);
        HYPRE_IJVectorInitialize(*v);
        HYPRE_IJVectorAssemble(*v);
    }
    HYPRE_IJVectorGetObject(ij_b, reinterpret_cast<void**>(&b));
    HYPRE_IJVectorGetObject(ij_x, reinterpret_cast<void**>(&x));
}

IJSystem::~IJSystem() {
    if (ij_A) HYPRE_IJMatrixDestroy(ij_A);
    if (ij_b) HYPRE_IJVectorDestroy(ij_b);
    if (ij_x) HYPRE_IJVectorDestroy(ij_x);
}

void IJSystem::set_vector(HYPRE_IJVector v, const Vector& src) const {
    HYPRE_IJVectorSetValues(v, n, rows.data(), src.data());
}

void IJSystem::get_vector(HYPRE_IJVector v, Vector& dst) const {
    HYPRE_IJVectorGetValues(v, n, rows.data(), dst.data());
}

HYPRE_Solver create_boomeramg(const BoomerAMGParams& p, bool as_preconditioner,
                              const std::vector<int>& dof_func, HYPRE_Int n) {
    HYPRE_Solver amg = nullptr;
    HYPRE_BoomerAMGCreate(&amg);
    HYPRE_BoomerAMGSetPrintLevel(amg, 0);
    HYPRE_BoomerAMGSetNumFunctions(amg, p.num_functions);
    if (!dof_func.empty()) {
        MLC_CHECK(static_cast<HYPRE_Int>(dof_func.size()) == n,
                  "BoomerAMG: dof_func has " << dof_func.size() << " entries for " << n
                                             << " unknowns");
        // hypre takes ownership of the array and frees it with free() (host memory).
        auto* f = static_cast<HYPRE_Int*>(std::malloc(sizeof(HYPRE_Int) * dof_func.size()));
        MLC_CHECK(f != nullptr, "BoomerAMG: out of memory");
        for (size_t i = 0; i < dof_func.size(); ++i) {
            MLC_CHECK(dof_func[i] >= 0 && dof_func[i] < p.num_functions,
                      "BoomerAMG: dof_func[" << i << "] = " << dof_func[i] << " is not in [0, "
                                             << p.num_functions << ")");
            f[i] = dof_func[i];
        }
        HYPRE_BoomerAMGSetDofFunc(amg, f);
    }
    if (p.nodal > 0) HYPRE_BoomerAMGSetNodal(amg, p.nodal);
    if (p.nodal_diag > 0) HYPRE_BoomerAMGSetNodalDiag(amg, p.nodal_diag);
    if (p.interp_vec_variant > 0) {
        HYPRE_BoomerAMGSetInterpVecVariant(amg, p.interp_vec_variant);
        if (p.interp_vec_q_max > 0) HYPRE_BoomerAMGSetInterpVecQMax(amg, p.interp_vec_q_max);
        if (p.smooth_interp_vectors > 0)
            HYPRE_BoomerAMGSetSmoothInterpVectors(amg, p.smooth_interp_vectors);
        if (p.interp_refine > 0) HYPRE_BoomerAMGSetInterpRefine(amg, p.interp_refine);
    }
    HYPRE_BoomerAMGSetStrongThreshold(amg, p.strong_threshold);
    HYPRE_BoomerAMGSetCoarsenType(amg, p.coarsen_type);
    HYPRE_BoomerAMGSetInterpType(amg, p.interp_type);
    HYPRE_BoomerAMGSetPMaxElmts(amg, p.p_max_elmts);
    HYPRE_BoomerAMGSetRelaxType(amg, p.relax_type);
    HYPRE_BoomerAMGSetAggNumLevels(amg, p.agg_num_levels);
    HYPRE_BoomerAMGSetNumSweeps(amg, 1);
    if (as_preconditioner) {
        HYPRE_BoomerAMGSetTol(amg, 0.0);
        HYPRE_BoomerAMGSetMaxIter(amg, 1);
    }
    return amg;
}

} // namespace hypre_detail

// One matrix in hypre and its BoomerAMG.
struct BoomerAMGPreconditioner::Impl : hypre_detail::IJSystem {
    HYPRE_Solver amg = nullptr;

    explicit Impl(const SparseMatrix& M) : IJSystem(M) {}
    ~Impl() {
        if (amg) HYPRE_BoomerAMGDestroy(amg);
    }
    void create_amg(const BoomerAMGParams& p, bool as_preconditioner,
                    const std::vector<int>& dof_func) {
        amg = hypre_detail::create_boomeramg(p, as_preconditioner, dof_func, n);
    }
};

BoomerAMGPreconditioner::BoomerAMGPreconditioner(BoomerAMGParams params) : params_(params) {
    params_.validate();
}

BoomerAMGPreconditioner::~BoomerAMGPreconditioner() = default;

void BoomerAMGPreconditioner::setup(const SparseMatrix& A) {
    smoothers::check_setup_matrix(A, "BoomerAMGPreconditioner::setup");
    MLC_CHECK(!dof_func_.empty() || A.rows() % params_.num_functions == 0,
              "BoomerAMG: " << A.rows() << " unknowns are not a multiple of num_functions = "
                            << params_.num_functions << " (interleaved vertex components expected)");
    impl_ = std::make_unique<Impl>(A);
    impl_->create_amg(params_, true, dof_func_);
    HYPRE_BoomerAMGSetup(impl_->amg, impl_->A, impl_->b, impl_->x);
}

void BoomerAMGPreconditioner::apply(const Vector& r, Vector& z) const {
    MLC_CHECK(impl_ != nullptr, "BoomerAMGPreconditioner: call setup first");
    smoothers::check_size(r, impl_->n, "BoomerAMGPreconditioner::apply", "r");
    z.setZero(r.size());
    impl_->set_vector(impl_->ij_b, r);
    impl_->set_vector(impl_->ij_x, z);
    HYPRE_BoomerAMGSolve(impl_->amg, impl_->A, impl_->b, impl_->x);
    impl_->get_vector(impl_->ij_x, z);
}

std::string BoomerAMGPreconditioner::name() const {
    std::ostringstream os;
    os << "amg(fn=" << params_.num_functions << ",theta=" << params_.strong_threshold << ")";
    return os.str();
}

namespace {

/// Near-null-space vectors in hypre, alive until destroyed (after the AMG that reads them).
struct InterpVectors {
    std::vector<HYPRE_IJVector> ij;
    std::vector<HYPRE_ParVector> par;
    InterpVectors(const std::vector<Vector>& v, const std::vector<HYPRE_BigInt>& rows) {
        const auto n = static_cast<HYPRE_Int>(rows.size());
        for (const Vector& x : v) {
            MLC_CHECK(x.size() == n, "BoomerAMG: an interpolation vector has "
                                         << x.size() << " entries for " << n << " unknowns");
            HYPRE_IJVector iv = nullptr;
            HYPRE_IJVectorCreate(MPI_COMM_SELF, 0, n - 1, &iv);
            HYPRE_IJVectorSetObjectType(iv, HYPRE_PARCSR);
            HYPRE_IJVectorInitialize(iv);
            HYPRE_IJVectorSetValues(iv, n, rows.data(), x.data());
            HYPRE_IJVectorAssemble(iv);
            HYPRE_ParVector pv = nullptr;
            HYPRE_IJVectorGetObject(iv, reinterpret_cast<void**>(&pv));
            ij.push_back(iv);
            par.push_back(pv);
        }
    }
    ~InterpVectors() {
        for (HYPRE_IJVector v : ij)
            HYPRE_IJVectorDestroy(v);
    }
    InterpVectors(const InterpVectors&) = delete;
    InterpVectors& operator=(const InterpVectors&) = delete;
};

} // namespace

SolveResult boomeramg_pcg(const SparseMatrix& A, const Vector& b, Vector& x, double rel_tol,
                          int max_iter, const BoomerAMGParams& params,
                          const std::vector<int>& dof_func,
                          const std::vector<Vector>& interp_vectors) {
    MLC_CHECK(interp_vectors.empty() || params.interp_vec_variant > 0,
              "boomeramg_pcg: interpolation vectors given but params.interp_vec_variant is 0");
    params.validate();
    smoothers::check_setup_matrix(A, "boomeramg_pcg");
    smoothers::check_size(b, A.rows(), "boomeramg_pcg", "b");
    MLC_CHECK(rel_tol > 0 && rel_tol < 1, "boomeramg_pcg: rel_tol must be in (0, 1), found " << rel_tol);
    MLC_CHECK(max_iter >= 1, "boomeramg_pcg: max_iter must be >= 1, found " << max_iter);
    ensure_hypre_initialized(); // once per process, not part of the setup time
    if (x.size() != b.size()) x = Vector::Zero(b.size());
    SolveResult res;
    Vector r = b;
    r.noalias() -= A * x;
    res.initial_residual = r.norm();
    const double t0 = wall_seconds();
    BoomerAMGPreconditioner::Impl h(A);
    const InterpVectors iv(interp_vectors, h.rows);
    h.create_amg(params, true, dof_func);
    if (!iv.par.empty())
        HYPRE_BoomerAMGSetInterpVectors(h.amg, static_cast<HYPRE_Int>(iv.par.size()),
                                        const_cast<HYPRE_ParVector*>(iv.par.data()));
    h.set_vector(h.ij_b, b);
    h.set_vector(h.ij_x, x);
    HYPRE_Solver pcg = nullptr;
    HYPRE_ParCSRPCGCreate(MPI_COMM_SELF, &pcg);
    HYPRE_PCGSetTol(pcg, rel_tol);
    HYPRE_PCGSetAbsoluteTol(pcg, 0.0);
    HYPRE_PCGSetMaxIter(pcg, max_iter);
    HYPRE_PCGSetTwoNorm(pcg, 1);
    HYPRE_PCGSetPrintLevel(pcg, 0);
    HYPRE_PCGSetPrecond(pcg, reinterpret_cast<HYPRE_PtrToSolverFcn>(HYPRE_BoomerAMGSolve),
                        reinterpret_cast<HYPRE_PtrToSolverFcn>(HYPRE_BoomerAMGSetup), h.amg);
    HYPRE_ParCSRPCGSetup(pcg, h.A, h.b, h.x);
    const double t1 = wall_seconds();
    HYPRE_ParCSRPCGSolve(pcg, h.A, h.b, h.x);
    const double t2 = wall_seconds();
    HYPRE_Int its = 0;
    HYPRE_Real rel = 0.0;
    HYPRE_PCGGetNumIterations(pcg, &its);
    HYPRE_PCGGetFinalRelativeResidualNorm(pcg, &rel);
    HYPRE_ParCSRPCGDestroy(pcg);
    h.get_vector(h.ij_x, x);
    res.iterations = static_cast<int>(its);
    r = b;
    r.noalias() -= A * x;
    res.final_residual = r.norm();
    const double bn = b.norm();
    res.relative_residual = bn > 0 ? res.final_residual / bn : res.final_residual;
    res.converged = std::isfinite(rel) && rel <= rel_tol;
    res.reason = res.converged ? StopReason::converged : StopReason::max_iter;
    if (its > 0 && res.initial_residual > 0)
        res.average_rate = std::pow(res.final_residual / res.initial_residual, 1.0 / its);
    res.setup_seconds = t1 - t0;
    res.solve_seconds = t2 - t1;
    return res;
}

namespace {

/// The global two-norm of the owned entries v over the processes of c.
double global_norm(const Vector& v, MPI_Comm c) {
    double s = v.squaredNorm();
    MPI_Allreduce(MPI_IN_PLACE, &s, 1, MPI_DOUBLE, MPI_SUM, c);
    return std::sqrt(s);
}

} // namespace

SolveResult boomeramg_pcg_par(const ParMatrix& A, const Vector& b, Vector& x, double rel_tol,
                              int max_iter, const BoomerAMGParams& params,
                              const std::vector<int>& dof_func) {
    ensure_hypre_initialized(); // once per process, not part of the setup time
    auto* par = static_cast<hypre_ParCSRMatrix*>(A.hypre_handle());
    const MPI_Comm c = hypre_ParCSRMatrixComm(par);
    const int n = A.n_rows();
    // Input checked on every process, then agreed on, so that all throw or none does.
    std::string problem;
    {
        std::ostringstream why;
        if (A.n_cols() != n || A.first_col() != A.first_row())
            why << "the matrix is not square (" << n << " rows, " << A.n_cols()
                << " columns owned)";
        else if (b.size() != n)
            why << "b has " << b.size() << " entries for " << n << " owned rows";
        else if (!(rel_tol > 0 && rel_tol < 1))
            why << "rel_tol must be in (0, 1), found " << rel_tol;
        else if (max_iter < 1)
            why << "max_iter must be >= 1, found " << max_iter;
        else if (!dof_func.empty() && static_cast<int>(dof_func.size()) != n)
            why << "dof_func has " << dof_func.size() << " entries for " << n << " owned rows";
        else {
            // BoomerAMG relaxes on the first entry of each row of the diagonal block.
            const hypre_CSRMatrix* D = hypre_ParCSRMatrixDiag(par);
            const HYPRE_Int* I = hypre_CSRMatrixI(D);
            const HYPRE_Int* J = hypre_CSRMatrixJ(D);
            for (int i = 0; i < n && why.tellp() == 0; ++i)
                if (I[i] == I[i + 1] || J[I[i]] != i)
                    why << "row " << A.first_row() + i
                        << " of the diagonal block does not start with its diagonal entry (build "
                           "the matrix from DistributedRows)";
        }
        problem = why.str();
    }
    int bad = problem.empty() ? 0 : 1;
    MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPI_INT, MPI_MAX, c);
    MLC_CHECK(problem.empty(), "boomeramg_pcg_par: " << problem);
    MLC_CHECK(bad == 0, "boomeramg_pcg_par: the input of another process is invalid (see its "
                        "message)");
    params.validate();
    if (x.size() != n) x = Vector::Zero(n);
    SolveResult res;
    Vector r;
    A.apply(x, r);
    r = b - r;
    res.initial_residual = global_norm(r, c);
    const double t0 = wall_seconds();
    HYPRE_Solver amg = hypre_detail::create_boomeramg(params, true, dof_func, n);
    const auto lo = static_cast<HYPRE_BigInt>(A.first_row());
    const auto hi = static_cast<HYPRE_BigInt>(A.first_row() + n - 1);
    std::vector<HYPRE_BigInt> rows(static_cast<size_t>(n));
    std::iota(rows.begin(), rows.end(), lo);
    HYPRE_IJVector ij_b = nullptr, ij_x = nullptr;
    HYPRE_ParVector pb = nullptr, px = nullptr;
    for (auto* v : {&ij_b, &ij_x}) {
        HYPRE_IJVectorCreate(c, lo, hi, v);
        HYPRE_IJVectorSetObjectType(*v, HYPRE_PARCSR);
        HYPRE_IJVectorInitialize(*v);
    }
    HYPRE_IJVectorSetValues(ij_b, n, rows.data(), b.data());
    HYPRE_IJVectorSetValues(ij_x, n, rows.data(), x.data());
    HYPRE_IJVectorAssemble(ij_b);
    HYPRE_IJVectorAssemble(ij_x);
    HYPRE_IJVectorGetObject(ij_b, reinterpret_cast<void**>(&pb));
    HYPRE_IJVectorGetObject(ij_x, reinterpret_cast<void**>(&px));
    const auto Ah = static_cast<HYPRE_ParCSRMatrix>(A.hypre_handle());
    HYPRE_Solver pcg = nullptr;
    HYPRE_ParCSRPCGCreate(c, &pcg);
    HYPRE_PCGSetTol(pcg, rel_tol);
    HYPRE_PCGSetAbsoluteTol(pcg, 0.0);
    HYPRE_PCGSetMaxIter(pcg, max_iter);
    HYPRE_PCGSetTwoNorm(pcg, 1);
    HYPRE_PCGSetPrintLevel(pcg, 0);
    HYPRE_PCGSetPrecond(pcg, reinterpret_cast<HYPRE_PtrToSolverFcn>(HYPRE_BoomerAMGSolve),
                        reinterpret_cast<HYPRE_PtrToSolverFcn>(HYPRE_BoomerAMGSetup), amg);
    HYPRE_ParCSRPCGSetup(pcg, Ah, pb, px);
    const double t1 = wall_seconds();
    HYPRE_ParCSRPCGSolve(pcg, Ah, pb, px);
    const double t2 = wall_seconds();
    HYPRE_Int its = 0;
    HYPRE_Real rel = 0.0;
    HYPRE_PCGGetNumIterations(pcg, &its);
    HYPRE_PCGGetFinalRelativeResidualNorm(pcg, &rel);
    HYPRE_ParCSRPCGDestroy(pcg);
    HYPRE_BoomerAMGDestroy(amg);
    // A solve that did not converge leaves hypre's global error flag set ("method did not
    // converge"), which the next hypre call checked by ParMatrix would report as its own failure:
    // the outcome is in the result.
    HYPRE_ClearAllErrors();
    HYPRE_IJVectorGetValues(ij_x, n, rows.data(), x.data());
    HYPRE_IJVectorDestroy(ij_b);
    HYPRE_IJVectorDestroy(ij_x);
    res.iterations = static_cast<int>(its);
    A.apply(x, r);
    r = b - r;
    res.final_residual = global_norm(r, c);
    const double bn = global_norm(b, c);
    res.relative_residual = bn > 0 ? res.final_residual / bn : res.final_residual;
    res.converged = std::isfinite(rel) && rel <= rel_tol;
    res.reason = res.converged ? StopReason::converged : StopReason::max_iter;
    if (its > 0 && res.initial_residual > 0)
        res.average_rate = std::pow(res.final_residual / res.initial_residual, 1.0 / its);
    res.setup_seconds = t1 - t0;
    res.solve_seconds = t2 - t1;
    return res;
}

} // namespace mlc::solvers

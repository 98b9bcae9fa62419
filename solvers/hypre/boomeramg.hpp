// SPDX-License-Identifier: MIT
/// @file hypre BoomerAMG as the outside reference for the elastic block (K on the free
/// displacement unknowns): a Preconditioner doing one AMG V-cycle, and hypre's own PCG with it.
/// Compiled only with MLC_WITH_HYPRE (MLC_HAVE_HYPRE defined); without it the functions below
/// throw mlc::InvalidInput. MPI is initialised once, on first use, as a single process (no
/// mpirun needed), and finalised at exit.
#pragma once

#include "core/linear_operator.hpp"

#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace mlc::solvers {

class ParMatrix;

/// BoomerAMG settings (names as in hypre's HYPRE_BoomerAMGSet* functions). The defaults are the
/// usual choice for 2D linear elasticity: systems AMG with the two displacement components as
/// two functions (unknown-based coarsening, interpolation within each component), HMIS
/// coarsening, extended+i interpolation truncated to 4 entries per row, l1-scaled symmetric
/// hybrid Gauss–Seidel, strength threshold 0.25 (hypre's value for 2D problems).
struct BoomerAMGParams {
    int num_functions = 2;        ///< unknowns per vertex, interleaved (SetNumFunctions)
    int nodal = 0;                ///< 0: unknown-based; >= 1: nodal coarsening norm (SetNodal)
    double strong_threshold = 0.25; ///< SetStrongThreshold, in (0, 1)
    int coarsen_type = 10;        ///< SetCoarsenType: 10 HMIS, 8 PMIS, 6 Falgout
    int interp_type = 6;          ///< SetInterpType: 6 extended+i
    int p_max_elmts = 4;          ///< SetPMaxElmts: interpolation truncation (0: none)
    int relax_type = 8;           ///< SetRelaxType: 8 l1-symmetric hybrid Gauss–Seidel
    int agg_num_levels = 0;       ///< SetAggNumLevels: aggressive coarsening levels
    /// Elasticity options (hypre's settings for systems with near-null-space vectors; 0 leaves
    /// hypre's default and is what the 2D elastic block runs with):
    int nodal_diag = 0;            ///< SetNodalDiag: diagonal of the nodal strength matrix
    int interp_vec_variant = 0;    ///< SetInterpVecVariant: 1, 2 (GM), 3 (LN); needs nodal
    int interp_vec_q_max = 0;      ///< SetInterpVecQMax: entries per row of the added Q
    int smooth_interp_vectors = 0; ///< SetSmoothInterpVectors: 1 smooths the vectors
    int interp_refine = 0;         ///< SetInterpRefine: steps of interpolation refinement
    void validate() const;
};

/// The settings for 3D linear elasticity (interleaved x, y, z per vertex): num_functions 3,
/// nodal coarsening (norm 4, nodal_diag 1), interpolation vectors (the rotational rigid-body
/// modes; GM variant 2, Q truncated to 4 entries per row, smoothed once, one refinement step),
/// strong threshold 0.5 (hypre's value for 3D), one level of aggressive coarsening (without it
/// the interpolation vectors raise the memory of the AMG hierarchy about threefold), HMIS,
/// extended+i interpolation truncated to 4, l1-symmetric hybrid Gauss-Seidel.
inline BoomerAMGParams boomeramg_elasticity3d() {
    BoomerAMGParams p;
    p.num_functions = 3;
    p.nodal = 4;
    p.nodal_diag = 1;
    p.strong_threshold = 0.5;
    p.interp_vec_variant = 2;
    p.interp_vec_q_max = 4;
    p.smooth_interp_vectors = 1;
    p.interp_refine = 1;
    p.agg_num_levels = 1;
    return p;
}

/// Threads hypre's kernels run on: OpenMP's maximum when hypre was built with OpenMP, else 1.
int hypre_threads();

std::ostream& operator<<(std::ostream& os, const BoomerAMGParams& p);

/// True when built with hypre.
bool have_hypre();

/// Calls MPI_Init once (single process) if MPI is not initialised yet, and HYPRE_Init; registers
/// their finalisation at exit. Throws mlc::InvalidInput when built without hypre.
void ensure_hypre_initialized();

/// One BoomerAMG V-cycle as a preconditioner (z = AMG(r) from z = 0). For symmetric positive
/// definite matrices with interleaved 2-component vertices (the elastic block). `setup` copies A
/// into hypre; `apply` copies r in and z out (no allocation). Not thread-safe.
class BoomerAMGPreconditioner final : public Preconditioner {
public:
    explicit BoomerAMGPreconditioner(BoomerAMGParams params = {});
    ~BoomerAMGPreconditioner() override;
    BoomerAMGPreconditioner(const BoomerAMGPreconditioner&) = delete;
    BoomerAMGPreconditioner& operator=(const BoomerAMGPreconditioner&) = delete;
    void setup(const SparseMatrix& A) override;
    void apply(const Vector& r, Vector& z) const override;
    /// "amg(fn=2,theta=0.25)".
    std::string name() const override;
    /// Function (displacement component) of every unknown, for systems AMG when the components
    /// are not strictly interleaved (a vertex with one prescribed component); values in
    /// [0, num_functions). Empty (default): unknown i has function i % num_functions.
    void set_dof_func(std::vector<int> dof_func) { dof_func_ = std::move(dof_func); }

    struct Impl;

private:
    BoomerAMGParams params_;
    std::vector<int> dof_func_;
    std::unique_ptr<Impl> impl_;
};

/// hypre's PCG preconditioned by BoomerAMG on A x = b to ||b - A x|| <= rel_tol ||b|| (two-norm).
/// Returns iterations, residuals and the setup (AMG hierarchy) and solve seconds separately.
/// x holds the initial guess on entry (resized to zero if empty).
/// `dof_func`: as BoomerAMGPreconditioner::set_dof_func (empty: interleaved).
/// `interp_vectors`: the near-null-space vectors (rigid-body modes, A.rows() entries each) for
/// HYPRE_BoomerAMGSetInterpVectors; needs params.interp_vec_variant > 0 and params.nodal > 0.
SolveResult boomeramg_pcg(const SparseMatrix& A, const Vector& b, Vector& x, double rel_tol,
                          int max_iter, const BoomerAMGParams& params = {},
                          const std::vector<int>& dof_func = {},
                          const std::vector<Vector>& interp_vectors = {});

/// Collective (every process of A's communicator): hypre's ParCSR PCG preconditioned by BoomerAMG
/// on the distributed A x = b to ||b - A x|| <= rel_tol ||b|| (two-norm, over all processes),
/// with the settings of boomeramg_pcg. b and x hold this process's owned entries (A.n_rows());
/// x holds the initial guess on entry (resized to zero if its size differs). `dof_func`: the
/// function of every owned unknown (empty: interleaved). A must be square and built from
/// DistributedRows (see ParMatrix::hypre_handle); throws InvalidInput on every process otherwise.
/// The residuals and relative residual are the true ones, computed here with global reductions;
/// setup (AMG hierarchy) and solve seconds are this process's.
SolveResult boomeramg_pcg_par(const ParMatrix& A, const Vector& b, Vector& x, double rel_tol,
                              int max_iter, const BoomerAMGParams& params = {},
                              const std::vector<int>& dof_func = {});

} // namespace mlc::solvers

// SPDX-License-Identifier: MIT
/// @file hypre MGR (multigrid reduction) on the whole contact Newton system, as a Preconditioner.
///
/// One reduction level: F = the displacement unknowns, C = the contact multipliers, preceded by
/// one global ILU(0) sweep (hypre's ILU as MGR's global smoother). The
/// multiplier rows of stuck nodes have zero diagonal blocks, so the multipliers cannot be the F
/// points (relaxed first, then eliminated) the way GEOS keeps displacements as C in its fracture
/// recipes; here the displacements are relaxed (one BoomerAMG V-cycle on A_FF, systems AMG over
/// the two displacement components) and the multipliers form the reduced (Schur complement)
/// system S = A_CC - A_CF D_FF^{-1} A_FC, solved by one BoomerAMG V-cycle. Compiled only with
/// MLC_WITH_HYPRE; without it the constructor throws mlc::InvalidInput.
#pragma once

#include "core/linear_operator.hpp"
#include "solvers/hypre/boomeramg.hpp"

#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace mlc::solvers {

/// MGR settings (names as in hypre's HYPRE_MGRSet* functions; see the README, "hypre MGR").
struct MGRParams {
    /// F-relaxation: 2 (default) one BoomerAMG V-cycle on A_FF (f_amg, SetLevelFRelaxType 2 with
    /// SetFSolver), or a hypre relaxation type for `f_sweeps` single-level sweeps
    /// (SetLevelFRelaxType: 0 Jacobi, 3 .. 8 Gauss–Seidel variants, 18 l1-Jacobi).
    int f_relax = 2;
    int f_sweeps = 1;      ///< sweeps of single-level F-relaxation (f_relax != 2)
    int interp_type = 2;   ///< SetInterpType: 2 diagonal (Jacobi) scaling of -A_FF^{-1} A_FC
    int restrict_type = 0; ///< SetRestrictType: 0 injection
    int coarse_method = 0; ///< SetCoarseGridMethod: 0 Galerkin R A P
    /// SetMaxGlobalSmoothIters: sweeps of a smoother on the whole system before the
    /// F-relaxation (default 1; 0: none). On the square it halves the iterations (level 3: 27
    /// -> 11 per Newton system; level 4: 28 -> 13).
    int global_smooth_iters = 1;
    /// SetGlobalSmoothType: 16 (default) hypre's ILU(0) of the whole system (with the
    /// multipliers next to their vertex, ILU's pivots are nonzero); 0 block Jacobi fails (the
    /// stuck multipliers' zero blocks).
    int global_smooth_type = 16;
    /// BoomerAMG on A_FF: systems AMG with the two displacement components (BoomerAMGParams'
    /// elasticity defaults).
    BoomerAMGParams f_amg{};
    /// BoomerAMG on the reduced multiplier system: one function, the same defaults otherwise.
    BoomerAMGParams c_amg{.num_functions = 1};
    void validate() const;
};

std::ostream& operator<<(std::ostream& os, const MGRParams& p);

/// Function of every unknown for MGR: 0 / 1 / 2 the x / y / z displacement component (z on a
/// 3D level), 3 a contact multiplier.
inline constexpr int kMultiplierFunction = 3;

/// One MGR cycle (max_iter 1, tolerance 0) as a preconditioner: z = MGR(r) from z = 0.
/// `setup` copies A into hypre and builds the reduction (A_FF's AMG, the reduced system and its
/// AMG); `update_values` does the same (the statuses changed the values). Not thread-safe.
class MGRPreconditioner final : public Preconditioner {
public:
    /// `unknown_function[i]` in {0, 1, 2, kMultiplierFunction}: the C/F marker (C = multipliers)
    /// and the function of each F row for the AMG of A_FF. Throws mlc::InvalidInput when there is
    /// no multiplier or no displacement, or when built without hypre.
    MGRPreconditioner(std::vector<int> unknown_function, MGRParams params = {});
    ~MGRPreconditioner() override;
    MGRPreconditioner(const MGRPreconditioner&) = delete;
    MGRPreconditioner& operator=(const MGRPreconditioner&) = delete;
    void setup(const SparseMatrix& A) override;
    void apply(const Vector& r, Vector& z) const override;
    /// "mgr(F=u:amg,C=lambda:amg)".
    std::string name() const override;
    /// Seconds of the last setup spent copying the matrix into hypre (part of the setup).
    double copy_seconds() const { return copy_seconds_; }
    /// MGR as hypre's own users run it: hypre's FlexGMRES(restart) preconditioned by this MGR
    /// (set up already) on the matrix of the last setup, to ||b - A x|| <= rel_tol ||b||, from
    /// x (resized to zero if empty). Returns iterations, the solve seconds and the true residual
    /// (recomputed here with `A`, which must be the matrix of the last setup).
    SolveResult solve_fgmres(const SparseMatrix& A, const Vector& b, Vector& x, double rel_tol,
                             int max_iter, int restart) const;

    struct Impl;

private:
    std::vector<int> function_;
    MGRParams params_;
    std::unique_ptr<Impl> impl_;
    double copy_seconds_ = 0.0;
};

} // namespace mlc::solvers

// SPDX-License-Identifier: MIT
/// @file Newton systems solved by a preconditioned Krylov method on the assembled Jacobian
/// (the papers' CGS/BiCG with DIAG, ILU(k), CF, SORCF and EBE preconditioners), and the level
/// data the level-aware preconditioners are built from.
#pragma once

#include "levels/newton_system.hpp"
#include "smoothers/ebe.hpp"
#include "solvers/coarse_fine.hpp"

#include <memory>
#include <string_view>
#include <vector>

namespace mlc::levels {

/// Assembles J(M) in place and solves with `spec.krylov` preconditioned by `spec.pc`.
///
/// Algebraic preconditioners ("none", "diag", "ilu:K", "sor", "ssor", "lu") come from
/// solvers::make_preconditioner. The level-aware ones are built here:
///
/// - "cf[:inner=lu|cgs,tol=T,maxit=N,scale=S,coarse=C]": coarse/fine (solvers/coarse_fine.hpp).
///   inner: A_ff by sparse LU (default) or by unpreconditioned CGS to relative tolerance T
///   (default 1e-2, at most N iterations, default 1000; the 1995 paper's way, a varying
///   preconditioner). scale: how multiplier entries pass between the levels, with q the factor
///   of Q at a coarse contact vertex (1/2 for the paper's rule): "q" (default: z_c = q z_H,
///   r_H = r_c; the Schur complement has A_H's multiplier columns times 1/q), "none" (no factor),
///   "qt" (z_c = q z_H, r_H = q r_c, as R = Q^T would), "qinv" (z_c = q z_H, r_H = r_c / q).
///   On the square (levels 1 -> 2 and 2 -> 3, mu = 0.1, 0.3, 1) all four give the same CGS
///   iteration count (the multipliers are a few dozen of the coarse unknowns; the mismatch
///   between A_H and the Schur complement on the displacements dominates); "q" is kept as the
///   consistent choice. coarse: "lu" (default: the coarse Jacobian at the converged coarse
///   statuses, assembled and factored by sparse LU here, refactored only when those statuses
///   change) or "solver" (the context's coarse Newton-system solver, called with the coarse
///   statuses at every application: the condensed "schur" solver redoes its reduced contact
///   system each call, and in the coarse-to-fine driver the level below may itself be a Krylov
///   solver, which makes CF recursive but 2-3 times slower on the square than "lu").
/// - "sorcf[:omega=W,block=0|1,scale=S,coarse=C]": SORCF (solvers/sorcf.hpp), A_ff^{-1}
///   replaced by the SSOR with the generalized diagonal D*, scalar (block=0, default; the
///   paper's eqs. 26-33) or 2x2 vertex / 4x4 vertex+multiplier blocks (block=1); 0 < W < 2
///   (default 1).
/// - "ebe[:variant=c1|c4|c5,unit=multipliers|contact]": element-by-element (smoothers/ebe.hpp)
///   on the level's elastic element matrices and the contact element tangents of the current
///   statuses (default c1); unit: where W~ = 1 (default multipliers; "contact", formulation.md's
///   reading, diverges with c1 on the square).
///
/// - "mg[:pre=N,post=N,omega=W,coarse=C]": one V-cycle over all levels (solvers/mg.hpp): N forward
/// /
///   backward vertex-block Gauss–Seidel sweeps before / after the coarse correction (defaults
///   1, 1; relaxation W, default 1), restriction R = T^T and prolongation T of the context's
///   transfer, and as coarse correction the level below's own cycle, set up on its Jacobian at
///   the converged coarse statuses through `NewtonSystemSolver::preconditioner_for` (so the
///   cycle recurses down to level 1), or, when the level below has no cycle (level 0, solved by
///   "schur"), a sparse LU of its Jacobian at those statuses. A fixed linear operator per
///   Newton system: CGS, BiCGStab and GMRES apply. Its mat-vecs are MatrixOperator with
///   MatVec::unrolled. coarse: "rediscretize" (default, the above) or "galerkin": the coarse
///   operators are R J T of this Newton system's J, then R A T level by level down to level 0
///   (factored by sparse LU), recomputed for every Newton system; they carry the fine statuses down
///   through the products (it needs the context chain, CoarseContext::below, down to level 0).
///
/// "cf", "sorcf" and "mg" need `context` with the level below (context->available()); without
/// it they throw mlc::InvalidInput ("cf needs the level below: use with --levels >= 1 and the
/// coarse-to-fine solve"). The context is borrowed and read at every solve: the driver may fill
/// or update coarse_M between load steps (it must hold the coarse level's statuses, converged
/// for the current load step, when `solve` is called). The context and its pointees must
/// outlive the returned object.
///
/// Assembly and preconditioner setup are skipped when `solve` is called with the same statuses
/// as the previous call (as when this solver is the coarse solve of the level above, called
/// once per application of that level's CF).
///
/// The returned SolveResult carries the Krylov iterations; a Krylov solve that does not
/// converge is reported (converged false), not thrown.
std::unique_ptr<NewtonSystemSolver> make_krylov_system_solver(const Level& level,
                                                              const LinearSolverSpec& spec,
                                                              const CoarseContext* context);

/// The elastic element matrices of a level for EBE: one per triangle, the 6x6 stiffness
/// fem::element_stiffness restricted to the free displacement unknowns (is_contact false).
/// Triangles whose six components are all prescribed are skipped.
std::vector<smoothers::ElementMatrix> elastic_element_matrices(const Level& level);

/// The contact element tangent of element e of `level` for the status matrix M (formulation.md
/// sect. 2, contact::for_each_tangent_entry) as a dense element matrix on its free unknowns
/// (is_contact true). `out` is overwritten; its dofs are reused when already set for e.
void contact_element_matrix(const Level& level, size_t e, const Eigen::Matrix2d& M,
                            smoothers::ElementMatrix& out);

/// How multiplier entries pass between the levels in CF (see make_krylov_system_solver).
enum class MultiplierScale { q, none, qt, qinv };

/// Parses "q", "none", "qt" or "qinv"; anything else throws mlc::InvalidInput.
MultiplierScale parse_multiplier_scale(std::string_view name);

/// The coarse/fine split of `fine` for CF/SORCF from the transfer's coarse_set, fine_set and
/// coarse_dof, with the multiplier factors of `scale` (q read from transfer.T at each coarse
/// contact multiplier; 1/2 when T is empty) and the vertex blocks of the fine set.
solvers::CoarseFineSplit coarse_fine_split(const Level& fine, const Level& coarse,
                                           const transfer::LevelTransfer& transfer,
                                           MultiplierScale scale = MultiplierScale::q);

} // namespace mlc::levels

// SPDX-License-Identifier: MIT
/// @file Newton systems solved by a preconditioned Krylov method on the assembled Jacobian
/// (the papers' CGS/BiCG with DIAG, ILU(k), CF, SORCF and EBE preconditioners), and the level
/// data the level-aware preconditioners are built from.
#pragma once

#include "levels/newton_system.hpp"
#include "smoothers/ebe.hpp"
#include "solvers/aggregation.hpp"
#include "solvers/coarse_fine.hpp"

#include <memory>
#include <string_view>
#include <vector>

namespace mlc::levels {

/// Assembles J(M) in place and solves with `spec.krylov` preconditioned by `spec.pc`, a spec of
/// the preconditioner registry (solvers/factory.hpp: `mlcontact run --help` lists it). The
/// level-aware entries get this level's data and the level below's (`below`) as
/// solvers::LevelData:
///
/// - "cf[:scale=S,coarse=C,inner=lu|cgs,tol=T,maxit=N]": coarse/fine (solvers/coarse_fine.hpp).
///   inner: A_ff by sparse LU (default) or by unpreconditioned CGS to relative tolerance T
///   (default 1e-2, at most N iterations, default 1000; the 1995 paper's way, a varying
///   preconditioner). scale: how multiplier entries pass between the levels
///   (solvers::MultiplierScale; "q" default). On the square (levels 1 -> 2 and 2 -> 3, mu = 0.1,
///   0.3, 1) all four scales give the same CGS iteration count (the multipliers are a few dozen
///   of the coarse unknowns; the mismatch between A_H and the Schur complement on the
///   displacements dominates); "q" is kept as the consistent choice. coarse: "lu" (default:
///   the coarse Jacobian at the converged coarse statuses, assembled and factored by sparse LU
///   here, refactored only when those statuses change) or "solver" (the level below's own
///   Newton-system solver, called with the coarse statuses at every application: the condensed
///   "schur" solver redoes its reduced contact system each call, and in the coarse-to-fine
///   driver the level below may itself be a Krylov solver, which makes CF recursive but 2-3
///   times slower on the square than "lu").
/// - "sorcf[:scale=S,coarse=C,omega=W,block=0|1]": SORCF (solvers/sorcf.hpp), A_ff^{-1} replaced
///   by the SSOR with the generalized diagonal D*, scalar (block=0, default; the paper's eqs.
///   26-33) or 2x2 vertex / 4x4 vertex+multiplier blocks (block=1); 0 < W < 2 (default 1).
/// - "ebe[:variant=c1|c4|c5,unit=multipliers|contact]": element-by-element (smoothers/ebe.hpp)
///   on the level's elastic element matrices and the contact element tangents of the current
///   statuses (default c1); unit: where W~ = 1 (default multipliers; "contact", formulation.md's
///   reading, diverges with c1 on the square).
/// - "mg[:pre=N,post=N,omega=W,coarse=C]": solvers::Multigrid, one V-cycle over all levels: N
///   forward / backward vertex-block Gauss–Seidel sweeps before / after the coarse correction
///   (defaults 1, 1; relaxation W, default 1), restriction R = T^T and prolongation T of the
///   level transfers. coarse: "rediscretize" (default): each level's operator is its own
///   Jacobian at its converged statuses; the multigrid of this level is built on the level
///   below's (Multigrid::above), whose solver refreshes that level (`prepare`) when the coarse
///   statuses arrive, down to level 1; on level 0 (solved by "schur") the Jacobian is assembled
///   here and factored by sparse LU. "galerkin": the coarse operators are R J T of this Newton
///   system's J, then R A T level by level down to level 0 (factored by sparse LU), recomputed
///   for every Newton system (it needs every level below in the solve). A fixed linear operator
///   per Newton system: CGS, BiCGStab and GMRES apply. Its mat-vecs are MatrixOperator with
///   MatVec::unrolled.
///
/// "cf", "sorcf" and "mg" need `below` (below->available()); without it they throw
/// mlc::InvalidInput ("cf needs the level below: use with --levels >= 1 and the coarse-to-fine
/// solve"). The coarse statuses reach the solver by `set_coarse_statuses`, called by the driver
/// after every load step of the level below and before this level's solves; a solve before
/// that throws mlc::InvalidInput. `below` and its pointees must outlive the returned object.
///
/// Assembly and preconditioner setup are skipped when `solve` or `prepare` is called with the
/// same statuses as the previous call (as when this solver's level serves the multigrid of the
/// level above).
///
/// The returned SolveResult carries the Krylov iterations; a Krylov solve that does not
/// converge is reported (converged false), not thrown.
std::unique_ptr<NewtonSystemSolver> make_krylov_system_solver(const Level& level,
                                                              const LinearSolverSpec& spec,
                                                              const LevelBelow* below);

/// The algebraic hierarchy's view of a level (solvers/aggregation.hpp): its elastic operator K
/// (borrowed: `level` must outlive the result), the vertex of each unknown and its kind (x, y,
/// and the contact multipliers lambda_t, lambda_n). mg builds its aggregation hierarchy from it
/// on a level without the level below.
solvers::AggregationInput aggregation_input(const Level& level);

/// The elastic element matrices of a level for EBE: one per triangle, the 6x6 stiffness
/// fem::element_stiffness restricted to the free displacement unknowns (is_contact false).
/// Triangles whose six components are all prescribed are skipped.
std::vector<smoothers::ElementMatrix> elastic_element_matrices(const Level& level);

/// The element matrices restricted to the unknowns [0, n) (EBE on one process's diagonal block,
/// docs/parallel.md#parallel-preconditioners): each element keeps the rows and columns of its
/// unknowns below n (a principal submatrix, in the element's order), and an element with none of
/// them is dropped. The restricted elements of all the elements around the unknowns [0, n) sum to
/// the block of those unknowns of the matrix the whole elements sum to.
void restrict_elements(std::vector<smoothers::ElementMatrix>& elements, Index n);

/// The contact element tangent of element e of `level` for the status matrix M (formulation.md
/// sect. 2, contact::for_each_tangent_entry) as a dense element matrix on its free unknowns
/// (is_contact true). `out` is overwritten; its dofs are reused when already set for e.
void contact_element_matrix(const Level& level, size_t e, const Eigen::Matrix2d& M,
                            smoothers::ElementMatrix& out);

/// The coarse/fine split of `fine` for CF/SORCF from the transfer's coarse_set, fine_set and
/// coarse_dof, with the multiplier factors of `scale` (q read from transfer.T at each coarse
/// contact multiplier; 1/2 when T is empty) and the vertex blocks of the fine set.
solvers::CoarseFineSplit
coarse_fine_split(const Level& fine, const Level& coarse, const transfer::LevelTransfer& transfer,
                  solvers::MultiplierScale scale = solvers::MultiplierScale::q);

/// The level below of a 3D level, for CF and SORCF. Its pointees must outlive the solvers built
/// with it; the coarse statuses reach the solver by NewtonSystemSolver3::set_coarse_statuses.
struct LevelBelow3 {
    const Level3* coarse = nullptr;         ///< the level below
    const SparseMatrix* P_vertex = nullptr; ///< its vertex prolongation to this level
    const SparseMatrix* T_full = nullptr; ///< all its unknowns to this level's (full_prolongation3)
    NewtonSystemSolver3* solver = nullptr; ///< its own exact solver (coarse=solver, fallback)
};

/// A 3D level's Newton systems by `spec.krylov` preconditioned by `spec.pc`, on the assembled
/// Jacobian (its pattern fixed per level): the preconditioners of the matrix alone (diag, ilu,
/// sor, ssor, lu), "cf" and "sorcf" with the split of coarse_fine_split3 and the level below's
/// Jacobian at its converged statuses (coarse=lu, by sparse LU; singular: the level below's own
/// exact solver) or its solver (coarse=solver), and hypre's "mgr" (systems BoomerAMG on the
/// three displacement components). What has no 3D form (PcSpec::dimension_reason: ebe, mg's
/// lattice sweep) throws InvalidInput; mg on a 3D level is the Galerkin multigrid of
/// levels::solve (Method3::mg). "cf" and "sorcf" need `below` (level >= 1). A Krylov solve that
/// does not converge is reported (converged false), not thrown.
std::unique_ptr<NewtonSystemSolver3> make_krylov_system_solver(const Level3& level,
                                                               const LinearSolverSpec& spec,
                                                               const LevelBelow3* below);

/// The coarse/fine split of a 3D level for CF/SORCF: the coarse set is every displacement of a
/// vertex of the level below (a row of P_vertex with the single entry 1), mapped to that
/// vertex's component, and every multiplier of such a vertex, mapped to the coarse multiplier of
/// that vertex its row of T_full weighs most (q, the weight: the mass ratio of the surface Q, the
/// frames of one vertex on two levels being nearly equal); the multiplier factors follow `scale`
/// as in 2D. The fine set is the rest, in one diagonal block per vertex.
solvers::CoarseFineSplit coarse_fine_split3(const Level3& fine, const Level3& coarse,
                                            const SparseMatrix& P_vertex,
                                            const SparseMatrix& T_full,
                                            solvers::MultiplierScale scale);

} // namespace mlc::levels

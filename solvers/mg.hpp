// SPDX-License-Identifier: MIT
/// @file Geometric multigrid over the level hierarchy: `Multigrid`, a Preconditioner that owns
/// its levels (operator, transfer, smoother, work vectors) and the coarse solve, smoothed by
/// vertex-block Gauss–Seidel (smoothers::BlockSOR with threaded parts and the unrolled kernel),
/// which copes with the zero diagonals of the contact multiplier rows: one block per vertex, its
/// 2 displacements and, at a contact vertex, its 1 or 2 multipliers, so the zero multiplier
/// diagonals of stick and slip rows sit inside a nonsingular 3x3/4x4 block.
///
/// One V-cycle on level k, A_k z = r (z = 0 on entry), is
///
///     pre-smooth:  z <- z + S_fwd (r - A_k z)              (nu1 forward block Gauss–Seidel sweeps)
///     coarse:      z <- z + T_k B_{k-1} R_k (r - A_k z)    (B_{k-1}: the cycle of level k-1)
///     post-smooth: z <- z + S_bwd (r - A_k z)              (nu2 backward sweeps)
///
/// (the cycle of solvers/vcycle.hpp, shared with the distributed multigrid) and on level 0
/// z = A_0^{-1} r by the coarse solver (sparse LU unless replaced). T_k is the
/// prolongation from level k-1 (P on displacements, Q on multipliers: transfer::LevelTransfer::T)
/// and R_k = T_k^T. Every step is linear in r and nothing depends on the iteration, so the cycle
/// is a fixed linear operator: CGS, BiCGStab and (non-flexible) GMRES all apply. With forward
/// pre- and backward post-sweeps (nu1 = nu2) and symmetric operators, the cycle is symmetric
/// too, so it also preconditions CG (`solvers::cg`) on the elastic block.
///
/// Two ways of filling the coarse operators:
/// - rediscretized: each level's operator is given by `set_operator` (the contact solve: each
///   level's own Jacobian at its converged statuses; the elastic block: each level's stiffness);
/// - Galerkin: `setup(A)` computes A_{k-1} = R_k A_k T_k from the finest down to level 0.
///
/// The coarse-to-fine solve runs one multigrid per level; `Multigrid::above` builds the one of
/// level l on the levels of level l-1's (shared, not copied: their operators, smoothers and
/// coarse solve), so each level is set up once per change of its operator.
#pragma once

#include "core/linear_operator.hpp"
#include "smoothers/block_sor.hpp"
#include "smoothers/lattice_gs.hpp"
#include "solvers/vcycle.hpp"

#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace mlc::solvers {

/// Parameters of `Multigrid` (its smoothing).
struct MultigridParams {
    int pre_sweeps = 1;  ///< forward smoothing sweeps before the coarse correction, >= 0
    int post_sweeps = 1; ///< backward sweeps after it, >= 0 (pre + post >= 1)
    double omega = 1.0;  ///< relaxation of the block Gauss–Seidel sweeps, in (0, 2)
    /// Precision of the cycle's stored data on the levels above the coarsest: the smoother's
    /// matrix values and block inverses (smoothers::BlockSORParams::precision) and the transfers
    /// T and R (float copies of their values, made at construction). The vectors of the cycle,
    /// the coarsest level's LU and the Krylov method stay double. Default float64; float32 is
    /// `mg:precision=single`.
    Precision precision = Precision::float64;
    /// The smoother of the levels above the coarsest. block (default): smoothers::BlockSOR.
    /// lattice (`mg:smoother=lattice`): smoothers::LatticeGS on every level whose
    /// MultigridLevelData gives lattice rows with at least 16 subdivisions per macro edge
    /// (BlockSOR on the others); double precision only.
    enum class Smoother { block, lattice };
    Smoother smoother = Smoother::block;
    /// Cycles of the level below per visit of a level: 1, the V-cycle (default); 2, the W-cycle
    /// (solvers/vcycle.hpp), the default of the 3D elastic multigrid (levels/elastic3d_levels.hpp).
    int cycles = 1;
    /// Throws mlc::InvalidInput naming the first field out of range.
    void validate() const;
};

/// The cycle of `p` as "V(1,1)" or "W(2,2)" (pre- and post-sweeps).
std::string cycle_text(const MultigridParams& p);

/// Prints every field of `p` on one line.
std::ostream& operator<<(std::ostream& os, const MultigridParams& p);

/// Plain data of one multigrid level: the transfer from the level below and the smoother blocks.
struct MultigridLevelData {
    /// Prolongation from the level below (this level's rows x the level below's), borrowed (it
    /// must outlive the Multigrid); null on the coarsest level.
    const SparseMatrix* T = nullptr;
    /// Restriction to the level below (usually T^T), borrowed; null on the coarsest level.
    const SparseMatrix* R = nullptr;
    /// Smoother blocks (smoothers::BlockSORParams::block_starts; empty: blocks of 2 rows).
    /// Unused on the coarsest level.
    std::vector<Index> block_starts;
    /// When set, the level keeps T and R alive (an algebraic hierarchy built for this multigrid
    /// alone, solvers/aggregation.hpp); T and R then point to them.
    std::shared_ptr<const SparseMatrix> T_storage, R_storage;
    /// The rows of the level's macro-triangle lattice (smoothers::LatticeGS), or null.
    std::shared_ptr<const smoothers::LatticeRows> lattice;
};

/// Lattices of at least this many subdivisions per macro edge get mg:smoother=lattice's
/// smoother (level 4 of a hierarchy refined from level 0 and above): below it too few of the
/// interior points are deep for the renumbering to pay.
inline constexpr int kMinLatticeSubdivisions = 16;

/// How the coarse operators are obtained.
enum class CoarseOperators {
    rediscretized, ///< given level by level (`set_operator`)
    galerkin       ///< R A T from the finest down, at every `setup`/`update_values`
};

/// One row of `MultigridReport`.
struct MultigridLevelReport {
    int level = 0;      ///< 0 = coarsest
    Index rows = 0;     ///< unknowns of the level's operator
    Index nonzeros = 0; ///< stored nonzeros of the level's operator
    std::string solve;  ///< "smoother" or the coarse solver's name
};

/// What a multigrid is: its levels and their sizes, complexities, smoother and coarse solve.
struct MultigridReport {
    std::vector<MultigridLevelReport> levels; ///< coarsest first
    /// Sum of the levels' nonzeros over the finest level's (the cost of a cycle in mat-vecs).
    double operator_complexity = 0.0;
    /// Sum of the levels' rows over the finest level's (the memory of the work vectors).
    double grid_complexity = 0.0;
    std::string cycle;            ///< e.g. "V(1,1), omega = 1"
    std::string smoother;         ///< e.g. "vertex-block Gauss-Seidel (2 threaded parts)"
    std::string coarse_solver;    ///< e.g. "sparse LU"
    std::string coarse_operators; ///< "rediscretized" or "Galerkin"
};

/// Prints `r` as a table: one row per level (finest first), then the complexities, cycle,
/// smoother and coarse solver.
std::ostream& operator<<(std::ostream& os, const MultigridReport& r);

/// The multigrid preconditioner (see the file comment). Not thread-safe (mutable work vectors);
/// `apply` does not allocate when the coarse solver does not.
class Multigrid final : public Preconditioner, private VCycle {
public:
    /// A multigrid on `levels` (coarsest first, at least two; T and R of every level above the
    /// coarsest, with consistent sizes). The coarse solve is a sparse LU of the coarsest
    /// operator. Validates `params`.
    Multigrid(std::vector<MultigridLevelData> levels, MultigridParams params,
              CoarseOperators coarse_operators = CoarseOperators::rediscretized);

    /// The multigrid of the level above `below`'s finest: `top` is the new finest level, the
    /// levels below are `below`'s own (shared; `below` may be destroyed first). Rediscretized.
    static std::unique_ptr<Multigrid> above(const Multigrid& below, MultigridLevelData top,
                                            MultigridParams params);

    /// How the coarse operators are filled.
    CoarseOperators coarse_operators() const { return coarse_operators_; }

    /// The finest level's operator as last set up (borrowed), or null before `setup`.
    const SparseMatrix* finest_operator() const;

    /// The finest level's lattice smoother (mg:smoother=lattice on a lattice level), or null:
    /// its `multiply` is the finest operator's product by the macros' stencils, after setup.
    const smoothers::LatticeGS* finest_lattice() const;
    /// The Krylov product: the finest level's lattice stencils when it sweeps by lattices, else
    /// the unrolled CSR product of A (MatVec::unrolled).
    std::unique_ptr<LinearOperator> krylov_operator(const SparseMatrix& A) const override;

    /// Number of levels (the finest is n_levels() - 1).
    int n_levels() const { return static_cast<int>(levels_.size()); }

    /// The operator of level k < finest (rediscretized): borrowed (it must stay valid until the
    /// next call for k). Sets up that level's smoother, or factors it on level 0 (a singular
    /// matrix throws mlc::SolverBreakdown; `set_coarse_solver` then installs another solve).
    /// The first call for a level does the full setup, later ones reuse its structure.
    void set_operator(int k, const SparseMatrix& A);

    /// Replaces the coarse solve of level 0, already set up (for instance an exact solver that
    /// copes with a singular coarse operator). Shared with the multigrids of the levels above.
    void set_coarse_solver(std::unique_ptr<Preconditioner> coarse);

    /// The finest level's operator (borrowed until the next setup). With Galerkin coarse
    /// operators, also computes and sets up every coarser level.
    void setup(const SparseMatrix& A) override;
    /// Same as setup, reusing the structure of every level. With Galerkin coarse operators and
    /// R = T^T on every level, when at most a tenth of A's stored entries changed since the last
    /// products (a Newton Jacobian whose contact rows changed), each coarse operator is
    /// refreshed by adding R_k (A_k - A_k,last) T_k instead of forming R A T again (equal up to
    /// round-off).
    void update_values(const SparseMatrix& A) override;
    /// One V-cycle from the finest level.
    void apply(const Vector& r, Vector& z) const override;
    /// "mg(pre=1,post=1,omega=1)" (the finest level's parameters), with ",precision=single"
    /// appended for float32 data.
    std::string name() const override;

    /// Levels, sizes, complexities, smoother and coarse solve (operators must be set).
    MultigridReport report() const;

    /// How many update_values calls refreshed the Galerkin operators incrementally.
    int galerkin_refreshes() const { return galerkin_refreshes_; }

private:
    struct Level;
    Multigrid() = default;
    CycleLevel cycle_level(int k) const override;
    void coarse_solve(const Vector& r, Vector& z) const override;
    void set_galerkin_operators(const SparseMatrix& A);
    bool refresh_galerkin_operators(const SparseMatrix& A);

    std::vector<std::shared_ptr<Level>> levels_; ///< coarsest first
    CoarseOperators coarse_operators_ = CoarseOperators::rediscretized;
    /// Galerkin: the finest operator's values at the last products (update_values then adds
    /// R (A - A_last) T level by level when few entries changed), and whether every level's R
    /// is T^T (the refresh reads T alone).
    std::vector<double> galerkin_values_;
    bool galerkin_symmetric_ = false;
    int galerkin_refreshes_ = 0;
};

/// The vertex blocks of a dof numbering in which each vertex's unknowns are contiguous:
/// `vertex_of_dof[i]` is the owner of unknown i; returns the first unknown of each run.
std::vector<Index> vertex_block_starts(const std::vector<int>& vertex_of_dof);

} // namespace mlc::solvers

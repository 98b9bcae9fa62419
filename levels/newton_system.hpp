// SPDX-License-Identifier: MIT
/// @file Solvers for the Newton system J(M) dx = b of one level, where J(M) is the generalized
/// Jacobian for the per-element status matrices M (formulation.md §2).
#pragma once

#include "core/linear_operator.hpp"
#include "levels/level.hpp"
#include "transfer/transfer.hpp"

#include <Eigen/Dense>
#include <memory>
#include <string>
#include <vector>

namespace mlc::levels {

/// Assembles J = K + sum of contact tangents into a CSR matrix whose pattern is built once, so
/// values are refreshed in place and a direct solver's symbolic analysis can be reused.
class JacobianAssembler {
public:
    /// `level` must outlive this object.
    explicit JacobianAssembler(const Level& level);
    /// Fills the values for the given per-element M matrices.
    void assemble(const std::vector<Eigen::Matrix2d>& M);
    const SparseMatrix& matrix() const { return J_; }

private:
    const Level& level_;
    SparseMatrix J_;
    std::vector<int> kpos_; ///< position in J's values of each K value
    std::vector<int> cpos_; ///< position of each contact tangent entry, in visiting order
};

/// Solves J x = b for an assembled matrix.
class LinearSolver {
public:
    virtual ~LinearSolver() = default;
    /// Solves J x = b (x holds the initial guess on entry); returns iterations, residuals, times.
    virtual SolveResult solve(const SparseMatrix& J, const Vector& b, Vector& x) = 0;
    virtual std::string name() const = 0;
};

/// solvers::SparseLUPreconditioner (Eigen SparseLU) on the assembled J: analyzes the pattern
/// once and refactors numerically afterwards while the pattern is unchanged (it is fixed per
/// level). A singular J throws mlc::SolverBreakdown.
std::unique_ptr<LinearSolver> make_sparse_lu_solver();

/// Strategy for one Newton linear system J(M) dx = b on a level.
class NewtonSystemSolver {
public:
    virtual ~NewtonSystemSolver() = default;
    /// dx = J(M)^{-1} b. dx is resized; its content on entry is the initial guess of an
    /// iterative method (zero is fine).
    virtual SolveResult solve(const std::vector<Eigen::Matrix2d>& M, const Vector& b,
                              Vector& dx) = 0;
    /// "lu", "schur", or the Krylov/preconditioner pair.
    virtual std::string name() const = 0;
    /// Inexact Newton: the relative tolerance of the following solves is max(eta, the solver's
    /// own rel_tol); 0 restores the solver's own. Direct solvers ignore it (they are exact).
    virtual void set_forcing(double eta) { (void)eta; }
    /// For the multilevel preconditioner of the level above: this solver's preconditioner set
    /// up on J(M) (assembled, and refreshed only when M differs from the last call's), or null
    /// when it has none (direct solvers). Valid until the next `solve` or call of this function.
    virtual const Preconditioner* preconditioner_for(const std::vector<Eigen::Matrix2d>& M) {
        (void)M;
        return nullptr;
    }
};

/// Assembles J(M) (pattern fixed per level) and calls `solver` on it. `level` must outlive it.
std::unique_ptr<NewtonSystemSolver>
make_assembled_system_solver(const Level& level, std::unique_ptr<LinearSolver> solver);

/// Exact solve by condensation on the contact components ("schur").
///
/// With B the map from displacement unknowns to the local contact components (t, n per
/// frictional node, n per frictionless node), K0 = K + B^T diag(r) B is symmetric positive
/// definite whenever the problem with every candidate node stuck is well posed (this is what
/// lets a body held only by contact be solved), and does not depend on the statuses. So K0 is
/// factored once (sparse Cholesky) and S = B K0^{-1} B^T (m x m, m contact components) computed
/// once per level. Because every status matrix M is a projector (M^2 = M), each Newton system
/// J(M) [du; dl] = [b_u; b_l] then reduces exactly to the dense m x m system
///     (S - (I - M) / r) y = w - M b_l,   w = B K0^{-1} b_u,
/// followed by z = w - S y, dl = y + r (z - b_l), du = K0^{-1} (b_u - B^T y).
/// Two sparse triangular solve pairs and one dense LU of size m per Newton step; nothing sparse
/// is refactored when statuses change. Setup: one Cholesky and m solves for S per level.
std::unique_ptr<NewtonSystemSolver> make_schur_system_solver(const Level& level);

/// How each Newton system is solved.
struct LinearSolverSpec {
    /// "schur" (exact, condensed on the contact set; default), "lu" (SparseLU on the assembled
    /// Jacobian) or "krylov" (the `krylov` method with the `pc` preconditioner).
    std::string method = "schur";
    std::string krylov = "cgs"; ///< cgs | bicg | bicgstab | gmres (method "krylov")
    std::string pc = "ilu:0"; ///< preconditioner spec, e.g. "ilu:1", "cf", "sorcf:omega=1.2", "ebe"
    /// Relative tolerance of the linear solve, ||b - J dx|| <= rel_tol ||b||. 1e-10 keeps the
    /// Newton iterates as exact as the papers' (they solve to near round-off).
    double rel_tol = 1e-10;
    int max_iter = 5000; ///< Krylov iterations per Newton step
    int restart = 50;    ///< GMRES restart length
    void validate() const;
};

std::ostream& operator<<(std::ostream& os, const LinearSolverSpec& s);

/// What multilevel preconditioners may use from the level below; all null/empty on level 0.
struct CoarseContext {
    const Level* coarse = nullptr;                     ///< the level below
    const transfer::LevelTransfer* transfer = nullptr; ///< coarse -> this level
    NewtonSystemSolver* coarse_solver = nullptr;       ///< exact solver of the coarse Jacobian
    std::vector<Eigen::Matrix2d> coarse_M;             ///< converged coarse statuses (per element)
    /// The level below's own context (null on level 0 or when the level below has none): the
    /// chain down to level 0, for operators built over all levels (mg:coarse=galerkin).
    const CoarseContext* below = nullptr;
    bool available() const { return coarse && transfer && coarse_solver; }
};

/// Builds the Newton system solver of `spec` for a level. `context` (may be null) gives
/// two-level preconditioners what they need; they throw InvalidInput without it. The context's
/// pointees must outlive the returned object.
std::unique_ptr<NewtonSystemSolver>
make_newton_system_solver(const Level& level, const LinearSolverSpec& spec,
                          const CoarseContext* context = nullptr);

} // namespace mlc::levels

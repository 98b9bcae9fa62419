// SPDX-License-Identifier: MIT
/// @file Solvers for the Newton system J(M) dx = b of one level, where J(M) is the generalized
/// Jacobian for the per-element status matrices M (formulation.md §2).
#pragma once

#include "core/linear_operator.hpp"
#include "levels/level.hpp"
#include "solvers/mg.hpp"
#include "solvers/pc_spec.hpp"
#include "transfer/transfer.hpp"

#include <Eigen/Dense>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace mlc::levels {

/// The status matrix of one contact element in `dim` dimensions (contact::LawProjection::M): rows
/// and columns the tangents, then the normal.
template <int dim> using StatusMatrix = Eigen::Matrix<double, dim, dim>;

/// Assembles J = K + sum of contact tangents into a CSR matrix whose pattern is built once, so
/// values are refreshed in place and a direct solver's symbolic analysis can be reused.
template <int dim> class BasicJacobianAssembler {
public:
    /// `level` must outlive this object.
    explicit BasicJacobianAssembler(const BasicLevel<dim>& level);
    /// Fills the values for the given per-element M matrices.
    void assemble(const std::vector<StatusMatrix<dim>>& M);
    const SparseMatrix& matrix() const { return J_; }

private:
    void reset_row(int i);

    const BasicLevel<dim>& level_;
    SparseMatrix J_;
    std::vector<int> merged_rows_;   ///< rows where contact adds columns K lacks (sorted)
    std::vector<size_t> kpos_start_; ///< per merged row, its first entry in kpos_
    std::vector<int> kpos_;          ///< positions in J of K's values, merged rows only
    std::vector<int> contact_rows_;  ///< rows holding a contact tangent entry (sorted)
    std::vector<int> cpos_;          ///< position of each contact tangent entry, in visiting order
};

extern template class BasicJacobianAssembler<2>;
extern template class BasicJacobianAssembler<3>;
/// The 2D assembler.
using JacobianAssembler = BasicJacobianAssembler<2>;

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
template <int dim> class BasicNewtonSystemSolver {
public:
    /// The status matrix of one element.
    using Matrix = StatusMatrix<dim>;

    virtual ~BasicNewtonSystemSolver() = default;
    /// dx = J(M)^{-1} b. dx is resized; its content on entry is the initial guess of an
    /// iterative method (zero is fine). `forcing` is the inexact-Newton tolerance of this solve:
    /// an iterative solver stops at the relative residual max(forcing, its own rel_tol); direct
    /// solvers ignore it (they are exact).
    virtual SolveResult solve(const std::vector<Matrix>& M, const Vector& b, Vector& dx,
                              double forcing) = 0;
    /// An exact-as-configured solve (forcing 0).
    SolveResult solve(const std::vector<Matrix>& M, const Vector& b, Vector& dx) {
        return solve(M, b, dx, 0.0);
    }
    /// "lu", "schur", or the Krylov/preconditioner pair.
    virtual std::string name() const = 0;
    /// The converged statuses of the level below for the current load step. The driver calls
    /// this after every load step of the level below, before this level's solves; solvers
    /// whose preconditioner uses the level below (cf, sorcf, mg) need it, the others ignore it.
    virtual void set_coarse_statuses(const std::vector<Matrix>& M) { (void)M; }
    /// Assembles J(M) and sets the preconditioner up on it, unless M is the last call's: the
    /// level above's multigrid, which shares this level's, calls it with this level's
    /// converged statuses. Direct solvers have nothing to prepare.
    virtual void prepare(const std::vector<Matrix>& M) { (void)M; }
    /// The multigrid preconditioner this solver uses (null when it has none).
    virtual const solvers::Multigrid* multigrid() const { return nullptr; }
};

/// The 2D Newton-system solver (every preconditioner of the registry).
using NewtonSystemSolver = BasicNewtonSystemSolver<2>;
/// The 3D Newton-system solver.
using NewtonSystemSolver3 = BasicNewtonSystemSolver<3>;

/// A NewtonSystemSolver that hands everything to another one: derive from it and override what
/// to watch (bench newton's recorder, the setup timer of the coarser levels, test captures).
template <int dim> class BasicForwardingSystemSolver : public BasicNewtonSystemSolver<dim> {
public:
    using Matrix = StatusMatrix<dim>;
    using Solver = BasicNewtonSystemSolver<dim>;

    explicit BasicForwardingSystemSolver(std::unique_ptr<Solver> inner)
        : inner_(std::move(inner)) {}
    using Solver::solve;
    SolveResult solve(const std::vector<Matrix>& M, const Vector& b, Vector& dx,
                      double forcing) override {
        return inner_->solve(M, b, dx, forcing);
    }
    std::string name() const override { return inner_->name(); }
    void set_coarse_statuses(const std::vector<Matrix>& M) override {
        inner_->set_coarse_statuses(M);
    }
    void prepare(const std::vector<Matrix>& M) override { inner_->prepare(M); }
    const solvers::Multigrid* multigrid() const override { return inner_->multigrid(); }

protected:
    Solver& inner() { return *inner_; }

private:
    std::unique_ptr<Solver> inner_;
};

using ForwardingSystemSolver = BasicForwardingSystemSolver<2>;

/// Assembles J(M) (pattern fixed per level) and calls `solver` on it. `level` must outlive it.
std::unique_ptr<NewtonSystemSolver>
make_assembled_system_solver(const Level& level, std::unique_ptr<LinearSolver> solver);
/// The same for a 3D level.
std::unique_ptr<NewtonSystemSolver3>
make_assembled_system_solver(const Level3& level, std::unique_ptr<LinearSolver> solver);

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
/// The same for a 3D level (B maps to (t1, t2, n) per frictional node, n per frictionless one).
std::unique_ptr<NewtonSystemSolver3> make_schur_system_solver(const Level3& level);

/// The Krylov iteration budget with an exact fallback: a solve projected to need more
/// iterations than this (at its observed rate) is given up and the system solved exactly. The
/// multigrid needs 5 to 30 on every scene we have; a few hundred means it is failing there.
inline constexpr int kFallbackKrylovBudget = 500;

/// How each Newton system is solved (levels::plan_solver fills it from a request).
struct LinearSolverSpec {
    /// schur (exact, condensed on the contact set; default), lu (SparseLU on the assembled
    /// Jacobian) or krylov (the `krylov` method with the `pc` preconditioner).
    solvers::Method method = solvers::Method::schur;
    solvers::Krylov krylov = solvers::Krylov::cgs; ///< method krylov
    solvers::PcSpec pc = solvers::parse_pc("ilu"); ///< method krylov: the preconditioner
    /// Relative tolerance of the linear solve, ||b - J dx|| <= rel_tol ||b||. 1e-10 keeps the
    /// Newton iterates as exact as the papers' (they solve to near round-off).
    double rel_tol = 1e-10;
    int max_iter = 5000; ///< Krylov iterations per Newton step
    int restart = 50;    ///< GMRES restart length
    /// Cut slow Krylov solves short: 0 (default) never, else the iteration budget of
    /// solvers::KrylovParams::give_up_budget. The driver sets kFallbackKrylovBudget when an
    /// exact fallback follows a failed solve (SolveOptions::exact_fallback).
    int give_up_budget = 0;
    /// The numbering the levels are built with (the planner sets it); unset: lattice where the
    /// preconditioner sweeps by lattices, else the problem's (levels::hierarchy_numbering).
    std::optional<Problem::Numbering> numbering{};
    void validate() const;
    /// The Krylov parameters of this spec (rel_tol, max_iter, restart, give_up_budget),
    /// validated.
    solvers::KrylovParams krylov_params() const;
    /// Whether the preconditioner uses the level below (a Krylov method with such an entry).
    bool uses_level_below() const {
        return method == solvers::Method::krylov && pc.entry != nullptr &&
               pc.entry->needs_level_below;
    }
};

std::ostream& operator<<(std::ostream& os, const LinearSolverSpec& s);

/// The level below, for the preconditioners that use it (registry entries with
/// needs_level_below). Its pointees must outlive the solvers built with it; the coarse statuses
/// reach the solver by NewtonSystemSolver::set_coarse_statuses.
struct LevelBelow {
    const Level* coarse = nullptr;                     ///< the level below
    const transfer::LevelTransfer* transfer = nullptr; ///< coarse -> this level
    NewtonSystemSolver* solver = nullptr;              ///< the level below's solver
    /// The level below's own LevelBelow (null on level 0 or when the level below has none):
    /// the chain down to the lowest level solved, for multigrids over all levels.
    const LevelBelow* below = nullptr;
    bool available() const { return coarse && transfer && solver; }
};

/// Builds the Newton system solver of `spec` for a level. `below` (may be null) gives the
/// preconditioners that need the level below what they use; they throw InvalidInput without
/// it. Its pointees must outlive the returned object.
std::unique_ptr<NewtonSystemSolver> make_newton_system_solver(const Level& level,
                                                              const LinearSolverSpec& spec,
                                                              const LevelBelow* below = nullptr);

} // namespace mlc::levels

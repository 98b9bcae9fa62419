// SPDX-License-Identifier: MIT
/// @file Preconditioned Krylov solvers as free functions: CGS (the papers' method, formulation.md
/// sect. 4), BiCG, BiCGStab and restarted GMRES, all reporting the true final residual.
#pragma once

#include "core/communicator.hpp"
#include "core/linear_operator.hpp"

#include <ostream>
#include <string>
#include <string_view>

namespace mlc::solvers {

/// Stopping and work parameters shared by every Krylov method.
///
/// Convergence test: ||r|| <= max(rel_tol * ||b||, abs_tol), with r the residual the method
/// monitors (see each solver) and, at exit, the true residual b - A x.
struct KrylovParams {
    /// Relative tolerance on ||b - A x|| / ||b||, in [0, 1). Default 1e-8: well below the
    /// discretization error of the meshes we use, and what the Newton loop needs for quadratic
    /// convergence; inexact Newton may pass a looser value.
    double rel_tol = 1e-8;
    /// Absolute tolerance on ||b - A x|| (units of b), >= 0. Default 0: only the relative test.
    double abs_tol = 0.0;
    /// Largest number of iterations, >= 0 (one iteration = one step of the method: two
    /// mat-vecs for CGS, BiCG and BiCGStab, one for GMRES). Default 1000: far above what a
    /// useful preconditioner needs; reaching it signals a preconditioner problem.
    int max_iter = 1000;
    /// GMRES restart length m >= 1 (ignored by the other methods). Default 50: memory
    /// (m + 1) n doubles, a usual compromise between robustness and cost.
    int restart = 50;
    /// Cut a slow solve short: every 50 iterations, when the residual reduction observed so far,
    /// continued at its average rate, would need more than `give_up_budget` iterations in all to
    /// reach the tolerance, stop (reason max_iter, the message says so). Default 0: never; the
    /// Newton driver sets it when an exact fallback solve follows a failure.
    int give_up_budget = 0;
    /// Store the monitored residual norm of every iteration in SolveResult::history.
    /// Default false: no allocation proportional to the iteration count.
    bool record_history = false;
    /// The processes the vectors are distributed over (each process passes its owned entries of
    /// b and x and an operator and preconditioner on them): every inner product and norm is
    /// summed over them, so all processes take the same steps and stop together. Borrowed, must
    /// outlive the solve. Default null: one process, the vectors are whole.
    const Communicator* comm = nullptr;

    /// Throws mlc::InvalidInput naming the first field out of range.
    void validate() const;
};

/// Prints every field of `p` on one line.
std::ostream& operator<<(std::ostream& os, const KrylovParams& p);

/// Common contract of the solvers below.
///
/// - A is square, b.size() == A.rows(). x is the initial guess on entry (an empty x means
///   x0 = 0) and the approximate solution on exit. Size mismatches throw mlc::InvalidInput.
/// - M is set up by the caller for the same matrix; M and A are only borrowed.
/// - A NaN or Inf in b throws mlc::SolverBreakdown; b = 0 gives x = 0, converged, 0 iterations.
/// - A numerical breakdown inside the iteration (a zero or non-finite inner product, a
///   non-finite residual) never throws and never loops: the solver returns with
///   converged = false, reason = breakdown, and `message` naming the quantity and iteration.
/// - Reaching max_iter returns converged = false, reason = max_iter.
/// - The result carries the TRUE final residual ||b - A x|| (recomputed), relative to ||b||.
///   When the monitored residual meets the test but the true one does not (loss of accuracy
///   in the recursion), the method restarts from the current x while iterations remain.
///   Conversely, `converged` is decided on the true residual: if it meets the test at exit
///   (even at max_iter or right after a breakdown), the result is converged.
/// - history (when asked for): history[0] is the initial true residual, history[k] the
///   monitored residual after iteration k.
/// - Work vectors are allocated once per call; the iteration loop does not allocate (given
///   operators and preconditioners whose apply does not allocate).
/// - solve_seconds is the wall time of the call; setup_seconds is left at 0 (the caller times
///   the preconditioner setup).

/// Preconditioned conjugate gradients for a symmetric positive definite A and preconditioner
/// (the elastic block with a symmetric V-cycle: `bench elastic`); not a `Krylov` method of the
/// Newton systems, which are not symmetric. Per iteration: 1 mat-vec, 1 C^{-1}, 2 reductions.
/// Monitors the recursive residual; a breakdown when (p, A p) is not positive.
SolveResult cg(const LinearOperator& A, const Preconditioner& M, const Vector& b, Vector& x,
               const KrylovParams& params = {});

/// Preconditioned CGS (Sonneveld), left preconditioned exactly as formulation.md sect. 4:
///   r0 = b - A x0, z0 = C^{-1} r0, p0 = q0 = z0; per iteration
///   y = C^{-1} A q, a = (z0, z) / (z0, y), h = p - a y, x += a (p + h), r -= a A (p + h),
///   z = C^{-1} r, beta = (z0, z_new) / (z0, z), p = z + beta h, q = p + beta (h + beta q).
/// Monitors the unpreconditioned recursive residual r. Per iteration: 2 mat-vecs, 2 C^{-1}.
SolveResult cgs(const LinearOperator& A, const Preconditioner& M, const Vector& b, Vector& x,
                const KrylovParams& params);

/// Preconditioned BiCG (Fletcher), with shadow residual r~0 = r0:
///   z = C^{-1} r, z~ = C^{-T} r~, rho = (z, r~), p = z + beta p, p~ = z~ + beta p~,
///   q = A p, q~ = A^T p~, alpha = rho / (p~, q), x += alpha p, r -= alpha q, r~ -= alpha q~.
/// Needs A.apply_transpose and M.apply_transpose (throws mlc::InvalidInput before iterating
/// when one is missing). Monitors the unpreconditioned recursive residual r. Per iteration:
/// A, A^T, C^{-1}, C^{-T} once each.
SolveResult bicg(const LinearOperator& A, const Preconditioner& M, const Vector& b, Vector& x,
                 const KrylovParams& params);

/// Right-preconditioned BiCGStab (van der Vorst), shadow residual r^ = r0:
///   p^ = C^{-1} p, v = A p^, alpha = rho / (r^, v), s = r - alpha v, s^ = C^{-1} s, t = A s^,
///   omega = (t, s) / (t, t), x += alpha p^ + omega s^, r = s - omega t.
/// Monitors the unpreconditioned recursive residual (also at the half step s). Breakdown on
/// rho = 0, (r^, v) = 0 or omega = 0. Per iteration: 2 mat-vecs, 2 C^{-1}.
SolveResult bicgstab(const LinearOperator& A, const Preconditioner& M, const Vector& b, Vector& x,
                     const KrylovParams& params);

/// Restarted GMRES(m), m = min(params.restart, n), right preconditioned: Arnoldi with modified
/// Gram–Schmidt on A C^{-1}, Givens rotations, x += C^{-1} V y at the end of each cycle. The
/// monitored residual is the least-squares residual, equal to the true ||b - A x|| in exact
/// arithmetic; the true residual is recomputed at every restart. C must be the same at every
/// iteration (use a flexible method for variable preconditioners). Per iteration: 1 mat-vec,
/// 1 C^{-1} (plus 1 C^{-1} per cycle). Memory: (m + 1) n doubles. A cycle that does not reduce
/// the true residual at all, or a singular Hessenberg matrix, ends with reason = breakdown.
SolveResult gmres(const LinearOperator& A, const Preconditioner& M, const Vector& b, Vector& x,
                  const KrylovParams& params);

/// Krylov method chosen at run time.
enum class Krylov { cgs, bicg, bicgstab, gmres };

/// "cgs", "bicg", "bicgstab" or "gmres".
std::string_view to_string(Krylov k);
/// Streams `to_string(k)`.
std::ostream& operator<<(std::ostream& os, Krylov k);

/// Parses one of the names printed by to_string (exact, lower case); anything else throws
/// mlc::InvalidInput listing the valid names.
Krylov parse_krylov(std::string_view name);

/// Dispatches to cgs, bicg, bicgstab or gmres (same contract).
SolveResult solve(Krylov method, const LinearOperator& A, const Preconditioner& M, const Vector& b,
                  Vector& x, const KrylovParams& params);

/// Convenience overload: wraps A in a MatrixOperator.
SolveResult solve(Krylov method, const SparseMatrix& A, const Preconditioner& M, const Vector& b,
                  Vector& x, const KrylovParams& params);

} // namespace mlc::solvers

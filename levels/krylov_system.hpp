// SPDX-License-Identifier: MIT
/// @file Newton systems solved by a preconditioned Krylov method on the assembled Jacobian
/// (the papers' CGS/BiCG with DIAG, ILU(k), CF, SORCF and EBE preconditioners).
#pragma once

#include "levels/newton_system.hpp"

namespace mlc::levels {

/// Assembles J(M) in place and solves with `spec.krylov` preconditioned by `spec.pc`.
/// Algebraic preconditioners ("none", "diag", "ilu:K", "sor", "ssor", "lu") come from
/// solvers::make_preconditioner; level-aware ones ("cf", "sorcf", "ebe") are built here from
/// the level and `context`. The returned SolveResult carries the Krylov iterations; a Krylov
/// solve that does not converge is reported (converged false), not thrown.
std::unique_ptr<NewtonSystemSolver> make_krylov_system_solver(const Level& level,
                                                              const LinearSolverSpec& spec,
                                                              const CoarseContext* context);

} // namespace mlc::levels

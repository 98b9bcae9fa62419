// SPDX-License-Identifier: MIT
/// @file Runs a problem through its load steps on the finest level and collects what the report
/// and the output files need.
#pragma once

#include "core/timer.hpp"
#include "levels/level.hpp"
#include "levels/newton.hpp"
#include "levels/newton_system.hpp"
#include "levels/problem.hpp"

#include <ostream>
#include <vector>

namespace mlc::levels {

/// Options of one run that are not part of the problem.
struct SolveOptions {
    std::ostream* progress = nullptr; ///< per-step progress lines, or null for silence
    bool keep_step_states = false;    ///< keep x after every step (for per-step VTU output)
    /// How Newton systems are solved (default: exact, condensed on the contact set).
    LinearSolverSpec linear;
};

/// Result of a run on the finest level.
struct RunResult {
    std::vector<Level> levels;           ///< levels 0..L (only the finest is solved here)
    std::vector<StepReport> steps;       ///< one per load step, finest level
    Vector x;                            ///< final unknowns of the finest level
    Vector u_full;                       ///< final nodal displacements (2 per vertex)
    Vector u_prev_full;                  ///< nodal displacements at the end of the previous step
    std::vector<ContactNodeState> nodes; ///< final contact node states
    std::vector<Vector> step_u_full;     ///< per step, when keep_step_states
    std::vector<std::vector<ContactNodeState>> step_nodes; ///< per step, when keep_step_states
    Timings timings;
    bool converged = false;
    std::string failure; ///< diagnosis of the first step that failed
    const Level& finest() const { return levels.back(); }
};

/// Builds levels 0..problem.levels by uniform refinement and solves every load step on the
/// finest level with the generalized Newton method (previous step's state as initial guess).
/// Stops at the first step that does not converge (RunResult::converged false, failure set).
RunResult solve(const Problem& problem, const SolveOptions& options = {});

/// Sum over the unknown rows of the contact forces and of the loads: global force balance
/// check. Returns |sum of reactions + loads + contact forces| / |largest of them| over the
/// free and fixed components, computed from the full nodal vectors.
double force_balance_error(const Level& level, double s, const Vector& u_full,
                           const std::vector<ContactNodeState>& nodes);

} // namespace mlc::levels

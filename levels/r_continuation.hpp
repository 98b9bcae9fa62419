// SPDX-License-Identifier: MIT
/// @file The r continuation of a load step (SolveOptions::r_continuation) and the memory test of
/// the exact schur solver it and the exact fallback build on demand.
#pragma once

#include "levels/newton.hpp"
#include "levels/resources.hpp"

#include <functional>
#include <memory>
#include <string>

namespace mlc::levels {

/// Empty when the exact schur solver of level l (predicted size `size`) fits in what the process
/// may still use, else why not (the exact fallback and the r continuation build it on demand).
std::string schur_does_not_fit(const LevelSize& size, int l);

/// Polled by the Newton of the continuation: `stop` after every iteration, `interrupt` before
/// every one (ContactNewton::set_stop, set_interrupt); empty: never.
struct NewtonPolls {
    std::function<bool()> stop;
    std::function<bool()> interrupt;
};

/// SolveOptions::r_continuation: `failed` is the report of Newton at the scene's r from x0 on
/// level L (index l), or an empty report (no iteration) when an earlier step of the level
/// needed the continuation at `first_factor` (tried first; 0: start at 1e-2). Returns the report
/// of the recovered step (x updated) or `failed` with what was tried appended to its message (x
/// unchanged).
StepReport continue_in_r(Level& L, int l, const LevelSize& size, const NewtonParams& params,
                         ContactNewton& nw, double s, const Vector& u_prev, const Vector& x0,
                         Vector& x, StepReport failed, double first_factor,
                         std::unique_ptr<NewtonSystemSolver>& kept, const NewtonPolls& polls,
                         Timings* timings);

} // namespace mlc::levels

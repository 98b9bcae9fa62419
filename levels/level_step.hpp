// SPDX-License-Identifier: MIT
/// @file The phases of a level's load step that the one-process run (levels::solve) and the
/// distributed levels (levels::solve_distributed) share.
#pragma once

#include "levels/newton.hpp"
#include "levels/solve.hpp"

#include <string>

namespace mlc::levels {

/// SolveOptions::extrapolate: the state 2 x - older (x the level's state of the last step, older
/// the one before), taken when Newton would stop there at once (ContactNewton::check): then x is
/// that state, ls.report check()'s report, ls.extrapolated set, and true returned; otherwise
/// nothing changes.
bool take_extrapolation(ContactNewton& nw, double s, const Vector& u_prev, const Vector& older,
                        Vector& x, LevelStep& ls);

/// ls.final_statuses at x, and the confusion of the predicted statuses against them when the
/// step was predicted.
void tally_statuses(const ContactNewton& nw, double s, const Vector& u_prev, const Vector& x,
                    LevelStep& ls);

/// " 1.00e+00 3.20e-02 ...": the residuals of a report, as failure messages list them.
std::string residual_history(const StepReport& rep);

} // namespace mlc::levels

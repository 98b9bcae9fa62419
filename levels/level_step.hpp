// SPDX-License-Identifier: MIT
/// @file The level loop of a load step and the phases of a level's step, which the one-process
/// run (levels::solve) and the distributed levels (levels::solve_distributed) share: the two
/// differ only in their StepLevel, that is in how a level is built, where its state lives, how
/// its guess comes from the level below and how its reports are reduced over the processes.
#pragma once

#include "levels/newton.hpp"
#include "levels/solve.hpp"

#include <span>
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

/// One level of the level loop. solve_levels calls, per load step and in this order:
/// begin_step, extrapolate, interpolate (when extrapolate did not take its state), the
/// predicted statuses at x(), solve (likewise), the final statuses and their confusion, reduce,
/// settle, report, then fail or accept.
class StepLevel {
public:
    virtual ~StepLevel() = default;
    virtual ContactNewton& newton() = 0;
    /// The nodal displacements of the previous converged step.
    virtual const Vector& u_prev() const = 0;
    /// The unknowns Newton iterates on (the state of the previous step until the step's guess).
    virtual Vector& x() = 0;
    /// The level's number in the hierarchy.
    virtual int index() const = 0;
    /// Before anything of the step (the state the level above's increment needs).
    virtual void begin_step() {}
    /// SolveOptions::extrapolate: true when the extrapolated state was taken (x() holds it,
    /// ls.report is check()'s); false otherwise, also when the option is off.
    virtual bool extrapolate(double s, LevelStep& ls) = 0;
    /// The coarse-to-fine guess from the level below into x(); false when the level takes none
    /// (x() stays the previous step's state).
    virtual bool interpolate(int step) = 0;
    /// Newton from x() (with what recovers a failed step), into ls.report.
    virtual void solve(int step, double s, LevelStep& ls) = 0;
    /// The status counts and the confusion summed over the processes (nothing on one).
    virtual void reduce(LevelStep& /*ls*/) {}
    /// After the step's statuses are known, whether it converged or not.
    virtual void settle(const LevelStep& /*ls*/) {}
    /// Reports the step (progress) and keeps it in the run's result; returns the kept report.
    virtual const StepReport& report(LevelStep ls) = 0;
    /// The step failed (or was stopped): the run's failure.
    virtual void fail(int step, double s, const StepReport& rep) = 0;
    /// The step converged: the state for the output and the level above.
    virtual void accept(int step, double s) = 0;
};

/// A level's load step through its phases (StepLevel), not yet reported.
LevelStep solve_level_step(StepLevel& level, int step, double s);

/// The level loop of load step `step` (load factor s): each level's step bottom up, reported,
/// and accepted when it converged; stops at the first level that does not (failed, false).
bool solve_levels(std::span<StepLevel* const> levels, int step, double s);

} // namespace mlc::levels

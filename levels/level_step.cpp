// SPDX-License-Identifier: MIT
// The level loop of a load step and the phases of a level's step.
#include "levels/level_step.hpp"

#include <iomanip>
#include <sstream>

namespace mlc::levels {

bool take_extrapolation(ContactNewton& nw, double s, const Vector& u_prev, const Vector& older,
                        Vector& x, LevelStep& ls) {
    Vector xe = 2.0 * x - older;
    StepReport r = nw.check(s, u_prev, xe);
    if (!r.converged) return false;
    x = std::move(xe);
    ls.report = std::move(r);
    ls.extrapolated = true;
    return true;
}

void tally_statuses(const ContactNewton& nw, double s, const Vector& u_prev, const Vector& x,
                    LevelStep& ls) {
    ls.final_statuses = nw.statuses(s, u_prev, x);
    if (ls.predicted)
        for (size_t e = 0; e < ls.final_statuses.size(); ++e)
            ++ls.confusion[static_cast<size_t>(ls.predicted_statuses[e])]
                          [static_cast<size_t>(ls.final_statuses[e])];
}

std::string residual_history(const StepReport& rep) {
    std::ostringstream os;
    for (double r : rep.residuals)
        os << " " << std::scientific << std::setprecision(2) << r;
    return os.str();
}

LevelStep solve_level_step(StepLevel& level, int step, double s) {
    ContactNewton& nw = level.newton();
    LevelStep ls;
    ls.level = level.index();
    level.begin_step();
    const bool extrapolated = level.extrapolate(s, ls);
    if (!extrapolated && level.interpolate(step)) {
        ls.predicted = true;
        ls.predicted_statuses = nw.statuses(s, level.u_prev(), level.x());
    }
    if (!extrapolated) level.solve(step, s, ls);
    ls.report.step = step;
    tally_statuses(nw, s, level.u_prev(), level.x(), ls);
    level.reduce(ls);
    level.settle(ls);
    return ls;
}

bool solve_levels(std::span<StepLevel* const> levels, int step, double s) {
    for (StepLevel* level : levels) {
        LevelStep ls = solve_level_step(*level, step, s);
        const bool ok = ls.report.converged;
        const StepReport& rep = level->report(std::move(ls));
        if (!ok) {
            level->fail(step, s, rep);
            return false;
        }
        level->accept(step, s);
    }
    return true;
}

} // namespace mlc::levels

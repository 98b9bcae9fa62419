// SPDX-License-Identifier: MIT
// Progress lines of a run (levels::ProgressLines) and the states an observer reads.
#include "levels/solve.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace mlc::levels {

const std::vector<ContactNodeState>& LevelStepState::nodes() const {
    if (!nodes_) nodes_ = node_states ? node_states() : std::vector<ContactNodeState>{};
    return *nodes_;
}

namespace {

void print_progress(std::ostream& os, int level, int n_levels, int step, int n_steps,
                    const LevelStep& ls) {
    const StepReport& rep = ls.report;
    os << "  step " << std::setw(3) << step << "/" << n_steps;
    if (n_levels > 1) os << "  level " << level;
    os << "  load " << std::fixed << std::setprecision(3) << rep.load_factor << "  newton "
       << std::setw(3) << rep.iterations;
    if (rep.linear_iterations > 0) os << "  lin.it " << std::setw(5) << rep.linear_iterations;
    os << "  residual " << std::scientific << std::setprecision(2) << rep.residuals.back()
       << "  gap " << rep.counts.gap << " stick " << rep.counts.stick << " slip+ "
       << rep.counts.slip_forward << " slip- " << rep.counts.slip_backward;
    if (ls.predicted) os << "  predicted " << std::fixed << std::setprecision(3) << ls.agreement();
    os << "  " << std::fixed << std::setprecision(2) << rep.seconds << " s" << std::defaultfloat
       << (rep.converged ? ""
           : rep.stopped ? "  stopped"
                         : "  FAILED");
}

/// "0.4 s", "12 s", "3 min 05 s", "1 h 02 min".
std::string format_duration(double t) {
    const long s = std::lround(std::max(0.0, t));
    std::ostringstream os;
    if (t < 9.95)
        os << std::fixed << std::setprecision(1) << std::max(0.0, t) << " s";
    else if (s < 60)
        os << s << " s";
    else if (s < 3600)
        os << s / 60 << " min " << std::setw(2) << std::setfill('0') << s % 60 << " s";
    else
        os << s / 3600 << " h " << std::setw(2) << std::setfill('0') << (s % 3600) / 60 << " min";
    return os.str();
}

/// Estimated seconds left after load step `step` of level `level`: the remaining levels of this
/// step and every level of the remaining steps, each at the mean time of its steps so far; a
/// level not solved yet at the time of the level below scaled by the ratio of unknowns.
double time_left(const std::vector<Level>& levels, int first, int level, int step, int n_steps,
                 const std::vector<double>& seconds, const std::vector<int>& count) {
    const int finest = static_cast<int>(levels.size()) - 1;
    std::vector<double> per(levels.size(), 0.0);
    for (int l = first; l <= finest; ++l) {
        const size_t li = static_cast<size_t>(l);
        if (count[li] > 0)
            per[li] = seconds[li] / count[li];
        else if (l > first)
            per[li] = per[li - 1] * static_cast<double>(levels[li].n_unknowns()) /
                      static_cast<double>(levels[li - 1].n_unknowns());
    }
    double left = 0.0, all = 0.0;
    for (int l = first; l <= finest; ++l) {
        all += per[static_cast<size_t>(l)];
        if (l > level) left += per[static_cast<size_t>(l)];
    }
    return left + (n_steps - step) * all;
}

/// A distributed level's line: its Newton and Krylov iterations and the processes.
void print_distributed(std::ostream& os, int n_steps, int processes, const LevelStep& ls) {
    const auto& r = ls.report;
    os << "  level " << ls.level << " step " << r.step << "/" << n_steps << ": "
       << (r.converged ? "converged" : "FAILED") << " in " << r.iterations << " Newton it, "
       << r.linear_iterations << " Krylov it, final residual " << std::scientific
       << std::setprecision(2) << (r.residuals.empty() ? 0.0 : r.residuals.back())
       << std::defaultfloat << std::setprecision(6) << ", " << std::fixed << std::setprecision(2)
       << r.seconds << " s" << std::defaultfloat << std::setprecision(6) << " (" << processes
       << " processes)" << std::endl;
}

} // namespace

void ProgressLines::level_step_done(const LevelStepProgress& p) {
    const LevelStep& ls = *p.step;
    if (p.processes > 0) {
        if (os_) print_distributed(*os_, p.load_steps, p.processes, ls);
        return;
    }
    const auto li = static_cast<size_t>(ls.level);
    if (const size_t n = std::max(li + 1, p.levels ? p.levels->size() : 0); seconds_.size() < n) {
        seconds_.resize(n, 0.0);
        count_.resize(n, 0);
    }
    seconds_[li] += ls.report.seconds;
    ++count_[li];
    if (!os_) return;
    std::ostream& os = *os_;
    print_progress(os, ls.level, p.n_levels, ls.report.step, p.load_steps, ls);
    if (eta_ && ls.report.converged && p.levels)
        os << "  [" << format_duration(p.elapsed) << " elapsed, ~"
           << format_duration(time_left(*p.levels, p.first_level, ls.level, ls.report.step,
                                        p.load_steps, seconds_, count_))
           << " left]";
    os << std::endl;
}

} // namespace mlc::levels

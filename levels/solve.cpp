// SPDX-License-Identifier: MIT
// Load stepping on the finest level.
#include "levels/solve.hpp"

#include "core/check.hpp"
#include "core/memory.hpp"
#include "solvers/factory.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace mlc::levels {

double LevelStep::agreement() const {
    if (!predicted || final_statuses.empty()) return 1.0;
    int same = 0;
    for (size_t e = 0; e < final_statuses.size(); ++e)
        same += predicted_statuses[e] == final_statuses[e];
    return static_cast<double>(same) / static_cast<double>(final_statuses.size());
}

namespace {

// The registry says which preconditioners use the level below.
bool needs_coarse_level(const LinearSolverSpec& spec) {
    if (spec.method != "krylov") return false;
    const solvers::PreconditionerEntry* entry = solvers::find_preconditioner(spec.pc);
    return entry != nullptr && entry->needs_level_below;
}

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

} // namespace

RunResult solve(const Problem& problem, const SolveOptions& options) {
    problem.validate();
    options.linear.validate();
    RunResult res;
    res.solver.spec = options.linear;
    res.solver.reason = "as given";
    MLC_CHECK(options.predicted_sizes.empty() ||
                  options.predicted_sizes.size() == static_cast<size_t>(problem.levels) + 1,
              "SolveOptions::predicted_sizes has " << options.predicted_sizes.size()
                                                   << " levels, the problem "
                                                   << problem.levels + 1);
    res.predicted_sizes =
        options.predicted_sizes.empty() ? predict_level_sizes(problem) : options.predicted_sizes;
    res.memory = estimate_memory(res.predicted_sizes, options.linear,
                                 options.coarse_to_fine || options.solve_all_levels ||
                                     needs_coarse_level(options.linear));
    res.memory_limit = process_memory_limit();
    check_memory_fits(res.memory, res.memory_limit, res.predicted_sizes);
    res.hierarchy = build_hierarchy(problem, options.q_rule, &res.timings);
    const auto& levels = res.hierarchy.levels;
    const int n_levels = res.hierarchy.n_levels();
    const int finest = n_levels - 1;
    const bool all_levels =
        options.coarse_to_fine || options.solve_all_levels || needs_coarse_level(options.linear);
    const int first = all_levels ? 0 : finest;

    // Solvers, Newton drivers and the level below of each level (fixed; the coarse statuses are
    // passed by set_coarse_statuses after every coarse load step).
    std::vector<LevelBelow> below(static_cast<size_t>(n_levels));
    std::vector<std::unique_ptr<ContactNewton>> newton(static_cast<size_t>(n_levels));
    std::vector<NewtonSystemSolver*> system(static_cast<size_t>(n_levels), nullptr);
    for (int l = first; l < n_levels; ++l) {
        ScopedTimer t(&res.timings, "setup/linear_solver");
        const Level& L = levels[static_cast<size_t>(l)];
        LinearSolverSpec spec = options.linear;
        if (l == 0 && l != finest) spec = LinearSolverSpec{};
        if (options.exact_fallback && spec.method == "krylov")
            spec.give_up_budget = kFallbackKrylovBudget;
        auto& lb = below[static_cast<size_t>(l)];
        if (l > first) {
            lb.coarse = &levels[static_cast<size_t>(l - 1)];
            lb.transfer = &res.hierarchy.transfers[static_cast<size_t>(l - 1)];
            lb.solver = system[static_cast<size_t>(l - 1)];
            if (l - 1 > first) lb.below = &below[static_cast<size_t>(l - 1)];
        }
        auto sys = make_newton_system_solver(L, spec, &lb);
        if (options.wrap_system_solver) sys = options.wrap_system_solver(l, L, std::move(sys));
        system[static_cast<size_t>(l)] = sys.get();
        newton[static_cast<size_t>(l)] =
            std::make_unique<ContactNewton>(L, problem.newton, std::move(sys), &res.timings);
        if (options.exact_fallback && spec.method == "krylov") {
            const LevelSize size = res.predicted_sizes[static_cast<size_t>(l)];
            newton[static_cast<size_t>(l)]->set_fallback([&L, size, l]() {
                const double need = estimate_memory({size}, LinearSolverSpec{}, false).solver_bytes;
                const MemoryLimit limit = process_memory_limit();
                const double free = limit.bytes - peak_rss_bytes();
                MLC_CHECK(need < free, "the exact schur solver of level "
                                           << l << " needs an estimated " << format_bytes(need)
                                           << ", more than the " << format_bytes(free) << " left ("
                                           << limit.source << ")");
                return make_schur_system_solver(L);
            });
        }
        newton[static_cast<size_t>(l)]->set_interrupt(options.interrupt_requested);
    }

    std::vector<Vector> x(static_cast<size_t>(n_levels)), u_prev(static_cast<size_t>(n_levels)),
        u_now(static_cast<size_t>(n_levels));
    for (int l = 0; l < n_levels; ++l) {
        x[static_cast<size_t>(l)] = Vector::Zero(levels[static_cast<size_t>(l)].n_unknowns());
        u_prev[static_cast<size_t>(l)] =
            Vector::Zero(2 * levels[static_cast<size_t>(l)].mesh.n_vertices());
    }
    std::vector<Vector> x_before(
        static_cast<size_t>(n_levels)); // each level's state before its solve
    res.level_steps.resize(static_cast<size_t>(n_levels));
    res.converged = true;
    for (auto& nw : newton)
        if (nw) nw->set_stop(options.stop);
    const double t_start = wall_seconds();
    std::vector<double> level_seconds(static_cast<size_t>(n_levels), 0.0);
    std::vector<int> level_count(static_cast<size_t>(n_levels), 0);
    for (int step = 1; step <= problem.load_steps && res.converged; ++step) {
        const double s = static_cast<double>(step) / problem.load_steps;
        for (int l = first; l < n_levels; ++l) {
            const size_t li = static_cast<size_t>(l);
            const Level& L = levels[li];
            ContactNewton& nw = *newton[li];
            LevelStep ls;
            ls.level = l;
            if (options.transfer_increment) x_before[li] = x[li]; // step - 1, for the level above
            if (options.coarse_to_fine && l > first) {
                // Initial guess (P u_H, Q lambda_H): displacements through the full nodal vectors
                // (prescribed values included), multipliers through Q.
                ScopedTimer t(&res.timings, "newton/interpolate");
                const auto& T = res.hierarchy.transfers[li - 1];
                // Increment mode: interpolate the coarse change over this step and add it to the
                // level's own previous state (x[li] still holds step - 1).
                const bool inc = options.transfer_increment && step > 1;
                Vector uf;
                T.interpolate_nodal(inc ? Vector(u_now[li - 1] - u_prev[li - 1]) : u_now[li - 1],
                                    uf);
                const Vector q = T.Q * (inc ? Vector(x[li - 1] - x_before[li - 1]) : x[li - 1]);
                Vector& xl = x[li];
                for (int v = 0; v < L.mesh.n_vertices(); ++v)
                    for (int c = 0; c < 2; ++c)
                        if (const int d = L.dofs.u_dof(v, c); d >= 0)
                            xl[d] = (inc ? xl[d] : 0.0) + uf[2 * v + c];
                for (size_t e = 0; e < L.contacts.size(); ++e)
                    for (int k = 0; k < L.contacts[e].n_multipliers(); ++k) {
                        const Index d = L.lambda_dof[e] + k;
                        xl[d] = (inc ? xl[d] : 0.0) + q[d];
                    }
                ls.predicted = true;
                ls.predicted_statuses = nw.statuses(s, u_prev[li], xl);
            }
            try {
                ls.report = nw.solve(s, u_prev[li], x[li]);
            } catch (const Interrupted& e) {
                throw Interrupted("load step " + std::to_string(step) + "/" +
                                  std::to_string(problem.load_steps) + " on level " +
                                  std::to_string(l) + ": " + e.what());
            }
            ls.report.step = step;
            ls.final_statuses = nw.statuses(s, u_prev[li], x[li]);
            if (ls.predicted)
                for (size_t e = 0; e < ls.final_statuses.size(); ++e)
                    ++ls.confusion[static_cast<size_t>(ls.predicted_statuses[e])]
                                  [static_cast<size_t>(ls.final_statuses[e])];
            level_seconds[li] += ls.report.seconds;
            ++level_count[li];
            if (options.progress) {
                std::ostream& os = *options.progress;
                print_progress(os, l, n_levels, step, problem.load_steps, ls);
                if (options.progress_eta && ls.report.converged)
                    os << "  [" << format_duration(wall_seconds() - t_start) << " elapsed, ~"
                       << format_duration(time_left(levels, first, l, step, problem.load_steps,
                                                    level_seconds, level_count))
                       << " left]";
                os << std::endl;
            }
            const bool ok = ls.report.converged;
            if (l == finest) res.steps.push_back(ls.report);
            res.level_steps[li].push_back(std::move(ls));
            if (!ok && res.level_steps[li].back().report.stopped) {
                std::ostringstream os;
                os << "stopped during load step " << step << " of " << problem.load_steps
                   << " (load factor " << s << ")";
                if (n_levels > 1) os << " on level " << l;
                os << " after " << res.level_steps[li].back().report.iterations
                   << " Newton iterations; " << res.completed_steps << " load steps completed";
                res.failure = os.str();
                res.stopped = true;
                res.converged = false;
                break;
            }
            if (!ok) {
                const auto& rep = res.level_steps[li].back().report;
                std::ostringstream os;
                os << "load step " << step << " (load factor " << s << ")";
                if (n_levels > 1) os << " on level " << l;
                os << " did not converge: " << rep.message << "; residual history:";
                for (double r : rep.residuals)
                    os << " " << std::scientific << std::setprecision(2) << r;
                res.failure = os.str();
                res.converged = false;
                break;
            }
            L.dofs.expand(x[li], L.u_fixed_at(s), u_now[li]);
            if (options.on_level_step) {
                const auto nodes = nw.node_states(s, u_prev[li], x[li]);
                options.on_level_step({l, step, s, &L, &u_now[li], &nodes});
            }
            if (l + 1 < n_levels) {
                // The level above's preconditioner (cf, sorcf, mg) uses this level at its
                // converged statuses.
                Vector R(x[li].size());
                std::vector<Eigen::Matrix2d> converged;
                nw.residual(s, u_prev[li], x[li], R, nullptr, &converged, nullptr);
                system[li + 1]->set_coarse_statuses(converged);
            }
        }
        if (!res.converged) break;
        res.nodes = newton.back()->node_states(s, u_prev.back(), x.back());
        res.u_full = u_now.back();
        if (options.keep_step_states) res.step_u_full.push_back(res.u_full);
        res.step_nodes.push_back(res.nodes);
        res.completed_steps = step;
        for (int l = first; l < n_levels; ++l)
            u_prev[static_cast<size_t>(l)] = u_now[static_cast<size_t>(l)];
    }
    res.x = x.back();
    if (const solvers::Multigrid* mg = system[static_cast<size_t>(finest)]->multigrid())
        res.multigrid = mg->report();
    return res;
}

} // namespace mlc::levels

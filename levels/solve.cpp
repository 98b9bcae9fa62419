// SPDX-License-Identifier: MIT
// Load stepping on the finest level.
#include "levels/solve.hpp"

#include "core/check.hpp"

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

bool needs_coarse_level(const LinearSolverSpec& spec) {
    if (spec.method != "krylov") return false;
    const std::string name = spec.pc.substr(0, spec.pc.find(':'));
    return name == "cf" || name == "sorcf" || name == "mg";
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
       << (rep.converged ? "" : "  FAILED") << "\n";
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

    // Solvers, Newton drivers and coarse contexts per level (contexts are updated every step).
    std::vector<CoarseContext> context(static_cast<size_t>(n_levels));
    std::vector<std::unique_ptr<ContactNewton>> newton(static_cast<size_t>(n_levels));
    std::vector<NewtonSystemSolver*> system(static_cast<size_t>(n_levels), nullptr);
    for (int l = first; l < n_levels; ++l) {
        ScopedTimer t(&res.timings, "setup/linear_solver");
        const Level& L = levels[static_cast<size_t>(l)];
        LinearSolverSpec spec = options.linear;
        if (l == 0 && l != finest) spec = LinearSolverSpec{};
        auto& ctx = context[static_cast<size_t>(l)];
        if (l > first) {
            ctx.coarse = &levels[static_cast<size_t>(l - 1)];
            ctx.transfer = &res.hierarchy.transfers[static_cast<size_t>(l - 1)];
            ctx.coarse_solver = system[static_cast<size_t>(l - 1)];
            if (l - 1 > first) ctx.below = &context[static_cast<size_t>(l - 1)];
        }
        auto sys = make_newton_system_solver(L, spec, &ctx);
        system[static_cast<size_t>(l)] = sys.get();
        newton[static_cast<size_t>(l)] =
            std::make_unique<ContactNewton>(L, problem.newton, std::move(sys), &res.timings);
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
            if (options.progress)
                print_progress(*options.progress, l, n_levels, step, problem.load_steps, ls);
            const bool ok = ls.report.converged;
            if (l == finest) res.steps.push_back(ls.report);
            res.level_steps[li].push_back(std::move(ls));
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
            if (l + 1 < n_levels) {
                // The level above needs this level's converged statuses (two-level
                // preconditioners).
                Vector R(x[li].size());
                nw.residual(s, u_prev[li], x[li], R, nullptr, &context[li + 1].coarse_M, nullptr);
            }
        }
        if (!res.converged) break;
        res.nodes = newton.back()->node_states(s, u_prev.back(), x.back());
        res.u_full = u_now.back();
        if (options.keep_step_states) {
            res.step_u_full.push_back(res.u_full);
            res.step_nodes.push_back(res.nodes);
        }
        for (int l = first; l < n_levels; ++l)
            u_prev[static_cast<size_t>(l)] = u_now[static_cast<size_t>(l)];
    }
    res.x = x.back();
    return res;
}

} // namespace mlc::levels

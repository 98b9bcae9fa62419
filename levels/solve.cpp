// SPDX-License-Identifier: MIT
// Load stepping on the finest level.
#include "levels/solve.hpp"
#include "levels/initial_gap.hpp"

#include "levels/diagnoses.hpp"
#include "levels/resources.hpp"

#include "core/check.hpp"
#include "core/first_touch.hpp"
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
    return spec.uses_level_below();
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

/// Empty when the exact schur solver of level l (predicted size `size`) fits in what the process
/// may still use, else why not (the exact fallback and the r continuation build it on demand).
std::string schur_does_not_fit(const LevelSize& size, int l) {
    const double need = estimate_memory({size}, LinearSolverSpec{}, false).solver_bytes;
    const MemoryLimit limit = process_memory_limit();
    const double free = limit.bytes - peak_rss_bytes();
    if (need < free) return {};
    std::ostringstream os;
    os << "the exact schur solver of level " << l << " needs an estimated " << format_bytes(need)
       << ", more than the " << format_bytes(free) << " left (" << limit.source << ")";
    return os.str();
}

/// Multiplies the augmentation parameter of every contact element of a level by `factor` for
/// its lifetime, and restores the exact values after.
class ScaledAugmentation {
public:
    ScaledAugmentation(Level& L, double factor) : L_(L) {
        r_.reserve(L.contacts.size());
        for (auto& e : L.contacts) {
            r_.push_back(e.r);
            e.r *= factor;
        }
    }
    ~ScaledAugmentation() {
        for (size_t e = 0; e < r_.size(); ++e)
            L_.contacts[e].r = r_[e];
    }
    ScaledAugmentation(const ScaledAugmentation&) = delete;
    ScaledAugmentation& operator=(const ScaledAugmentation&) = delete;

private:
    Level& L_;
    std::vector<double> r_;
};

/// SolveOptions::r_continuation: `failed` is the report of Newton at the scene's r from x0 on
/// level L (index l), or an empty report (no iteration) when an earlier step of the level
/// needed the continuation at `first_factor` (tried first; 0: start at 1e-2). Returns the report
/// of the recovered step (x updated) or `failed` with what was tried appended to its message (x
/// unchanged).
StepReport continue_in_r(Level& L, int l, const LevelSize& size, const NewtonParams& params,
                         ContactNewton& nw, double s, const Vector& u_prev, const Vector& x0,
                         Vector& x, StepReport failed, double first_factor,
                         std::unique_ptr<NewtonSystemSolver>& kept, const SolveOptions& options,
                         Timings* timings) {
    int spent = failed.iterations;
    std::ostringstream tried;
    std::vector<double> factors;
    for (const double f : {1e-2, 1e-4})
        if (first_factor <= 0 || f <= first_factor) factors.push_back(f);
    for (const double factor : factors) {
        const bool reuse = kept && factor == first_factor;
        if (const std::string why = reuse ? std::string() : schur_does_not_fit(size, l);
            !why.empty()) {
            tried << "; no r continuation: " << why;
            break;
        }
        Vector xc = x0;
        StepReport low;
        {
            ScopedTimer t(timings, "newton/r_continuation");
            ScaledAugmentation scaled(L, factor);
            // The schur solver of the scaled level (its factorization holds r) is kept for the
            // later steps of the level, which start at the same factor.
            if (!reuse) kept = make_schur_system_solver(L);
            ContactNewton cn(L, params, std::move(kept), timings);
            cn.set_stop(options.stop);
            cn.set_interrupt(options.interrupt_requested);
            low = cn.solve(s, u_prev, xc);
            kept = cn.release_solver();
        }
        spent += low.iterations;
        if (low.stopped) {
            low.iterations = spent;
            return low;
        }
        if (!low.converged) {
            tried << "; at " << factor << " r (schur) from the same initial guess: " << low.message;
            continue;
        }
        const int low_iterations = low.iterations;
        Vector xf = xc;
        StepReport fin = nw.solve(s, u_prev, xf);
        spent += fin.iterations;
        if (fin.stopped) {
            fin.iterations = spent;
            return fin;
        }
        if (!fin.converged) {
            tried << "; at " << factor << " r: converged in " << low_iterations
                  << " Newton iterations, then at r from there: " << fin.message;
            continue;
        }
        std::ostringstream note;
        if (failed.iterations > 0)
            note << "Newton at r failed (" << failed.message << "); ";
        else
            note << "r continuation " << failed.message << ": ";
        note << "solved at " << factor << " r by schur in " << low_iterations
             << " Newton iterations, then at r in " << fin.iterations;
        fin.continuation_factor = factor;
        fin.continuation_iterations = spent - fin.iterations;
        fin.continuation_note = note.str();
        fin.iterations = spent;
        fin.linear_iterations += failed.linear_iterations;
        fin.linear_seconds += failed.linear_seconds + low.linear_seconds;
        fin.linear_setup_seconds += failed.linear_setup_seconds + low.linear_setup_seconds;
        fin.linear_assembly_seconds += failed.linear_assembly_seconds + low.linear_assembly_seconds;
        fin.fallback_solves += failed.fallback_solves;
        if (fin.fallback_reason.empty()) fin.fallback_reason = failed.fallback_reason;
        fin.seconds += failed.seconds + low.seconds;
        x = xf;
        return fin;
    }
    failed.iterations = spent;
    failed.message += tried.str();
    return failed;
}

} // namespace

RunResult solve(const Problem& problem, const SolveOptions& options) {
    problem.validate();
    options.linear.validate();
    // The levels are numbered as the solver needs them (a lattice sweep: by macro triangles).
    const Problem::Numbering numbering = hierarchy_numbering(problem, options.linear);
    const auto numbered_at_step = [&](int step) {
        Problem p = problem.at_step(step);
        p.numbering = numbering;
        return p;
    };
    RunResult res;
    res.solver.spec = options.linear;
    res.solver.spec.numbering = numbering;
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
                                     needs_coarse_level(options.linear),
                                 {problem.load_steps, options.keep_step_states});
    res.memory_limit = process_memory_limit();
    check_memory_fits(res.memory, res.memory_limit, res.predicted_sizes);
    // Supports released or taken up between load steps (Support::active) change which components
    // are unknowns: the hierarchy, its solvers and Newton drivers are then rebuilt for the new
    // step's supports (Problem::at_step), and the state carried over through the nodal values.
    int phase_step = 1; // the load step whose supports the current hierarchy has
    res.hierarchy = build_hierarchy(numbered_at_step(1), options.q_rule, &res.timings);
    const auto& levels = res.hierarchy.levels;
    res.warnings = initial_gap_warnings(problem, levels.front());
    const int n_levels = res.hierarchy.n_levels();
    const int finest = n_levels - 1;
    const bool all_levels =
        options.coarse_to_fine || options.solve_all_levels || needs_coarse_level(options.linear);
    const int first = all_levels ? 0 : finest;

    // Solvers, Newton drivers and the level below of each level (fixed while the supports are;
    // the coarse statuses are passed by set_coarse_statuses after every coarse load step).
    std::vector<LevelBelow> below(static_cast<size_t>(n_levels));
    std::vector<std::unique_ptr<ContactNewton>> newton(static_cast<size_t>(n_levels));
    std::vector<NewtonSystemSolver*> system(static_cast<size_t>(n_levels), nullptr);
    auto setup_solvers = [&]() {
        for (int l = first; l < n_levels; ++l) {
            ScopedTimer t(&res.timings, "setup/linear_solver");
            const Level& L = levels[static_cast<size_t>(l)];
            LinearSolverSpec spec = options.linear;
            if (l == 0 && l != finest) spec = LinearSolverSpec{};
            if (options.exact_fallback && spec.method == solvers::Method::krylov)
                spec.give_up_budget = kFallbackKrylovBudget;
            auto& lb = below[static_cast<size_t>(l)];
            lb = LevelBelow{};
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
            if (options.exact_fallback && spec.method == solvers::Method::krylov) {
                const LevelSize size = res.predicted_sizes[static_cast<size_t>(l)];
                newton[static_cast<size_t>(l)]->set_fallback([&L, size, l]() {
                    const std::string why = schur_does_not_fit(size, l);
                    MLC_CHECK(why.empty(), why);
                    return make_schur_system_solver(L);
                });
            }
            newton[static_cast<size_t>(l)]->set_interrupt(options.interrupt_requested);
            newton[static_cast<size_t>(l)]->set_stop(options.stop);
        }
    };
    setup_solvers();

    std::vector<Vector> x(static_cast<size_t>(n_levels)), u_prev(static_cast<size_t>(n_levels)),
        u_now(static_cast<size_t>(n_levels));
    for (int l = 0; l < n_levels; ++l) {
        x[static_cast<size_t>(l)] = Vector::Zero(levels[static_cast<size_t>(l)].n_unknowns());
        u_prev[static_cast<size_t>(l)] =
            Vector::Zero(2 * levels[static_cast<size_t>(l)].mesh.n_vertices());
    }
    std::vector<Vector> x_before(
        static_cast<size_t>(n_levels)); // each level's state before its solve
    // SolveOptions::extrapolate: each level's state two steps back (x^0 = 0; emptied when the
    // supports change, the states before then being of another set of unknowns).
    std::vector<Vector> x_older(static_cast<size_t>(n_levels));
    if (options.extrapolate)
        for (int l = 0; l < n_levels; ++l)
            x_older[static_cast<size_t>(l)] = Vector::Zero(x[static_cast<size_t>(l)].size());
    res.level_steps.resize(static_cast<size_t>(n_levels));
    res.converged = true;
    const double t_start = wall_seconds();
    std::vector<double> level_seconds(static_cast<size_t>(n_levels), 0.0);
    std::vector<int> level_count(static_cast<size_t>(n_levels), 0);
    // SolveOptions::r_continuation: the factor that worked on each level (0: not needed yet).
    std::vector<double> continued(static_cast<size_t>(n_levels), 0.0);
    std::vector<std::unique_ptr<NewtonSystemSolver>> continuation_solver(
        static_cast<size_t>(n_levels));
    Deformation deformation; // the largest of the completed steps, finest level
    int rotation_step = 0, strain_step = 0;
    std::string not_unique; // the first completed step whose state is not unique
    for (int step = 1; step <= problem.load_steps && res.converged; ++step) {
        const double s = static_cast<double>(step) / problem.load_steps;
        if (!problem.same_supports(step, phase_step)) {
            // New supports: rebuild, then carry the state over. Displacements through the nodal
            // values at the end of the previous step (u_prev, every component, prescribed or
            // not), multipliers by contactor vertex.
            std::vector<std::vector<std::pair<int, Vector>>> lambda(static_cast<size_t>(n_levels));
            for (int l = first; l < n_levels; ++l) {
                const Level& L = levels[static_cast<size_t>(l)];
                for (size_t e = 0; e < L.contacts.size(); ++e)
                    lambda[static_cast<size_t>(l)].emplace_back(
                        L.contacts[e].vertex[0],
                        x[static_cast<size_t>(l)].segment(L.lambda_dof[e],
                                                          L.contacts[e].n_multipliers()));
            }
            for (auto& nw : newton)
                nw.reset(); // they refer to the levels about to be replaced
            for (auto& c : continuation_solver)
                c.reset(); // likewise (SolveOptions::r_continuation starts over)
            std::fill(continued.begin(), continued.end(), 0.0);
            {
                ScopedTimer t(&res.timings, "setup/supports_changed");
                try {
                    res.hierarchy =
                        build_hierarchy(numbered_at_step(step), options.q_rule, &res.timings);
                } catch (const InvalidInput& e) {
                    throw InvalidInput("load step " + std::to_string(step) +
                                       ", with the supports active from this step on: " + e.what());
                }
            }
            MLC_CHECK(res.hierarchy.n_levels() == n_levels,
                      "internal error: the rebuilt hierarchy has another number of levels");
            // The contact nodes must stay those of the first step: the per-step states
            // (step_nodes, contact_steps.csv) are read with the final level's contact elements.
            // They change only when a support fully fixes or frees a contactor vertex.
            for (int l = first; l < n_levels; ++l) {
                const Level& L = levels[static_cast<size_t>(l)];
                const auto& old = lambda[static_cast<size_t>(l)];
                bool same = old.size() == L.contacts.size();
                for (size_t e = 0; same && e < old.size(); ++e)
                    same = old[e].first == L.contacts[e].vertex[0];
                if (same) continue;
                // A vertex that is no longer a contact node (now fully fixed), or a new one.
                std::vector<char> was(static_cast<size_t>(L.mesh.n_vertices()), 0);
                for (const auto& o : old)
                    was[static_cast<size_t>(o.first)] = 1;
                int v = -1;
                bool fixed = false;
                for (const auto& o : old)
                    if (v < 0 && L.contact_of_vertex[static_cast<size_t>(o.first)] < 0) {
                        v = o.first;
                        fixed = true;
                    }
                for (const auto& c : L.contacts)
                    if (v < 0 && !was[static_cast<size_t>(c.vertex[0])]) v = c.vertex[0];
                const Vec2& p = L.mesh.vertices[static_cast<size_t>(std::max(v, 0))];
                MLC_CHECK(false, "load step "
                                     << step << ": the supports active from this step on "
                                     << (fixed ? "fix both components of" : "free a component of")
                                     << " the contactor vertex (" << p.x() << ", " << p.y()
                                     << ") on level " << l
                                     << ", which changes the contact nodes; a support that is "
                                        "released or taken up along the path may hold one "
                                        "component of a contactor vertex only");
            }
            setup_solvers();
            phase_step = step;
            for (auto& xo : x_older)
                xo.resize(0);
            for (int l = 0; l < n_levels; ++l) {
                const size_t li = static_cast<size_t>(l);
                const Level& L = levels[li];
                x[li] = Vector::Zero(L.n_unknowns());
                for (int v = 0; v < L.mesh.n_vertices(); ++v)
                    for (int c = 0; c < 2; ++c)
                        if (const int d = L.dofs.u_dof(v, c); d >= 0)
                            x[li][d] = u_prev[li][2 * v + c];
                for (const auto& [v, lam] : lambda[li]) {
                    const int e = L.contact_of_vertex[static_cast<size_t>(v)];
                    if (e >= 0 && L.contacts[static_cast<size_t>(e)].n_multipliers() ==
                                      static_cast<int>(lam.size()))
                        x[li].segment(L.lambda_dof[static_cast<size_t>(e)], lam.size()) = lam;
                }
            }
        }
        for (int l = first; l < n_levels; ++l) {
            const size_t li = static_cast<size_t>(l);
            const Level& L = levels[li];
            ContactNewton& nw = *newton[li];
            LevelStep ls;
            ls.level = l;
            if (options.transfer_increment) x_before[li] = x[li]; // step - 1, for the level above
            // SolveOptions::extrapolate: the level's own state extrapolated from its last two
            // steps, taken when Newton would stop there at once (the step is then linear: no
            // status changed); otherwise the usual guess below, as without the option.
            bool extrapolated = false;
            if (options.extrapolate) {
                if (x_older[li].size() == x[li].size()) {
                    Vector xe = 2.0 * x[li] - x_older[li];
                    x_older[li] = x[li];
                    StepReport r = nw.check(s, u_prev[li], xe);
                    if (r.converged) {
                        x[li] = std::move(xe);
                        ls.report = std::move(r);
                        extrapolated = true;
                        ls.extrapolated = true;
                    }
                } else {
                    x_older[li] = x[li];
                }
            }
            if (options.coarse_to_fine && l > first && !extrapolated) {
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
                const Vector inc_coarse = inc ? Vector(x[li - 1] - x_before[li - 1]) : Vector();
                const Vector& xc = inc ? inc_coarse : x[li - 1];
                Vector& xl = x[li];
                parallel::for_rows(static_cast<size_t>(L.mesh.n_vertices()),
                                   parallel::kTouchRowsPerChunk / 2, [&](size_t b, size_t e) {
                                       for (auto v = static_cast<int>(b); v < static_cast<int>(e);
                                            ++v)
                                           for (int c = 0; c < 2; ++c)
                                               if (const int d = L.dofs.u_dof(v, c); d >= 0)
                                                   xl[d] = (inc ? xl[d] : 0.0) + uf[2 * v + c];
                                   });
                // Q's rows of the multipliers only (Q is zero on the displacement rows); the sums
                // of Eigen's row-major `T.Q * xc`, whose result starts at zero.
                const SparseMatrix& Q = T.Q;
                for (size_t e = 0; e < L.contacts.size(); ++e)
                    for (int k = 0; k < L.contacts[e].n_multipliers(); ++k) {
                        const Index d = L.lambda_dof[e] + k;
                        double row = 0.0;
                        for (SparseMatrix::InnerIterator it(Q, d); it; ++it)
                            row += it.value() * xc[it.index()];
                        xl[d] = (inc ? xl[d] : 0.0) + (0.0 + 1.0 * row);
                    }
                ls.predicted = true;
                ls.predicted_statuses = nw.statuses(s, u_prev[li], xl);
            }
            try {
                const Vector x0 = options.r_continuation ? x[li] : Vector();
                if (extrapolated) {
                    // ls.report is check()'s: converged at the extrapolated state.
                } else if (continued[li] > 0) {
                    // Newton at r failed on this level in an earlier step: straight to the
                    // continuation (a failed attempt at r would only cost).
                    ls.report = StepReport{};
                    ls.report.load_factor = s;
                    ls.report.message = "as in an earlier load step of this level";
                } else {
                    ls.report = nw.solve(s, u_prev[li], x[li]);
                }
                if (options.r_continuation && !ls.report.converged && !ls.report.stopped &&
                    !L.contacts.empty()) {
                    x[li] = x0;
                    ls.report = continue_in_r(res.hierarchy.levels[li], l, res.predicted_sizes[li],
                                              problem.newton, nw, s, u_prev[li], x0, x[li],
                                              std::move(ls.report), continued[li],
                                              continuation_solver[li], options, &res.timings);
                    continued[li] = ls.report.continuation_factor;
                }
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
                // The cause, when it is one of the problem's (a load with no equilibrium, a
                // rigid motion nothing holds), comes first: how Newton failed on it follows.
                std::string why = no_equilibrium(problem, L, s);
                if (why.empty() && rep.counts.stick == 0 &&
                    rep.counts.slip_forward + rep.counts.slip_backward > 0) {
                    // Newton's last iterate (the report's statuses): no node sticks. Whether a
                    // free rigid motion is tangential at every contact node is then all to ask.
                    std::vector<ContactNodeState> slipping(L.contacts.size());
                    for (auto& n : slipping)
                        n.status = contact::Status::slip_forward;
                    why = unheld_tangential_motion(problem, L, slipping);
                }
                if (!why.empty()) os << ": " << why << ". Newton";
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
        {
            // Small-displacement theory and uniqueness, on the finest level at this step: the
            // largest rotation and strain over the steps, the first non-unique state.
            const Deformation d = max_deformation(levels[static_cast<size_t>(finest)], res.u_full);
            if (d.rotation > deformation.rotation) {
                deformation.rotation = d.rotation;
                deformation.rotation_triangle = d.rotation_triangle;
                rotation_step = step;
            }
            if (d.strain > deformation.strain) {
                deformation.strain = d.strain;
                deformation.strain_triangle = d.strain_triangle;
                strain_step = step;
            }
            if (not_unique.empty()) {
                not_unique = unheld_tangential_motion(problem, levels[static_cast<size_t>(finest)],
                                                      res.nodes);
                if (!not_unique.empty())
                    not_unique = "load step " + std::to_string(step) + ": " + not_unique;
            }
        }
        for (int l = first; l < n_levels; ++l)
            u_prev[static_cast<size_t>(l)] = u_now[static_cast<size_t>(l)];
    }
    res.x = x.back();
    {
        const Level& F = levels[static_cast<size_t>(finest)];
        const auto centroid = [&](int t) {
            const auto& tri = F.mesh.triangles[static_cast<size_t>(t)];
            Vec2 c = Vec2::Zero();
            for (int v : tri)
                c += F.mesh.vertices[static_cast<size_t>(v)] / 3.0;
            std::ostringstream os;
            os << "triangle " << t << " at (" << c.x() << ", " << c.y() << ")";
            return os.str();
        };
        std::ostringstream os;
        os << std::setprecision(3);
        if (deformation.rotation > kSmallRotationLimit) {
            os << "large rotation: " << centroid(deformation.rotation_triangle)
               << " of the finest level rotates by " << deformation.rotation << " rad at load step "
               << rotation_step << ", above " << kSmallRotationLimit
               << " rad: small-displacement theory (linear strains, contact normals and gaps of "
                  "the undeformed shape) does not hold there and the results are not reliable; "
                  "hold the body so that it cannot roll or turn, or reduce the loads";
            res.warnings.push_back(os.str());
            os.str("");
        }
        if (deformation.strain > kSmallStrainLimit) {
            os << "large strain: " << centroid(deformation.strain_triangle)
               << " of the finest level has a principal strain of " << deformation.strain
               << " at load step " << strain_step << ", above " << kSmallStrainLimit
               << ": small-displacement theory (linear elasticity) does not hold there and the "
                  "results are not reliable; reduce the loads or prescribed displacements";
            res.warnings.push_back(os.str());
        }
        if (!not_unique.empty()) res.warnings.push_back(not_unique);
    }
    if (const solvers::Multigrid* mg = system[static_cast<size_t>(finest)]->multigrid())
        res.multigrid = mg->report();
    return res;
}

} // namespace mlc::levels

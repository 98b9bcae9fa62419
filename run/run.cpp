// SPDX-License-Identifier: MIT
// `mlcontact run`.
#include "run/run.hpp"
#include "run/run3.hpp"
#include "scene/scene3.hpp"

#include "core/check.hpp"
#include "core/memory.hpp"
#include "core/parallel.hpp"
#include "core/stop.hpp"
#include "levels/solve.hpp"
#include "run/interrupt.hpp"
#include "run/output.hpp"
#include "run/plot_script.hpp"
#include "scene/scene.hpp"

#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>

namespace mlc::apps {

void apply_overrides(levels::Problem& p, const RunOptions& opt) {
    if (opt.levels) {
        // Refinements of the scene's mesh: of the file's mesh when its levels were recovered
        // (the file's mesh is then level p.recovered_levels), as [scene].levels counts them.
        const int k = p.recovered_levels;
        MLC_CHECK(*opt.levels >= 0 && *opt.levels <= 12 - k,
                  "--levels must lie in [0, "
                      << 12 - k << "], found " << *opt.levels
                      << (k > 0 ? " (the scene's Gmsh mesh is already "
                                  "level " +
                                      std::to_string(k) + " of its recovered levels)"
                                : std::string()));
        p.levels = k + *opt.levels;
    }
    if (opt.numbering) p.numbering = levels::parse_numbering(*opt.numbering, "--numbering");
    if (opt.load_steps) {
        MLC_CHECK(*opt.load_steps >= 1, "--steps must be at least 1, found " << *opt.load_steps);
        p.load_steps = *opt.load_steps;
    }
    for (auto& c : p.contacts) {
        if (opt.mu) {
            MLC_CHECK(std::isfinite(*opt.mu) && *opt.mu >= 0,
                      "--mu must be >= 0, found " << *opt.mu);
            c.mu = *opt.mu;
        }
        if (opt.r) {
            MLC_CHECK(std::isfinite(*opt.r) && *opt.r > 0, "--r must be > 0, found " << *opt.r);
            c.r = *opt.r;
        }
    }
    p.validate();
}

levels::SolverRequest solver_request(const RunOptions& opt) {
    levels::SolverRequest req;
    if (opt.linear) req.linear = solvers::parse_method(*opt.linear);
    if (opt.krylov) req.krylov = solvers::parse_krylov(*opt.krylov);
    if (opt.pc) req.pc = solvers::parse_pc(*opt.pc);
    req.rel_tol = opt.linear_rel_tol;
    if (opt.numbering) req.numbering = levels::parse_numbering(*opt.numbering, "--numbering");
    return req;
}

levels::SolveOptions run_solve_options(levels::Problem& p, const RunOptions& opt,
                                       levels::SolverPlan& plan, int processes) {
    levels::SolveOptions so;
    so.predicted_sizes = levels::predict_level_sizes(p); // level 0 built once for both
    plan = levels::plan_solver(p, solver_request(opt), processes, &so.predicted_sizes);
    p.numbering = plan.numbering();
    so.coarse_to_fine = !opt.cold;
    so.extrapolate = !opt.no_extrapolation;
    so.linear = plan.spec;
    MLC_CHECK(!opt.no_fallback || plan.spec.method == solvers::Method::krylov,
              "--no-fallback applies to Krylov solves only; the solver of this run is "
                  << plan.spec.method << " (" << plan.reason << ")");
    so.exact_fallback = !opt.no_fallback;
    so.r_continuation = !opt.no_continuation;
    return so;
}

namespace {

/// A Newton residual that became NaN/Inf in the last load step: a numerical breakdown (exit 3),
/// not a lack of convergence.
bool nonfinite_residual(const levels::RunResult& r) {
    for (const auto& s : r.steps)
        for (double v : s.residuals)
            if (!std::isfinite(v)) return true;
    return false;
}

/// What the run's memory estimate, multigrid, exact fallbacks and r continuations were.
void print_solve_notes(std::ostream& os, const levels::RunResult& r) {
    os << "memory: estimated peak " << levels::format_bytes(r.memory.bytes) << " of "
       << levels::format_bytes(r.memory_limit.bytes) << " available (" << r.memory_limit.source
       << "); measured peak " << levels::format_bytes(peak_rss_bytes()) << "\n";
    if (r.multigrid) os << *r.multigrid;
    {
        int fallbacks = 0;
        std::string first;
        for (const auto& ls : r.level_steps)
            for (const auto& st : ls) {
                if (first.empty() && !st.report.fallback_reason.empty())
                    first = "level " + std::to_string(st.level) + ", load step " +
                            std::to_string(st.report.step) + ": " + st.report.fallback_reason;
                fallbacks += st.report.fallback_solves;
            }
        if (fallbacks > 0)
            os << "exact fallback: " << fallbacks
               << " Newton system(s) solved again by the exact schur solver after the Krylov "
                  "solve failed (first: "
               << first << ")\n";
        for (const auto& ls : r.level_steps)
            for (const auto& st : ls)
                if (st.report.continuation_factor > 0)
                    os << "r continuation: level " << st.level << ", load step " << st.report.step
                       << ": " << st.report.continuation_note << "\n";
    }
}

/// The files written (the step series summed up), after "wrote".
void print_written(std::ostream& os, const std::filesystem::path& dir, const SummaryStatus& st,
                   const StepFiles* steps) {
    std::vector<std::string> files;
    for (const auto& f : st.files)
        if (f.rfind("solution_step_", 0) != 0 && f.rfind("solution_level_", 0) != 0 &&
            !f.ends_with(".pvd") && f != "contact.png")
            files.push_back(f);
    if (steps) {
        for (const auto& c : steps->collections())
            files.push_back(c);
        if (steps->finest_steps() > 0)
            files.push_back("solution_step_*.vtu (" + std::to_string(steps->finest_steps()) +
                            " load steps)");
    }
    if (st.plot == "written") files.push_back("contact.png");
    files.push_back("summary.json");
    os << "\nwrote";
    for (size_t i = 0; i < files.size(); ++i)
        os << (i ? ", " : " ") << (dir / files[i]).string();
    os << "\n";
}

/// A run stopped by a signal: what its files hold; returns the exit code 128 + signal.
int print_stopped(std::ostream& os, const levels::RunResult& r, const SummaryStatus& st) {
    const int sig = stop_signal();
    if (r.stopped)
        os << "\nstopped by " << signal_name(sig) << ": " << r.failure << "; the files above hold "
           << (r.completed_steps > 0 ? "load steps 1-" + std::to_string(r.completed_steps)
                                     : std::string("no load step"))
           << "\n";
    else
        os << "\nstopped by " << signal_name(sig)
           << " while the files were written: " << st.stopped_at
           << "; summary.json lists the files written\n";
    return 128 + (sig > 0 ? sig : 2);
}

} // namespace

int run_scene(const RunOptions& opt, std::ostream& os) {
    if (scene::scene_dimension(opt.scene) == 3) return run_scene3(opt, os);
    // A signal while the scene's domains are meshed stops the meshing; nothing is written.
    std::optional<levels::Problem> loaded;
    try {
        loaded = scene::load_scene(opt.scene, [&] { return opt.stop && opt.stop->load(); });
    } catch (const Interrupted& e) {
        const int sig = stop_signal();
        os << "stopped by " << signal_name(sig) << " while meshing the scene (" << e.what()
           << "); nothing written\n";
        return 128 + (sig > 0 ? sig : 2);
    }
    levels::Problem p = std::move(*loaded);
    apply_overrides(p, opt);
    MLC_CHECK(opt.vtu == "binary" || opt.vtu == "ascii",
              "--vtu must be binary or ascii, found '" << opt.vtu << "'");
    OutputOptions out;
    out.vtu = opt.vtu == "ascii" ? mesh::VtuFormat::ascii : mesh::VtuFormat::binary;
    const std::filesystem::path dir = opt.out.empty() ? "out/" + p.name : opt.out;
    // The folder is checked and locked before the solve: a second run on it is refused at once,
    // an unwritable one before any time is spent.
    OutputFolder folder(dir);
    set_stop_summary(dir / "summary.json", killed_summary(p.name, SIGINT, 1),
                     killed_summary(p.name, SIGTERM, 1));
    levels::SolverPlan choice;
    levels::SolveOptions so = run_solve_options(p, opt, choice);
    std::optional<StepFiles> steps;
    if (opt.every_step || opt.every_level) steps.emplace(folder, p, opt.every_level, out.vtu);
    // Progress lines, the stop flag, and the files of every step when asked.
    struct RunObserver final : levels::ProgressLines {
        using ProgressLines::ProgressLines;
        const std::atomic<bool>* stop = nullptr;
        std::optional<StepFiles>* steps = nullptr;
        void level_step(const levels::LevelStepState& s) override {
            if (*steps) (**steps)(s);
        }
        bool stop_requested() override { return stop && stop->load(); }
    } observer(opt.quiet ? nullptr : &os, opt.progress_eta);
    observer.stop = opt.stop;
    observer.steps = &steps;
    os << "mlcontact: solving '" << p.name << "'\n";
    if (folder.took_over_from() > 0)
        os << "note: the output folder's lock was left by process " << folder.took_over_from()
           << ", which has ended; taken over\n";
    os << "Newton-system solver: " << choice.spec << " (" << choice.reason << ")\n";
    {
        // The BLAS behind CHOLMOD (docs/results/blas.md).
        const std::string blas = parallel::blas_library();
        const bool openblas = blas.find("OpenBLAS") != std::string::npos;
        if (choice.spec.method == solvers::Method::schur && !openblas && blas != "none")
            os << "note: the BLAS is " << blas << ", not OpenBLAS: schur's set-up runs 1.9-2.5x "
               << "slower with it (scripts/deps.sh installs libopenblas0-serial)\n";
        if (openblas && blas.find("SINGLE_THREADED") == std::string::npos &&
            !std::getenv("OPENBLAS_NUM_THREADS"))
            os << "note: the BLAS is a threaded OpenBLAS (" << blas << "): its threads spin "
               << "against ours (short runs take up to 2x); set OPENBLAS_NUM_THREADS=1 or choose "
               << "libopenblas0-serial with update-alternatives\n";
    }
    levels::RunResult r = levels::solve(p, so, &observer);
    r.solver = choice;
    print_solve_notes(os, r);
    os << "\n";
    print_header(os, p, r);
    print_summary(os, p, r);
    if (!r.converged && !r.stopped) {
        const bool breakdown = nonfinite_residual(r);
        if (!breakdown) os << "\nerror: " << r.failure << "\n"; // else main says it
        if (!folder.files().empty()) { // step files were written: say what they are
            SummaryStatus st;
            st.files = folder.files();
            write_summary(dir, p, r, out, st);
        }
        set_stop_summary({}, {}, {});
        if (breakdown) throw SolverBreakdown(r.failure);
        return 2;
    }
    // Writing. A run stopped during its solve writes the files of its completed steps; a signal
    // that arrives while a finished run writes abandons the file being written and skips the
    // rest (summary.json then says "stopped": true, "complete": false).
    set_writes_stoppable(!r.stopped);
    SummaryStatus st;
    st.stopped = r.stopped;
    if (r.stopped) st.stopped_at = r.failure;
    bool plot_failed = false;
    std::string plot_cause;
    try {
        folder.begin_writing(p.name);
        std::vector<std::string> written;
        try {
            write_result_files(dir, p, r, out, written);
        } catch (const Interrupted&) {
            for (const auto& w : written)
                folder.add(w);
            throw;
        }
        for (const auto& w : written)
            folder.add(w);
        if (opt.plot && r.completed_steps > 0) {
            // A failed plot leaves no plot (an earlier run's would not show these results).
            std::error_code ec;
            std::filesystem::remove(dir / "contact.png", ec);
            if (run_plot_script("plot_contact.py", dir, os, steps ? "--all-steps" : "",
                                &plot_cause)) {
                folder.add("contact.png");
                st.plot = "written";
            } else {
                std::filesystem::remove(dir / "contact.png", ec);
                plot_failed = true;
                st.plot = "failed: " + plot_cause;
            }
        }
    } catch (const Interrupted& e) {
        st.stopped = true;
        st.complete = false;
        st.stopped_at = e.what();
    }
    set_writes_stoppable(false);
    if (!st.stopped && stop_requested()) { // after the last file: all written
        st.stopped = true;
        st.stopped_at = "after the result files were written";
    }
    st.files = folder.files();
    write_summary(dir, p, r, out, st);
    set_stop_summary({}, {}, {});
    print_written(os, dir, st, steps ? &*steps : nullptr);
    if (st.stopped) return print_stopped(os, r, st);
    if (plot_failed) {
        std::cerr << "mlcontact: error: the results were written, but the plot failed: "
                  << plot_cause << "\n";
        return 4;
    }
    return 0;
}

} // namespace mlc::apps

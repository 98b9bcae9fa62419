// SPDX-License-Identifier: MIT
// `mlcontact run`.
#include "apps/run.hpp"

#include "apps/interrupt.hpp"
#include "apps/output.hpp"
#include "apps/study_status_transfer.hpp"
#include "core/check.hpp"
#include "core/memory.hpp"
#include "core/parallel.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
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

levels::SolveOptions run_solve_options(levels::Problem& p, const RunOptions& opt,
                                       levels::SolverChoice& choice) {
    levels::SolveOptions so;
    so.predicted_sizes = levels::predict_level_sizes(p); // level 0 built once for both
    choice = levels::choose_solver(
        p, {opt.linear, opt.krylov, opt.pc, opt.linear_rel_tol, opt.numbering},
        &so.predicted_sizes);
    // The default mg's lattice sweep needs its levels numbered by macro triangle.
    if (choice.lattice_numbering) p.numbering = levels::Problem::Numbering::lattice;
    so.coarse_to_fine = !opt.cold;
    so.extrapolate = !opt.no_extrapolation;
    so.linear = choice.spec;
    MLC_CHECK(!opt.no_fallback || choice.spec.method == "krylov",
              "--no-fallback applies to Krylov solves only; the solver of this run is "
                  << choice.spec.method << " (" << choice.reason << ")");
    so.exact_fallback = !opt.no_fallback;
    so.r_continuation = !opt.no_continuation;
    return so;
}

int run_scene(const RunOptions& opt, std::ostream& os) {
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
    levels::SolverChoice choice;
    levels::SolveOptions so = run_solve_options(p, opt, choice);
    so.progress = opt.quiet ? nullptr : &os;
    so.progress_eta = opt.progress_eta;
    so.stop = opt.stop;
    std::optional<StepFiles> steps;
    if (opt.every_step || opt.every_level) {
        steps.emplace(dir, p, opt.every_level, out.vtu);
        so.on_level_step = [&](const levels::LevelStepState& s) { (*steps)(s); };
    }
    os << "mlcontact: solving '" << p.name << "'\n";
    os << "Newton-system solver: " << choice.spec << " (" << choice.reason << ")\n";
    {
        // The BLAS behind CHOLMOD (README "The BLAS behind schur").
        const std::string blas = parallel::blas_library();
        const bool openblas = blas.find("OpenBLAS") != std::string::npos;
        if (choice.spec.method == "schur" && !openblas && blas != "none")
            os << "note: the BLAS is " << blas << ", not OpenBLAS: schur's set-up runs 1.9-2.5x "
               << "slower with it (scripts/deps.sh installs libopenblas0-serial)\n";
        if (openblas && blas.find("SINGLE_THREADED") == std::string::npos &&
            !std::getenv("OPENBLAS_NUM_THREADS"))
            os << "note: the BLAS is a threaded OpenBLAS (" << blas << "): its threads spin "
               << "against ours (short runs take up to 2x); set OPENBLAS_NUM_THREADS=1 or choose "
               << "libopenblas0-serial with update-alternatives\n";
    }
    levels::RunResult r = levels::solve(p, so);
    r.solver = choice;
    os << "memory: estimated peak " << levels::format_bytes(r.memory.bytes) << " of "
       << levels::format_bytes(r.memory_limit.bytes) << " available (" << r.memory_limit.source
       << "); measured peak " << levels::format_bytes(peak_rss_bytes()) << "\n";
    for (const auto& w : r.warnings)
        os << "warning: " << w << "\n";
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
    os << "\n";
    print_header(os, p, r);
    print_summary(os, p, r);
    if (!r.converged && !r.stopped) {
        os << "\nerror: " << r.failure << "\n";
        return 2;
    }
    std::vector<std::string> files = write_outputs(dir, p, r, out);
    if (steps) {
        for (const auto& c : steps->collections())
            files.push_back(c);
        if (steps->finest_steps() > 0)
            files.push_back("solution_step_*.vtu (" + std::to_string(steps->finest_steps()) +
                            " load steps)");
    }
    if (opt.plot && r.completed_steps > 0 &&
        run_plot_script("plot_contact.py", dir, os, steps ? "--all-steps" : ""))
        files.push_back("contact.png");
    os << "\nwrote";
    for (size_t i = 0; i < files.size(); ++i)
        os << (i ? ", " : " ") << (dir / files[i]).string();
    os << "\n";
    if (r.stopped) {
        const int sig = stop_signal();
        os << "\nstopped by " << signal_name(sig) << ": " << r.failure << "; the files above hold "
           << (r.completed_steps > 0 ? "load steps 1-" + std::to_string(r.completed_steps)
                                     : std::string("no load step"))
           << "\n";
        return 128 + (sig > 0 ? sig : 2);
    }
    return 0;
}

} // namespace mlc::apps

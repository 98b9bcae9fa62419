// SPDX-License-Identifier: MIT
// `mlcontact run`.
#include "apps/run.hpp"

#include "apps/output.hpp"
#include "core/check.hpp"
#include "core/memory.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"

#include <cmath>

namespace mlc::apps {

void apply_overrides(levels::Problem& p, const RunOptions& opt) {
    if (opt.levels) {
        MLC_CHECK(*opt.levels >= 0 && *opt.levels <= 12,
                  "--levels must lie in [0, 12], found " << *opt.levels);
        p.levels = *opt.levels;
    }
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

levels::SolveOptions run_solve_options(const levels::Problem& p, const RunOptions& opt,
                                       levels::SolverChoice& choice) {
    levels::SolveOptions so;
    so.predicted_sizes = levels::predict_level_sizes(p); // level 0 built once for both
    choice = levels::choose_solver(p, {opt.linear, opt.krylov, opt.pc, opt.linear_rel_tol},
                                   &so.predicted_sizes);
    so.coarse_to_fine = !opt.cold;
    so.linear = choice.spec;
    return so;
}

int run_scene(const RunOptions& opt, std::ostream& os) {
    levels::Problem p = scene::load_scene(opt.scene);
    apply_overrides(p, opt);
    levels::SolverChoice choice;
    levels::SolveOptions so = run_solve_options(p, opt, choice);
    so.progress = opt.quiet ? nullptr : &os;
    os << "mlcontact: solving '" << p.name << "'\n";
    os << "Newton-system solver: " << choice.spec << " (" << choice.reason << ")\n";
    levels::RunResult r = levels::solve(p, so);
    r.solver = choice;
    os << "memory: estimated peak " << levels::format_bytes(r.memory.bytes) << " of "
       << levels::format_bytes(r.memory_limit.bytes) << " available (" << r.memory_limit.source
       << "); measured peak " << levels::format_bytes(peak_rss_bytes()) << "\n";
    os << "\n";
    print_header(os, p, r);
    print_summary(os, p, r);
    const std::string dir = opt.out.empty() ? "out/" + p.name : opt.out;
    if (!r.converged) {
        os << "\nerror: " << r.failure << "\n";
        return 2;
    }
    write_outputs(dir, p, r);
    os << "\nwrote " << dir << "/solution.vtu, " << dir << "/contact.csv, " << dir
       << "/summary.json\n";
    return 0;
}

} // namespace mlc::apps

// SPDX-License-Identifier: MIT
// `mlcontact run`.
#include "apps/run.hpp"

#include "apps/output.hpp"
#include "core/check.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"

#include <cmath>

namespace mlc::apps {

int run_scene(const RunOptions& opt, std::ostream& os) {
    levels::Problem p = scene::load_scene(opt.scene);
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
    levels::SolveOptions so;
    so.progress = opt.quiet ? nullptr : &os;
    so.coarse_to_fine = !opt.cold;
    so.linear.method = opt.linear;
    so.linear.krylov = opt.krylov;
    so.linear.pc = opt.pc;
    so.linear.rel_tol = opt.linear_rel_tol;
    so.linear.validate();
    os << "mlcontact: solving '" << p.name << "'\n";
    levels::RunResult r = levels::solve(p, so);
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

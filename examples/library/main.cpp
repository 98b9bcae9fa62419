// SPDX-License-Identifier: MIT
// Solves a scene with the installed mlcontact library, as `mlcontact run SCENE --levels L` does,
// and prints the resultant contact force of every contact pair.
//   contact_resultant [SCENE [LEVELS]]     (default: square, the scene's levels)
#include <mlcontact/core/check.hpp>
#include <mlcontact/levels/checks.hpp>
#include <mlcontact/levels/solve.hpp>
#include <mlcontact/run/run.hpp>
#include <mlcontact/scene/scene.hpp>

#include <cstdio>
#include <exception>
#include <string>

int main(int argc, char** argv) {
    try {
        mlc::apps::RunOptions opt;
        if (argc > 1) opt.scene = argv[1];
        if (argc > 2) opt.levels = std::stoi(argv[2]);
        mlc::levels::Problem p = mlc::scene::load_scene(opt.scene);
        mlc::apps::apply_overrides(p, opt); // the driver's checks and overrides
        mlc::levels::SolverPlan choice;
        const mlc::levels::SolveOptions so = mlc::apps::run_solve_options(p, opt, choice);
        const mlc::levels::RunResult r = mlc::levels::solve(p, so);
        if (!r.converged) {
            std::fprintf(stderr, "not converged: %s\n", r.failure.c_str());
            return 2;
        }
        for (size_t k = 0; k < p.contacts.size(); ++k) {
            int closed = 0;
            const mlc::Vec2 f = mlc::levels::contact_resultant(r, static_cast<int>(k), &closed);
            std::printf("contact '%s': resultant %.17g %.17g, %d nodes in contact\n",
                        p.contacts[k].name.c_str(), f.x(), f.y(), closed);
        }
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
}

// SPDX-License-Identifier: MIT
// The studies' subcommands: their options and what runs them.
#include "studies/commands.hpp"

#include "run/preconditioners.hpp"
#include "run/run3_detail.hpp"
#include "scene/scene.hpp"
#include "scene/scene3.hpp"
#include "studies/accuracy.hpp"
#include "studies/error_vs_time.hpp"
#include "studies/extremes.hpp"
#include "studies/preconditioners.hpp"
#include "studies/status_transfer.hpp"

#include <algorithm>
#include <memory>

namespace mlc::apps {

namespace {

Action add_status_transfer(CLI::App& st) {
    struct Args {
        StatusTransferOptions o;
        std::string scene = "square", out, q = "paper";
    };
    auto a = std::make_shared<Args>();
    st.add_option("scene", a->scene, "scene file or built-in name (default square)");
    st.add_option("--levels,-l", a->o.levels, "finest level (default 3)");
    st.add_option("--out,-o", a->out, "output folder (default out/<scene>/status_transfer)");
    st.add_option("--q-rule", a->q, "multiplier interpolation: paper (default) or conservative")
        ->check(CLI::IsMember({"paper", "conservative"}));
    st.add_flag("--increment", a->o.increment,
                "warm start = own previous state + interpolated coarse increment");
    st.add_flag("!--no-plot", a->o.plot, "do not draw the PNG");
    return [a, &st](const Launch& at) {
        a->o.out = a->out;
        a->o.q_rule = a->q == "paper" ? transfer::QRule::paper : transfer::QRule::conservative;
        if (scene::scene_dimension(a->scene) == 3) {
            if (st.count("--q-rule") > 0 || a->o.increment)
                throw InvalidInput(std::string(st.count("--q-rule") > 0 ? "--q-rule" : "--increment") +
                                   " applies to 2D scenes: 3D multipliers travel by the surface Q, "
                                   "from the level below's state of the same step");
            return study_status_transfer3(scene::load_scene3(a->scene), a->o, at.os);
        }
        return study_status_transfer(scene::load_scene(a->scene), a->o, at.os);
    };
}

Action add_extremes(CLI::App& ex) {
    struct Args {
        ExtremesOptions o;
        std::string out;
    };
    auto a = std::make_shared<Args>();
    ex.add_option("--levels,-l", a->o.levels,
                  "finest level of every case (default 2; 1 with --dimension 3)");
    ex.add_option("--seconds", a->o.seconds_per_case, "time bound per case (default 120)");
    ex.add_option("--only", a->o.only, "run only cases whose name contains this text");
    ex.add_option("--out,-o", a->out, "output folder (default out/studies/extremes)");
    ex.add_option("--linear", a->o.linear,
                  "Newton-system solver of every case: schur, lu or krylov (default: each "
                  "solver the run default may choose, one table each)")
        ->check(CLI::IsMember({"schur", "lu", "krylov"}));
    ex.add_option("--krylov", a->o.krylov, "Krylov method (implies a Krylov solve)");
    ex.add_option("--pc", a->o.pc, pc_option_help("preconditioner (implies a Krylov solve)"));
    ex.add_option("--linear-tol", a->o.linear_rel_tol,
                  "relative tolerance of each Krylov solve (implies a Krylov solve)");
    ex.add_option("--dimension", a->o.dimension,
                  "2: the square-based cases (default); 3: the block3d- and stack3d-based ones "
                  "(default --levels 1; --linear schur|lu only)")
        ->check(CLI::IsMember({2, 3}));
    return [a, &ex](const Launch& at) {
        a->o.out = a->out;
        if (a->o.dimension == 3) {
            if (ex.count("--levels") == 0) a->o.levels = 1;
            return study_extremes3(a->o, at.os);
        }
        return study_extremes(a->o, at.os);
    };
}

Action add_error_vs_time(CLI::App& ev) {
    struct Args {
        ErrorVsTimeOptions o;
        std::string scene = "square", out;
    };
    auto a = std::make_shared<Args>();
    ev.add_option("scene", a->scene, "scene file or built-in name (default square)");
    ev.add_option("--levels,-l", a->o.max_level,
                  "configurations on levels 0..L (default 3; 1 on a 3D scene)");
    ev.add_option("--ilu-levels", a->o.ilu_max_level,
                  "the ILU(0) configurations only up to this level (default 3)");
    ev.add_option("--only", a->o.only,
                  "run only the configurations whose name contains this text (e.g. mg)");
    ev.add_option("--out,-o", a->out, "output folder (default out/studies/<scene>_error_vs_time)");
    ev.add_flag("!--no-plot", a->o.plot, "do not draw the PNG");
    return [a, &ev](const Launch& at) {
        a->o.out = a->out;
        if (scene::scene_dimension(a->scene) == 3) {
            if (ev.count("--ilu-levels") > 0)
                throw InvalidInput("--ilu-levels applies to 2D scenes: the 3D grid has no ILU(0) "
                                   "configurations (gmres+mg, schur and lu, coarse-to-fine and "
                                   "cold)");
            if (ev.count("--levels") == 0) a->o.max_level = 1;
            return study_error_vs_time3(scene::load_scene3(a->scene), a->o, at.os);
        }
        return study_error_vs_time(scene::load_scene(a->scene), a->o, at.os);
    };
}

struct PreconditionerArgs {
    PreconditionerStudyOptions o;
    std::string scene = "square", out;
};

// The preconditioner study on a 3D scene: every cell an `mlcontact run` (one process without
// --np-list), GMRES by default, the papers' family that has a 3D form beside mg and hypre's MGR
// (BoomerAMG on the displacements); over processes the ones with a distributed form.
int preconditioners3(PreconditionerArgs& a, const CLI::App& ps, const Launch& at) {
    const levels::ElasticProblem3 p = scene::load_scene3(a.scene);
    NpStudyScene sc;
    sc.name = p.name;
    sc.dimension = 3;
    sc.young_modulus = p.bodies.front().material.E;
    for (const auto& b : p.bodies)
        sc.young_modulus = std::min(sc.young_modulus, b.material.E);
    sc.check = [](const std::string& kr, const std::string& pc, int np) {
        RunOptions ro;
        ro.krylov = kr;
        ro.pc = pc;
        (void)detail3::krylov_spec3(ro, np > 1);
    };
    PreconditionerStudyOptions& o = a.o;
    if (o.np_list.empty()) o.np_list = {1};
    const bool several = *std::max_element(o.np_list.begin(), o.np_list.end()) > 1;
    if (ps.count("--pc") == 0)
        o.pcs = several ? std::vector<std::string>{"diag", "ilu:0", "mg"}
                        : std::vector<std::string>{"diag", "ilu:0", "cf", "sorcf", "mgr", "mg"};
    if (ps.count("--krylov") == 0) o.krylovs = {"gmres"};
    o.scene_arg = a.scene;
    return study_preconditioners_np(sc, o, at.os);
}

Action add_preconditioners(CLI::App& ps) {
    using Args = PreconditionerArgs;
    auto a = std::make_shared<Args>();
    ps.add_option("scene", a->scene, "scene file or built-in name (default square)");
    ps.add_option("--levels,-l", a->o.levels, "finest level (default 2)");
    ps.add_option("--mu", a->o.mu, "friction coefficients (list)")->delimiter(',');
    ps.add_option("--r", a->o.r_over_E, "penalty factors r/E (list)")->delimiter(',');
    ps.add_option(
        "--pc", a->o.pcs,
        pc_option_help("preconditioners (list; default diag ilu:0 cf sorcf ebe ebe:variant=c5)"));
    ps.add_option("--krylov", a->o.krylovs, "Krylov methods (list; default cgs)")->delimiter(',');
    ps.add_option("--steps", a->o.load_steps, "load steps (default: the scene's)");
    ps.add_option("--tol", a->o.rel_tol, "Krylov relative tolerance (default 1e-8)");
    ps.add_option("--max-iter", a->o.max_iter, "Krylov iterations per Newton step (default 5000)");
    ps.add_option("--seconds", a->o.seconds_per_run, "time bound per combination (default 600)");
    ps.add_option("--out,-o", a->out, "output folder");
    ps.add_flag("!--no-plot", a->o.plot, "do not draw the PNG");
    auto* np = ps.add_option("--np-list", a->o.np_list,
                             "process counts (list, e.g. 1,2,4): run each cell as `mlcontact "
                             "run` on N processes (mpiexec -n N for N > 1) and tabulate the "
                             "Krylov iterations per Newton step by N (default --pc diag "
                             "ilu:0 ebe mg)")
                   ->delimiter(',');
    ps.add_option("--mpiexec", a->o.mpiexec,
                  "with --np-list: the MPI launcher (default mpiexec or mpirun on PATH, with "
                  "--oversubscribe for Open MPI)")
        ->needs(np);
    return [a, &ps](const Launch& at) {
        a->o.out = a->out;
        if (scene::scene_dimension(a->scene) == 3) return preconditioners3(*a, ps, at);
        if (!a->o.np_list.empty()) {
            a->o.scene_arg = a->scene;
            if (ps.count("--pc") == 0) a->o.pcs = {"diag", "ilu:0", "ebe", "mg"};
            return study_preconditioners_np(scene::load_scene(a->scene), a->o, at.os);
        }
        return study_preconditioners(scene::load_scene(a->scene), a->o, at.os);
    };
}

Action add_accuracy(CLI::App& ac) {
    struct Args {
        AccuracyOptions o;
        std::string scene = "hertz", out;
    };
    auto a = std::make_shared<Args>();
    ac.add_option("scene", a->scene, "scene file or built-in name (default hertz)");
    ac.add_option("--levels,-l", a->o.levels, "levels 0..L (default 3)");
    ac.add_option("--out,-o", a->out, "output folder (default out/<scene>/accuracy)");
    ac.add_flag("!--no-plot", a->o.plot, "do not draw the PNG");
    ac.add_flag("!--no-compare", a->o.compare_integration,
                "node-on-facet scenes: do not also solve with the other integration variants");
    return [a, &ac](const Launch& at) {
        a->o.out = a->out;
        if (scene::scene_dimension(a->scene) == 3) {
            if (ac.count("--no-compare") > 0)
                throw InvalidInput("--no-compare applies to 2D node-on-facet scenes; the 3D "
                                   "accuracy study compares no integration variants");
            return study_accuracy3(scene::load_scene3(a->scene), a->o, at.os);
        }
        return study_accuracy(scene::load_scene(a->scene), a->o, at.os);
    };
}

} // namespace

std::vector<Command> study_commands() {
    return {
        {.name = "status-transfer",
         .usage = "predicted vs converged statuses and Newton iterations, coarse-to-fine vs "
                  "cold, per level",
         .add = add_status_transfer},
        {.name = "extremes",
         .usage = "stiff and extreme cases, each bounded in time",
         .add = add_extremes},
        {.name = "error-vs-time",
         .usage = "error against wall time over levels and solvers",
         .add = add_error_vs_time},
        {.name = "preconditioners",
         .usage = "Krylov iterations and times per Newton step per preconditioner",
         .add = add_preconditioners},
        {.name = "accuracy",
         .usage = "closed-form errors per level and observed orders (hertz, mindlin, patch)",
         .add = add_accuracy},
    };
}

} // namespace mlc::apps

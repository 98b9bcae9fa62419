// SPDX-License-Identifier: MIT
// The mlcontact command-line driver.
//
// `mlcontact run` with no argument solves the built-in `square` scene (the 1997 paper's square
// test); `mlcontact scenes` lists the built-in scenes; `mlcontact show NAME` prints one, as a
// starting point for your own scene file. Every error is reported as one line on stderr with a
// non-zero exit code: 1 for bad input (a bad command line included), 2 for a solve that did not
// converge, 3 for a numerical breakdown (NaN/Inf included), 4 for a run whose results were
// written but whose --plot failed; a run stopped by SIGINT / SIGTERM exits 130 / 143 after
// writing the files of its completed load steps.
#include "bench/bench.hpp"
#include "bench/comm.hpp"
#include "bench/distributed.hpp"
#include "run/interrupt.hpp"
#include "run/preconditioners.hpp"
#include "run/run.hpp"
#include "run/run_distributed.hpp"
#include "studies/accuracy.hpp"
#include "studies/error_vs_time.hpp"
#include "studies/extremes.hpp"
#include "studies/preconditioners.hpp"
#include "studies/status_transfer.hpp"
#include "comm/world.hpp"
#include "core/check.hpp"
#include "core/memory.hpp"
#include "mesh/io/gmsh.hpp"
#include "scene/scene.hpp"

#include <CLI/CLI.hpp>
#include <iostream>
#include <unistd.h>

int main(int argc, char** argv) {
    mlc::keep_freed_memory();
    CLI::App app{"mlcontact: multilevel frictional contact in 2D linear elasticity"};
    app.set_version_flag("--version", std::string("mlcontact ") + MLC_VERSION);
    app.require_subcommand(1);
    mlc::apps::RunOptions ro;
    auto* run = app.add_subcommand("run", "solve a scene (default: the built-in 'square')");
    run->add_option("scene", ro.scene, "scene file (.toml) or built-in scene name");
    run->add_option("--levels,-l", ro.levels, "number of 1->4 refinements of the level-0 mesh");
    run->add_option("--numbering", ro.numbering,
                    "order of each level's unknowns: hilbert (along a Hilbert curve) or lattice "
                    "(macro triangle by macro triangle, the order mg:smoother=lattice sweeps in "
                    "without copies; levels that are not refinements keep hilbert). Default: "
                    "lattice when the default solver sweeps by lattices (mg above the crossover, "
                    "--levels >= 4), else hilbert; hilbert with the default solver keeps its block "
                    "sweep")
        ->check(CLI::IsMember({"hilbert", "lattice"}));
    run->add_option("--mu", ro.mu, "friction coefficient for every contact pair");
    run->add_option("--r", ro.r, "augmentation parameter r for every contact pair");
    run->add_option("--steps", ro.load_steps, "number of load steps");
    run->add_option("--out,-o", ro.out, "output folder (default out/<scene name>)");
    run->add_flag("--quiet,-q", ro.quiet, "no per-step progress");
    run->add_flag("--cold", ro.cold,
                  "solve the finest level from the previous step alone (default: coarse-to-fine)");
    run->add_option("--linear", ro.linear,
                    "Newton system solver: schur (exact, condensed), lu, or krylov (default: "
                    "chosen by size, see the report)")
        ->check(CLI::IsMember({"schur", "lu", "krylov"}));
    run->add_option("--krylov", ro.krylov,
                    "Krylov method (implies a Krylov solve): cgs, bicg, bicgstab, gmres (default: "
                    "bicgstab with the driver's mg, cgs with --pc)");
    run->add_option("--pc", ro.pc,
                    mlc::apps::pc_option_help("preconditioner (implies a Krylov solve; default mg "
                                              "above the crossover, see the report)"));
    run->add_flag("--no-fallback", ro.no_fallback,
                  "a Newton system the Krylov solve fails on ends the run, instead of being "
                  "solved again by the exact schur solver (the default; reported)");
    run->add_flag("--no-extrapolation", ro.no_extrapolation,
                  "every load step starts from the usual guess (coarse-to-fine or the previous "
                  "step), instead of first trying each level's last two states extrapolated, taken "
                  "when no status changes over the step (then it is exact: 0 Newton iterations)");
    run->add_flag("--no-continuation", ro.no_continuation,
                  "a load step whose Newton fails at the scene's r ends the run, instead of being "
                  "solved again at r/100 (then r/1e4) with the exact schur solver and finished "
                  "at r from there (the default; reported)");
    run->add_option("--partition-level", ro.partition_level,
                    "under mpirun with several processes: the level whose mesh is partitioned "
                    "(default: the coarsest with 2000 triangles per process, at most --levels - 1; "
                    "see docs/parallel.md#parallel-partition-level)")
        ->check(CLI::NonNegativeNumber);
    run->add_option("--linear-tol", ro.linear_rel_tol,
                    "relative tolerance of each Krylov solve (implies a Krylov solve; default "
                    "1e-10)");
    auto* pcs = app.add_subcommand("preconditioners",
                                   "list the preconditioners, their options and what they need");
    run->add_option("--vtu", ro.vtu,
                    "VTU encoding: binary (appended, zlib-compressed; default) or ascii")
        ->check(CLI::IsMember({"binary", "ascii"}));
    run->add_flag("--every-step", ro.every_step,
                  "write a VTU per load step (solution_step_0001.vtu, ...) and solution.pvd");
    run->add_flag("--every-level", ro.every_level,
                  "with --every-step's files, a VTU series and solution_level_<l>.pvd per "
                  "coarser level solved");
    run->add_flag("--plot", ro.plot,
                  "draw contact.png: pressure and tangential traction along each contact pair");
    auto* study = app.add_subcommand("study", "run a study (see docs/studies.md#studies)");
    study->require_subcommand(1);
    mlc::apps::StatusTransferOptions sto;
    std::string sto_scene = "square", sto_out, sto_q = "paper";
    auto* st = study->add_subcommand("status-transfer",
                                     "predicted vs converged statuses and Newton iterations, "
                                     "coarse-to-fine vs cold, per level");
    st->add_option("scene", sto_scene, "scene file or built-in name (default square)");
    st->add_option("--levels,-l", sto.levels, "finest level (default 3)");
    st->add_option("--out,-o", sto_out, "output folder (default out/<scene>/status_transfer)");
    st->add_option("--q-rule", sto_q, "multiplier interpolation: paper (default) or conservative")
        ->check(CLI::IsMember({"paper", "conservative"}));
    st->add_flag("--increment", sto.increment,
                 "warm start = own previous state + interpolated coarse increment");
    st->add_flag("!--no-plot", sto.plot, "do not draw the PNG");
    mlc::apps::ExtremesOptions exo;
    std::string exo_out;
    auto* ex = study->add_subcommand("extremes", "stiff and extreme cases, each bounded in time");
    ex->add_option("--levels,-l", exo.levels, "finest level of every case (default 2)");
    ex->add_option("--seconds", exo.seconds_per_case, "time bound per case (default 120)");
    ex->add_option("--only", exo.only, "run only cases whose name contains this text");
    ex->add_option("--out,-o", exo_out, "output folder (default out/studies/extremes)");
    ex->add_option("--linear", exo.linear,
                   "Newton-system solver of every case: schur, lu or krylov (default: each "
                   "solver the run default may choose, one table each)")
        ->check(CLI::IsMember({"schur", "lu", "krylov"}));
    ex->add_option("--krylov", exo.krylov, "Krylov method (implies a Krylov solve)");
    ex->add_option("--pc", exo.pc,
                   mlc::apps::pc_option_help("preconditioner (implies a Krylov solve)"));
    ex->add_option("--linear-tol", exo.linear_rel_tol,
                   "relative tolerance of each Krylov solve (implies a Krylov solve)");
    mlc::apps::ErrorVsTimeOptions evo;
    std::string evo_scene = "square", evo_out;
    auto* ev =
        study->add_subcommand("error-vs-time", "error against wall time over levels and solvers");
    ev->add_option("scene", evo_scene, "scene file or built-in name (default square)");
    ev->add_option("--levels,-l", evo.max_level, "configurations on levels 0..L (default 3)");
    ev->add_option("--ilu-levels", evo.ilu_max_level,
                   "the ILU(0) configurations only up to this level (default 3)");
    ev->add_option("--only", evo.only,
                   "run only the configurations whose name contains this text (e.g. mg)");
    ev->add_option("--out,-o", evo_out,
                   "output folder (default out/studies/<scene>_error_vs_time)");
    ev->add_flag("!--no-plot", evo.plot, "do not draw the PNG");
    mlc::apps::PreconditionerStudyOptions pso;
    std::string pso_scene = "square", pso_out;
    auto* ps = study->add_subcommand(
        "preconditioners", "Krylov iterations and times per Newton step per preconditioner");
    ps->add_option("scene", pso_scene, "scene file or built-in name (default square)");
    ps->add_option("--levels,-l", pso.levels, "finest level (default 2)");
    ps->add_option("--mu", pso.mu, "friction coefficients (list)")->delimiter(',');
    ps->add_option("--r", pso.r_over_E, "penalty factors r/E (list)")->delimiter(',');
    ps->add_option("--pc", pso.pcs,
                   mlc::apps::pc_option_help(
                       "preconditioners (list; default diag ilu:0 cf sorcf ebe ebe:variant=c5)"));
    ps->add_option("--krylov", pso.krylovs, "Krylov methods (list; default cgs)")->delimiter(',');
    ps->add_option("--steps", pso.load_steps, "load steps (default: the scene's)");
    ps->add_option("--tol", pso.rel_tol, "Krylov relative tolerance (default 1e-8)");
    ps->add_option("--max-iter", pso.max_iter, "Krylov iterations per Newton step (default 5000)");
    ps->add_option("--seconds", pso.seconds_per_run, "time bound per combination (default 600)");
    ps->add_option("--out,-o", pso_out, "output folder");
    ps->add_flag("!--no-plot", pso.plot, "do not draw the PNG");
    auto* ps_np = ps->add_option("--np-list", pso.np_list,
                                 "process counts (list, e.g. 1,2,4): run each cell as `mlcontact "
                                 "run` on N processes (mpiexec -n N for N > 1) and tabulate the "
                                 "Krylov iterations per Newton step by N (default --pc diag "
                                 "ilu:0 ebe mg)")
                      ->delimiter(',');
    ps->add_option("--mpiexec", pso.mpiexec,
                   "with --np-list: the MPI launcher (default mpiexec or mpirun on PATH, with "
                   "--oversubscribe for Open MPI)")
        ->needs(ps_np);
    mlc::apps::AccuracyOptions aco;
    std::string aco_scene = "hertz", aco_out;
    auto* ac = study->add_subcommand(
        "accuracy", "closed-form errors per level and observed orders (hertz, mindlin, patch)");
    ac->add_option("scene", aco_scene, "scene file or built-in name (default hertz)");
    ac->add_option("--levels,-l", aco.levels, "levels 0..L (default 3)");
    ac->add_option("--out,-o", aco_out, "output folder (default out/<scene>/accuracy)");
    ac->add_flag("!--no-plot", aco.plot, "do not draw the PNG");
    ac->add_flag("!--no-compare", aco.compare_integration,
                 "node-on-facet scenes: do not also solve with the other integration variants");
    auto* bench =
        app.add_subcommand("bench", "scaling benchmarks (see docs/studies.md#bench)");
    bench->require_subcommand(1);
    mlc::apps::BenchSquareOptions bso;
    std::string bso_out;
    auto* bsq =
        bench->add_subcommand("square", "full coarse-to-fine solve per solver: JSON per level");
    bsq->add_option("scene", bso.scene, "scene file or built-in name (default square)");
    bsq->add_option("--levels,-l", bso.levels, "finest level (default 3)");
    bsq->add_option(
        "--pc", bso.pcs,
        mlc::apps::pc_option_help(
            "solvers (space-separated list): schur, lu, default (the run's default above the "
            "crossover: BiCGStab + mg:pre=0,post=2, damped with a two-body pair, with "
            "smoother=lattice from level 4 on levels numbered by lattices), or "
            "preconditioner specs (default: default)"));
    bsq->add_option("--krylov", bso.krylov,
                    "Krylov method for the preconditioners (default cgs; for `default` the run's, "
                    "bicgstab)");
    bsq->add_option(
           "--numbering", bso.numbering,
           "order of each level's unknowns: hilbert or lattice (as run's); default: lattice "
           "when every solver is the default one and --levels >= 4 (the run's default "
           "there), else hilbert")
        ->check(CLI::IsMember({"hilbert", "lattice"}));
    bsq->add_option("--tol", bso.rel_tol, "Krylov relative tolerance (default 1e-8)");
    bsq->add_option("--max-iter", bso.max_iter, "Krylov iterations per Newton step (default 5000)");
    bsq->add_option("--repeat", bso.repeat, "runs per solver, times are medians (default 1)");
    bsq->add_flag("--extrapolate", bso.extrapolate,
                  "take linear load steps at the extrapolated state, as `run` does by default "
                  "(default here: every step's Newton measured)");
    bsq->add_option("--out,-o", bso_out, "JSON file (default out/bench/<scene>_L<L>.json)");
    bsq->add_option("--stream-doubles", bso.stream_doubles,
                    "STREAM array length in doubles (default 2^25 = 33554432: 256 MiB each)")
        ->check(CLI::PositiveNumber);
    mlc::apps::BenchElasticOptions beo;
    std::string beo_out;
    auto* bel = bench->add_subcommand("elastic", "elastic block: BoomerAMG-PCG vs mg-CG/GMRES");
    bel->add_option("scene", beo.scene, "scene file or built-in name (default square)");
    bel->add_option("--levels,-l", beo.levels, "level of the elastic block (default 3)");
    bel->add_option("--tol", beo.rel_tol, "relative tolerance of every solve (default 1e-8)");
    bel->add_option("--max-iter", beo.max_iter, "iterations of every solve (default 1000)");
    bel->add_option("--repeat", beo.repeat, "runs per solver, times are medians (default 1)");
    bel->add_option("--out,-o", beo_out, "JSON file (default out/bench/elastic_<scene>_L<L>.json)");
    mlc::apps::BenchCommOptions bco;
    std::string bco_out;
    auto* bcm = bench->add_subcommand(
        "comm", "messages, bytes, reductions and seconds per V-cycle, mat-vec and Krylov "
                "iteration of the distributed mg (under mpirun with the PMPI library preloaded; "
                "see docs/parallel.md#cluster-communication)");
    bcm->add_option("scene", bco.scene, "scene file or built-in name (default square)");
    bcm->add_option("--levels,-l", bco.levels, "finest level, 1..8 (default 5)");
    bcm->add_option("--partition-level", bco.partition_level,
                    "partition level p (default: the run's rule)")
        ->check(CLI::NonNegativeNumber);
    bcm->add_option("--ops", bco.ops, "repetitions of each operation per timing (default 10)");
    bcm->add_option("--tol", bco.rel_tol, "relative tolerance of the CGS solve (default 1e-8)");
    bcm->add_option("--out,-o", bco_out,
                    "JSON file (default out/bench/comm_<scene>_L<L>_np<N>.json)");
    mlc::apps::BenchNewtonOptions bno;
    std::string bno_out;
    bool bno_no_amg = false;
    auto* bnw = bench->add_subcommand(
        "newton", "the finest level's Newton systems of a run: mg vs hypre MGR and BoomerAMG");
    bnw->add_option("scene", bno.scene, "scene file or built-in name (default square)");
    bnw->add_option("--levels,-l", bno.levels, "finest level, >= 1 (default 3)");
    bnw->add_option("--pc", bno.pc, "our preconditioner, the run's (default mg)");
    bnw->add_option("--mgr", bno.mgr, "the hypre MGR spec (default mgr; see --pc mgr in run)");
    bnw->add_flag("--no-amg", bno_no_amg, "leave out BoomerAMG on the whole Jacobian");
    bnw->add_flag("!--no-hypre-gmres", bno.hypre_gmres,
                  "leave out MGR inside hypre's own FlexGMRES(50) (column mgr+fgmres)");
    bnw->add_option("--krylov", bno.krylov, "Krylov method of every solve (default cgs)");
    bnw->add_option("--tol", bno.rel_tol, "relative tolerance of every solve (default 1e-8)");
    bnw->add_option("--max-iter", bno.max_iter,
                    "iterations per solve (default 1000; hopeless solves stop earlier)");
    bnw->add_option("--repeat", bno.repeat, "runs per thread count, times are medians (default 1)");
    bnw->add_option("--threads", bno.threads,
                    "thread counts of our preconditioner's runs (default 1 2; hypre: 1)")
        ->delimiter(',');
    bnw->add_option("--out,-o", bno_out, "JSON file (default out/bench/newton_<scene>_L<L>.json)");
    auto* scenes = app.add_subcommand("scenes", "list the built-in scenes");
    std::string show_name;
    auto* show =
        app.add_subcommand("show", "print a built-in scene's TOML (or a mesh file it reads)");
    show->add_option("name", show_name,
                     "built-in scene name, or a mesh file name such as hertz_gmsh.msh")
        ->required();
    int show_msh_level = -1;
    show->add_option("--msh-level", show_msh_level,
                     "print the scene's mesh refined L times as a Gmsh 2.2 file instead "
                     "(`show square --msh-level 4 > square_L4.msh`; a scene reading it recovers "
                     "its levels unless [scene].recover_levels = false)")
        ->check(CLI::NonNegativeNumber);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // Bad command lines are bad input: exit 1 with the usual prefix, and where to look.
        if (e.get_exit_code() == 0) return app.exit(e);
        // The deepest command parsed, e.g. `mlcontact study`.
        CLI::App* at = &app;
        std::string where = "mlcontact";
        for (bool deeper = true; deeper;) {
            deeper = false;
            for (auto* sub : at->get_subcommands([](CLI::App*) { return true; }))
                if (sub->parsed()) {
                    at = sub;
                    where += " " + sub->get_name();
                    deeper = true;
                    break;
                }
        }
        std::string what = e.what();
        const auto subs = at->get_subcommands([](CLI::App*) { return true; });
        if (!subs.empty() && at->get_subcommands().empty()) {
            // A command that needs a subcommand got none it knows: name the word it got.
            std::string word;
            for (int i = 1; i < argc; ++i) {
                const std::string a = argv[i];
                if (a.empty() || a[0] == '-' || a == at->get_name()) continue;
                bool known = false;
                for (CLI::App* c = &app; c; c = c->get_parent())
                    known = known || c->get_name() == a;
                for (const char* n : {"run", "study", "bench", "show", "scenes", "preconditioners"})
                    known = known || a == n;
                if (!known) {
                    word = a;
                    break;
                }
            }
            std::string names;
            for (const auto* sub : subs)
                names += (names.empty() ? "" : ", ") + sub->get_name();
            what = (word.empty() ? "`" + where + "` needs a command"
                                 : "unknown command '" + word + "' for `" + where + "`") +
                   " (one of: " + names + ")";
        }
        std::cerr << "mlcontact: error: " << what << " (see `" << where << " --help`)\n";
        return 1;
    }
    // Started by mpirun with several processes: `run` and `bench square|elastic` are distributed
    // (issue 12); the other commands are one process only and say so (N copies of a one-process
    // run would write the same files). One process, with or without mpirun, runs as always.
    const bool distributed = mlc::comm::launched_by_mpirun() && mlc::comm::world().size() > 1;
    const int rank = distributed ? mlc::comm::world().rank() : 0;
    if (distributed && !*run && !*bsq && !*bel && !*bcm) {
        if (rank == 0)
            std::cerr
                << "mlcontact: error: started as " << mlc::comm::world().size()
                << " MPI processes, but this command runs as one process: on several "
                   "processes run `mlcontact run` (one-body scenes, Krylov + mg) or `mlcontact "
                   "bench square|elastic|comm`; run the others without mpirun or with mpirun -np "
                   "1\n";
        return 1;
    }
    try {
        if (*run) {
            if (run->count("--out") > 0 && ro.out.empty())
                throw mlc::InvalidInput("--out needs a folder name, found an empty one; leave "
                                        "--out out to write to out/<scene name>");
            // Several processes: a signal ends them at once (mpirun follows its SIGTERM with
            // SIGKILL after a second; a stop after the current Newton iteration would need every
            // process to see it at the same iteration): temporaries removed, summary.json
            // written by process 0 saying so.
            if (distributed) {
                mlc::apps::install_stop_handlers(true, rank == 0 ? 0 : 500);
                return mlc::apps::run_scene_distributed(ro, mlc::comm::world(), std::cout);
            }
            // Under mpirun -np 1 too, a signal ends the run at once: mpirun follows it with
            // SIGKILL after a second, too soon for a stop after the current Newton iteration.
            mlc::apps::install_stop_handlers(mlc::comm::launched_by_mpirun());
            ro.stop = &mlc::apps::stop_flag();
            ro.progress_eta = ::isatty(STDOUT_FILENO) == 1;
            if (ro.partition_level)
                throw mlc::InvalidInput("--partition-level applies to runs on several processes "
                                        "(mpirun -np N, N > 1); this run is one process");
            return mlc::apps::run_scene(ro, std::cout);
        }
        if (*bsq) {
            bso.out = bso_out;
            if (distributed)
                return mlc::apps::bench_square_distributed(bso, mlc::comm::world(), std::cout);
            return mlc::apps::bench_square(bso, std::cout);
        }
        if (*bcm) {
            bco.out = bco_out;
            return mlc::apps::bench_comm(bco, mlc::comm::world(), std::cout);
        }
        if (*bnw) {
            bno.out = bno_out;
            bno.amg = !bno_no_amg;
            return mlc::apps::bench_newton(bno, std::cout);
        }
        if (*bel) {
            beo.out = beo_out;
            if (distributed)
                return mlc::apps::bench_elastic_distributed(beo, mlc::comm::world(), std::cout);
            return mlc::apps::bench_elastic(beo, std::cout);
        }
        if (*ev) {
            evo.out = evo_out;
            return mlc::apps::study_error_vs_time(mlc::scene::load_scene(evo_scene), evo,
                                                  std::cout);
        }
        if (*ac) {
            aco.out = aco_out;
            return mlc::apps::study_accuracy(mlc::scene::load_scene(aco_scene), aco, std::cout);
        }
        if (*ps) {
            pso.out = pso_out;
            if (!pso.np_list.empty()) {
                pso.scene_arg = pso_scene;
                if (ps->count("--pc") == 0) pso.pcs = {"diag", "ilu:0", "ebe", "mg"};
                return mlc::apps::study_preconditioners_np(mlc::scene::load_scene(pso_scene), pso,
                                                           std::cout);
            }
            return mlc::apps::study_preconditioners(mlc::scene::load_scene(pso_scene), pso,
                                                    std::cout);
        }
        if (*ex) {
            exo.out = exo_out;
            return mlc::apps::study_extremes(exo, std::cout);
        }
        if (*st) {
            sto.out = sto_out;
            sto.q_rule =
                sto_q == "paper" ? mlc::transfer::QRule::paper : mlc::transfer::QRule::conservative;
            return mlc::apps::study_status_transfer(mlc::scene::load_scene(sto_scene), sto,
                                                    std::cout);
        }
        if (*pcs) {
            mlc::apps::print_preconditioners(std::cout);
            return 0;
        }
        if (*scenes) {
            for (const auto& n : mlc::scene::builtin_scene_names())
                std::cout << n << "\n";
            return 0;
        }
        if (*show && show_msh_level >= 0) {
            // The scene's level-L mesh as a level-0 Gmsh file (its tags as physical curves).
            mlc::mesh::Mesh m = mlc::scene::load_scene(show_name).mesh0;
            for (int l = 0; l < show_msh_level; ++l)
                m = mlc::mesh::refine(m);
            mlc::mesh::write_gmsh(m, std::cout);
            return 0;
        }
        if (*show) {
            // A scene, or a mesh file a built-in scene reads (`show hertz_gmsh.msh`).
            std::string t = mlc::scene::builtin_scene_text(show_name);
            if (t.empty()) t = mlc::scene::builtin_file_text(show_name);
            if (t.empty()) throw mlc::InvalidInput("no built-in scene named '" + show_name + "'");
            std::cout << t;
            return 0;
        }
    } catch (const mlc::InvalidInput& e) {
        // Several processes: input errors are found by every process alike; rank 0 says it.
        if (rank == 0) std::cerr << "mlcontact: error: " << e.what() << "\n";
        return 1;
    } catch (const mlc::Interrupted& e) {
        // A stop request seen outside the solve (e.g. while meshing): nothing was written.
        const int sig = mlc::apps::stop_signal();
        if (rank == 0)
            std::cerr << "mlcontact: stopped by " << mlc::apps::signal_name(sig) << ": " << e.what()
                      << "\n";
        return 128 + (sig > 0 ? sig : 2);
    } catch (const mlc::SolverBreakdown& e) {
        std::cerr << "mlcontact: numerical breakdown"
                  << (distributed ? " (process " + std::to_string(rank) + ")" : "") << ": "
                  << e.what() << "\n";
        if (distributed) mlc::comm::abort_all(3); // the others may wait in a collective
        return 3;
    } catch (const std::exception& e) {
        std::cerr << "mlcontact: error"
                  << (distributed ? " (process " + std::to_string(rank) + ")" : "") << ": "
                  << e.what() << "\n";
        if (distributed) mlc::comm::abort_all(1);
        return 1;
    }
    return 0;
}

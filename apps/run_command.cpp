// SPDX-License-Identifier: MIT
// `mlcontact run`: its options, and the run on one process or on several.
#include "apps/driver.hpp"

#include "core/check.hpp"
#include "run/interrupt.hpp"
#include "run/preconditioners.hpp"
#include "run/run.hpp"
#include "run/run_distributed.hpp"

#include <memory>
#include <unistd.h>

namespace mlc::apps {

namespace {

Action add_run(CLI::App& run) {
    auto ro = std::make_shared<RunOptions>();
    run.add_option("scene", ro->scene, "scene file (.toml) or built-in scene name");
    run.add_option("--levels,-l", ro->levels, "number of 1->4 refinements of the level-0 mesh");
    run.add_option("--numbering", ro->numbering,
                   "order of each level's unknowns: hilbert (along a Hilbert curve) or lattice "
                   "(macro triangle by macro triangle, the order mg:smoother=lattice sweeps in "
                   "without copies; levels that are not refinements keep hilbert). Default: "
                   "lattice when the default solver sweeps by lattices (mg above the crossover, "
                   "--levels >= 4), else hilbert; hilbert with the default solver keeps its block "
                   "sweep")
        ->check(CLI::IsMember({"hilbert", "lattice"}));
    run.add_option("--mu", ro->mu, "friction coefficient for every contact pair");
    run.add_option("--r", ro->r, "augmentation parameter r for every contact pair");
    run.add_option("--steps", ro->load_steps, "number of load steps");
    run.add_option("--out,-o", ro->out, "output folder (default out/<scene name>)");
    run.add_flag("--quiet,-q", ro->quiet, "no per-step progress");
    run.add_flag("--cold", ro->cold,
                 "solve the finest level from the previous step alone (default: coarse-to-fine)");
    run.add_option("--linear", ro->linear,
                   "Newton system solver: schur (exact, condensed), lu, or krylov (default: "
                   "chosen by size, see the report)")
        ->check(CLI::IsMember({"schur", "lu", "krylov"}));
    run.add_option("--krylov", ro->krylov,
                   "Krylov method (implies a Krylov solve): cgs, bicg, bicgstab, gmres (default: "
                   "bicgstab with the driver's mg, cgs with --pc)");
    run.add_option("--pc", ro->pc,
                   pc_option_help("preconditioner (implies a Krylov solve; default mg "
                                  "above the crossover, see the report)"));
    run.add_flag("--no-fallback", ro->no_fallback,
                 "a Newton system the Krylov solve fails on ends the run, instead of being "
                 "solved again by the exact schur solver (the default; reported)");
    run.add_flag("--no-extrapolation", ro->no_extrapolation,
                 "every load step starts from the usual guess (coarse-to-fine or the previous "
                 "step), instead of first trying each level's last two states extrapolated, taken "
                 "when no status changes over the step (then it is exact: 0 Newton iterations)");
    run.add_flag("--no-continuation", ro->no_continuation,
                 "a load step whose Newton fails at the scene's r ends the run, instead of being "
                 "solved again at r/100 (then r/1e4) with the exact schur solver and finished "
                 "at r from there (the default; reported)");
    run.add_option("--partition-level", ro->partition_level,
                   "under mpirun with several processes: the level whose mesh is partitioned "
                   "(default: the coarsest with 2000 triangles per process, at most --levels - 1; "
                   "see docs/parallel.md#parallel-partition-level)")
        ->check(CLI::NonNegativeNumber);
    run.add_option("--linear-tol", ro->linear_rel_tol,
                   "relative tolerance of each Krylov solve (implies a Krylov solve; default "
                   "1e-10)");
    run.add_option("--vtu", ro->vtu,
                   "VTU encoding: binary (appended, zlib-compressed; default) or ascii")
        ->check(CLI::IsMember({"binary", "ascii"}));
    run.add_flag("--every-step", ro->every_step,
                 "write a VTU per load step (solution_step_0001.vtu, ...) and solution.pvd");
    run.add_flag("--every-level", ro->every_level,
                 "with --every-step's files, a VTU series and solution_level_<l>.pvd per "
                 "coarser level solved");
    run.add_flag("--plot", ro->plot,
                 "draw contact.png: pressure and tangential traction along each contact pair");
    return [ro, &run](const Launch& at) {
        if (run.count("--out") > 0 && ro->out.empty())
            throw InvalidInput("--out needs a folder name, found an empty one; leave "
                               "--out out to write to out/<scene name>");
        // Several processes: a signal ends them at once (mpirun follows its SIGTERM with
        // SIGKILL after a second; a stop after the current Newton iteration would need every
        // process to see it at the same iteration): temporaries removed, summary.json
        // written by process 0 saying so.
        if (at.distributed) {
            install_stop_handlers(true, at.rank == 0 ? 0 : 500);
            return run_scene_distributed(*ro, comm::world(), at.os);
        }
        // Under mpirun -np 1 too, a signal ends the run at once: mpirun follows it with
        // SIGKILL after a second, too soon for a stop after the current Newton iteration.
        install_stop_handlers(comm::launched_by_mpirun());
        ro->stop = &stop_flag();
        ro->progress_eta = ::isatty(STDOUT_FILENO) == 1;
        if (ro->partition_level)
            throw InvalidInput("--partition-level applies to runs on several processes "
                               "(mpirun -np N, N > 1); this run is one process");
        return run_scene(*ro, at.os);
    };
}

} // namespace

Command run_command() {
    return {.name = "run",
            .usage = "solve a scene (default: the built-in 'square')",
            .add = add_run,
            .distributed = true};
}

} // namespace mlc::apps

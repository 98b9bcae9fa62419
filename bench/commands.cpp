// SPDX-License-Identifier: MIT
// The benches' subcommands: their options and what runs them.
#include "bench/commands.hpp"

#include "bench/bench.hpp"
#include "bench/comm.hpp"
#include "bench/distributed.hpp"
#include "comm/world.hpp"
#include "core/check.hpp"
#include "run/preconditioners.hpp"
#include "scene/scene3.hpp"

#include <memory>

namespace mlc::apps {

namespace {

Action add_square(CLI::App& bsq) {
    struct Args {
        BenchSquareOptions o;
        std::string out;
    };
    auto a = std::make_shared<Args>();
    bsq.add_option("scene", a->o.scene, "scene file or built-in name (default square)");
    auto* levels = bsq.add_option("--levels,-l", a->o.levels,
                                  "finest level (default 3; a 3D scene: its [scene].levels)");
    bsq.add_option(
        "--pc", a->o.pcs,
        pc_option_help(
            "solvers (space-separated list): schur, lu, default (the run's default above the "
            "crossover: BiCGStab + mg:pre=0,post=2, damped with a two-body pair, with "
            "smoother=lattice from level 4 on levels numbered by lattices), or "
            "preconditioner specs (default: default). A 3D scene: default or mg (the 3D "
            "run's plan), schur, lu"));
    bsq.add_option("--krylov", a->o.krylov,
                   "Krylov method for the preconditioners (default cgs; for `default` the run's, "
                   "bicgstab)");
    bsq.add_option("--numbering", a->o.numbering,
                   "order of each level's unknowns: hilbert or lattice (as run's); default: "
                   "lattice when every solver is the default one and --levels >= 4 (the run's "
                   "default there), else hilbert")
        ->check(CLI::IsMember({"hilbert", "lattice"}));
    bsq.add_option("--tol", a->o.rel_tol, "Krylov relative tolerance (default 1e-8)");
    bsq.add_option("--max-iter", a->o.max_iter, "Krylov iterations per Newton step (default 5000)");
    bsq.add_option("--repeat", a->o.repeat, "runs per solver, times are medians (default 1)");
    bsq.add_flag("--extrapolate", a->o.extrapolate,
                 "take linear load steps at the extrapolated state, as `run` does by default "
                 "(default here: every step's Newton measured)");
    bsq.add_option("--out,-o", a->out, "JSON file (default out/bench/<scene>_L<L>.json)");
    bsq.add_option("--stream-doubles", a->o.stream_doubles,
                   "STREAM array length in doubles (default 2^25 = 33554432: 256 MiB each)")
        ->check(CLI::PositiveNumber);
    bsq.add_flag("--scaling", a->o.scaling,
                 "a 3D scene: finest L-1 and finest L alternated (--repeat runs each) and the "
                 "scaling criterion: mat-vecs per fine Newton step grow by <= 10 %, whole-run "
                 "time ratio <= 10");
    return [a, levels, &bsq](const Launch& at) {
        a->o.out = a->out;
        a->o.levels_from_scene = levels->count() == 0;
        a->o.given.clear();
        for (const CLI::Option* o : bsq.get_options())
            if (o->count() > 0) a->o.given.push_back(o->get_name());
        if (at.distributed) {
            MLC_CHECK(scene::scene_dimension(a->o.scene) != 3,
                      "bench square on a 3D scene runs on one process (3D runs are on one "
                      "process so far): run it without mpirun");
            MLC_CHECK(!a->o.scaling, "bench square: --scaling is for 3D scenes, on one process");
            return bench_square_distributed(a->o, comm::world(), at.os);
        }
        return bench_square(a->o, at.os);
    };
}

Action add_elastic(CLI::App& bel) {
    struct Args {
        BenchElasticOptions o;
        std::string out;
    };
    auto a = std::make_shared<Args>();
    bel.add_option("scene", a->o.scene, "scene file or built-in name (default square)");
    auto* levels = bel.add_option("--levels,-l", a->o.levels,
                                  "level of the elastic block (default 3; a 3D scene: its "
                                  "[scene].levels)");
    bel.add_option("--tol", a->o.rel_tol, "relative tolerance of every solve (default 1e-8)");
    bel.add_option("--max-iter", a->o.max_iter, "iterations of every solve (default 1000)");
    bel.add_option("--repeat", a->o.repeat, "runs per solver, times are medians (default 1)");
    bel.add_option("--out,-o", a->out, "JSON file (default out/bench/elastic_<scene>_L<L>.json)");
    bel.add_flag("--direct", a->o.direct,
                 "a 3D scene: also the direct solve, CHOLMOD's Cholesky factor in its "
                 "fill-reducing order (refused when its estimated memory does not fit)");
    return [a, levels](const Launch& at) {
        a->o.out = a->out;
        a->o.levels_from_scene = levels->count() == 0;
        if (at.distributed) return bench_elastic_distributed(a->o, comm::world(), at.os);
        return bench_elastic(a->o, at.os);
    };
}

Action add_comm(CLI::App& bcm) {
    struct Args {
        BenchCommOptions o;
        std::string out;
    };
    auto a = std::make_shared<Args>();
    bcm.add_option("scene", a->o.scene, "scene file or built-in name (default square)");
    bcm.add_option("--levels,-l", a->o.levels, "finest level, 1..8 (default 5)");
    bcm.add_option("--partition-level", a->o.partition_level,
                   "partition level p (default: the run's rule)")
        ->check(CLI::NonNegativeNumber);
    bcm.add_option("--ops", a->o.ops, "repetitions of each operation per timing (default 10)");
    bcm.add_option("--tol", a->o.rel_tol, "relative tolerance of the CGS solve (default 1e-8)");
    bcm.add_option("--out,-o", a->out,
                   "JSON file (default out/bench/comm_<scene>_L<L>_np<N>.json)");
    return [a](const Launch& at) {
        a->o.out = a->out;
        return bench_comm(a->o, comm::world(), at.os);
    };
}

Action add_newton(CLI::App& bnw) {
    struct Args {
        BenchNewtonOptions o;
        std::string out;
        bool no_amg = false;
    };
    auto a = std::make_shared<Args>();
    bnw.add_option("scene", a->o.scene, "scene file or built-in name (default square)");
    bnw.add_option("--levels,-l", a->o.levels, "finest level, >= 1 (default 3)");
    bnw.add_option("--pc", a->o.pc, "our preconditioner, the run's (default mg)");
    bnw.add_option("--mgr", a->o.mgr, "the hypre MGR spec (default mgr; see --pc mgr in run)");
    bnw.add_flag("--no-amg", a->no_amg, "leave out BoomerAMG on the whole Jacobian");
    bnw.add_flag("!--no-hypre-gmres", a->o.hypre_gmres,
                 "leave out MGR inside hypre's own FlexGMRES(50) (column mgr+fgmres)");
    bnw.add_option("--krylov", a->o.krylov, "Krylov method of every solve (default cgs)");
    bnw.add_option("--tol", a->o.rel_tol, "relative tolerance of every solve (default 1e-8)");
    bnw.add_option("--max-iter", a->o.max_iter,
                   "iterations per solve (default 1000; hopeless solves stop earlier)");
    bnw.add_option("--repeat", a->o.repeat, "runs per thread count, times are medians (default 1)");
    bnw.add_option("--threads", a->o.threads,
                   "thread counts of our preconditioner's runs (default 1 2; hypre: 1)")
        ->delimiter(',');
    bnw.add_option("--out,-o", a->out, "JSON file (default out/bench/newton_<scene>_L<L>.json)");
    return [a](const Launch& at) {
        a->o.out = a->out;
        a->o.amg = !a->no_amg;
        return bench_newton(a->o, at.os);
    };
}

} // namespace

std::vector<Command> bench_commands() {
    return {
        {.name = "square",
         .usage = "full coarse-to-fine solve per solver: JSON per level",
         .add = add_square,
         .distributed = true},
        {.name = "elastic",
         .usage = "elastic block: BoomerAMG-PCG vs mg-CG/GMRES",
         .add = add_elastic,
         .distributed = true},
        {.name = "comm",
         .usage = "messages, bytes, reductions and seconds per V-cycle, mat-vec and Krylov "
                  "iteration of the distributed mg (under mpirun with the PMPI library "
                  "preloaded; see docs/parallel.md#cluster-communication)",
         .add = add_comm,
         .distributed = true},
        {.name = "newton",
         .usage = "the finest level's Newton systems of a run: mg vs hypre MGR and BoomerAMG",
         .add = add_newton},
    };
}

} // namespace mlc::apps

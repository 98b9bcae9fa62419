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
#include "apps/driver.hpp"
#include "bench/commands.hpp"
#include "core/memory.hpp"
#include "studies/commands.hpp"

#include <iostream>

int main(int argc, char** argv) {
    using namespace mlc::apps;
    mlc::keep_freed_memory();
    CLI::App app{"mlcontact: multilevel frictional contact in 2D linear elasticity"};
    app.set_version_flag("--version", std::string("mlcontact ") + MLC_VERSION);
    app.require_subcommand(1);
    std::vector<AddedCommand> added = add_commands(app, {run_command(), preconditioners_command()});
    for (auto group :
         {add_command_group(app, "study", "run a study (see docs/studies.md#studies)",
                            study_commands()),
          add_command_group(app, "bench", "scaling benchmarks (see docs/studies.md#bench)",
                            bench_commands()),
          add_commands(app, {scenes_command(), show_command()})})
        added.insert(added.end(), group.begin(), group.end());
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return report_parse_error(app, e, argc, argv);
    }
    const AddedCommand* chosen = chosen_command(added);
    if (!chosen) return 1; // require_subcommand makes the parse fail first
    // Started by mpirun with several processes: `run` and `bench square|elastic|comm` are
    // distributed; the other commands are one process only and say so (N copies of a
    // one-process run would write the same files). One process, with or without mpirun, runs as
    // always.
    const bool distributed = mlc::comm::launched_by_mpirun() && mlc::comm::world().size() > 1;
    const int rank = distributed ? mlc::comm::world().rank() : 0;
    if (distributed && !chosen->distributed) {
        if (rank == 0)
            std::cerr
                << "mlcontact: error: started as " << mlc::comm::world().size()
                << " MPI processes, but this command runs as one process: on several "
                   "processes run `mlcontact run` (one-body scenes, Krylov + mg) or `mlcontact "
                   "bench square|elastic|comm`; run the others without mpirun or with mpirun -np "
                   "1\n";
        return 1;
    }
    return run_reporting_errors(*chosen, {distributed, rank, std::cout});
}

// SPDX-License-Identifier: MIT
/// @file `mlcontact run` on several processes (mpirun -np N, N > 1): the one-body
/// scenes with Krylov + the distributed mg (levels/distributed_solve.hpp), the report on rank 0,
/// and solution.pvtu (one piece per process), contact.csv and summary.json written once.
#pragma once

#include "core/communicator.hpp"
#include "levels/newton_system.hpp"
#include "run/output.hpp"
#include "run/run.hpp"

#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <toml++/toml.h>

namespace mlc::apps {

/// Collective: `mlcontact run` on the processes of `comm`; progress and report on rank 0's `out`.
/// Returns the exit code (0, or 2 when a load step does not converge). Throws InvalidInput for
/// what is not distributed (--cold, --every-step, --every-level, --levels 0, a solver without a
/// distributed form: levels::plan_solver), on every process alike.
/// A 3D scene goes to run_scene3_distributed.
int run_scene_distributed(const RunOptions& opt, const Communicator& comm, std::ostream& out);

/// Collective: `mlcontact run` on a 3D scene on the processes of `comm` (run/run3_distributed.cpp):
/// levels 0..p on every process, the levels above distributed (levels/distributed_solve3.hpp);
/// the report on rank 0's `out`; solution.pvtu and one piece per process, contact.csv,
/// contact_steps.csv, iterations.csv and summary.json written by process 0. Returns 0, or 2 when
/// a load step does not converge. Throws InvalidInput for what is not distributed (--cold,
/// --linear, --levels 0, the 2D-only options), on every process alike.
int run_scene3_distributed(const RunOptions& opt, const Communicator& comm, std::ostream& out);

/// Process 0, at the end of a distributed run: summary.json (written last, its name added to
/// `files`), and the summary a signal would have written is dropped.
void write_summary_last(const std::filesystem::path& dir, const toml::table& summary,
                        std::vector<std::string>& files);
/// Collective, once every file is written: "wrote <files>" on rank 0's `os`.
void print_written(std::ostream& os, const Communicator& comm, const std::filesystem::path& dir,
                   const std::vector<std::string>& files);

/// Collective: process 0 checks and locks `dir` (OutputFolder) and sets the summary a signal
/// writes; every process throws InvalidInput when it was refused (process 0 with the reason).
/// `folder` is set on process 0 only.
void open_output_folder(std::optional<OutputFolder>& folder, const std::filesystem::path& dir,
                        const std::string& scene, const Communicator& comm, std::ostream& os);

} // namespace mlc::apps

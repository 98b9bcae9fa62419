// SPDX-License-Identifier: MIT
/// @file `mlcontact run` on several processes (mpirun -np N, N > 1): the one-body
/// scenes with Krylov + the distributed mg (levels/distributed_solve.hpp), the report on rank 0,
/// and solution.pvtu (one piece per process), contact.csv and summary.json written once.
#pragma once

#include "core/communicator.hpp"
#include "levels/newton_system.hpp"
#include "run/run.hpp"

#include <ostream>

namespace mlc::apps {

/// Collective: `mlcontact run` on the processes of `comm`; progress and report on rank 0's `out`.
/// Returns the exit code (0, or 2 when a load step does not converge). Throws InvalidInput for
/// what is not distributed (--cold, --every-step, --every-level, --levels 0, a solver without a
/// distributed form: levels::plan_solver), on every process alike.
int run_scene_distributed(const RunOptions& opt, const Communicator& comm, std::ostream& out);

} // namespace mlc::apps

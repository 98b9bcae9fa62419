// SPDX-License-Identifier: MIT
/// @file `mlcontact run` on several processes (mpirun -np N, N > 1): the one-body
/// scenes with Krylov + the distributed mg (levels/distributed_solve.hpp), the report on rank 0,
/// and solution.pvtu (one piece per process), contact.csv and summary.json written once.
#pragma once

#include "run/run.hpp"
#include "core/communicator.hpp"
#include "levels/newton_system.hpp"

#include <ostream>

namespace mlc::apps {

/// The Newton-system solver of a run on several processes: Krylov with mg (the default; its
/// pre/post/omega options apply). Defaults as on one process: BiCGStab + mg's V(0,2) cycle
/// (levels::kMgDefaultOneBody), damped with a two-body pair (`two_body`,
/// levels::kMgDefaultTwoBody); a named `pc` without `krylov` takes CGS (BiCGStab with a
/// two-body pair), as before the V(0,2) default. Throws InvalidInput for
/// --linear schur|lu and names what works.
levels::LinearSolverSpec distributed_solver_spec(const RunOptions& opt, bool two_body = false);

/// Collective: `mlcontact run` on the processes of `comm`; progress and report on rank 0's `out`.
/// Returns the exit code (0, or 2 when a load step does not converge). Throws InvalidInput for
/// what is not distributed (--cold, --every-step, --every-level, --levels 0,
/// solvers other than Krylov + mg), on every process alike.
int run_scene_distributed(const RunOptions& opt, const Communicator& comm, std::ostream& out);

} // namespace mlc::apps

// SPDX-License-Identifier: MIT
/// @file `mlcontact bench square` on several processes (mpirun -np N, N > 1; issue 12): the
/// coarse-to-fine solve of the scene with Krylov + the distributed mg
/// (levels/distributed_solve.hpp), timed `repeat` times; per level the Krylov iterations per
/// Newton step (mean, max) and per process its unknowns and peak RSS. The JSON
/// (out/bench/<scene>_L<L>_np<N>.json unless --out) is written by rank 0.
#pragma once

#include "apps/bench.hpp"
#include "core/communicator.hpp"

#include <ostream>

namespace mlc::apps {

/// Collective. Throws InvalidInput for a preconditioner other than mg (one --pc), --levels < 1,
/// or a scene with no distributed form (two-body pairs). Returns 0 when every run converged.
int bench_square_distributed(const BenchSquareOptions& opt, const Communicator& comm,
                             std::ostream& os);

} // namespace mlc::apps

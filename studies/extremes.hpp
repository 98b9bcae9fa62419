// SPDX-License-Identifier: MIT
/// @file `mlcontact study extremes`: the stiff and extreme cases of benchmarks.md, each run in
/// its own process with a time bound, one row per case (converged or a named diagnosis).
#pragma once

#include <filesystem>
#include <optional>
#include <ostream>
#include <string>

namespace mlc::apps {

/// Options of the stability study.
struct ExtremesOptions {
    int levels = 2;                  ///< finest level of every case (coarse-to-fine)
    double seconds_per_case = 120.0; ///< wall-clock bound; a case past it is killed and reported
    std::string only;                ///< run only the cases whose name contains this text
    std::filesystem::path out;       ///< output folder (default out/studies/extremes)
    /// Newton-system solver of every case, as for `mlcontact run` (levels::plan_solver). None
    /// given: every case is run with each solver the default may choose (schur, and BiCGStab +
    /// V(0,2) mg, undamped and damped, when levels >= 1), one table per solver.
    std::optional<std::string> linear, krylov, pc;
    std::optional<double> linear_rel_tol;
};

/// Runs every case with every solver; prints one table per solver (Krylov iterations per Newton
/// system where the solver is iterative) and writes extremes.csv and extremes.json. Returns 0 when
/// every case either converged or failed with a diagnosis, 3 when a case crashed or timed out.
int study_extremes(const ExtremesOptions& opt, std::ostream& os);

} // namespace mlc::apps

// SPDX-License-Identifier: MIT
/// @file `mlcontact study extremes`: the stiff and extreme cases of benchmarks.md, each run in
/// its own process with a time bound, one row per case (converged or a named diagnosis).
#pragma once

#include <filesystem>
#include <functional>
#include <map>
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
    /// 2: the square-based cases (study_extremes); 3: the block3d- and stack3d-based ones
    /// (study_extremes3). `mlcontact study extremes --dimension 3`.
    int dimension = 2;
};

/// What a case reports: key = value (status, diagnosis, newton, residual, ...).
using ExtremesFields = std::map<std::string, std::string>;

/// Runs `run` in a child process (fork) with a wall-clock bound of `seconds` and returns its
/// fields, read back through a pipe (a newline in a value becomes a space), with "exit" the
/// child's exit code (0 when its status is "converged", else 2). An exception in the child gives
/// status "error" with its message; a child killed by a signal status "crash" ("signal ..."); one
/// past the bound is killed and reported as status "timeout". OpenMP's idle threads are ended
/// before the fork (omp_pause_resource_all), since a child cannot use the parent's.
ExtremesFields run_isolated(const std::function<ExtremesFields()>& run, double seconds);

/// Runs every case with every solver; prints one table per solver (Krylov iterations per Newton
/// system where the solver is iterative) and writes extremes.csv and extremes.json. Returns 0 when
/// every case either converged or failed with a diagnosis, 3 when a case crashed or timed out.
int study_extremes(const ExtremesOptions& opt, std::ostream& os);

/// The 3D cases (opt.dimension 3): block3d with mu from 0 to 10, r from 1e-4 to 1e4 E h0 (a 3D
/// multiplier is a nodal force: h0 the mean level-0 edge of the contactor's faces), nu up to
/// 0.4999, loads from 1e-8 to 1e3 times nominal, full lift-off and gross slip, and stack3d with
/// Young's moduli 1e6 apart both ways round (mu = 0.3). Each runs in its own process
/// (run_isolated) on levels 0..opt.levels coarse-to-fine, once per solver: opt.linear ("schur" or
/// "lu": exact on every level), or when none is given the run's plan (levels::plan_contact3:
/// schur or lu on level 0, GMRES + mg above) and lu. Prints one table per solver and writes
/// extremes.csv and extremes.json (default folder out/studies/extremes3). Throws InvalidInput for
/// levels outside 0..4, a non-positive time bound and the 2D-only solver options (krylov, pc,
/// linear_rel_tol, linear = "krylov"). Returns 0 when every case converged or ended with a
/// diagnosis, 3 when one crashed, timed out or produced a non-finite value.
int study_extremes3(const ExtremesOptions& opt, std::ostream& os);

} // namespace mlc::apps

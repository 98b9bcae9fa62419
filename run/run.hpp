// SPDX-License-Identifier: MIT
/// @file The `mlcontact run` command: load a scene, apply command-line overrides, solve, report,
/// write the result files.
#pragma once

#include "levels/problem.hpp"
#include "levels/resources.hpp"
#include "levels/solve.hpp"
#include <atomic>

#include <optional>
#include <ostream>
#include <string>

namespace mlc::apps {

/// Options of `mlcontact run`.
struct RunOptions {
    std::string scene = "square"; ///< file path or built-in scene name
    std::optional<int> levels;    ///< overrides [scene].levels
    /// "hilbert" or "lattice" (levels::Problem::numbering); unset: lattice where the solver
    /// sweeps by lattices (levels::plan_solver), else hilbert.
    std::optional<std::string> numbering;
    std::optional<double> mu;      ///< overrides mu of every contact pair
    std::optional<double> r;       ///< overrides r of every contact pair
    std::optional<int> load_steps; ///< overrides [scene].load_steps
    std::string out;               ///< output folder; empty: out/<scene name>
    bool quiet = false;            ///< no per-step progress
    bool cold = false;             ///< finest level from the previous step only (no coarse-to-fine)
    /// Newton-system solver: schur | lu | krylov; unset with no Krylov option: chosen by size
    /// (levels::plan_solver).
    std::optional<std::string> linear;
    std::optional<std::string> krylov;    ///< Krylov method (implies a Krylov solve)
    std::optional<std::string> pc;        ///< preconditioner spec (implies a Krylov solve)
    std::optional<double> linear_rel_tol; ///< relative tolerance of each Krylov solve
    /// No exact fallback: a Newton system the Krylov solve fails on ends the run (exit 2/3)
    /// instead of being solved again by the exact schur solver.
    bool no_fallback = false;
    /// No r continuation (levels::SolveOptions::r_continuation): a load step whose Newton fails
    /// at the scene's r ends the run (exit 2) instead of being solved again through a reduced r.
    bool no_continuation = false;
    /// No extrapolation of linear load steps (levels::SolveOptions::extrapolate, on by default).
    bool no_extrapolation = false;
    std::string vtu = "binary"; ///< VTU encoding: binary (zlib, appended) or ascii
    bool every_step = false;    ///< a VTU per load step of the finest level + solution.pvd
    bool every_level = false;   ///< also a VTU series + collection per coarser level
    bool plot = false;          ///< draw contact.png (scripts/plot_contact.py)
    bool progress_eta = false;  ///< progress lines with the time left (stdout is a terminal)
    /// Polled by the solve (levels::SolveObserver::stop_requested); when it is set, the run stops
    /// after the current Newton iteration, writes the files of the completed steps and returns 128
    /// + stop_signal() (run/interrupt.hpp). Null: never stops.
    const std::atomic<bool>* stop = nullptr;
    /// Several processes: the partition level (levels::partition_level when unset). A flag
    /// that cannot take effect on one process: refused there.
    std::optional<int> partition_level;
};

/// Applies the overrides of `opt` (levels, load steps, mu and r of every pair) to `p`, each checked
/// as the command line checks it, and validates the result. Throws InvalidInput naming the option.
void apply_overrides(levels::Problem& p, const RunOptions& opt);

/// The solver options of `opt` parsed (the one place their text is read): --linear, --krylov,
/// --pc, --linear-tol and --numbering as a typed request. Throws InvalidInput naming the option.
levels::SolverRequest solver_request(const RunOptions& opt);

/// The solve options of `mlcontact run` for `p` (after apply_overrides): the Newton-system solver
/// planned for `processes` processes (levels::plan_solver, returned in `plan`), coarse-to-fine
/// unless opt.cold, no progress stream; p.numbering is the plan's. The Python module solves
/// with these, so that its numbers are the driver's.
levels::SolveOptions run_solve_options(levels::Problem& p, const RunOptions& opt,
                                       levels::SolverPlan& plan, int processes = 1);

/// Runs a scene. The output folder is checked and locked before the solve (OutputFolder: a
/// folder another run is writing is refused). Returns the process exit code: 0 on success, 2 when
/// a load step did not converge (the report says which and how), 4 when the results were written
/// but --plot failed (the cause on stderr, no contact.png left), 130 / 143 when stopped by SIGINT
/// / SIGTERM during the solve (see RunOptions::stop) or while the files were written. Throws
/// InvalidInput for bad input (the folder included) and SolverBreakdown when the Newton residual
/// became NaN/Inf. summary.json is written last ("complete", "stopped", "files").
int run_scene(const RunOptions& opt, std::ostream& os);

} // namespace mlc::apps

// SPDX-License-Identifier: MIT
/// @file `mlcontact study preconditioners`: Krylov iterations and times per Newton step for every
/// (preconditioner, Krylov method) pair, level, friction coefficient and penalty, next to the
/// numbers of Alart, Barboteu & Lebon (1997).
#pragma once

#include "levels/problem.hpp"

#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace mlc::apps {

/// Options of the preconditioner study.
struct PreconditionerStudyOptions {
    int levels = 2;                       ///< finest level (runs on every level 0..L)
    std::vector<double> mu = {1.0};       ///< friction coefficients
    std::vector<double> r_over_E = {0.1}; ///< penalty factors r / E
    std::vector<std::string> pcs = {"diag", "ilu:0", "cf", "sorcf", "ebe", "ebe:variant=c5"};
    std::vector<std::string> krylovs = {"cgs"};
    int load_steps = 0;             ///< 0: the scene's
    double rel_tol = 1e-8;          ///< Krylov relative tolerance
    int max_iter = 5000;            ///< Krylov iterations per Newton step
    double seconds_per_run = 600.0; ///< a run past this is stopped and reported
    bool plot = true;
    std::filesystem::path out; ///< default out/studies/<scene>_preconditioners
    /// Process counts (--np-list): non-empty runs study_preconditioners_np instead.
    std::vector<int> np_list;
    /// The launcher for N > 1 (--mpiexec, split at spaces); empty: mpiexec or mpirun on PATH,
    /// with --oversubscribe when it is Open MPI's.
    std::string mpiexec;
    /// The scene as given on the command line (file or built-in name), for the runs' command.
    std::string scene_arg = "square";
};

/// Runs the grid: every combination and every finest level l = 1..L, coarse-to-fine over levels
/// 0..l (each level's Newton systems solved by the Krylov method with the preconditioner; the
/// coarsest exactly), one process per (combination, l) with a time bound, reporting level l;
/// after a failure or a timeout the finer levels of that combination are not run. Writes
/// preconditioners.csv/json, prints the table next to the 1997 paper's (square test) and draws
/// preconditioners.png.
int study_preconditioners(const levels::Problem& problem, const PreconditionerStudyOptions& opt,
                          std::ostream& os);

/// The preconditioners of the processes' study (`--np-list 1,2,4`): for every
/// (Krylov method, preconditioner, mu, r/E), process count N and finest level l = 1..L, one
/// `mlcontact run SCENE --levels l` (N = 1: this executable alone; N > 1: under `mpiexec -n N`,
/// where the default partition level is l - 1 at most, so level l is distributed and solved with
/// the preconditioner on each process's diagonal block, Jacobi across the cuts; levels 0..p as
/// one process solves them), bounded by opt.seconds_per_run, without exact fallback or r
/// continuation (as the one-process study solves). Reads each run's iterations.csv and reports
/// level l's Newton steps and Krylov iterations per Newton step (mean, max). Writes
/// preconditioners_np.csv/json, the runs' folders (runs/<name>: run.log, iterations.csv,
/// summary.json) and preconditioners_np.png. Throws InvalidInput for bad options, a
/// preconditioner with no distributed form when some N > 1, or no launcher for N > 1.
int study_preconditioners_np(const levels::Problem& problem, const PreconditionerStudyOptions& opt,
                             std::ostream& os);

/// What the processes' study needs of its scene, in 2D or 3D.
struct NpStudyScene {
    std::string name;
    double young_modulus = 1.0; ///< r = (r/E) times this
    /// 2: the runs also get --no-fallback and --no-continuation (the Krylov solve alone); 3D
    /// runs have neither.
    int dimension = 2;
    /// Throws InvalidInput when (Krylov method, preconditioner) cannot run on np processes,
    /// with the run's own message.
    std::function<void(const std::string& krylov, const std::string& pc, int np)> check;
};

/// study_preconditioners_np for a scene of any dimension (a 3D scene's runs: the levels above
/// level 0 by the Krylov method and preconditioner, on one process or distributed).
int study_preconditioners_np(const NpStudyScene& scene, const PreconditionerStudyOptions& opt,
                             std::ostream& os);

} // namespace mlc::apps

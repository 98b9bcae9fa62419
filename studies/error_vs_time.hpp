// SPDX-License-Identifier: MIT
/// @file `mlcontact study error-vs-time`: a work-precision study over levels and solver
/// configurations, with the Pareto front of error against wall time.
#pragma once

#include "levels/problem.hpp"

#include <filesystem>
#include <ostream>
#include <string>

namespace mlc::apps {

/// Options of the work-precision study.
struct ErrorVsTimeOptions {
    int max_level = 3; ///< configurations run on levels 0..max_level
    /// The reference solution is computed on level max_level + reference_offset (exact solver,
    /// coarse-to-fine).
    int reference_offset = 1;
    /// The ILU(0) configurations run on levels 0..min(max_level, ilu_max_level): their Krylov
    /// iterations grow with the level (the 5000-iteration cap near 30 000 unknowns), so above
    /// level 3 they cost minutes per run without a chance of the front.
    int ilu_max_level = 3;
    /// Only the configurations whose name contains this text (empty: all).
    std::string only;
    bool plot = true;
    std::filesystem::path out; ///< default out/studies/<scene>_error_vs_time
};

/// The preconditioner spec the configuration named `configuration` runs on level `level` of
/// `problem` ("c2f default bicgstab+mg": the run's default above the crossover, with the lattice
/// sweep from level 4). Throws InvalidInput for an unknown name.
std::string error_vs_time_pc(const levels::Problem& problem, const std::string& configuration,
                             int level);

/// Configurations: the run's default above the crossover (coarse-to-fine BiCGStab + `mg`,
/// levels 1..max_level), coarse-to-fine and cold CGS + `mg` (levels 1..max_level: mg needs a level
/// below), coarse-to-fine CGS + hypre MGR (`mgr`, in builds with hypre), coarse-to-fine and cold
/// `schur`, `schur` with Newton tolerance 1e-6, coarse-to-fine and cold `lu`, and GMRES / CGS +
/// ILU(0) (up to ilu_max_level). A run that throws is recorded as not converged.
/// Runs every configuration on every level and records the wall time of the solve and the errors
/// against the reference: displacement error in the energy norm and the L2 norm (along the
/// contact boundary) of the contact traction difference, both relative; for `hertz` also the
/// relative L2 error of the pressure against the closed form (the primary error there). Writes
/// error_vs_time.csv/json, marks the Pareto front, and draws error_vs_time.png.
int study_error_vs_time(const levels::Problem& problem, const ErrorVsTimeOptions& opt,
                        std::ostream& os);

} // namespace mlc::apps

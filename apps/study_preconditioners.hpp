// SPDX-License-Identifier: MIT
/// @file `mlcontact study preconditioners`: Krylov iterations and times per Newton step for every
/// (preconditioner, Krylov method) pair, level, friction coefficient and penalty, next to the
/// numbers of Alart, Barboteu & Lebon (1997).
#pragma once

#include "levels/problem.hpp"

#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

namespace mlc::apps {

/// Options of the preconditioner study.
struct PreconditionerStudyOptions {
    int levels = 2;                                   ///< finest level (runs on every level 0..L)
    std::vector<double> mu = {1.0};                   ///< friction coefficients
    std::vector<double> r_over_E = {0.1};             ///< penalty factors r / E
    std::vector<std::string> pcs = {"diag", "ilu:0", "cf", "sorcf", "ebe", "ebe:variant=c5"};
    std::vector<std::string> krylovs = {"cgs"};
    int load_steps = 0;                               ///< 0: the scene's
    double rel_tol = 1e-8;                            ///< Krylov relative tolerance
    int max_iter = 5000;                              ///< Krylov iterations per Newton step
    double seconds_per_run = 600.0;                   ///< a run past this is stopped and reported
    bool plot = true;
    std::filesystem::path out;                        ///< default out/studies/<scene>_preconditioners
};

/// Runs the grid: every combination and every finest level l = 1..L, coarse-to-fine over levels
/// 0..l (each level's Newton systems solved by the Krylov method with the preconditioner; the
/// coarsest exactly), one process per (combination, l) with a time bound, reporting level l;
/// after a failure or a timeout the finer levels of that combination are not run. Writes preconditioners.csv/json, prints the table
/// next to the 1997 paper's (square test) and draws preconditioners.png.
int study_preconditioners(const levels::Problem& problem, const PreconditionerStudyOptions& opt,
                          std::ostream& os);

} // namespace mlc::apps

// SPDX-License-Identifier: MIT
/// @file `mlcontact study error-vs-time`: a work-precision study over levels and solver
/// configurations, with the Pareto front of error against wall time.
#pragma once

#include "levels/problem.hpp"

#include <filesystem>
#include <ostream>

namespace mlc::apps {

/// Options of the work-precision study.
struct ErrorVsTimeOptions {
    int max_level = 3;         ///< configurations run on levels 0..max_level
    /// The reference solution is computed on level max_level + reference_offset (exact solver,
    /// coarse-to-fine).
    int reference_offset = 1;
    bool plot = true;
    std::filesystem::path out; ///< default out/studies/<scene>_error_vs_time
};

/// Runs every configuration on every level and records the wall time of the solve and the errors
/// against the reference: displacement error in the energy norm and the L2 norm (along the
/// contact boundary) of the contact traction difference, both relative; for `hertz` also the
/// relative L2 error of the pressure against the closed form (the primary error there). Writes
/// error_vs_time.csv/json, marks the Pareto front, and draws error_vs_time.png.
int study_error_vs_time(const levels::Problem& problem, const ErrorVsTimeOptions& opt,
                        std::ostream& os);

} // namespace mlc::apps

// SPDX-License-Identifier: MIT
/// @file `mlcontact study extremes`: the stiff and extreme cases of benchmarks.md, each run in
/// its own process with a time bound, one row per case (converged or a named diagnosis).
#pragma once

#include <filesystem>
#include <ostream>
#include <string>

namespace mlc::apps {

/// Options of the stability study.
struct ExtremesOptions {
    int levels = 2;                  ///< finest level of every case (coarse-to-fine)
    double seconds_per_case = 120.0; ///< wall-clock bound; a case past it is killed and reported
    std::string only;                ///< run only the cases whose name contains this text
    std::filesystem::path out;       ///< output folder (default out/studies/extremes)
};

/// Runs every case; prints the table and writes extremes.csv and extremes.json. Returns 0 when
/// every case either converged or failed with a diagnosis, 3 when a case crashed or timed out.
int study_extremes(const ExtremesOptions& opt, std::ostream& os);

} // namespace mlc::apps

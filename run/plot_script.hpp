// SPDX-License-Identifier: MIT
/// @file The plotting scripts (scripts/plot_*.py), installed with the program in
/// share/mlcontact/plots and found from where the program (or the Python module) lies.
#pragma once

#include <filesystem>
#include <ostream>
#include <string>

namespace mlc::apps {

/// The folder of the plotting scripts: $MLC_PLOT_DIR when set, else the first
/// share/mlcontact/plots found in a folder above the file this code was loaded from (the
/// driver, or the Python module) or above the running executable. Empty when none is found.
/// The build tree holds a copy in <build>/share/mlcontact/plots, an install in
/// <prefix>/share/mlcontact/plots.
std::filesystem::path plot_script_dir();

/// Runs a plotting script with Debian's python3 (which has matplotlib), its output (stdout and
/// stderr) captured. Returns false when the script is missing or failed, and says why on `os`
/// with the script's own last message (e.g. "ModuleNotFoundError: No module named
/// 'matplotlib'"), also stored in `cause` if given. `extra` is appended to the command line
/// (further arguments, already quoted).
bool run_plot_script(const std::string& script, const std::filesystem::path& dir, std::ostream& os,
                     const std::string& extra = "", std::string* cause = nullptr);

} // namespace mlc::apps

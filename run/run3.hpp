// SPDX-License-Identifier: MIT
/// @file `mlcontact run` on a 3D scene ([scene] dimension = 3): one elastic body against rigid
/// obstacles, solved coarse to fine on the tetrahedral hierarchy (levels/solve3.hpp), with the
/// report and the files a 2D run writes, in their 3D form.
#pragma once

#include "run/run.hpp"

#include <ostream>

namespace mlc::apps {

/// Runs a 3D scene: the options of `mlcontact run` that apply in 3D (--levels, --steps, --mu,
/// --r, --out, --quiet, --cold, --linear schur|lu, --vtu); the others are refused with the reason.
/// Writes, into the output folder (locked as a 2D run's, OutputFolder):
/// - solution.vtu: the tetrahedra with point fields displacement, contact_status (-1 off the
///   contact nodes, else 0 gap, 1 stick, 2 slip), contact_force (the force the obstacle exerts,
///   global components), pressure, and the cell field body;
/// - contact.csv: one row per contact node of the finest level at the end (write_contact3_csv);
/// - contact_steps.csv: the same per load step, with the columns step and s first;
/// - iterations.csv: one row per Newton system of every solved level (as in 2D);
/// - summary.json: the run's figures, written last.
/// Returns 0, or 2 when a load step did not converge (the report says where and why), or
/// 128 + signal when stopped by SIGINT/SIGTERM during the solve (nothing is written then).
int run_scene3(const RunOptions& opt, std::ostream& os);

} // namespace mlc::apps

// SPDX-License-Identifier: MIT
/// @file `mlcontact study status-transfer`: how well the interpolated coarse solution predicts
/// the fine contact statuses, and what the coarse-to-fine start saves in Newton iterations.
#pragma once

#include "levels/problem.hpp"
#include "transfer/transfer.hpp"

#include <filesystem>
#include "levels/solve3.hpp"

#include <ostream>
#include <string>

namespace mlc::apps {

/// Options of the status-transfer study.
struct StatusTransferOptions {
    std::string scene = "square";
    int levels = 3;            ///< finest level
    std::filesystem::path out; ///< output folder (default out/<scene>/status_transfer)
    transfer::QRule q_rule = transfer::QRule::paper;
    bool increment = false; ///< warm start from the interpolated coarse increment
                            ///< (SolveOptions::transfer_increment)
    bool plot = true;       ///< draw the PNG with matplotlib
};

/// Runs the scene coarse-to-fine and cold on levels 0..L (every level solved in both), prints the
/// per-level table (Newton iterations per load step warm and cold, predicted-status agreement,
/// where mispredicted nodes sit) and the confusion tables, and writes status_transfer.csv,
/// status_transfer.json, statuses.csv and status_transfer.png. Returns the exit code.
int study_status_transfer(const levels::Problem& problem, const StatusTransferOptions& opt,
                          std::ostream& os);

/// The same study of a 3D scene (levels 1..4): the per-level table, the 3 x 3 confusion tables
/// of the 3D status codes (gap, stick, slip), status_transfer.csv and status_transfer.json. The
/// multipliers travel by the surface Q (no Q rule to choose, no increment start).
int study_status_transfer3(const levels::ElasticProblem3& problem,
                           const StatusTransferOptions& opt, std::ostream& os);

} // namespace mlc::apps

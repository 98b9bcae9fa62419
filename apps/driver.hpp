// SPDX-License-Identifier: MIT
/// @file The driver's own commands and its error reports (apps/main.cpp lists the commands).
#pragma once

#include "comm/world.hpp"
#include "run/command.hpp"

namespace mlc::apps {

/// `mlcontact run`.
Command run_command();
/// `mlcontact preconditioners`.
Command preconditioners_command();
/// `mlcontact scenes`.
Command scenes_command();
/// `mlcontact show`.
Command show_command();

/// A bad command line: says what and where to look on stderr ("mlcontact: error: ..."),
/// returns 1 (0 for --help and --version, whose text CLI11 prints).
int report_parse_error(CLI::App& app, const CLI::ParseError& e, int argc, char** argv);

/// Runs `command`'s action and turns what it throws into the driver's exit codes and messages:
/// 1 bad input, 3 numerical breakdown, 128 + signal when stopped; on several processes the
/// others are ended when one process fails alone.
int run_reporting_errors(const AddedCommand& command, const Launch& at);

} // namespace mlc::apps

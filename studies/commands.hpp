// SPDX-License-Identifier: MIT
/// @file The studies' subcommands (`mlcontact study ...`), see docs/studies.md.
#pragma once

#include "run/command.hpp"

namespace mlc::apps {

/// status-transfer, extremes, error-vs-time, preconditioners, accuracy: in this order.
std::vector<Command> study_commands();

} // namespace mlc::apps

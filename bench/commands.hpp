// SPDX-License-Identifier: MIT
/// @file The benches' subcommands (`mlcontact bench ...`), see docs/studies.md#bench.
#pragma once

#include "run/command.hpp"

namespace mlc::apps {

/// square, elastic, comm, newton: in this order.
std::vector<Command> bench_commands();

} // namespace mlc::apps

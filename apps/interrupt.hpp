// SPDX-License-Identifier: MIT
/// @file SIGINT/SIGTERM during a run: a flag the solve polls, so that the run stops cleanly after
/// the current Newton iteration and keeps the files of the completed load steps.
#pragma once

#include <atomic>

namespace mlc::apps {

/// Installs handlers for SIGINT and SIGTERM that record the signal and set stop_flag(). Each
/// handler is one-shot (SA_RESETHAND): a second Ctrl-C ends the process at once.
void install_stop_handlers();

/// Set by the first SIGINT/SIGTERM after install_stop_handlers().
const std::atomic<bool>& stop_flag();

/// The signal that set stop_flag() (SIGINT or SIGTERM), or 0.
int stop_signal();

/// "SIGINT", "SIGTERM" or "signal N".
const char* signal_name(int sig);

} // namespace mlc::apps

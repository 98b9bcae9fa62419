// SPDX-License-Identifier: MIT
/// @file SIGINT/SIGTERM during a run: a flag the solve polls (core/stop.hpp), so that the run
/// stops cleanly after the current Newton iteration and keeps the files of the completed load
/// steps; while the result files are written, the current file is abandoned and the rest skipped.
#pragma once

#include <atomic>
#include <filesystem>
#include <string>

namespace mlc::apps {

/// Installs handlers for SIGINT and SIGTERM. The first signal records itself (mlc::request_stop:
/// stop_flag(), stop_signal()) and the run stops at its next check. A second signal, or the
/// first when exit_at_once is set (processes under mpirun, which follows a signal with SIGKILL
/// after a second), ends the process at once with 128 + the signal: the registered temporaries
/// are removed (core/atomic_file.hpp) and the summary set by set_stop_summary, if any, is written
/// first, so that every file left is complete or absent.
///
/// `exit_delay_ms` (with exit_at_once): the handler waits that long before ending the process.
/// Processes other than 0 under mpirun wait, so that process 0 writes its summary before Open
/// MPI, seeing a process end, kills the others.
void install_stop_handlers(bool exit_at_once = false, int exit_delay_ms = 0);

/// Set by the first SIGINT/SIGTERM after install_stop_handlers() (mlc::stop_request_flag()).
const std::atomic<bool>& stop_flag();

/// True once a stop was requested (mlc::stop_requested()).
bool stop_requested();

/// The signal that set stop_flag() (SIGINT or SIGTERM), or 0.
int stop_signal();

/// "SIGINT", "SIGTERM" or "a signal".
const char* signal_name(int sig);

/// The summary a signal handler that ends the process at once writes to `file` (through a
/// temporary renamed into place): `text_for(sig)` is rendered now, for SIGINT and SIGTERM, since
/// a handler may not allocate. An empty file clears it.
void set_stop_summary(const std::filesystem::path& file, std::string sigint_text,
                      std::string sigterm_text);

} // namespace mlc::apps

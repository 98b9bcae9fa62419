// SPDX-License-Identifier: MIT
/// @file A process-wide stop request (SIGINT / SIGTERM), set by the driver's signal handlers
/// (apps/interrupt.hpp) and polled by long loops in any library (meshing, file writing) without
/// depending on the driver. Nothing here installs a handler: in a process that installs none
/// (the Python module, the tests) a stop is never requested.
#pragma once

#include <atomic>

namespace mlc {

/// Records a stop request by signal `sig` (the first one is kept). Async-signal-safe.
void request_stop(int sig) noexcept;

/// True once a stop was requested.
bool stop_requested() noexcept;

/// The signal of the first stop request, or 0.
int stop_request_signal() noexcept;

/// The flag itself, for code that polls an atomic (levels::SolveObserver::stop_requested).
const std::atomic<bool>& stop_request_flag() noexcept;

/// Whether a stop request also stops file writing (write_file_atomically, the VTU writers):
/// off by default. A writer that sees stop_requested() while writes are stoppable abandons the
/// file (its temporary removed, the file left as it was) by throwing mlc::Interrupted.
void set_writes_stoppable(bool on) noexcept;

/// stop_requested() while writes are stoppable.
bool write_stop_requested() noexcept;

/// Forgets a stop request (for tests of the writers; a run never takes one back).
void clear_stop_request() noexcept;

} // namespace mlc

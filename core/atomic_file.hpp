// SPDX-License-Identifier: MIT
/// @file Files that are never seen half-written: written under a temporary name in the same
/// folder and renamed into place when complete.
#pragma once

#include <filesystem>
#include <fstream>
#include <functional>
#include <ostream>

namespace mlc {

/// A temporary name for writing `file`, unique to this process and this call:
/// "<file>.<pid>.<n>.tmp" in the same folder (so that the final rename stays on one file
/// system), n counting the temporaries this process named. Two processes (or two writers in one
/// process) writing the same file never share a temporary.
std::filesystem::path temporary_path(const std::filesystem::path& file);

/// Calls write(os) on a stream to a temporary_path(file), then closes it and renames it to
/// `file` (atomic on POSIX: a reader sees the old file or the complete new one). Throws
/// InvalidInput when the temporary cannot be created (folder missing or read-only),
/// std::runtime_error when a write or the rename fails, and mlc::Interrupted when a stop was
/// requested while writes are stoppable (core/stop.hpp: the stream then fails at once and the
/// file is abandoned). On any exception, including one from `write`, the temporary is removed and
/// `file` is left as it was.
void write_file_atomically(const std::filesystem::path& file,
                           const std::function<void(std::ostream&)>& write);

/// Registers a temporary file being written, for remove_registered_temporaries(); deregisters it
/// when destroyed. A fixed number of files can be registered at once (beyond, silently not).
class RegisteredTemporary {
public:
    explicit RegisteredTemporary(const std::filesystem::path& tmp);
    RegisteredTemporary(const RegisteredTemporary&) = delete;
    RegisteredTemporary& operator=(const RegisteredTemporary&) = delete;
    ~RegisteredTemporary();
    /// Deregisters now (after the rename or removal).
    void release();

private:
    int slot_ = -1;
};

/// Removes every registered temporary (unlink). Async-signal-safe: for a signal handler that
/// ends the process at once, so that no half-written temporary is left behind.
void remove_registered_temporaries() noexcept;

/// An output file stream written to a temporary_path(file) and renamed to `file` when closed: a
/// drop-in for std::ofstream in code that writes a file piece by piece. close() (or the
/// destructor, when the scope ends normally) closes and renames; a write or rename failure sets
/// failbit, so `good()` after close() says whether the file is complete. Destroyed during stack
/// unwinding (an exception), it removes the temporary and leaves `file` as it was.
class AtomicOfstream : public std::ofstream {
public:
    explicit AtomicOfstream(const std::filesystem::path& file);
    AtomicOfstream(AtomicOfstream&& other) noexcept;
    AtomicOfstream& operator=(AtomicOfstream&&) = delete;
    ~AtomicOfstream() override;
    /// Closes the temporary and renames it to the file (once; later calls do nothing).
    void close();

private:
    AtomicOfstream(const std::filesystem::path& file, std::filesystem::path tmp);
    std::filesystem::path file_, tmp_;
    int uncaught_ = 0;
    bool pending_ = false; ///< the temporary exists and was not renamed or removed yet
};

} // namespace mlc

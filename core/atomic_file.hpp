// SPDX-License-Identifier: MIT
/// @file Files that are never seen half-written: written under a temporary name in the same
/// folder and renamed into place when complete.
#pragma once

#include <filesystem>
#include <fstream>
#include <functional>
#include <ostream>

namespace mlc {

/// The temporary name write_file_atomically (and the VTU writers) use for `file`:
/// "<file>.tmp", in the same folder, so that the final rename stays on one file system.
std::filesystem::path temporary_path(const std::filesystem::path& file);

/// Calls write(os) on a stream to temporary_path(file), then closes it and renames it to `file`
/// (atomic on POSIX: a reader sees the old file or the complete new one). Throws InvalidInput when
/// the temporary cannot be created (folder missing or read-only) and std::runtime_error when a
/// write or the rename fails; on any exception, including one from `write`, the temporary is
/// removed and `file` is left as it was.
void write_file_atomically(const std::filesystem::path& file,
                           const std::function<void(std::ostream&)>& write);

/// An output file stream written to temporary_path(file) and renamed to `file` when closed: a
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
    std::filesystem::path file_;
    int uncaught_ = 0;
    bool pending_ = false; ///< the temporary exists and was not renamed or removed yet
};

} // namespace mlc

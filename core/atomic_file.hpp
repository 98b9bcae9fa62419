// SPDX-License-Identifier: MIT
/// @file Files that are never seen half-written: written under a temporary name in the same
/// folder and renamed into place when complete.
#pragma once

#include <filesystem>
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

} // namespace mlc

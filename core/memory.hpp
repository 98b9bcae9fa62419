// SPDX-License-Identifier: MIT
/// @file Process-wide memory policy for the solver executables.
#pragma once

namespace mlc {

/// Keeps freed heap memory in the process instead of returning it to the system (glibc: blocks
/// up to 32 MiB from the heap, and a trim threshold of 1 GiB). Every Krylov solve allocates its
/// work vectors and every Newton residual a few level vectors; at level 6 of the square these are
/// 17 MB each, and with glibc's defaults each allocation came back as fresh pages that the kernel
/// zeroes first: 7 % of a level-6 bench run went to zeroing pages. Call once at the start of
/// main. Elsewhere than glibc it does nothing.
void keep_freed_memory();

/// Peak resident memory of this process so far, in bytes (getrusage ru_maxrss).
double peak_rss_bytes();

/// Resident memory of this process now, in bytes (/proc/self/statm; 0 where it cannot be read).
double current_rss_bytes();

} // namespace mlc

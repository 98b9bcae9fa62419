// SPDX-License-Identifier: MIT
// Process-wide memory policy.
#include "core/memory.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <fstream>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace mlc {

void keep_freed_memory() {
#if defined(__GLIBC__)
    // 32 MiB is the largest mmap threshold glibc accepts on 64-bit systems: vectors up to that
    // size (4 million doubles) come from the heap and are reused.
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
}

double peak_rss_bytes() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return static_cast<double>(u.ru_maxrss) * 1024.0; // ru_maxrss is in KiB on Linux
}

double current_rss_bytes() {
    std::ifstream in("/proc/self/statm");
    double size = 0, resident = 0;
    if (!(in >> size >> resident)) return 0.0;
    return resident * static_cast<double>(sysconf(_SC_PAGESIZE));
}

} // namespace mlc

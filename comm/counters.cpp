// SPDX-License-Identifier: MIT
#include "comm/counters.hpp"

#include <dlfcn.h>

#include <filesystem>
#include <system_error>

namespace mlc::comm {

std::optional<MpiCounts> mpi_counts() {
    using Fn = int (*)(std::int64_t*, int);
    // The symbol exists only when the PMPI library is preloaded (it is in no library we link).
    static const Fn fn = reinterpret_cast<Fn>(dlsym(RTLD_DEFAULT, "mlc_pmpi_counters"));
    if (!fn) return std::nullopt;
    std::int64_t c[7] = {};
    fn(c, 7);
    return MpiCounts{c[0], c[1], c[2], c[3], c[4], c[5], c[6]};
}

std::string pmpi_counters_library() {
    std::error_code ec;
    const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    const std::filesystem::path dir = ec ? std::filesystem::path("build/bin") : exe.parent_path();
    return (dir.parent_path() / "lib" / "libmlc_pmpi_counters.so").string();
}

} // namespace mlc::comm

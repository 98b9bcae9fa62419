// SPDX-License-Identifier: MIT
// libFuzzer target: the input bytes as a Gmsh .msh file for mesh::read_gmsh. mlc::InvalidInput is
// the expected answer to a bad file; any other exception, a crash, a sanitizer report or a hang is
// a finding.
#include "core/check.hpp"
#include "mesh/io/gmsh.hpp"

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <unistd.h>

namespace {

/// The file the input is written to: one per process, so parallel fuzzers (-jobs) do not collide.
const std::filesystem::path& scratch_file() {
    static const std::filesystem::path file =
        std::filesystem::temp_directory_path() /
        ("mlc_fuzz_gmsh_" + std::to_string(::getpid()) + ".msh");
    // Registered after `file` is constructed, so it runs before `file` is destroyed.
    static const bool remove_at_exit = std::atexit([] {
        std::error_code ec;
        std::filesystem::remove(scratch_file(), ec);
    }) == 0;
    (void)remove_at_exit;
    return file;
}

void read(const std::string& surface) {
    try {
        mlc::mesh::read_gmsh(scratch_file(), surface);
    } catch (const mlc::InvalidInput&) {
        // The expected answer to a bad file. Anything else propagates: libFuzzer reports it.
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    {
        std::ofstream out(scratch_file(), std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    }
    // All 2D elements; the physical surface named by the first quoted string (in a good file, the
    // first physical name), which exercises the selection by name and its "no such surface"
    // message; and an unnamed physical surface by tag.
    read("");
    const std::string text(reinterpret_cast<const char*>(data), size);
    const std::size_t q0 = text.find('"');
    const std::size_t q1 = q0 == std::string::npos ? q0 : text.find('"', q0 + 1);
    if (q1 != std::string::npos && q1 - q0 <= 64) read(text.substr(q0 + 1, q1 - q0 - 1));
    read("tag1");
    return 0;
}

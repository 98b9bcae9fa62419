// SPDX-License-Identifier: MIT
// The `bench/` target of `mlcontact bench square`: bench_square [LEVELS [SOLVER ...]]
// (default: level 4, solver mg; CGS, relative tolerance 1e-8; JSON in out/bench/).
#include "apps/bench.hpp"
#include "core/check.hpp"
#include "core/memory.hpp"

#include <charconv>
#include <cstring>
#include <iostream>

int main(int argc, char** argv) {
    mlc::keep_freed_memory();
    mlc::apps::BenchSquareOptions o;
    o.levels = 4;
    try {
        if (argc > 1) {
            const char* s = argv[1];
            const auto [ptr, ec] = std::from_chars(s, s + std::strlen(s), o.levels);
            MLC_CHECK(ec == std::errc() && *ptr == '\0',
                      "usage: bench_square [LEVELS [SOLVER ...]]; LEVELS '"
                          << s << "' is not an integer");
        }
        if (argc > 2) o.pcs.assign(argv + 2, argv + argc);
        return mlc::apps::bench_square(o, std::cout);
    } catch (const mlc::InvalidInput& e) {
        std::cerr << "bench_square: error: " << e.what() << "\n";
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "bench_square: error: " << e.what() << "\n";
        return 3;
    }
}

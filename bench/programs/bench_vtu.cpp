// SPDX-License-Identifier: MIT
// Binary (zlib, appended) against ASCII solution.vtu: size and write time.
//   bench_vtu [SCENE [LEVEL [REPEAT [DIR]]]]   (default: square 5 3 out/bench/vtu)
// Solves the scene once on the given level (the run's default solver), then writes the final
// state's solution.vtu REPEAT times in each format, alternating, and prints one JSON object:
// sizes in bytes, write times in seconds (median and all), and the ratios.
#include "core/check.hpp"
#include "core/memory.hpp"
#include "core/timer.hpp"
#include "levels/solve.hpp"
#include "run/output.hpp"
#include "scene/scene.hpp"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

namespace {

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void print_list(const std::vector<double>& v) {
    std::cout << "[";
    for (size_t i = 0; i < v.size(); ++i)
        std::cout << (i ? ", " : "") << v[i];
    std::cout << "]";
}

} // namespace

int main(int argc, char** argv) {
    using namespace mlc;
    keep_freed_memory();
    try {
        const std::string scene_name = argc > 1 ? argv[1] : "square";
        const int level = argc > 2 ? std::stoi(argv[2]) : 5;
        const int repeat = argc > 3 ? std::stoi(argv[3]) : 3;
        const std::filesystem::path dir = argc > 4 ? argv[4] : "out/bench/vtu";
        MLC_CHECK(level >= 0 && level <= 8 && repeat >= 1,
                  "usage: bench_vtu [SCENE [LEVEL 0..8 [REPEAT >= 1 [DIR]]]]");
        levels::Problem p = scene::load_scene(scene_name);
        p.levels = level;
        levels::SolveOptions so;
        so.predicted_sizes = levels::predict_level_sizes(p);
        so.linear = levels::plan_solver(p, {}, 1, &so.predicted_sizes).spec;
        const double t0 = wall_seconds();
        const levels::RunResult r = levels::solve(p, so);
        const double solve_seconds = wall_seconds() - t0;
        MLC_CHECK(r.converged, "the solve did not converge: " << r.failure);
        std::filesystem::create_directories(dir);
        const auto& L = r.finest();
        std::vector<double> t_bin, t_ascii;
        const auto bin = dir / "solution_binary.vtu", ascii = dir / "solution_ascii.vtu";
        for (int k = 0; k < repeat; ++k) {
            double t = wall_seconds();
            apps::write_solution_vtu(bin, L, r.u_full, r.nodes, mesh::VtuFormat::binary);
            t_bin.push_back(wall_seconds() - t);
            t = wall_seconds();
            apps::write_solution_vtu(ascii, L, r.u_full, r.nodes, mesh::VtuFormat::ascii);
            t_ascii.push_back(wall_seconds() - t);
        }
        const auto size_bin = std::filesystem::file_size(bin);
        const auto size_ascii = std::filesystem::file_size(ascii);
        std::cout << "{\"scene\": \"" << p.name << "\", \"level\": " << level
                  << ", \"vertices\": " << L.mesh.n_vertices()
                  << ", \"triangles\": " << L.mesh.n_cells()
                  << ", \"solve_seconds\": " << solve_seconds << ", \"repeat\": " << repeat
                  << ",\n \"binary_bytes\": " << size_bin << ", \"ascii_bytes\": " << size_ascii
                  << ", \"size_ratio_ascii_over_binary\": "
                  << static_cast<double>(size_ascii) / static_cast<double>(size_bin)
                  << ",\n \"binary_seconds_median\": " << median(t_bin)
                  << ", \"ascii_seconds_median\": " << median(t_ascii)
                  << ", \"time_ratio_ascii_over_binary\": " << median(t_ascii) / median(t_bin)
                  << ",\n \"binary_seconds\": ";
        print_list(t_bin);
        std::cout << ", \"ascii_seconds\": ";
        print_list(t_ascii);
        std::cout << "}\n";
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "bench_vtu: error: " << e.what() << "\n";
        return 1;
    }
}

// SPDX-License-Identifier: MIT
// `mlcontact bench square` on several processes.
#include "apps/bench_distributed.hpp"

#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "core/memory.hpp"
#include "core/parallel.hpp"
#include "levels/distributed_solve.hpp"
#include "scene/scene.hpp"

#include <algorithm>
#include <iomanip>
#include <sstream>

namespace mlc::apps {

namespace {
double median_of(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
} // namespace

int bench_square_distributed(const BenchSquareOptions& opt, const Communicator& comm,
                             std::ostream& out) {
    std::ostream null_stream(nullptr);
    const bool root = comm.rank() == 0;
    std::ostream& os = root ? out : null_stream;
    MLC_CHECK(opt.levels >= 1 && opt.levels <= 8,
              "bench square: --levels must be in 1..8, found " << opt.levels);
    MLC_CHECK(opt.repeat >= 1, "bench square: --repeat must be >= 1, found " << opt.repeat);
    MLC_CHECK(opt.pcs.size() == 1 && opt.pcs.front().rfind("mg", 0) == 0,
              "bench square on several processes runs mg alone (--pc mg[:options]); the other "
              "preconditioners have no distributed form");
    levels::Problem p = scene::load_scene(opt.scene);
    p.levels = opt.levels;
    p.validate();
    parallel::set_num_threads(1);
    const int np = comm.size();
    const int plevel = levels::partition_level(p.mesh0.n_triangles(), p.levels, np);
    levels::SolveOptions so;
    so.coarse_to_fine = true;
    so.linear = {.method = "krylov",
                 .krylov = opt.krylov,
                 .pc = opt.pcs.front(),
                 .rel_tol = opt.rel_tol,
                 .max_iter = opt.max_iter};
    os << "bench " << opt.scene << ": levels 0.." << opt.levels << ", coarse-to-fine, "
       << p.load_steps << " load steps, " << np << " processes (one thread each), partition level "
       << plevel << ", Krylov " << opt.krylov << " + distributed " << opt.pcs.front() << " rel_tol "
       << opt.rel_tol << ", times are medians of " << opt.repeat << " run(s)\n";
    std::vector<double> walls;
    levels::DistributedRunResult last;
    for (int rep = 0; rep < opt.repeat; ++rep) {
        last = levels::DistributedRunResult{}; // one run's data alive at a time, as on one process
        comm.barrier();
        const double t0 = wall_seconds();
        levels::DistributedRunResult r = levels::solve_distributed(p, so, comm, plevel);
        comm.barrier();
        walls.push_back(wall_seconds() - t0);
        MLC_CHECK(r.converged, "bench square: the run did not converge: " << r.failure);
        last = std::move(r);
    }
    const double wall = median_of(walls);
    // Per level: the serial levels 0..p (every process alike) and the distributed ones.
    struct Row {
        int level;
        std::int64_t unknowns;
        int newton = 0;
        double its_mean = 0, its_max = 0, seconds = 0;
        bool distributed;
    };
    std::vector<Row> rows;
    auto add = [&](int level, std::int64_t unknowns, const std::vector<levels::LevelStep>& steps,
                   bool dist) {
        Row row{level, unknowns, 0, 0, 0, 0, dist};
        std::vector<int> its;
        for (const auto& st : steps) {
            row.newton += st.report.iterations;
            its.insert(its.end(), st.report.linear_iterations_per_newton.begin(),
                       st.report.linear_iterations_per_newton.end());
            row.seconds += st.report.seconds;
        }
        double sum = 0;
        for (int i : its)
            sum += i;
        row.its_mean = its.empty() ? 0.0 : sum / static_cast<double>(its.size());
        row.its_max = its.empty() ? 0.0 : *std::max_element(its.begin(), its.end());
        rows.push_back(row);
    };
    for (size_t l = 0; l < last.serial.level_steps.size(); ++l)
        add(static_cast<int>(l), last.serial.levels()[l].n_unknowns(), last.serial.level_steps[l],
            false);
    for (size_t k = 1; k < last.level_steps.size(); ++k)
        add(plevel + static_cast<int>(k), last.levels[k].n_global_dofs, last.level_steps[k], true);
    std::vector<double> mine{static_cast<double>(peak_rss_bytes()),
                             static_cast<double>(last.finest().n_owned)};
    const auto all = comm.allgather(std::span<const double>(mine));
    double rss_max = 0;
    for (int q = 0; q < np; ++q)
        rss_max = std::max(rss_max, all[2 * static_cast<size_t>(q)]);
    os << std::setw(6) << "level" << std::setw(12) << "unknowns" << std::setw(13) << "where"
       << std::setw(8) << "newton" << std::setw(10) << "its/newt" << std::setw(6) << "max"
       << std::setw(10) << "seconds\n";
    for (const auto& r : rows)
        os << std::setw(6) << r.level << std::setw(12) << r.unknowns << std::setw(13)
           << (r.distributed ? "distributed" : "every proc.") << std::setw(8) << r.newton
           << std::setw(10) << std::fixed << std::setprecision(2) << r.its_mean << std::setw(6)
           << std::setprecision(0) << r.its_max << std::setw(10) << std::setprecision(3)
           << r.seconds << std::defaultfloat << std::setprecision(6) << "\n";
    os << "wall " << std::fixed << std::setprecision(3) << wall << " s (median of " << walls.size()
       << "; runs";
    for (double w : walls)
        os << " " << w;
    os << "), peak RSS per process max " << std::setprecision(1) << rss_max / (1024.0 * 1024.0)
       << " MiB:" << std::defaultfloat << std::setprecision(6);
    for (int q = 0; q < np; ++q)
        os << " " << levels::format_bytes(all[2 * static_cast<size_t>(q)]);
    os << "\n";
    if (root) {
        const std::filesystem::path file =
            !opt.out.empty() ? opt.out
                             : std::filesystem::path("out/bench/" + opt.scene + "_L" +
                                                     std::to_string(opt.levels) + "_np" +
                                                     std::to_string(np) + ".json");
        if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
        write_file_atomically(file, [&](std::ostream& js) {
            js << std::setprecision(9) << "{\n  \"scene\": \"" << opt.scene
               << "\",\n  \"levels\": " << opt.levels << ",\n  \"processes\": " << np
               << ",\n  \"threads_per_process\": 1,\n  \"partition_level\": " << plevel
               << ",\n  \"krylov\": \"" << opt.krylov << "\",\n  \"pc\": \"" << opt.pcs.front()
               << "\",\n  \"rel_tol\": " << opt.rel_tol << ",\n  \"repeat\": " << opt.repeat
               << ",\n  \"wall_seconds\": " << wall << ",\n  \"wall_seconds_runs\": [";
            for (size_t i = 0; i < walls.size(); ++i)
                js << (i ? ", " : "") << walls[i];
            js << "],\n  \"peak_rss_bytes_max\": " << rss_max << ",\n  \"per_process\": [";
            for (int q = 0; q < np; ++q)
                js << (q ? ", " : "") << "{\"rank\": " << q
                   << ", \"peak_rss_bytes\": " << all[2 * static_cast<size_t>(q)]
                   << ", \"owned_unknowns\": "
                   << static_cast<std::int64_t>(all[2 * static_cast<size_t>(q) + 1]) << "}";
            js << "],\n  \"levels_table\": [";
            for (size_t i = 0; i < rows.size(); ++i) {
                const auto& r = rows[i];
                js << (i ? ",\n    " : "\n    ") << "{\"level\": " << r.level
                   << ", \"unknowns\": " << r.unknowns
                   << ", \"distributed\": " << (r.distributed ? "true" : "false")
                   << ", \"newton\": " << r.newton << ", \"its_per_newton\": " << r.its_mean
                   << ", \"its_max\": " << r.its_max << ", \"seconds\": " << r.seconds << "}";
            }
            js << "\n  ]\n}\n";
        });
        os << "wrote " << file.string() << "\n";
    }
    return 0;
}

} // namespace mlc::apps

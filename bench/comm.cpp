// SPDX-License-Identifier: MIT
// `mlcontact bench comm`: messages, bytes, reductions and seconds per operation of the distributed
// mg (see the header).
#include "bench/comm.hpp"

#include "bench/distributed.hpp"
#include "comm/counters.hpp"
#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "core/memory.hpp"
#include "core/parallel.hpp"
#include "core/timer.hpp"
#include "levels/distributed_solve.hpp"
#include "levels/newton_system.hpp"

#include <Eigen/SparseLU>

#include <algorithm>
#include <array>
#include <iomanip>

namespace mlc::apps {

namespace {

/// One measured operation: seconds per operation (slowest process, median of the repetitions) and
/// per-process counts per operation (max and mean over the processes).
struct Phase {
    std::string name;
    int level = 0;      ///< the level it starts from (matvec, vcycle, cgs), p for coarse_lu
    double per_op = 1;  ///< operations counted per call (the CGS iterations for cgs)
    double seconds = 0; ///< per operation
    std::array<double, 7> max{}, mean{};
};

constexpr std::array<const char*, 7> kCountNames = {"p2p_messages",    "p2p_bytes", "reductions",
                                                    "reduction_bytes", "gathers",   "gather_bytes",
                                                    "barriers"};

std::array<double, 7> as_array(const comm::MpiCounts& c) {
    return {static_cast<double>(c.p2p_messages), static_cast<double>(c.p2p_bytes),
            static_cast<double>(c.reductions),   static_cast<double>(c.reduction_bytes),
            static_cast<double>(c.gathers),      static_cast<double>(c.gather_bytes),
            static_cast<double>(c.barriers)};
}

double median3(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

/// The sizes per level, the table of operations and the JSON file (process 0); returns the
/// exit code.
int report_comm(std::ostream& os, bool root, const BenchCommOptions& opt, const Communicator& comm,
                const ElasticHierarchy& h, const std::vector<Phase>& phases, bool counting,
                bool converged) {
    const int np = comm.size();
    const int p = h.partition_level;
    const auto& dl = h.levels;
    const size_t m = dl.size() - 1;
    // Sizes: per level the global unknowns and the largest owned and ghost counts.
    std::vector<double> mine;
    for (size_t k = 0; k <= m; ++k) {
        mine.push_back(static_cast<double>(dl[k].n_owned));
        mine.push_back(static_cast<double>(dl[k].local.n_unknowns() - dl[k].n_owned));
    }
    mine.push_back(peak_rss_bytes());
    const auto sizes = comm.allgather(std::span<const double>(mine));
    const size_t w = mine.size();
    auto max_over = [&](size_t c) {
        double v = 0;
        for (int q = 0; q < np; ++q)
            v = std::max(v, sizes[w * static_cast<size_t>(q) + c]);
        return v;
    };

    os << "bench comm: " << opt.scene << " elastic block, levels " << p << ".." << opt.levels
       << " (partition level " << p << ", coarse LU of " << h.level_p.n_unknowns()
       << " unknowns on every process), " << np << " process(es), one thread each; "
       << (counting ? "MPI counts from the PMPI library" : "one process: times only") << "\n";
    os << std::setw(6) << "level" << std::setw(14) << "unknowns" << std::setw(12) << "owned max"
       << std::setw(12) << "ghost max\n";
    for (size_t k = 0; k <= m; ++k)
        os << std::setw(6) << p + static_cast<int>(k) << std::setw(14) << dl[k].n_global_dofs
           << std::setw(12) << max_over(2 * k) << std::setw(12) << max_over(2 * k + 1) << "\n";
    os << std::setw(10) << "operation" << std::setw(6) << "from" << std::setw(12) << "seconds"
       << std::setw(10) << "msgs" << std::setw(12) << "bytes" << std::setw(8) << "reduce"
       << std::setw(8) << "gather" << std::setw(14) << "gather bytes"
       << "   (per operation; counts: max over processes)\n";
    for (const Phase& ph : phases)
        os << std::setw(10) << ph.name << std::setw(6) << ph.level << std::scientific
           << std::setprecision(3) << std::setw(12) << ph.seconds << std::defaultfloat
           << std::setprecision(4) << std::setw(10) << ph.max[0] << std::setw(12) << ph.max[1]
           << std::setw(8) << ph.max[2] << std::setw(8) << ph.max[4] << std::setw(14) << ph.max[5]
           << "\n";
    const double cgs_its = phases.back().per_op;
    os << "cgs: " << cgs_its << " iterations to " << opt.rel_tol
       << (converged ? "" : "  NOT CONVERGED") << "\n";
    if (root) {
        const std::filesystem::path file =
            !opt.out.empty() ? opt.out
                             : std::filesystem::path("out/bench/comm_" + opt.scene + "_L" +
                                                     std::to_string(opt.levels) + "_np" +
                                                     std::to_string(np) + ".json");
        if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
        write_file_atomically(file, [&](std::ostream& js) {
            js << std::setprecision(12) << "{\n  \"scene\": \"" << opt.scene
               << "\",\n  \"level\": " << opt.levels << ",\n  \"processes\": " << np
               << ",\n  \"threads_per_process\": 1,\n  \"partition_level\": " << p
               << ",\n  \"coarse_unknowns\": " << h.level_p.n_unknowns()
               << ",\n  \"level0_triangles\": " << h.problem.mesh0.n_cells()
               << ",\n  \"counted\": " << (counting ? "true" : "false")
               << ",\n  \"ops\": " << opt.ops << ",\n  \"cgs_iterations\": " << cgs_its
               << ",\n  \"cgs_converged\": " << (converged ? "true" : "false")
               << ",\n  \"peak_rss_bytes_max\": " << max_over(w - 1) << ",\n  \"levels\": [";
            for (size_t k = 0; k <= m; ++k)
                js << (k ? ", " : "") << "{\"level\": " << p + static_cast<int>(k)
                   << ", \"unknowns\": " << dl[k].n_global_dofs
                   << ", \"owned_max\": " << max_over(2 * k)
                   << ", \"ghost_max\": " << max_over(2 * k + 1) << "}";
            js << "],\n  \"operations\": [";
            for (size_t i = 0; i < phases.size(); ++i) {
                const Phase& ph = phases[i];
                js << (i ? "," : "") << "\n    {\"name\": \"" << ph.name
                   << "\", \"level\": " << ph.level << ", \"seconds\": " << ph.seconds
                   << ", \"max\": {";
                for (size_t c = 0; c < 7; ++c)
                    js << (c ? ", " : "") << "\"" << kCountNames[c] << "\": " << ph.max[c];
                js << "}, \"mean\": {";
                for (size_t c = 0; c < 7; ++c)
                    js << (c ? ", " : "") << "\"" << kCountNames[c] << "\": " << ph.mean[c];
                js << "}}";
            }
            js << "\n  ]\n}\n";
        });
        os << "wrote " << file.string() << "\n";
    }
    return converged ? 0 : 2;
}

} // namespace

int bench_comm(const BenchCommOptions& opt, const Communicator& comm, std::ostream& out) {
    std::ostream null_stream(nullptr);
    const bool root = comm.rank() == 0;
    std::ostream& os = root ? out : null_stream;
    MLC_CHECK(opt.levels >= 1 && opt.levels <= 8,
              "bench comm: --levels must be in 1..8, found " << opt.levels);
    MLC_CHECK(opt.ops >= 1, "bench comm: --ops must be >= 1, found " << opt.ops);
    MLC_CHECK(opt.rel_tol > 0 && opt.rel_tol < 1,
              "bench comm: --tol must be in (0, 1), found " << opt.rel_tol);
    const int np = comm.size();
    const bool counting = comm::mpi_counts().has_value();
    // Every process must agree (a launcher may preload on some hosts only).
    MLC_CHECK(comm.min(counting ? 1 : 0) == comm.max(counting ? 1 : 0),
              "bench comm: the PMPI library is loaded on some processes only");
    MLC_CHECK(np == 1 || counting, "bench comm counts MPI traffic with the PMPI library "
                                       << comm::pmpi_counters_library()
                                       << ", which is not loaded: run mpirun -np " << np
                                       << " -x LD_PRELOAD=" << comm::pmpi_counters_library()
                                       << " mlcontact bench comm ...");
    parallel::set_num_threads(1);
    const auto h = build_elastic_hierarchy(opt.scene, opt.levels, opt.partition_level, comm);
    const int p = h->partition_level;
    const auto& dl = h->levels;
    const size_t m = dl.size() - 1;
    MLC_CHECK(m >= 1, "bench comm: no distributed level above the partition level");

    const levels::LinearSolverSpec spec{.method = solvers::Method::krylov,
                                        .krylov = solvers::Krylov::cgs,
                                        .pc = solvers::parse_pc("mg"),
                                        .rel_tol = opt.rel_tol,
                                        .max_iter = 1000};
    levels::DistributedMultigrid mg(dl, h->transfers, comm, spec,
                                    levels::distributed_mg_params(spec));
    mg.set_coarse(h->level_p, {});
    for (size_t k = 1; k <= m; ++k)
        mg.prepare(k, {});

    std::vector<Phase> phases;
    // Runs f ops times between barriers, three times; the counts of the last repetition.
    auto measure = [&](Phase ph, auto&& f) {
        std::vector<double> secs;
        std::array<double, 7> mine{};
        for (int rep = 0; rep < 3; ++rep) {
            comm.barrier();
            const auto c0 = comm::mpi_counts();
            const double t0 = wall_seconds();
            double per_op = 0;
            for (int i = 0; i < opt.ops; ++i)
                per_op += f();
            const double t1 = wall_seconds();
            const auto c1 = comm::mpi_counts();
            ph.per_op = per_op / opt.ops;
            secs.push_back(comm.max(t1 - t0) / (opt.ops * ph.per_op));
            if (c0 && c1) mine = as_array(*c1 - *c0);
        }
        ph.seconds = median3(secs);
        const auto all = comm.allgather(std::span<const double>(mine.data(), mine.size()));
        for (size_t c = 0; c < 7; ++c) {
            double mx = 0, sum = 0;
            for (int q = 0; q < np; ++q) {
                const double v = all[7 * static_cast<size_t>(q) + c] / (opt.ops * ph.per_op);
                mx = std::max(mx, v);
                sum += v;
            }
            ph.max[c] = mx;
            ph.mean[c] = sum / np;
        }
        phases.push_back(ph);
    };

    const levels::DistributedLevel& fine = dl[m];
    const Vector b = fine.local.elastic.f.head(fine.n_owned);
    Vector y;
    measure({.name = "matvec", .level = opt.levels}, [&] {
        mg.matrix(m).apply(b, y);
        return 1.0;
    });
    for (size_t k = m; k >= 1; --k) {
        const auto pc = mg.preconditioner(k);
        const Vector r = Vector::Ones(dl[k].n_owned);
        measure({.name = "vcycle", .level = p + static_cast<int>(k)}, [&] {
            pc->apply(r, y);
            return 1.0;
        });
    }
    {
        levels::JacobianAssembler a(h->level_p);
        a.assemble({});
        Eigen::SparseLU<SparseMatrixCol> lu;
        lu.compute(a.matrix());
        MLC_CHECK(lu.info() == Eigen::Success, "bench comm: level p's LU failed");
        const Vector r = Vector::Ones(h->level_p.n_unknowns());
        Vector z;
        measure({.name = "coarse_lu", .level = p}, [&] {
            z = lu.solve(r);
            return 1.0;
        });
    }
    bool converged = true;
    measure({.name = "cgs", .level = opt.levels}, [&] {
        Vector x = Vector::Zero(fine.n_owned);
        const SolveResult s = mg.solve(m, {}, b, x, 0.0);
        converged = converged && s.converged;
        return static_cast<double>(std::max(1, s.iterations));
    });

    return report_comm(os, root, opt, comm, *h, phases, counting, converged);
}

} // namespace mlc::apps

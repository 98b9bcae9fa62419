// SPDX-License-Identifier: MIT
// `mlcontact bench square` on several processes.
#include "bench/distributed.hpp"

#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "core/memory.hpp"
#include "core/parallel.hpp"
#include "core/timer.hpp"
#include "levels/distributed_solve.hpp"
#include "levels/level.hpp"
#include "levels/resources.hpp"
#include "mesh/mesh.hpp"
#include "scene/scene.hpp"
#include "solvers/hypre/boomeramg.hpp"
#include "solvers/krylov.hpp"

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
    MLC_CHECK(opt.pcs.size() == 1,
              "bench square on several processes runs one solver at a time (--pc default or "
              "one preconditioner with a distributed form), found "
                  << opt.pcs.size());
    levels::Problem p = scene::load_scene(opt.scene);
    p.levels = opt.levels;
    p.validate();
    // The plan numbers the levels (by lattices for a lattice sweep, else along a Hilbert curve).
    const levels::SolverPlan plan = bench_plan(opt, opt.pcs.front(), p, comm.size());
    p.numbering = plan.numbering();
    parallel::set_num_threads(1);
    const int np = comm.size();
    const int plevel = levels::partition_level(p.mesh0.n_cells(), p.levels, np);
    levels::SolveOptions so;
    so.coarse_to_fine = true;
    so.linear = plan.spec;
    os << "bench " << opt.scene << ": levels 0.." << opt.levels << ", coarse-to-fine, "
       << p.load_steps << " load steps, " << np << " processes (one thread each), partition level "
       << plevel << ", Krylov " << plan.spec.krylov << " + distributed " << plan.spec.pc
       << " rel_tol " << opt.rel_tol << ", times are medians of " << opt.repeat << " run(s)\n";
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
               << ",\n  \"krylov\": \"" << plan.spec.krylov << "\",\n  \"pc\": \"" << plan.spec.pc
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

namespace {

/// One solver's numbers in bench elastic on several processes.
struct ElasticRow {
    std::string name;
    std::vector<double> setup, solve; ///< per repetition, the slowest process's
    int iterations = 0;
    double relative_residual = 0, x_norm = 0, x_max = 0;
    bool converged = false;
};

/// ||b - K x|| / ||b|| over the processes (K a ParMatrix, owned entries).
double global_relres(const solvers::ParMatrix& K, const Vector& b, const Vector& x,
                     const Communicator& comm) {
    Vector r;
    K.apply(x, r);
    r = b - r;
    const double rn = std::sqrt(comm.sum(r.squaredNorm()));
    const double bn = std::sqrt(comm.sum(b.squaredNorm()));
    return bn > 0 ? rn / bn : rn;
}

} // namespace

std::unique_ptr<ElasticHierarchy> build_elastic_hierarchy(const std::string& scene, int L,
                                                          int partition_level,
                                                          const Communicator& comm) {
    auto h = std::make_unique<ElasticHierarchy>();
    h->problem = scene::load_scene(scene);
    levels::Problem& problem = h->problem;
    // Without contact pairs the levels have no multipliers: every level's K is the elastic block
    // on the free displacements (the one-process bench's restriction).
    problem.contacts.clear();
    problem.levels = L;
    problem.validate();
    const int p = partition_level >= 0
                      ? partition_level
                      : levels::partition_level(problem.mesh0.n_cells(), L, comm.size());
    MLC_CHECK(p >= 0 && p < L, "the partition level must lie in 0.." << L - 1 << ", found " << p);
    h->partition_level = p;

    // The levels p..L as a distributed run builds them, and level p whole (the coarse solve).
    comm.barrier();
    const double th0 = wall_seconds();
    mesh::Mesh mp = problem.mesh0;
    for (int l = 0; l < p; ++l)
        mp = mesh::refine(mp);
    h->level_p = levels::build_level(problem, mp);
    {
        auto dh = mesh::distribute(mp, L - p, comm);
        mp = mesh::Mesh{};
        for (auto& lv : dh.levels)
            h->levels.push_back(levels::build_distributed_level(problem, std::move(lv), comm));
    }
    for (size_t k = 1; k < h->levels.size(); ++k)
        h->transfers.push_back(
            levels::build_distributed_transfer(h->levels[k - 1], h->levels[k], comm));
    h->seconds = comm.max(wall_seconds() - th0);
    return h;
}

namespace {

/// BoomerAMG-PCG: hypre's ParCSR PCG on a copy of K made through IJ (which puts the diagonal
/// entry first in each row, as BoomerAMG expects); the copy is part of the setup, as on one
/// process. `x`: the last repetition's solution.
ElasticRow boomeramg_pcg_row(const levels::DistributedLevel& fine, const Vector& b,
                             const BenchElasticOptions& opt, const Communicator& comm, Vector& x) {
    const Index n = fine.n_owned;
    std::vector<int> dof_func(static_cast<size_t>(n));
    for (Index i = 0; i < n; ++i) {
        const int v = fine.local.dofs.vertex_of(i);
        dof_func[static_cast<size_t>(i)] = fine.local.dofs.u_dof(v, 0) == i ? 0 : 1;
    }
    const solvers::DistributedRows rows = solvers::distributed_rows(*fine.K_blocks);
    ElasticRow r;
    r.name = "boomeramg-pcg";
    for (int rep = 0; rep < opt.repeat; ++rep) {
        comm.barrier();
        const double t0 = wall_seconds();
        const solvers::ParMatrix K(comm, rows);
        const double copy = wall_seconds() - t0;
        x = Vector::Zero(n);
        const SolveResult s =
            solvers::boomeramg_pcg_par(K, b, x, opt.rel_tol, opt.max_iter, {}, dof_func);
        r.setup.push_back(comm.max(copy + s.setup_seconds));
        r.solve.push_back(comm.max(s.solve_seconds));
        r.iterations = s.iterations;
        r.converged = s.converged;
    }
    return r;
}

/// The JSON file of the distributed elastic bench (process 0); returns its path.
std::filesystem::path write_elastic_json(const BenchElasticOptions& opt, int np, int p,
                                         Index unknowns, std::int64_t nnz, double hierarchy_s,
                                         double diff, double rss_max,
                                         const std::vector<double>& all,
                                         const std::vector<ElasticRow>& results) {
    const std::filesystem::path file =
        !opt.out.empty() ? opt.out
                         : std::filesystem::path("out/bench/elastic_" + opt.scene + "_L" +
                                                 std::to_string(opt.levels) + "_np" +
                                                 std::to_string(np) + ".json");
    if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
    write_file_atomically(file, [&](std::ostream& js) {
        js << std::setprecision(12) << "{\n  \"scene\": \"" << opt.scene
           << "\",\n  \"level\": " << opt.levels << ",\n  \"processes\": " << np
           << ",\n  \"threads_per_process\": 1,\n  \"partition_level\": " << p
           << ",\n  \"unknowns\": " << unknowns << ",\n  \"nonzeros\": " << nnz
           << ",\n  \"rel_tol\": " << opt.rel_tol << ",\n  \"repeat\": " << opt.repeat
           << ",\n  \"levels_seconds\": " << hierarchy_s << ",\n  \"solution_difference\": " << diff
           << ",\n  \"peak_rss_bytes_max\": " << rss_max << ",\n  \"per_process\": [";
        for (int q = 0; q < np; ++q)
            js << (q ? ", " : "") << "{\"rank\": " << q
               << ", \"peak_rss_bytes\": " << all[2 * static_cast<size_t>(q)]
               << ", \"owned_unknowns\": "
               << static_cast<std::int64_t>(all[2 * static_cast<size_t>(q) + 1]) << "}";
        js << "],\n  \"solvers\": [";
        for (size_t k = 0; k < results.size(); ++k) {
            const auto& r = results[k];
            const double su = median_of(r.setup), so = median_of(r.solve);
            js << (k ? "," : "") << "\n    {\"solver\": \"" << r.name
               << "\", \"setup_seconds\": " << su << ", \"solve_seconds\": " << so
               << ", \"total_seconds\": " << su + so << ", \"iterations\": " << r.iterations
               << ", \"relative_residual\": " << r.relative_residual
               << ", \"converged\": " << (r.converged ? "true" : "false")
               << ", \"x_norm\": " << r.x_norm << ", \"x_max_norm\": " << r.x_max << "}";
        }
        js << "\n  ]\n}\n";
    });
    return file;
}

} // namespace

int bench_elastic_distributed(const BenchElasticOptions& opt, const Communicator& comm,
                              std::ostream& out) {
    std::ostream null_stream(nullptr);
    const bool root = comm.rank() == 0;
    std::ostream& os = root ? out : null_stream;
    MLC_CHECK(!opt.direct, "bench elastic: --direct runs on one process (a 3D scene's direct "
                           "solve); run it without mpirun");
    MLC_CHECK(opt.levels >= 1 && opt.levels <= 8,
              "bench elastic: --levels must be in 1..8, found " << opt.levels);
    MLC_CHECK(opt.repeat >= 1, "bench elastic: --repeat must be >= 1, found " << opt.repeat);
    MLC_CHECK(opt.rel_tol > 0 && opt.rel_tol < 1,
              "bench elastic: --tol must be in (0, 1), found " << opt.rel_tol);
    parallel::set_num_threads(1);
    const auto h = build_elastic_hierarchy(opt.scene, opt.levels, -1, comm);
    const int np = comm.size();
    const int L = opt.levels;
    const int p = h->partition_level;
    const double hierarchy_s = h->seconds;
    const levels::Level& level_p = h->level_p;
    const std::vector<levels::DistributedLevel>& dl = h->levels;
    const std::vector<levels::DistributedTransfer>& transfers = h->transfers;
    const size_t m = dl.size() - 1;
    const levels::DistributedLevel& fine = dl.back();
    const Index n = fine.n_owned;
    const Vector b = fine.local.elastic.f.head(n);
    MLC_CHECK(comm.sum(b.squaredNorm()) > 0,
              "bench elastic: the scene has no load on the free unknowns");
    const std::int64_t nnz = comm.sum(
        static_cast<std::int64_t>(fine.K_blocks->diag.nonZeros() + fine.K_blocks->offd.nonZeros()));
    os << "bench elastic: " << opt.scene << " level " << L << ", elastic block "
       << fine.n_global_dofs << " unknowns, " << nnz << " nonzeros, " << np
       << " processes (one thread each), partition level " << p << ", rel_tol " << opt.rel_tol
       << ", times are medians of " << opt.repeat
       << " run(s) of the slowest process (levels built in " << std::fixed << std::setprecision(2)
       << hierarchy_s << std::defaultfloat << " s)\n";

    std::vector<ElasticRow> results;
    std::vector<Vector> solutions;
    auto finish = [&](ElasticRow& r, const Vector& x) {
        r.relative_residual = global_relres(*fine.K, b, x, comm);
        r.x_norm = std::sqrt(comm.sum(x.squaredNorm()));
        r.x_max = comm.max(x.size() ? x.lpNorm<Eigen::Infinity>() : 0.0);
        r.converged = comm.min(r.converged ? 1 : 0) == 1;
        results.push_back(r);
        solutions.push_back(x);
    };
    // BoomerAMG-PCG: hypre's ParCSR PCG on a copy of K made through IJ (which puts the diagonal
    // entry first in each row, as BoomerAMG expects); the copy is part of the setup, as on one
    // process.
    {
        Vector x;
        ElasticRow r = boomeramg_pcg_row(fine, b, opt, comm, x);
        finish(r, x);
    }
    // The distributed V-cycle inside GMRES and CGS, set up anew in every repetition (like AMG):
    // the multigrid, the coarse LU of level p and every level's smoother.
    // CG too: hybrid Gauss-Seidel forward before and backward after the coarse correction make the
    // V-cycle a symmetric preconditioner of the symmetric K, as on one process.
    for (const std::string krylov : {"gmres", "cgs", "cg"}) {
        const bool cg = krylov == "cg";
        const levels::LinearSolverSpec spec{.method = solvers::Method::krylov,
                                            .krylov = solvers::parse_krylov(cg ? "cgs" : krylov),
                                            .pc = solvers::parse_pc("mg"),
                                            .rel_tol = opt.rel_tol,
                                            .max_iter = opt.max_iter};
        ElasticRow r;
        r.name = "mg-" + krylov;
        Vector x;
        for (int rep = 0; rep < opt.repeat; ++rep) {
            comm.barrier();
            const double t0 = wall_seconds();
            levels::DistributedMultigrid mg(dl, transfers, comm, spec,
                                            levels::distributed_mg_params(spec));
            mg.set_coarse(level_p, {});
            for (size_t k = 1; k <= m; ++k)
                mg.prepare(k, {});
            const auto pc = mg.preconditioner(m);
            const double t1 = wall_seconds();
            x = Vector::Zero(n);
            solvers::KrylovParams kp;
            kp.rel_tol = opt.rel_tol;
            kp.max_iter = opt.max_iter;
            kp.comm = &comm;
            const SolveResult s =
                cg ? solvers::cg(mg.matrix(m), *pc, b, x, kp) : mg.solve(m, {}, b, x, 0.0);
            const double t2 = wall_seconds();
            r.setup.push_back(comm.max(t1 - t0));
            r.solve.push_back(comm.max(t2 - t1));
            r.iterations = s.iterations;
            r.converged = s.converged;
        }
        finish(r, x);
    }
    // Relative difference of the AMG and mg-gmres solutions (the same owned entries).
    const double diff = std::sqrt(comm.sum((solutions[0] - solutions[1]).squaredNorm())) /
                        std::max(results[0].x_norm, 1e-300);

    std::vector<double> mine{peak_rss_bytes(), static_cast<double>(n)};
    const auto all = comm.allgather(std::span<const double>(mine));
    double rss_max = 0;
    for (int q = 0; q < np; ++q)
        rss_max = std::max(rss_max, all[2 * static_cast<size_t>(q)]);

    os << std::setw(16) << "solver" << std::setw(10) << "setup s" << std::setw(10) << "solve s"
       << std::setw(10) << "total s" << std::setw(7) << "its" << std::setw(12) << "rel.res"
       << std::setw(14) << "||x||"
       << "\n";
    int code = 0;
    for (const auto& r : results) {
        const double su = median_of(r.setup), so = median_of(r.solve);
        if (!r.converged) code = 2;
        os << std::setw(16) << r.name << std::fixed << std::setprecision(3) << std::setw(10) << su
           << std::setw(10) << so << std::setw(10) << su + so << std::setw(7) << r.iterations
           << std::scientific << std::setprecision(2) << std::setw(12) << r.relative_residual
           << std::setprecision(6) << std::setw(14) << r.x_norm << std::defaultfloat
           << std::setprecision(6) << (r.converged ? "" : "  NOT CONVERGED") << "\n";
    }
    os << "relative difference of the AMG and mg-gmres solutions: " << std::scientific
       << std::setprecision(2) << diff << std::defaultfloat << std::setprecision(6)
       << "; peak RSS per process:";
    for (int q = 0; q < np; ++q)
        os << " " << levels::format_bytes(all[2 * static_cast<size_t>(q)]);
    os << "\n";
    if (root) {
        const std::filesystem::path file = write_elastic_json(
            opt, np, p, fine.n_global_dofs, nnz, hierarchy_s, diff, rss_max, all, results);
        os << "wrote " << file.string() << "\n";
    }
    return code;
}

} // namespace mlc::apps

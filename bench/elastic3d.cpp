// SPDX-License-Identifier: MIT
// `mlcontact bench elastic` on a 3D scene: mg-CG beside BoomerAMG-PCG on the finest level's
// elastic block.
#include "bench/bench.hpp"
#include "bench/common.hpp"

#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "core/linear_operator.hpp"
#include "core/memory.hpp"
#include "core/parallel.hpp"
#include "core/timer.hpp"
#include "levels/elastic3d_levels.hpp"
#include "scene/scene3.hpp"
#include "solvers/cholesky.hpp"
#include "solvers/hypre/boomeramg.hpp"
#include "solvers/krylov.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>

namespace mlc::apps {

namespace {

struct Run3 {
    std::string name;
    std::vector<double> setup, solve;
    int iterations = 0;
    double relative_residual = 0;
    bool converged = false;
    double peak_rss_mib = 0; ///< peak resident memory of the process after this solver
    double estimate_mib = 0; ///< its predicted peak (hierarchy + this solver)
    double x_norm = 0;
    /// One repetition's figures.
    void add(double setup_seconds, const SolveResult& s) {
        setup.push_back(setup_seconds);
        solve.push_back(s.solve_seconds);
        iterations = s.iterations;
        relative_residual = s.relative_residual;
        converged = s.converged;
    }
};

constexpr double kMiB = 1024.0 * 1024.0;

/// "W(2,2)": the cycle of levels::elastic3_mg_params.
std::string mg_cycle() {
    return solvers::cycle_text(levels::elastic3_mg_params());
}

/// mg-CG: the multigrid set up anew in every repetition (its setup timed), CG to rel_tol.
Run3 run_mg(const levels::Hierarchy3& h, const Vector& b, const BenchElasticOptions& opt,
            Vector& x) {
    Run3 r;
    r.name = "mg-cg";
    const SparseMatrix& K = h.finest().elastic.K;
    for (int rep = 0; rep < opt.repeat; ++rep) {
        const double t0 = wall_seconds();
        const auto mg = levels::elastic3_multigrid(h);
        const double t1 = wall_seconds();
        x = Vector::Zero(K.rows());
        solvers::KrylovParams kp;
        kp.rel_tol = opt.rel_tol;
        kp.max_iter = opt.max_iter;
        const SolveResult s = solvers::cg(MatrixOperator(K, MatVec::unrolled), *mg, b, x, kp);
        r.add(t1 - t0, s);
    }
    r.x_norm = x.norm();
    return r;
}

/// BoomerAMG-PCG with hypre's elasticity settings and the three rotational rigid-body modes.
Run3 run_amg(const levels::Hierarchy3& h, const Vector& b, const BenchElasticOptions& opt,
             Vector& x) {
    Run3 r;
    r.name = "boomeramg-pcg";
    const SparseMatrix& K = h.finest().elastic.K;
    // The rotations: hypre's unknown-based interpolation reproduces the translations already.
    const std::vector<Vector> all = levels::rigid_body_modes3(h.finest());
    const std::vector<Vector> modes(all.begin() + 3, all.end());
    for (int rep = 0; rep < opt.repeat; ++rep) {
        x = Vector::Zero(K.rows());
        const SolveResult s = solvers::boomeramg_pcg(K, b, x, opt.rel_tol, opt.max_iter,
                                                     solvers::boomeramg_elasticity3d(), {}, modes);
        r.add(s.setup_seconds, s);
    }
    r.x_norm = x.norm();
    return r;
}

/// The direct solve: CHOLMOD's supernodal Cholesky factor of K in its fill-reducing order (AMD or
/// METIS nested dissection), then the two triangular solves; the order and the factor are the
/// setup, timed in every repetition. One "iteration".
Run3 run_direct(const levels::Hierarchy3& h, const Vector& b, const BenchElasticOptions& opt,
                Vector& x, double& factor_nonzeros) {
    Run3 r;
    r.name = "cholmod";
    const SparseMatrix& K = h.finest().elastic.K;
    const Index n = K.rows();
    for (int rep = 0; rep < opt.repeat; ++rep) {
        const double t0 = wall_seconds();
        const SparseMatrixCol Kc(K);
        const std::vector<int> order = solvers::SparseCholesky::fill_reducing_order(Kc);
        Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> perm(n); // perm[old] = new
        for (Index k = 0; k < n; ++k)
            perm.indices()[order[static_cast<size_t>(k)]] = static_cast<int>(k);
        SparseMatrixCol Kp(n, n);
        Kp.selfadjointView<Eigen::Lower>() = Kc.selfadjointView<Eigen::Lower>().twistedBy(perm);
        solvers::SparseCholesky chol;
        chol.factor(Kp);
        factor_nonzeros = chol.factor_nonzeros();
        const double t1 = wall_seconds();
        Vector xp;
        chol.solve(perm * b, xp);
        x = perm.inverse() * xp;
        const double t2 = wall_seconds();
        SolveResult s;
        s.iterations = 1;
        s.solve_seconds = t2 - t1;
        s.relative_residual = (b - K * x).norm() / b.norm();
        s.converged = std::isfinite(s.relative_residual) && s.relative_residual <= opt.rel_tol;
        r.add(t1 - t0, s);
    }
    r.x_norm = x.norm();
    return r;
}

/// Sets the thread count for the bench and restores it after.
struct ThreadsFor {
    int was;
    explicit ThreadsFor(int n) : was(parallel::num_threads()) { parallel::set_num_threads(n); }
    ~ThreadsFor() { parallel::set_num_threads(was); }
    ThreadsFor(const ThreadsFor&) = delete;
    ThreadsFor& operator=(const ThreadsFor&) = delete;
};

void write_json3(std::ostream& js, const BenchElasticOptions& opt, int L,
                 const levels::Hierarchy3& h, const std::vector<levels::ElasticLevelSize3>& sizes,
                 const levels::ElasticMemory3& mem, const std::vector<Run3>& runs, double ratio,
                 double diff, int threads, double hierarchy_s, double factor_nonzeros,
                 const levels::ElasticPlan3& plan) {
    const auto& K = h.finest().elastic.K;
    js << "{\n  \"scene\": " << json_string(opt.scene) << ",\n  \"dimension\": 3"
       << ",\n  \"level\": " << L << ",\n  \"unknowns\": " << K.rows()
       << ",\n  \"nonzeros\": " << K.nonZeros()
       << ",\n  \"predicted_unknowns\": " << std::setprecision(12) << sizes.back().unknowns
       << std::setprecision(6) << ",\n  \"rel_tol\": " << opt.rel_tol
       << ",\n  \"repeat\": " << opt.repeat << ",\n  \"threads\": " << threads
       << ",\n  \"hierarchy_seconds\": " << hierarchy_s
       << ",\n  \"memory_estimate_mib\": " << mem.bytes() / kMiB
       << ",\n  \"peak_rss_mib\": " << peak_rss_mib()
       << ",\n  \"mg_cycle\": " << (plan.multigrid ? json_string(mg_cycle()) : std::string("null"))
       << ",\n  \"plan\": " << json_string(plan.multigrid ? "mg-cg" : "cholmod")
       << ",\n  \"time_ratio_mg_over_amg\": ";
    if (plan.multigrid)
        js << ratio;
    else
        js << "null";
    if (factor_nonzeros > 0) js << ",\n  \"cholmod_factor_nonzeros\": " << factor_nonzeros;
    js << ",\n  \"solution_difference\": " << diff << ",\n  \"levels\": [";
    for (size_t l = 0; l < h.levels.size(); ++l)
        js << (l ? ", " : "") << "{\"level\": " << l
           << ", \"unknowns\": " << h.levels[l].elastic.K.rows()
           << ", \"nonzeros\": " << h.levels[l].elastic.K.nonZeros() << "}";
    js << "],\n  \"solvers\": [";
    for (size_t k = 0; k < runs.size(); ++k) {
        const Run3& r = runs[k];
        const double su = median(r.setup), so = median(r.solve);
        js << (k ? "," : "") << "\n    {\"solver\": " << json_string(r.name)
           << ", \"unknowns\": " << K.rows() << ", \"iterations\": " << r.iterations
           << ", \"setup_seconds\": " << su << ", \"solve_seconds\": " << so
           << ", \"total_seconds\": " << su + so
           << ", \"relative_residual\": " << r.relative_residual
           << ", \"converged\": " << (r.converged ? "true" : "false")
           << ", \"peak_rss_mib\": " << r.peak_rss_mib
           << ", \"memory_estimate_mib\": " << r.estimate_mib
           << ", \"x_norm\": " << std::setprecision(12) << r.x_norm << std::setprecision(6) << "}";
    }
    js << "\n  ]\n}\n";
}

} // namespace

int bench_elastic3d(const BenchElasticOptions& opt, std::ostream& os) {
    MLC_CHECK(opt.repeat >= 1, "bench elastic: --repeat must be >= 1, found " << opt.repeat);
    MLC_CHECK(opt.rel_tol > 0 && opt.rel_tol < 1,
              "bench elastic: --tol must be in (0, 1), found " << opt.rel_tol);
    // A contact scene's elastic block: its stiffness on the displacements alone, the contact
    // pairs left out (the system `mlcontact run`'s Newton solves adds their rows and columns).
    levels::ElasticProblem3 p = scene::load_scene3(opt.scene);
    const size_t n_pairs = p.contacts.size();
    p.contacts.clear();
    if (n_pairs > 0)
        os << "bench elastic: '" << p.name << "' has " << n_pairs
           << " contact pair(s); the elastic block is its stiffness on the displacements alone\n";
    const int L = opt.levels_from_scene ? p.levels : opt.levels;
    MLC_CHECK(L >= 0 && L <= levels::kMaxLevels3, "bench elastic: a 3D scene's level must be in 0.."
                                                      << levels::kMaxLevels3 << ", found " << L);
    // The planner's solver: the multigrid when a level below exists, else the direct factor.
    const levels::ElasticPlan3 plan = levels::plan_elastic3(L);
    const bool direct = opt.direct || !plan.multigrid;
    // Sizes and memory first: a run that cannot fit is refused before anything is built.
    const auto sizes = levels::predict_elastic3_sizes(p, L);
    const levels::ElasticMemory3 mem = levels::estimate_elastic3_memory(sizes);
    const levels::MemoryLimit limit = levels::process_memory_limit();
    levels::check_elastic3_fits(mem, limit, sizes);
    // The direct solve runs after the others, beside the hierarchy alone.
    const double direct_peak =
        mem.baseline_bytes + mem.hierarchy_bytes + levels::estimate_direct3_bytes(sizes.back());
    if (direct && direct_peak > limit.bytes)
        throw InvalidInput("bench elastic --direct: the direct solve of level " +
                           std::to_string(L) + " (" +
                           std::to_string(static_cast<long>(sizes.back().unknowns)) +
                           " unknowns) needs an estimated " + levels::format_bytes(direct_peak) +
                           " (its Cholesky factor grows like unknowns^1.39) but this process "
                           "may use " +
                           levels::format_bytes(std::max(0.0, limit.bytes)) + " (" + limit.source +
                           "): drop --direct or use fewer --levels");
    // Equal cores: hypre's thread count for both.
    const int threads = solvers::hypre_threads();
    const ThreadsFor set_threads(threads);
    const double th0 = wall_seconds();
    const levels::Hierarchy3 h = levels::build_hierarchy(p, L);
    const double hierarchy_s = wall_seconds() - th0;
    const SparseMatrix& K = h.finest().elastic.K;
    const Vector& b = h.finest().elastic.f;
    MLC_CHECK(b.norm() > 0, "bench elastic: the scene has no load on the free unknowns");
    os << "bench elastic: " << opt.scene << " (3D) level " << L << ", elastic block " << K.rows()
       << " unknowns (predicted " << std::setprecision(7) << sizes.back().unknowns
       << std::setprecision(6) << "), " << K.nonZeros() << " nonzeros, rel_tol " << opt.rel_tol
       << ", " << threads << " thread(s) each, times are medians of " << opt.repeat
       << " run(s) (hierarchy built in " << std::fixed << std::setprecision(2) << hierarchy_s
       << std::defaultfloat << " s; memory estimate " << levels::format_bytes(mem.bytes()) << ")\n";
    os << "plan: " << plan.reason << "\n";
    std::vector<Run3> runs;
    Vector x_mg, x_amg, x_direct;
    // mg first (its peak is the hierarchy and the multigrid), then BoomerAMG, then the direct
    // solve beside the hierarchy alone.
    if (plan.multigrid) {
        runs.push_back(run_mg(h, b, opt, x_mg));
        runs.back().peak_rss_mib = peak_rss_mib();
        runs.back().estimate_mib = mem.mg_peak() / kMiB;
    }
    runs.push_back(run_amg(h, b, opt, x_amg));
    runs.back().peak_rss_mib = peak_rss_mib();
    runs.back().estimate_mib = mem.bytes() / kMiB;
    double factor_nonzeros = 0;
    if (direct) {
        runs.push_back(run_direct(h, b, opt, x_direct, factor_nonzeros));
        runs.back().peak_rss_mib = peak_rss_mib();
        runs.back().estimate_mib = direct_peak / kMiB;
    }
    const Run3& planned = runs.front(); // mg-cg, or the direct solve on level 0
    const Run3& amg = plan.multigrid ? runs[1] : runs[0];
    const Vector& x_planned = plan.multigrid ? x_mg : x_direct;
    const double diff = (x_amg - x_planned).norm() / std::max(x_amg.norm(), 1e-300);
    const auto total = [](const Run3& r) { return median(r.setup) + median(r.solve); };
    // The planned solver's time over BoomerAMG-PCG's (mg-cg's, or on level 0 the direct solve's).
    const double ratio = total(amg) > 0 ? total(planned) / total(amg) : 0.0;

    const std::filesystem::path out = bench_json_path(opt.out, "elastic_", opt.scene, L);
    AtomicOfstream js = open_json(out);
    write_json3(js, opt, L, h, sizes, mem, runs, ratio, diff, threads, hierarchy_s, factor_nonzeros,
                plan);
    os << std::setw(16) << "solver" << std::setw(10) << "unknowns" << std::setw(6) << "its"
       << std::setw(10) << "setup s" << std::setw(10) << "solve s" << std::setw(10) << "total s"
       << std::setw(11) << "rel.res" << std::setw(14) << "peak RSS MiB" << std::setw(14)
       << "estimate MiB"
       << "\n";
    int code = 0;
    for (const Run3& r : runs) {
        if (!r.converged) code = 2;
        os << std::setw(16) << r.name << std::setw(10) << K.rows() << std::setw(6) << r.iterations
           << std::fixed << std::setprecision(3) << std::setw(10) << median(r.setup)
           << std::setw(10) << median(r.solve) << std::setw(10) << total(r) << std::scientific
           << std::setprecision(2) << std::setw(11) << r.relative_residual << std::fixed
           << std::setprecision(0) << std::setw(14) << r.peak_rss_mib << std::setw(14)
           << r.estimate_mib << std::defaultfloat << (r.converged ? "" : "  NOT CONVERGED") << "\n";
    }
    if (plan.multigrid) os << "mg-cg: " << mg_cycle() << " cycle, vertex-block Gauss-Seidel\n";
    if (direct) {
        os << "cholmod: " << std::setprecision(3) << factor_nonzeros
           << " nonzeros in the Cholesky factor (" << factor_nonzeros / K.nonZeros()
           << " times K's)";
        if (plan.multigrid)
            os << "; time ratio mg-cg / cholmod " << std::fixed
               << (total(runs.back()) > 0 ? total(planned) / total(runs.back()) : 0.0)
               << std::defaultfloat;
        os << std::setprecision(6) << "\n";
    }
    if (plan.multigrid)
        os << "time ratio mg-cg / boomeramg-pcg: " << std::fixed << std::setprecision(3) << ratio
           << std::defaultfloat;
    else
        os << "time ratio cholmod / boomeramg-pcg: " << std::fixed << std::setprecision(3) << ratio
           << std::defaultfloat;
    os << "\nrelative difference of the AMG and " << (plan.multigrid ? "mg" : "direct")
       << " solutions: " << std::scientific << std::setprecision(2) << diff << std::defaultfloat
       << "\nwrote " << out.string() << "\n";
    return code;
}

} // namespace mlc::apps

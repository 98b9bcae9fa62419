// SPDX-License-Identifier: MIT
// `mlcontact bench square` and `mlcontact bench elastic`.
#include "bench/bench.hpp"
#include "bench/common.hpp"

#include "run/preconditioners.hpp"

#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "core/csr.hpp"
#include "core/memory.hpp"
#include "core/parallel.hpp"
#include "core/timer.hpp"
#include "core/traffic.hpp"
#include "levels/elastic_block.hpp"
#include "levels/hierarchy.hpp"
#include "levels/newton_system.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"
#include "scene/scene3.hpp"
#include "solvers/direct.hpp"
#include "solvers/factory.hpp"
#include "solvers/hypre/boomeramg.hpp"
#include "solvers/hypre/mgr.hpp"
#include "solvers/krylov.hpp"
#include "solvers/mg.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

namespace mlc::apps {

namespace {

struct SquareRow {
    int level = 0;
    Index unknowns = 0;
    long nonzeros = 0;
    int newton = 0;
    double its_mean = 0, its_max = 0;
    std::vector<double> assembly_s, setup_s, solve_s, total_s;
    // Bandwidth account (first run's bytes and passes; per-run seconds).
    traffic::Account traffic;                   // summed over the level's Newton solves
    std::vector<traffic::Account> traffic_runs; // one per run
    std::vector<double> krylov_s;               // Krylov solve seconds per run
    int solves = 0;                             // Newton systems solved (first run)
    double rss_growth = 0;                      // bytes (first run)
};

/// The JSON file's head and the table's header; `def`: the default solver when one is benched.
void print_square_header(std::ostream& os, std::ostream& js, const BenchSquareOptions& opt,
                         int load_steps, const std::string& krylov_label,
                         const std::string& numbering, const levels::SolverPlan* def) {
    js << "{\n  \"scene\": " << json_string(opt.scene) << ",\n  \"levels\": " << opt.levels
       << ",\n  \"krylov\": " << json_string(krylov_label) << ",\n  \"rel_tol\": " << opt.rel_tol
       << ",\n  \"repeat\": " << opt.repeat << ",\n  \"numbering\": " << json_string(numbering)
       << ",\n  \"extrapolate\": " << (opt.extrapolate ? "true" : "false") << ",\n  \"runs\": [";
    os << "bench " << opt.scene << ": levels 0.." << opt.levels << ", coarse-to-fine, "
       << load_steps << " load steps, Krylov " << krylov_label << " rel_tol " << opt.rel_tol
       << ", times are medians of " << opt.repeat << " run(s)\n";
    if (def)
        os << "default = " << bench_label(*def) << " (the run's default above the crossover)\n";
    os << std::setw(14) << "solver" << std::setw(6) << "level" << std::setw(10) << "unknowns"
       << std::setw(11) << "nonzeros" << std::setw(7) << "newton" << std::setw(10) << "its/newt"
       << std::setw(6) << "max" << std::setw(10) << "asm s" << std::setw(10) << "setup s"
       << std::setw(10) << "solve s" << std::setw(11) << "s/newton" << std::setw(13)
       << "us/newt/unk"
       << "\n";
}

/// Adds one run's per-level figures to `rows` (the first run's bytes, passes and memory).
void record_rows(const levels::RunResult& r, const std::vector<LevelTraffic>& lt, int rep,
                 std::vector<SquareRow>& rows) {
    if (rows.empty()) {
        rows.resize(r.level_steps.size());
        for (size_t l = 0; l < rows.size(); ++l) {
            rows[l].level = static_cast<int>(l);
            rows[l].unknowns = r.levels()[l].n_unknowns();
            rows[l].nonzeros = jacobian_nonzeros(r.levels()[l]);
        }
    }
    for (size_t l = 0; l < r.level_steps.size(); ++l) {
        SquareRow& row = rows[l];
        std::vector<int> its;
        double assembly = 0, setup = 0, lin = 0, total = 0;
        int newton = 0;
        for (const auto& st : r.level_steps[l]) {
            newton += st.report.iterations;
            its.insert(its.end(), st.report.linear_iterations_per_newton.begin(),
                       st.report.linear_iterations_per_newton.end());
            assembly += st.report.linear_assembly_seconds;
            setup += st.report.linear_setup_seconds;
            lin += st.report.linear_seconds;
            total += st.report.seconds;
        }
        row.newton = newton;
        double sum = 0;
        for (int i : its)
            sum += i;
        row.its_mean = its.empty() ? 0.0 : sum / static_cast<double>(its.size());
        row.its_max = its.empty() ? 0.0 : *std::max_element(its.begin(), its.end());
        row.assembly_s.push_back(assembly);
        row.setup_s.push_back(setup - assembly);
        row.solve_s.push_back(lin - setup);
        row.total_s.push_back(total);
        const LevelTraffic& t = lt[l];
        row.traffic_runs.push_back(t.account);
        row.krylov_s.push_back(t.krylov_seconds);
        if (rep == 0) {
            row.traffic = t.account;
            row.solves = t.solves;
            row.rss_growth = t.rss_growth;
        }
    }
}

/// One level of one solver: its JSON object, its rows of the table, the bandwidth account and
/// the memory table.
void report_level(std::ostream& os, std::ostream& js, std::ostream& bw_table,
                  std::ostream& mem_table, const std::string& pc, const SquareRow& row, size_t l,
                  const std::optional<traffic::Stream>& stream) {
    const double assembly = median(row.assembly_s), setup = median(row.setup_s),
                 solve = median(row.solve_s);
    const double per_newton = row.newton > 0 ? (assembly + setup + solve) / row.newton : 0.0;
    const double per_unknown = per_newton / static_cast<double>(row.unknowns);
    js << (l ? "," : "") << "\n      {\"level\": " << row.level
       << ", \"unknowns\": " << row.unknowns << ", \"nonzeros\": " << row.nonzeros
       << ", \"newton_steps\": " << row.newton << ", \"krylov_per_newton\": " << row.its_mean
       << ", \"krylov_per_newton_max\": " << row.its_max << ", \"assembly_seconds\": " << assembly
       << ", \"setup_seconds\": " << setup << ", \"solve_seconds\": " << solve
       << ", \"level_seconds\": " << median(row.total_s)
       << ", \"seconds_per_newton\": " << per_newton
       << ", \"seconds_per_newton_per_unknown\": " << per_unknown;
    // Bandwidth account: the first run's bytes and passes, medians of the seconds.
    const traffic::Account& a = row.traffic;
    traffic::Account sec;
    for (int k = 0; k < traffic::kKinds; ++k) {
        std::vector<double> v;
        for (const auto& t : row.traffic_runs)
            v.push_back(t.seconds[static_cast<size_t>(k)]);
        sec.seconds[static_cast<size_t>(k)] = median(v);
    }
    const double ks = median(row.krylov_s);
    const double rest = std::max(0.0, ks - sec.timed_seconds());
    const double steps = std::max(1, row.solves);
    const double mat_gbs = gbs(matrix_bytes(a), matrix_seconds(sec));
    const double triad = stream ? stream->triad_gbs : 0.0;
    js << ",\n       \"bandwidth\": {\"newton_solves\": " << row.solves
       << ", \"krylov_seconds\": " << ks << ", \"bytes\": " << whole(a.total_bytes())
       << ", \"bytes_per_newton\": " << a.total_bytes() / steps
       << ", \"gbs\": " << gbs(a.total_bytes(), ks) << ", \"matrix_passes_gbs\": " << mat_gbs
       << ", \"matrix_passes_of_triad\": " << (triad > 0 ? mat_gbs / triad : 0.0)
       << ", \"kinds\": {";
    for (int k = 0; k < traffic::kKinds; ++k) {
        const auto kind = static_cast<traffic::Kind>(k);
        const bool vec = kind == traffic::Kind::vector;
        const double s_k = vec ? rest : sec.s(kind);
        js << (k ? ", " : "") << json_string(std::string(traffic::to_string(kind)))
           << ": {\"bytes\": " << whole(a.b(kind)) << ", \"passes\": " << whole(a.p(kind))
           << ", \"bytes_per_newton\": " << a.b(kind) / steps
           << ", \"passes_per_newton\": " << a.p(kind) / steps << ", \""
           << (vec ? "seconds_outside_timed_kinds" : "seconds") << "\": " << s_k
           << ", \"gbs\": " << gbs(a.b(kind), s_k) << "}";
    }
    js << "}},\n       \"memory\": {\"solver_rss_growth_bytes\": " << whole(row.rss_growth)
       << ", \"solver_rss_growth_bytes_per_unknown\": "
       << row.rss_growth / static_cast<double>(row.unknowns) << "}";
    if (row.solves > 0 && a.total_bytes() > 0) {
        using traffic::Kind;
        bw_table << std::setw(14) << pc << std::setw(6) << row.level << std::fixed
                 << std::setprecision(1) << std::setw(10) << a.total_bytes() / steps / 1e6
                 << std::setw(9) << a.b(Kind::matvec) / steps / 1e6 << std::setw(9)
                 << a.b(Kind::smoother) / steps / 1e6 << std::setw(9)
                 << a.b(Kind::transfer) / steps / 1e6 << std::setw(9)
                 << a.b(Kind::vector) / steps / 1e6 << std::setw(9)
                 << a.b(Kind::structured) / steps / 1e6 << std::setprecision(4) << std::setw(10)
                 << ks / steps << std::setprecision(2) << std::setw(8) << gbs(a.total_bytes(), ks)
                 << std::setw(8) << gbs(a.b(Kind::matvec), sec.s(Kind::matvec)) << std::setw(8)
                 << gbs(a.b(Kind::smoother), sec.s(Kind::smoother)) << std::setw(8)
                 << gbs(a.b(Kind::transfer), sec.s(Kind::transfer)) << std::setw(8)
                 << gbs(a.b(Kind::vector), rest) << std::setw(8)
                 << gbs(a.b(Kind::structured), sec.s(Kind::structured)) << std::setw(8) << mat_gbs
                 << std::setw(7) << std::setprecision(0)
                 << (triad > 0 ? 100 * mat_gbs / triad : 0.0) << std::defaultfloat << "\n";
    }
    mem_table << std::setw(14) << pc << std::setw(6) << row.level << std::setw(10) << row.unknowns
              << std::fixed << std::setprecision(1) << std::setw(12)
              << row.rss_growth / (1024.0 * 1024.0) << std::setprecision(0) << std::setw(11)
              << row.rss_growth / static_cast<double>(row.unknowns) << std::defaultfloat << "\n";
    js << "}";
    os << std::setw(14) << pc << std::setw(6) << row.level << std::setw(10) << row.unknowns
       << std::setw(11) << row.nonzeros << std::setw(7) << row.newton << std::setw(10) << std::fixed
       << std::setprecision(1) << row.its_mean << std::setw(6) << std::setprecision(0)
       << row.its_max << std::setw(10) << std::setprecision(3) << assembly << std::setw(10) << setup
       << std::setw(10) << solve << std::setw(11) << std::setprecision(4) << per_newton
       << std::setw(13) << std::setprecision(3) << 1e6 * per_unknown << std::defaultfloat << "\n";
}

/// The bandwidth account, STREAM and the memory per level, after the per-level table.
void print_square_tables(std::ostream& os, const std::string& bw_table,
                         const std::string& mem_table,
                         const std::optional<traffic::Stream>& stream) {
    os << "\nbandwidth account per Newton step (compulsory bytes, "
          "docs/studies.md#bench-bandwidth); "
          "MB / Newton step by kind, GB/s = bytes / seconds\n"
       << std::setw(14) << "solver" << std::setw(6) << "level" << std::setw(10) << "MB/newt"
       << std::setw(9) << "matvec" << std::setw(9) << "smooth" << std::setw(9) << "transf"
       << std::setw(9) << "vector" << std::setw(9) << "struct" << std::setw(10) << "krylov s"
       << std::setw(8) << "GB/s" << std::setw(8) << "matvec" << std::setw(8) << "smooth"
       << std::setw(8) << "transf" << std::setw(8) << "vector" << std::setw(8) << "struct"
       << std::setw(8) << "matrix" << std::setw(7) << "%triad"
       << "\n"
       << bw_table;
    if (stream)
        os << "STREAM (same binary, " << stream->threads << " thread(s), " << stream->n
           << " doubles per array, best of " << stream->repeats << "): copy " << std::fixed
           << std::setprecision(2) << stream->copy_gbs << " GB/s, triad " << stream->triad_gbs
           << " GB/s" << std::defaultfloat << "\n";
    os << "\nmemory per level: RSS growth while the run built the level's Newton-system solver "
          "and ran its first Newton solve\n"
       << std::setw(14) << "solver" << std::setw(6) << "level" << std::setw(10) << "unknowns"
       << std::setw(12) << "MiB" << std::setw(11) << "B/unknown"
       << "\n"
       << mem_table;
}

} // namespace

levels::SolverPlan bench_plan(const BenchSquareOptions& opt, const std::string& pc,
                              const levels::Problem& problem, int processes) {
    levels::SolverRequest req;
    if (pc == "schur" || pc == "lu") {
        req.linear = solvers::parse_method(pc);
        return levels::plan_solver(problem, req, processes);
    }
    if (opt.krylov) req.krylov = solvers::parse_krylov(*opt.krylov);
    req.rel_tol = opt.rel_tol;
    if (processes == 1)
        req.numbering = problem.numbering;
    else if (opt.numbering)
        req.numbering = levels::parse_numbering(*opt.numbering, "bench square: --numbering");
    levels::SolverPlan plan;
    if (pc == "default") {
        plan = levels::plan_default_mg(problem, req, processes);
    } else {
        req.pc = solvers::parse_pc(pc);
        plan = levels::plan_solver(problem, req, processes);
    }
    plan.spec.max_iter = opt.max_iter;
    return plan;
}

std::string bench_label(const levels::SolverPlan& plan) {
    const levels::LinearSolverSpec& s = plan.spec;
    if (s.method != solvers::Method::krylov) return std::string(solvers::to_string(s.method));
    return std::string(solvers::to_string(s.krylov)) + " + " + s.pc.text();
}

std::string bench_numbering(const BenchSquareOptions& opt) {
    if (opt.numbering) return *opt.numbering;
    const bool all_default = std::all_of(opt.pcs.begin(), opt.pcs.end(),
                                         [](const std::string& pc) { return pc == "default"; });
    const bool named_lattice =
        std::any_of(opt.pcs.begin(), opt.pcs.end(), [](const std::string& pc) {
            return pc != "default" && pc != "schur" && pc != "lu" &&
                   solvers::parse_pc(pc).lattice_numbering();
        });
    return named_lattice || (all_default && opt.levels >= levels::kMgDefaultLatticeLevel)
               ? "lattice"
               : "hilbert";
}

int bench_square(const BenchSquareOptions& opt, std::ostream& os) {
    if (scene::scene_dimension(opt.scene) == 3) return bench_square3(opt, os);
    MLC_CHECK(!opt.scaling, "bench square: --scaling is for 3D scenes (the 2D square's levels "
                            "are compared by two runs of `bench square --levels L`)");
    MLC_CHECK(opt.levels >= 1 && opt.levels <= 8,
              "bench square: --levels must be in 1..8, found " << opt.levels);
    MLC_CHECK(opt.repeat >= 1, "bench square: --repeat must be >= 1, found " << opt.repeat);
    MLC_CHECK(!opt.pcs.empty(), "bench square: no --pc given");
    std::vector<std::string> named;
    for (const std::string& pc : opt.pcs)
        if (pc != "default") named.push_back(pc);
    check_preconditioner_names(named, true);
    levels::Problem base = scene::load_scene(opt.scene);
    base.levels = opt.levels;
    const std::string numbering = bench_numbering(opt);
    base.numbering = levels::parse_numbering(numbering, "bench square: --numbering");
    const levels::SolverPlan def = bench_plan(opt, "default", base);
    const std::string def_krylov(solvers::to_string(def.spec.krylov));
    const std::string named_krylov = opt.krylov.value_or("cgs");
    std::string krylov_label = named_krylov;
    if (named.size() != opt.pcs.size())
        krylov_label = named.empty() ? def_krylov : named_krylov + " (default: " + def_krylov + ")";
    const std::filesystem::path out = bench_json_path(opt.out, "", opt.scene, opt.levels);
    AtomicOfstream js = open_json(out);
    print_square_header(os, js, opt, base.load_steps, krylov_label, numbering,
                        named.size() != opt.pcs.size() ? &def : nullptr);
    int code = 0;
    // Per-call timing of the counted kernels (core/traffic.hpp) for the bandwidth account.
    const bool timing_was = traffic::timing();
    traffic::set_timing(true);
    struct RestoreTiming {
        bool was;
        ~RestoreTiming() { traffic::set_timing(was); }
    } restore_timing{timing_was};
    std::optional<traffic::Stream> stream;
    std::ostringstream bw_table, mem_table;
    for (size_t ip = 0; ip < opt.pcs.size(); ++ip) {
        const std::string& pc = opt.pcs[ip];
        levels::SolveOptions so;
        so.coarse_to_fine = true;
        so.extrapolate = opt.extrapolate;
        so.linear = bench_plan(opt, pc, base).spec;
        std::vector<SquareRow> rows;
        std::vector<double> walls;
        double estimate_mib = 0;
        bool converged = true;
        std::string failure;
        double matvec_s = 0, matvec_bytes = 0, hierarchy_rss = 0;
        for (int rep = 0; rep < opt.repeat && converged; ++rep) {
            std::vector<LevelTraffic> lt(static_cast<size_t>(opt.levels) + 1);
            int depth = 0;
            std::vector<Eigen::Matrix2d> last_M;
            const double rss_before_run = current_rss_bytes();
            double rss_prev = -1;
            levels::SolverWrapper wrap([&](int level, const levels::Level&,
                                           std::unique_ptr<levels::NewtonSystemSolver> sys)
                                           -> std::unique_ptr<levels::NewtonSystemSolver> {
                MLC_CHECK(level >= 0 && level <= opt.levels, "bench square: level " << level);
                // The first solver handed over: its construction is counted with the
                // hierarchy (both happen before the first hand-over).
                if (rss_prev < 0) {
                    rss_prev = current_rss_bytes();
                    hierarchy_rss = rss_prev - rss_before_run;
                }
                auto w = std::make_unique<TrafficRecorder<2>>(
                    std::move(sys), &lt[static_cast<size_t>(level)], &depth, rss_prev,
                    level == opt.levels ? &last_M : nullptr);
                rss_prev = lt[static_cast<size_t>(level)].rss_at_build;
                return w;
            });
            const double t0 = wall_seconds();
            const levels::RunResult r = levels::solve(base, so, &wrap);
            walls.push_back(wall_seconds() - t0);
            converged = r.converged;
            failure = r.failure;
            estimate_mib = r.memory.bytes / (1024.0 * 1024.0);
            record_rows(r, lt, rep, rows);
            // The unit: one CSR mat-vec of the finest Jacobian (at the last Newton system's
            // statuses), same binary, same threads, timed after the run.
            if (rep == 0 && !last_M.empty()) {
                levels::JacobianAssembler jac(r.finest());
                jac.assemble(last_M);
                const SparseMatrix& J = jac.matrix();
                matvec_s = time_matvec(J);
                matvec_bytes = traffic::csr_bytes(J.rows(), J.cols(), J.nonZeros(), false);
            }
        }
        const double rss = peak_rss_mib();
        // STREAM once, after the first solver's runs (and after its peak RSS was read).
        if (!stream) stream = traffic::measure_stream(opt.stream_doubles, opt.stream_repeats);
        if (!converged) code = 2;
        js << (ip ? "," : "") << "\n    {\"solver\": " << json_string(pc)
           << ", \"converged\": " << (converged ? "true" : "false")
           << ", \"wall_seconds\": " << median(walls) << ", \"peak_rss_mib\": " << rss
           << ", \"memory_estimate_mib\": " << estimate_mib;
        if (!converged) js << ", \"failure\": " << json_string(failure);
        const SquareRow& fine_row = rows.back();
        const double fine_step_s = fine_row.newton > 0
                                       ? (median(fine_row.assembly_s) + median(fine_row.setup_s) +
                                          median(fine_row.solve_s)) /
                                             fine_row.newton
                                       : 0.0;
        js << ",\n     \"threads\": " << parallel::num_threads()
           << ", \"hierarchy_rss_growth_bytes\": " << whole(hierarchy_rss);
        if (matvec_s > 0)
            js << ",\n     \"matvec_unit\": {\"seconds\": " << matvec_s
               << ", \"bytes\": " << whole(matvec_bytes)
               << ", \"gbs\": " << gbs(matvec_bytes, matvec_s)
               << "}, \"fine_newton_step_seconds\": " << fine_step_s
               << ", \"fine_newton_step_in_matvecs\": " << fine_step_s / matvec_s;
        bw_table << std::setw(14) << pc << "  fine mat-vec (level " << opt.levels << ", "
                 << std::setprecision(3) << matvec_bytes / 1e6 << " MB): " << std::fixed
                 << std::setprecision(3) << 1e3 * matvec_s << " ms = " << std::setprecision(2)
                 << gbs(matvec_bytes, matvec_s)
                 << " GB/s; a fine Newton step = " << std::setprecision(1)
                 << (matvec_s > 0 ? fine_step_s / matvec_s : 0.0) << " mat-vecs"
                 << std::defaultfloat << "\n";
        js << ",\n     \"levels\": [";
        for (size_t l = 0; l < rows.size(); ++l)
            report_level(os, js, bw_table, mem_table, pc, rows[l], l, stream);
        js << "\n     ]}";
        os << std::setw(14) << pc << "  total wall " << std::fixed << std::setprecision(2)
           << median(walls) << " s (median), peak RSS " << std::setprecision(0) << rss
           << " MiB (estimate " << estimate_mib << " MiB)" << std::defaultfloat
           << (converged ? "" : "  FAILED: " + failure) << "\n";
    }
    js << "\n  ]";
    if (stream)
        js << ",\n  \"stream\": {\"copy_gbs\": " << stream->copy_gbs
           << ", \"triad_gbs\": " << stream->triad_gbs << ", \"doubles\": " << stream->n
           << ", \"repeats\": " << stream->repeats << ", \"threads\": " << stream->threads << "}";
    js << "\n}\n";
    print_square_tables(os, bw_table.str(), mem_table.str(), stream);
    os << "wrote " << out.string() << "\n";
    return code;
}

namespace {

struct ElasticResult {
    std::string name;
    std::vector<double> setup, solve;
    int iterations = 0;
    double relative_residual = 0;
    double x_norm = 0, x_max = 0; ///< 2-norm and max-norm of the last repetition's solution
    bool converged = false;
};

} // namespace

int bench_elastic(const BenchElasticOptions& opt, std::ostream& os) {
    if (scene::scene_dimension(opt.scene) == 3) return bench_elastic3d(opt, os);
    MLC_CHECK(!opt.direct, "bench elastic: --direct is for 3D scenes; on a 2D scene the exact "
                           "solver is `bench square --pc schur` or `run --linear schur`");
    MLC_CHECK(opt.levels >= 1 && opt.levels <= 8,
              "bench elastic: --levels must be in 1..8, found " << opt.levels);
    MLC_CHECK(opt.repeat >= 1, "bench elastic: --repeat must be >= 1, found " << opt.repeat);
    MLC_CHECK(opt.rel_tol > 0 && opt.rel_tol < 1,
              "bench elastic: --tol must be in (0, 1), found " << opt.rel_tol);
    levels::Problem problem = scene::load_scene(opt.scene);
    problem.levels = opt.levels;
    const double th0 = wall_seconds();
    const levels::Hierarchy h = levels::build_hierarchy(problem);
    const double hierarchy_s = wall_seconds() - th0;
    std::vector<levels::ElasticBlock> blocks;
    for (const auto& L : h.levels)
        blocks.push_back(levels::elastic_block(L));
    const levels::ElasticBlock& fine = blocks.back();
    const Vector b = fine.restrict(h.finest().elastic.f);
    MLC_CHECK(b.norm() > 0, "bench elastic: the scene has no load on the free unknowns");
    const auto n = fine.K.rows();
    os << "bench elastic: " << opt.scene << " level " << opt.levels << ", elastic block " << n
       << " unknowns, " << fine.K.nonZeros() << " nonzeros, rel_tol " << opt.rel_tol
       << ", times are medians of " << opt.repeat << " run(s) (hierarchy built in " << std::fixed
       << std::setprecision(2) << hierarchy_s << std::defaultfloat << " s)\n";

    std::vector<ElasticResult> results;
    Vector x_amg, x_mg;
    // BoomerAMG-PCG (hypre's PCG, two-norm relative residual).
    {
        ElasticResult r;
        r.name = "boomeramg-pcg";
        for (int rep = 0; rep < opt.repeat; ++rep) {
            x_amg = Vector::Zero(n);
            const SolveResult s = solvers::boomeramg_pcg(fine.K, b, x_amg, opt.rel_tol,
                                                         opt.max_iter, {}, fine.component);
            r.setup.push_back(s.setup_seconds);
            r.solve.push_back(s.solve_seconds);
            r.iterations = s.iterations;
            r.relative_residual = s.relative_residual;
            r.converged = s.converged;
        }
        r.x_norm = x_amg.norm();
        r.x_max = x_amg.lpNorm<Eigen::Infinity>();
        results.push_back(r);
    }
    // Our V-cycle over levels 0..L (set up anew in every repetition, like AMG).
    for (const std::string method : {"mg-cg", "mg-gmres"}) {
        ElasticResult r;
        r.name = method;
        for (int rep = 0; rep < opt.repeat; ++rep) {
            const double t0 = wall_seconds();
            const levels::ElasticMultigrid mg(h, blocks);
            const double t1 = wall_seconds();
            x_mg = Vector::Zero(n);
            SolveResult s;
            if (method == std::string("mg-cg")) {
                solvers::KrylovParams kp;
                kp.rel_tol = opt.rel_tol;
                kp.max_iter = opt.max_iter;
                s = solvers::cg(MatrixOperator(fine.K, MatVec::unrolled), mg.finest(), b, x_mg, kp);
            } else {
                solvers::KrylovParams kp;
                kp.rel_tol = opt.rel_tol;
                kp.max_iter = opt.max_iter;
                s = solvers::solve(solvers::Krylov::gmres, fine.K, mg.finest(), b, x_mg, kp);
            }
            r.setup.push_back(t1 - t0);
            r.solve.push_back(s.solve_seconds);
            r.iterations = s.iterations;
            r.relative_residual = s.relative_residual;
            r.converged = s.converged;
        }
        r.x_norm = x_mg.norm();
        r.x_max = x_mg.lpNorm<Eigen::Infinity>();
        results.push_back(r);
    }
    const double diff = (x_amg - x_mg).norm() / std::max(x_amg.norm(), 1e-300);

    const std::filesystem::path out = bench_json_path(opt.out, "elastic_", opt.scene, opt.levels);
    AtomicOfstream js = open_json(out);
    js << "{\n  \"scene\": " << json_string(opt.scene) << ",\n  \"level\": " << opt.levels
       << ",\n  \"unknowns\": " << n << ",\n  \"nonzeros\": " << fine.K.nonZeros()
       << ",\n  \"rel_tol\": " << opt.rel_tol << ",\n  \"repeat\": " << opt.repeat
       << ",\n  \"solution_difference\": " << diff << ",\n  \"peak_rss_mib\": " << peak_rss_mib()
       << ",\n  \"solvers\": [";
    os << std::setw(16) << "solver" << std::setw(10) << "setup s" << std::setw(10) << "solve s"
       << std::setw(10) << "total s" << std::setw(7) << "its" << std::setw(12) << "rel.res"
       << "\n";
    int code = 0;
    for (size_t k = 0; k < results.size(); ++k) {
        const auto& r = results[k];
        const double su = median(r.setup), so = median(r.solve);
        if (!r.converged) code = 2;
        js << (k ? "," : "") << "\n    {\"solver\": " << json_string(r.name)
           << ", \"setup_seconds\": " << su << ", \"solve_seconds\": " << so
           << ", \"total_seconds\": " << su + so << ", \"iterations\": " << r.iterations
           << ", \"relative_residual\": " << r.relative_residual
           << ", \"converged\": " << (r.converged ? "true" : "false")
           << ", \"x_norm\": " << std::setprecision(12) << r.x_norm
           << ", \"x_max_norm\": " << r.x_max << std::setprecision(6) << "}";
        os << std::setw(16) << r.name << std::fixed << std::setprecision(3) << std::setw(10) << su
           << std::setw(10) << so << std::setw(10) << su + so << std::setw(7) << r.iterations
           << std::scientific << std::setprecision(2) << std::setw(12) << r.relative_residual
           << std::defaultfloat << (r.converged ? "" : "  NOT CONVERGED") << "\n";
    }
    js << "\n  ]\n}\n";
    os << "relative difference of the AMG and mg solutions: " << std::scientific
       << std::setprecision(2) << diff << std::defaultfloat << "\nwrote " << out.string() << "\n";
    return code;
}

} // namespace mlc::apps

// SPDX-License-Identifier: MIT
// `mlcontact bench square` and `mlcontact bench elastic`.
#include "apps/bench.hpp"

#include "apps/preconditioners.hpp"

#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "core/memory.hpp"
#include "core/timer.hpp"
#include "levels/elastic_block.hpp"
#include "levels/hierarchy.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"
#include "solvers/direct.hpp"
#include "solvers/hypre/boomeramg.hpp"
#include "solvers/krylov.hpp"
#include "solvers/mg.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <fstream>
#include <iomanip>
#include <memory>
#include <set>
#include <sstream>

namespace mlc::apps {

namespace {

double peak_rss_mib() {
    return peak_rss_bytes() / (1024.0 * 1024.0);
}

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        out += c;
    }
    return out + "\"";
}

AtomicOfstream open_json(const std::filesystem::path& file) {
    if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
    AtomicOfstream f(file);
    MLC_CHECK(f.good(), "cannot write " << file.string());
    f << std::setprecision(6);
    return f;
}

// Nonzeros of the Jacobian pattern of a level: K plus the contact tangent entries outside it.
long jacobian_nonzeros(const levels::Level& L) {
    const SparseMatrix& K = L.elastic.K;
    std::set<std::pair<int, int>> extra;
    const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
    for (size_t e = 0; e < L.contacts.size(); ++e)
        contact::for_each_tangent_entry(
            L.contacts[e], I, L.dofs, L.lambda_dof[e], [&](int row, int col, double) {
                const int* b = K.innerIndexPtr() + K.outerIndexPtr()[row];
                const int* en = K.innerIndexPtr() + K.outerIndexPtr()[row + 1];
                if (!std::binary_search(b, en, col)) extra.emplace(row, col);
            });
    return static_cast<long>(K.nonZeros()) + static_cast<long>(extra.size());
}

struct SquareRow {
    int level = 0;
    Index unknowns = 0;
    long nonzeros = 0;
    int newton = 0;
    double its_mean = 0, its_max = 0;
    std::vector<double> assembly_s, setup_s, solve_s, total_s;
};

} // namespace

int bench_square(const BenchSquareOptions& opt, std::ostream& os) {
    MLC_CHECK(opt.levels >= 1 && opt.levels <= 8,
              "bench square: --levels must be in 1..8, found " << opt.levels);
    MLC_CHECK(opt.repeat >= 1, "bench square: --repeat must be >= 1, found " << opt.repeat);
    MLC_CHECK(!opt.pcs.empty(), "bench square: no --pc given");
    check_preconditioner_names(opt.pcs, true);
    levels::Problem base = scene::load_scene(opt.scene);
    base.levels = opt.levels;
    const std::filesystem::path out =
        opt.out.empty() ? std::filesystem::path("out/bench/" + opt.scene + "_L" +
                                                std::to_string(opt.levels) + ".json")
                        : opt.out;
    AtomicOfstream js = open_json(out);
    js << "{\n  \"scene\": " << json_string(opt.scene) << ",\n  \"levels\": " << opt.levels
       << ",\n  \"krylov\": " << json_string(opt.krylov) << ",\n  \"rel_tol\": " << opt.rel_tol
       << ",\n  \"repeat\": " << opt.repeat << ",\n  \"runs\": [";
    os << "bench " << opt.scene << ": levels 0.." << opt.levels << ", coarse-to-fine, "
       << base.load_steps << " load steps, Krylov " << opt.krylov << " rel_tol " << opt.rel_tol
       << ", times are medians of " << opt.repeat << " run(s)\n";
    os << std::setw(14) << "solver" << std::setw(6) << "level" << std::setw(10) << "unknowns"
       << std::setw(11) << "nonzeros" << std::setw(7) << "newton" << std::setw(10) << "its/newt"
       << std::setw(6) << "max" << std::setw(10) << "asm s" << std::setw(10) << "setup s"
       << std::setw(10) << "solve s" << std::setw(11) << "s/newton" << std::setw(13)
       << "us/newt/unk"
       << "\n";
    int code = 0;
    for (size_t ip = 0; ip < opt.pcs.size(); ++ip) {
        const std::string& pc = opt.pcs[ip];
        levels::SolveOptions so;
        so.coarse_to_fine = true;
        if (pc == "schur" || pc == "lu")
            so.linear.method = pc;
        else
            so.linear = {.method = "krylov",
                         .krylov = opt.krylov,
                         .pc = pc,
                         .rel_tol = opt.rel_tol,
                         .max_iter = opt.max_iter};
        std::vector<SquareRow> rows;
        std::vector<double> walls;
        double estimate_mib = 0;
        bool converged = true;
        std::string failure;
        for (int rep = 0; rep < opt.repeat && converged; ++rep) {
            const double t0 = wall_seconds();
            const levels::RunResult r = levels::solve(base, so);
            walls.push_back(wall_seconds() - t0);
            converged = r.converged;
            failure = r.failure;
            estimate_mib = r.memory.bytes / (1024.0 * 1024.0);
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
            }
        }
        const double rss = peak_rss_mib();
        if (!converged) code = 2;
        js << (ip ? "," : "") << "\n    {\"solver\": " << json_string(pc)
           << ", \"converged\": " << (converged ? "true" : "false")
           << ", \"wall_seconds\": " << median(walls) << ", \"peak_rss_mib\": " << rss
           << ", \"memory_estimate_mib\": " << estimate_mib;
        if (!converged) js << ", \"failure\": " << json_string(failure);
        js << ",\n     \"levels\": [";
        for (size_t l = 0; l < rows.size(); ++l) {
            const SquareRow& row = rows[l];
            const double assembly = median(row.assembly_s), setup = median(row.setup_s),
                         solve = median(row.solve_s);
            const double per_newton =
                row.newton > 0 ? (assembly + setup + solve) / row.newton : 0.0;
            const double per_unknown = per_newton / static_cast<double>(row.unknowns);
            js << (l ? "," : "") << "\n      {\"level\": " << row.level
               << ", \"unknowns\": " << row.unknowns << ", \"nonzeros\": " << row.nonzeros
               << ", \"newton_steps\": " << row.newton
               << ", \"krylov_per_newton\": " << row.its_mean
               << ", \"krylov_per_newton_max\": " << row.its_max
               << ", \"assembly_seconds\": " << assembly << ", \"setup_seconds\": " << setup
               << ", \"solve_seconds\": " << solve << ", \"level_seconds\": " << median(row.total_s)
               << ", \"seconds_per_newton\": " << per_newton
               << ", \"seconds_per_newton_per_unknown\": " << per_unknown << "}";
            os << std::setw(14) << pc << std::setw(6) << row.level << std::setw(10) << row.unknowns
               << std::setw(11) << row.nonzeros << std::setw(7) << row.newton << std::setw(10)
               << std::fixed << std::setprecision(1) << row.its_mean << std::setw(6)
               << std::setprecision(0) << row.its_max << std::setw(10) << std::setprecision(3)
               << assembly << std::setw(10) << setup << std::setw(10) << solve << std::setw(11)
               << std::setprecision(4) << per_newton << std::setw(13) << std::setprecision(3)
               << 1e6 * per_unknown << std::defaultfloat << "\n";
        }
        js << "\n     ]}";
        os << std::setw(14) << pc << "  total wall " << std::fixed << std::setprecision(2)
           << median(walls) << " s (median), peak RSS " << std::setprecision(0) << rss
           << " MiB (estimate " << estimate_mib << " MiB)" << std::defaultfloat
           << (converged ? "" : "  FAILED: " + failure) << "\n";
    }
    js << "\n  ]\n}\n";
    os << "wrote " << out.string() << "\n";
    return code;
}

namespace {

struct ElasticResult {
    std::string name;
    std::vector<double> setup, solve;
    int iterations = 0;
    double relative_residual = 0;
    bool converged = false;
};

} // namespace

int bench_elastic(const BenchElasticOptions& opt, std::ostream& os) {
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
                s = solvers::pcg(fine.K, mg.finest(), b, x_mg, opt.rel_tol, opt.max_iter);
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
        results.push_back(r);
    }
    const double diff = (x_amg - x_mg).norm() / std::max(x_amg.norm(), 1e-300);

    const std::filesystem::path out =
        opt.out.empty() ? std::filesystem::path("out/bench/elastic_" + opt.scene + "_L" +
                                                std::to_string(opt.levels) + ".json")
                        : opt.out;
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
           << ", \"converged\": " << (r.converged ? "true" : "false") << "}";
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

// SPDX-License-Identifier: MIT
// `mlcontact bench elastic`.
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

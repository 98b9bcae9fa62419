// SPDX-License-Identifier: MIT
// `mlcontact bench newton`.
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

// Iteration cap of BoomerAMG on the whole Jacobian (the naive choice) in bench newton.
constexpr int kAmgWholeMaxIter = 50;

// One timed solve of one Newton system.
struct NewtonSample {
    double setup = 0;      // preconditioner setup (our mg: what the run builds for this system)
    double setup_full = 0; // mg: plus the coarser levels' setups of this load step
    double copy = 0;       // hypre: of setup, copying the matrix into hypre
    double solve = 0;
    double relres = 0; // ||b - J x|| / ||b||, computed here
    int iterations = 0;
    bool converged = false;
    std::string failure;
};

struct NewtonSystemRow {
    int step = 0, newton = 0; // load step and Newton iteration (1-based)
    int gap = 0, stick = 0, slip = 0;
    std::map<std::string, std::vector<NewtonSample>> samples; // "mg@1", "mgr", "amg", ...
};

// Statuses from the generalized derivative M of each contact element (contact/law.hpp): gap 0,
// stick I, slip [[0, -eps mu], [0, 1]].
void count_statuses(const std::vector<Eigen::Matrix2d>& M, NewtonSystemRow& row) {
    for (const auto& m : M) {
        if (m(1, 1) == 0.0)
            ++row.gap;
        else if (m(0, 0) == 1.0)
            ++row.stick;
        else
            ++row.slip;
    }
}

double true_relres(const SparseMatrix& J, const Vector& b, const Vector& x) {
    if (!x.allFinite()) return std::numeric_limits<double>::infinity();
    const double bn = b.norm();
    const Vector r = b - J * x;
    return bn > 0 ? r.norm() / bn : r.norm();
}

// A coarser level's solver: forwards everything and keeps the largest setup (assembly, smoother,
// the level below's operator) of its Newton systems in the current load step.
class CoarseSetupTimer final : public levels::ForwardingSystemSolver {
public:
    CoarseSetupTimer(std::unique_ptr<levels::NewtonSystemSolver> inner, double* slot)
        : levels::ForwardingSystemSolver(std::move(inner)), slot_(slot) {}
    SolveResult solve(const std::vector<Eigen::Matrix2d>& M, const Vector& b, Vector& dx,
                      double forcing) override {
        SolveResult r = inner().solve(M, b, dx, forcing);
        *slot_ = std::max(*slot_, r.setup_seconds);
        return r;
    }
    void set_coarse_statuses(const std::vector<Eigen::Matrix2d>& M) override {
        *slot_ = 0.0; // a new load step of this level
        inner().set_coarse_statuses(M);
    }

private:
    double* slot_;
};

struct NewtonBenchPass {
    int threads = 1;
    bool hypre = false; // also MGR on every system
    bool amg = false;   // also BoomerAMG on the whole Jacobian on every system
};

// The finest level's solver: every system it is given is first solved from zero to the bench
// tolerance by the run's own solver (timed, setup included), then by MGR and AMG on the same
// assembled Jacobian; then the run's own solve proceeds as in any run.
class NewtonSystemRecorder final : public levels::ForwardingSystemSolver {
public:
    NewtonSystemRecorder(std::unique_ptr<levels::NewtonSystemSolver> inner,
                         const levels::Level& level, const BenchNewtonOptions& opt,
                         const NewtonBenchPass& pass, const std::vector<double>* coarse_setups,
                         std::vector<NewtonSystemRow>& rows)
        : levels::ForwardingSystemSolver(std::move(inner)), level_(level), jac_(level), opt_(opt),
          pass_(pass), coarse_setups_(coarse_setups), rows_(rows) {
        params_.rel_tol = opt.rel_tol;
        params_.max_iter = opt.max_iter;
        params_.give_up_budget = opt.max_iter;
        // BoomerAMG on the whole Jacobian stagnates (the multiplier rows have no diagonal to
        // relax on; level 5: relative residual 2e-6 .. 1e-5 after 100 iterations, 60 s a system):
        // at most kAmgWholeMaxIter iterations, in the first 1-thread run only, so that it does
        // not dominate the bench.
        amg_params_ = params_;
        amg_params_.max_iter = std::min(opt.max_iter, kAmgWholeMaxIter);
        amg_params_.give_up_budget = amg_params_.max_iter;
        method_ = solvers::parse_krylov(opt.krylov);
        functions_.assign(static_cast<size_t>(level.n_unknowns()), solvers::kMultiplierFunction);
        for (int v = 0; v < level.dofs.n_vertices(); ++v)
            for (int c = 0; c < 2; ++c)
                if (const int i = level.dofs.u_dof(v, c); i >= 0)
                    functions_[static_cast<size_t>(i)] = c;
    }

    SolveResult solve(const std::vector<Eigen::Matrix2d>& M, const Vector& b, Vector& dx,
                      double forcing) override {
        ++newton_;
        const size_t k = index_++;
        if (rows_.size() <= k) {
            NewtonSystemRow row;
            row.step = step_;
            row.newton = newton_;
            count_statuses(M, row);
            rows_.push_back(std::move(row));
        }
        NewtonSystemRow& row = rows_[k];
        jac_.assemble(M); // the run's assembler: the matrix the run's solver sees
        const SparseMatrix& J = jac_.matrix();
        // Ours, as the run uses it (a fresh solve from zero to the bench tolerance).
        {
            NewtonSample s;
            double coarse = 0.0;
            if (coarse_setups_ != nullptr)
                for (double c : *coarse_setups_)
                    coarse += c;
            Vector x = Vector::Zero(b.size());
            const SolveResult r = inner().solve(M, b, x, 0.0);
            s.setup = r.setup_seconds - r.assembly_seconds;
            s.setup_full = s.setup + coarse;
            s.solve = r.solve_seconds;
            s.iterations = r.iterations;
            s.relres = true_relres(J, b, x);
            s.converged = r.converged && s.relres <= opt_.rel_tol * (1 + 1e-6);
            if (!s.converged) s.failure = std::string(to_string(r.reason)) + " " + r.message;
            row.samples[opt_.pc + "@" + std::to_string(pass_.threads)].push_back(s);
        }
        if (pass_.hypre) {
            solvers::LevelData data;
            data.has_multipliers = true;
            data.unknown_functions = [this]() { return functions_; };
            row.samples["mgr"].push_back(hypre_solve(
                J, b, params_, [&]() { return solvers::make_preconditioner(opt_.mgr, &data); }));
            if (opt_.hypre_gmres) row.samples["mgr+fgmres"].push_back(hypre_fgmres(J, b, data));
            if (opt_.amg && pass_.amg)
                row.samples["amg"].push_back(hypre_solve(J, b, amg_params_, [&]() {
                    solvers::BoomerAMGParams p;
                    p.num_functions = 3; // u_x, u_y, lambda
                    auto pc = std::make_unique<solvers::BoomerAMGPreconditioner>(p);
                    pc->set_dof_func(functions_);
                    return std::unique_ptr<Preconditioner>(std::move(pc));
                }));
        }
        return inner().solve(M, b, dx, forcing);
    }
    void set_coarse_statuses(const std::vector<Eigen::Matrix2d>& M) override {
        ++step_;
        newton_ = 0;
        inner().set_coarse_statuses(M);
    }

private:
    template <class Make>
    NewtonSample hypre_solve(const SparseMatrix& J, const Vector& b,
                             const solvers::KrylovParams& params, Make&& make) {
        NewtonSample s;
        Vector x = Vector::Zero(b.size());
        try {
            std::unique_ptr<Preconditioner> pc = make();
            const double t0 = wall_seconds();
            pc->setup(J);
            s.setup = wall_seconds() - t0;
            if (const auto* m = dynamic_cast<const solvers::MGRPreconditioner*>(pc.get()))
                s.copy = m->copy_seconds();
            const SolveResult r =
                solvers::solve(method_, MatrixOperator(J, MatVec::unrolled), *pc, b, x, params);
            s.solve = r.solve_seconds;
            s.iterations = r.iterations;
            s.relres = true_relres(J, b, x);
            s.converged = r.converged && s.relres <= opt_.rel_tol * (1 + 1e-6);
            if (!s.converged)
                s.failure =
                    std::string(to_string(r.reason)) + (r.message.empty() ? "" : ": " + r.message);
        } catch (const std::exception& e) {
            s.relres = true_relres(J, b, x);
            s.failure = std::string("exception: ") + e.what();
        }
        return s;
    }

    // MGR in hypre's FlexGMRES(50), to the same tolerance from zero.
    NewtonSample hypre_fgmres(const SparseMatrix& J, const Vector& b,
                              const solvers::LevelData& data) {
        NewtonSample s;
        Vector x = Vector::Zero(b.size());
        try {
            std::unique_ptr<Preconditioner> pc = solvers::make_preconditioner(opt_.mgr, &data);
            auto* m = dynamic_cast<solvers::MGRPreconditioner*>(pc.get());
            MLC_CHECK(m != nullptr, "bench newton: --mgr is not an MGR spec");
            const double t0 = wall_seconds();
            m->setup(J);
            s.setup = wall_seconds() - t0;
            s.copy = m->copy_seconds();
            const SolveResult r = m->solve_fgmres(J, b, x, opt_.rel_tol, opt_.max_iter, 50);
            s.solve = r.solve_seconds;
            s.iterations = r.iterations;
            s.relres = true_relres(J, b, x);
            s.converged = r.converged && s.relres <= opt_.rel_tol * (1 + 1e-6);
            if (!s.converged) s.failure = "FlexGMRES did not reach the tolerance";
        } catch (const std::exception& e) {
            s.relres = true_relres(J, b, x);
            s.failure = std::string("exception: ") + e.what();
        }
        return s;
    }

    const levels::Level& level_;
    levels::JacobianAssembler jac_;
    const BenchNewtonOptions& opt_;
    NewtonBenchPass pass_;
    const std::vector<double>* coarse_setups_;
    std::vector<NewtonSystemRow>& rows_;
    std::vector<int> functions_;
    solvers::KrylovParams params_, amg_params_;
    solvers::Krylov method_ = solvers::Krylov::cgs;
    int step_ = 0, newton_ = 0;
    size_t index_ = 0;
};

struct SampleMedian {
    NewtonSample s; // times: medians; the rest from the first sample
    bool present = false;
};

SampleMedian median_of(const std::vector<NewtonSample>& v) {
    SampleMedian m;
    if (v.empty()) return m;
    m.present = true;
    m.s = v.front();
    std::vector<double> a, b, c, d;
    for (const auto& s : v) {
        a.push_back(s.setup);
        b.push_back(s.setup_full);
        c.push_back(s.solve);
        d.push_back(s.copy);
        m.s.converged = m.s.converged && s.converged;
    }
    m.s.setup = median(a);
    m.s.setup_full = median(b);
    m.s.solve = median(c);
    m.s.copy = median(d);
    return m;
}

std::string json_number(double v) {
    if (!std::isfinite(v)) return "null";
    std::ostringstream os;
    os << std::setprecision(6) << v;
    return os.str();
}

/// Columns of hypre's solvers (their setup has no coarser levels).
bool is_hypre(const std::string& key) {
    return key == "mgr" || key == "mgr+fgmres" || key == "amg";
}

/// The table and JSON array of every Newton system and solver, and the totals per solver;
/// returns 2 when one of our solvers or MGR failed on a system, else 0.
int report_systems(std::ostream& os, std::ostream& js, const std::vector<NewtonSystemRow>& rows,
                   const std::vector<std::string>& keys, const std::string& ours) {
    int code = 0;
    std::map<std::string, double> total_setup, total_solve, total_full;
    std::map<std::string, int> total_its, failed;
    os << std::setw(4) << "sys" << std::setw(5) << "step" << std::setw(4) << "nwt" << std::setw(6)
       << "gap" << std::setw(6) << "stick" << std::setw(6) << "slip";
    for (const auto& key : keys)
        os << "  | " << std::setw(18) << std::left << key << std::right << std::setw(6) << "its"
           << std::setw(9) << "setup" << std::setw(9) << "solve" << std::setw(9) << "relres";
    os << "\n";
    for (size_t k = 0; k < rows.size(); ++k) {
        const NewtonSystemRow& row = rows[k];
        js << (k ? "," : "") << "\n    {\"index\": " << k << ", \"load_step\": " << row.step
           << ", \"newton_iteration\": " << row.newton << ", \"gap\": " << row.gap
           << ", \"stick\": " << row.stick << ", \"slip\": " << row.slip;
        os << std::setw(4) << k << std::setw(5) << row.step << std::setw(4) << row.newton
           << std::setw(6) << row.gap << std::setw(6) << row.stick << std::setw(6) << row.slip;
        for (const auto& key : keys) {
            const auto it = row.samples.find(key);
            const SampleMedian m = it == row.samples.end() ? SampleMedian{} : median_of(it->second);
            if (!m.present) {
                os << "  | " << std::setw(18 + 6 + 27) << "-";
                continue;
            }
            const NewtonSample& s = m.s;
            total_setup[key] += s.setup;
            total_full[key] += is_hypre(key) ? s.setup : s.setup_full;
            total_solve[key] += s.solve;
            total_its[key] += s.iterations;
            failed[key] += !s.converged;
            if (!s.converged && key != "amg") code = 2;
            js << ",\n     " << json_string(key) << ": {\"iterations\": " << s.iterations
               << ", \"setup_seconds\": " << json_number(s.setup);
            if (!is_hypre(key))
                js << ", \"setup_with_coarse_levels_seconds\": " << json_number(s.setup_full);
            else
                js << ", \"copy_to_hypre_seconds\": " << json_number(s.copy);
            js << ", \"solve_seconds\": " << json_number(s.solve)
               << ", \"relative_residual\": " << json_number(s.relres)
               << ", \"converged\": " << (s.converged ? "true" : "false");
            if (!s.failure.empty()) js << ", \"failure\": " << json_string(s.failure);
            js << "}";
            os << "  | " << std::setw(18) << (s.converged ? "" : "FAILED") << std::setw(6)
               << s.iterations << std::fixed << std::setprecision(3) << std::setw(9) << s.setup
               << std::setw(9) << s.solve << std::scientific << std::setprecision(1) << std::setw(9)
               << s.relres << std::defaultfloat;
        }
        js << "}";
        os << "\n";
    }
    js << "\n  ],\n  \"totals\": {";
    os << "totals over " << rows.size() << " Newton systems (seconds; mg setup with the coarser "
       << "levels' setups of each load step in brackets):\n";
    for (size_t i = 0; i < keys.size(); ++i) {
        const std::string& key = keys[i];
        const double total = total_full[key] + total_solve[key];
        js << (i ? "," : "") << "\n    " << json_string(key)
           << ": {\"setup_seconds\": " << json_number(total_setup[key])
           << ", \"setup_full_seconds\": " << json_number(total_full[key])
           << ", \"solve_seconds\": " << json_number(total_solve[key])
           << ", \"total_seconds\": " << json_number(total)
           << ", \"iterations\": " << total_its[key] << ", \"failed\": " << failed[key];
        if (key != ours && total_full[ours] + total_solve[ours] > 0)
            js << ", \"time_over_" << ours
               << "\": " << json_number(total / (total_full[ours] + total_solve[ours]));
        js << "}";
        os << "  " << std::setw(18) << std::left << key << std::right << " setup " << std::fixed
           << std::setprecision(3) << total_setup[key];
        if (!is_hypre(key)) os << " [" << total_full[key] << "]";
        os << "  solve " << total_solve[key] << "  total " << total << "  iterations "
           << total_its[key] << std::defaultfloat;
        if (failed[key] > 0) os << "  FAILED on " << failed[key] << " system(s)";
        if (key != ours && total_full[ours] + total_solve[ours] > 0)
            os << "  (" << std::setprecision(3) << total / (total_full[ours] + total_solve[ours])
               << "x " << ours << ")";
        os << "\n";
    }
    return code;
}

} // namespace

int bench_newton(const BenchNewtonOptions& opt, std::ostream& os) {
    MLC_CHECK(opt.levels >= 1 && opt.levels <= 8,
              "bench newton: --levels must be in 1..8 (the finest level's Newton systems, "
              "coarse-to-fine), found "
                  << opt.levels);
    MLC_CHECK(opt.repeat >= 1, "bench newton: --repeat must be >= 1, found " << opt.repeat);
    MLC_CHECK(opt.rel_tol > 0 && opt.rel_tol < 1,
              "bench newton: --tol must be in (0, 1), found " << opt.rel_tol);
    MLC_CHECK(opt.max_iter >= 1, "bench newton: --max-iter must be >= 1, found " << opt.max_iter);
    MLC_CHECK(!opt.threads.empty(), "bench newton: --threads is empty");
    for (int t : opt.threads)
        MLC_CHECK(t >= 1 && t <= 256, "bench newton: --threads must be in 1..256, found " << t);
    check_preconditioner_names({opt.pc, opt.mgr});
    MLC_CHECK(solvers::parse_pc(opt.mgr).entry->name == "mgr",
              "bench newton: --mgr must be an mgr spec (mgr[:options]), found '" << opt.mgr << "'");
    MLC_CHECK(solvers::have_hypre(),
              "bench newton compares with hypre MGR and BoomerAMG: this build has "
              "MLC_WITH_HYPRE=OFF (install libhypre-dev and reconfigure)");
    (void)solvers::parse_krylov(opt.krylov);
    levels::Problem problem = scene::load_scene(opt.scene);
    problem.levels = opt.levels;
    // Thread counts: 1 first (hypre's runs), then the others as given.
    std::vector<int> threads{1};
    for (int t : opt.threads)
        if (std::find(threads.begin(), threads.end(), t) == threads.end()) threads.push_back(t);
    const int threads_before = parallel::num_threads();

    std::vector<NewtonSystemRow> rows;
    Index unknowns = 0;
    long nonzeros = 0;
    std::string run_solver, failure;
    bool runs_converged = true;
    int mismatch_runs = 0;
    os << "bench newton: " << opt.scene << " level " << opt.levels
       << " (coarse-to-fine run, levels 0.." << opt.levels << ", " << problem.load_steps
       << " load steps); every finest-level Newton system solved from zero to " << opt.rel_tol
       << " by " << opt.krylov << " + " << opt.pc << " (threads";
    for (int t : threads)
        os << " " << t;
    os << ") and, at 1 thread, " << opt.krylov << " + " << opt.mgr
       << (opt.amg ? " and " + opt.krylov + " + BoomerAMG on the whole Jacobian" : "")
       << "; times are medians of " << opt.repeat << " run(s)\n";
    for (int t : threads) {
        parallel::set_num_threads(t);
        for (int rep = 0; rep < opt.repeat; ++rep) {
            std::vector<NewtonSystemRow> pass_rows;
            std::vector<NewtonSystemRow>& into = (t == 1 && rep == 0) ? rows : pass_rows;
            std::vector<double> coarse(static_cast<size_t>(opt.levels), 0.0);
            const NewtonBenchPass pass{t, t == 1, t == 1 && rep == 0};
            levels::SolveOptions so;
            so.coarse_to_fine = true;
            so.linear = {.method = solvers::Method::krylov,
                         .krylov = solvers::parse_krylov(opt.krylov),
                         .pc = solvers::parse_pc(opt.pc),
                         .rel_tol = opt.rel_tol,
                         .max_iter = opt.max_iter};
            levels::SolverWrapper wrap([&](int level, const levels::Level& L,
                                           std::unique_ptr<levels::NewtonSystemSolver> s)
                                           -> std::unique_ptr<levels::NewtonSystemSolver> {
                if (level == opt.levels)
                    return std::make_unique<NewtonSystemRecorder>(std::move(s), L, opt, pass,
                                                                  &coarse, into);
                if (level == 0) return s; // schur: no part of the multigrid
                return std::make_unique<CoarseSetupTimer>(std::move(s),
                                                          &coarse[static_cast<size_t>(level)]);
            });
            const levels::RunResult r = levels::solve(problem, so, &wrap);
            if (!r.converged) {
                runs_converged = false;
                failure = r.failure;
            }
            if (unknowns == 0) {
                unknowns = r.finest().n_unknowns();
                nonzeros = jacobian_nonzeros(r.finest());
                run_solver = r.steps.empty() ? "" : r.solver.spec.pc.text();
            }
            if (&into == &rows) continue;
            // Later runs: the same systems (same sequence) add their samples.
            if (pass_rows.size() != rows.size()) ++mismatch_runs;
            for (size_t k = 0; k < std::min(rows.size(), pass_rows.size()); ++k)
                for (auto& [key, v] : pass_rows[k].samples)
                    rows[k].samples[key].insert(rows[k].samples[key].end(), v.begin(), v.end());
        }
    }
    parallel::set_num_threads(threads_before);

    // Table and JSON.
    std::vector<std::string> keys;
    for (int t : threads)
        keys.push_back(opt.pc + "@" + std::to_string(t));
    keys.push_back("mgr");
    if (opt.hypre_gmres) keys.push_back("mgr+fgmres");
    if (opt.amg) keys.push_back("amg");
    const std::string ours = opt.pc + "@1";
    const std::filesystem::path out = bench_json_path(opt.out, "newton_", opt.scene, opt.levels);
    AtomicOfstream js = open_json(out);
    js << "{\n  \"scene\": " << json_string(opt.scene) << ",\n  \"level\": " << opt.levels
       << ",\n  \"unknowns\": " << unknowns << ",\n  \"nonzeros\": " << nonzeros
       << ",\n  \"load_steps\": " << problem.load_steps
       << ",\n  \"krylov\": " << json_string(opt.krylov) << ",\n  \"rel_tol\": " << opt.rel_tol
       << ",\n  \"max_iter\": " << opt.max_iter << ",\n  \"repeat\": " << opt.repeat
       << ",\n  \"threads\": [";
    for (size_t i = 0; i < threads.size(); ++i)
        js << (i ? ", " : "") << threads[i];
    js << "],\n  \"hypre_threads\": 1,\n  \"solvers\": {";
    for (size_t i = 0; i < keys.size(); ++i) {
        const std::string& key = keys[i];
        std::string spec = key == "mgr"          ? opt.mgr
                           : key == "mgr+fgmres" ? opt.mgr + " in hypre's FlexGMRES(50)"
                           : key == "amg"
                               ? "BoomerAMG on the whole Jacobian (3 functions: u_x, u_y, lambda)"
                               : opt.pc;
        js << (i ? ", " : "") << json_string(key) << ": " << json_string(spec);
    }
    js << "},\n  \"runs_converged\": " << (runs_converged ? "true" : "false");
    if (!runs_converged) js << ", \"run_failure\": " << json_string(failure);
    js << ",\n  \"mismatched_runs\": " << mismatch_runs << ",\n  \"systems\": [";
    int code = report_systems(os, js, rows, keys, ours);
    js << "\n  },\n  \"peak_rss_mib\": " << peak_rss_mib() << "\n}\n";
    if (mismatch_runs > 0)
        os << "note: " << mismatch_runs
           << " run(s) had a different number of Newton systems than the first (their extra "
              "systems are left out)\n";
    if (!runs_converged) {
        os << "the run did not converge: " << failure << "\n";
        code = 2;
    }
    (void)run_solver;
    os << "wrote " << out.string() << "\n";
    return code;
}

} // namespace mlc::apps

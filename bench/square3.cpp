// SPDX-License-Identifier: MIT
// `mlcontact bench square` on a 3D scene: the whole coarse-to-fine run of levels/solve3.hpp
// measured level by level, and the scaling criterion (--scaling).
#include "bench/bench.hpp"
#include "bench/common.hpp"

#include "core/check.hpp"
#include "core/memory.hpp"
#include "core/parallel.hpp"
#include "core/timer.hpp"
#include "core/traffic.hpp"
#include "levels/resources.hpp"
#include "levels/solve3.hpp"
#include "scene/scene3.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <optional>
#include <sstream>

namespace mlc::apps {

namespace {

constexpr double kMiB3 = 1024.0 * 1024.0;

/// The options of `bench square` a 3D scene refuses, naming the option and why.
void refuse_2d_options(const BenchSquareOptions& opt) {
    auto given = [&](const std::string& name) {
        return std::find(opt.given.begin(), opt.given.end(), name) != opt.given.end();
    };
    const std::string solved =
        "3D contact levels are solved as `mlcontact run` solves them (level 0 exactly, GMRES with "
        "the Galerkin vertex-block multigrid above, relative tolerance 1e-10; or exactly on every "
        "level with --pc schur|lu)";
    auto refuse = [](bool is_given, const std::string& option, const std::string& why) {
        if (is_given)
            throw InvalidInput("bench square " + option + " does not apply to a 3D scene: " + why);
    };
    refuse(opt.krylov.has_value() || given("--krylov"), "--krylov", solved);
    refuse(given("--tol"), "--tol", solved);
    refuse(given("--max-iter"), "--max-iter", solved);
    refuse(opt.numbering.has_value() || given("--numbering"), "--numbering",
           "3D levels number their vertices along a Hilbert curve only");
    refuse(opt.extrapolate || given("--extrapolate"), "--extrapolate",
           "a 3D run starts every load step from the secant extrapolation, as `run` does, and "
           "every step's Newton is measured");
    for (const std::string& pc : opt.pcs)
        if (pc != "default" && pc != "mg" && pc != "schur" && pc != "lu")
            throw InvalidInput("bench square --pc '" + pc +
                               "' does not apply to a 3D scene: its solvers are default or mg "
                               "(the 3D run's plan: schur, or lu when schur does not fit, on "
                               "level 0 and GMRES + the Galerkin multigrid above), schur and lu "
                               "(exact on every level, as `run --linear schur|lu`)");
}

/// One level of the runs of one solver with one finest level.
struct Row3 {
    int level = 0;
    Index unknowns = 0;
    int contact_nodes = 0;
    long nonzeros = 0;                ///< stored entries of the assembled Jacobian
    std::vector<int> newton_per_step; ///< Newton iterations of each load step (first run)
    std::vector<int> krylov;          ///< Krylov iterations of each Newton system (first run)
    std::vector<double> linear_s;     ///< per run: the Newton systems (assembly, setup, solve)
    std::vector<double> level_s;      ///< per run: the level's load steps in all
    std::vector<double> matvec_s;     ///< per run: one CSR mat-vec of the level's Jacobian
    double matvec_bytes = 0;          ///< its compulsory bytes
    traffic::Account traffic;         ///< first run: counted passes of the Newton solves
    std::vector<traffic::Account> traffic_runs;
    std::vector<double> krylov_s; ///< per run: SolveResult::solve_seconds summed
    int solves = 0;               ///< Newton systems solved (first run)
    double rss_growth = 0;        ///< bytes (first run)

    int newton() const {
        int n = 0;
        for (int k : newton_per_step)
            n += k;
        return n;
    }
    double seconds_per_newton() const { return newton() > 0 ? median(linear_s) / newton() : 0.0; }
    /// Median over the runs of each run's Newton step in the same run's mat-vecs.
    double step_in_matvecs() const {
        std::vector<double> v;
        for (size_t i = 0; i < linear_s.size() && i < matvec_s.size(); ++i)
            if (newton() > 0 && matvec_s[i] > 0) v.push_back(linear_s[i] / newton() / matvec_s[i]);
        return median(v);
    }
    double bytes_per_newton() const { return traffic.total_bytes() / std::max(1, solves); }
};

/// The runs of one solver with one finest level.
struct Series3 {
    std::string pc;
    int finest = 0;
    levels::Plan3 plan;
    double estimate_bytes = 0;
    std::vector<Row3> rows;
    std::vector<double> walls;
    double peak_rss_mib = 0;  ///< after the first run
    double hierarchy_rss = 0; ///< first run: RSS growth before the first solver was handed over
    bool converged = true;
    std::string failure;
    int runs = 0;
    const Row3& fine() const { return rows.back(); }
};

/// The series of `pc` with finest level `finest`: its plan as `run` makes it.
Series3 make_series(const levels::ElasticProblem3& base, const std::string& pc, int finest) {
    Series3 s;
    s.pc = pc;
    s.finest = finest;
    std::optional<levels::Method3> forced;
    if (pc == "schur") forced = levels::Method3::schur;
    if (pc == "lu") forced = levels::Method3::lu;
    const auto sizes = levels::predict_elastic3_sizes(base, finest);
    s.plan = levels::plan_contact3(sizes, forced, levels::process_memory_limit());
    s.estimate_bytes = levels::estimate_contact3_bytes(sizes, s.plan.level0, s.plan.upper);
    return s;
}

/// One whole coarse-to-fine run of `s` (the scene's load steps on levels 0..s.finest), recorded
/// level by level; each level's mat-vec is timed after the run at its last Newton statuses.
void run_once(levels::ElasticProblem3 problem, Series3& s) {
    problem.levels = s.finest;
    levels::SolveOptions3 so;
    so.coarse_to_fine = true;
    so.extrapolate = true;
    so.level0 = s.plan.level0;
    so.upper = s.plan.upper;
    const auto nl = static_cast<size_t>(s.finest) + 1;
    std::vector<LevelTraffic> lt(nl);
    std::vector<std::vector<levels::StatusMatrix<3>>> last_M(nl);
    int depth = 0;
    const double rss_before_run = current_rss_bytes();
    double rss_prev = -1, hierarchy_rss = 0;
    so.wrap_system_solver = [&](int level, const levels::Level3&,
                                std::unique_ptr<levels::NewtonSystemSolver3> sys)
        -> std::unique_ptr<levels::NewtonSystemSolver3> {
        MLC_CHECK(level >= 0 && static_cast<size_t>(level) < nl, "bench square: level " << level);
        const auto l = static_cast<size_t>(level);
        // The first solver handed over: its construction is counted with the hierarchy.
        if (rss_prev < 0) {
            rss_prev = current_rss_bytes();
            hierarchy_rss = rss_prev - rss_before_run;
        }
        auto w = std::make_unique<TrafficRecorder<3>>(std::move(sys), &lt[l], &depth, rss_prev,
                                                      &last_M[l]);
        rss_prev = lt[l].rss_at_build;
        return w;
    };
    const double t0 = wall_seconds();
    const levels::RunResult3 r = levels::solve(problem, so);
    s.walls.push_back(wall_seconds() - t0);
    const bool first = s.runs == 0;
    ++s.runs;
    if (first) {
        s.peak_rss_mib = peak_rss_mib();
        s.hierarchy_rss = hierarchy_rss;
        s.rows.resize(nl);
    }
    if (!r.converged) {
        s.converged = false;
        s.failure = r.failure;
    }
    for (size_t l = 0; l < nl; ++l) {
        Row3& row = s.rows[l];
        const levels::Level3& L = r.hierarchy.levels[l];
        double linear = 0, total = 0;
        std::vector<int> per_step, krylov;
        for (const auto& st : r.level_steps[l]) {
            per_step.push_back(st.report.iterations);
            krylov.insert(krylov.end(), st.report.linear_iterations_per_newton.begin(),
                          st.report.linear_iterations_per_newton.end());
            linear += st.report.linear_seconds;
            total += st.report.seconds;
        }
        row.linear_s.push_back(linear);
        row.level_s.push_back(total);
        row.traffic_runs.push_back(lt[l].account);
        row.krylov_s.push_back(lt[l].krylov_seconds);
        // A level that took no Newton step: its Jacobian at unit statuses (same pattern; the
        // values do not change a mat-vec's time).
        levels::BasicJacobianAssembler<3> jac(L);
        if (last_M[l].empty())
            jac.assemble(std::vector<levels::StatusMatrix<3>>(L.contacts.size(),
                                                              levels::StatusMatrix<3>::Identity()));
        else
            jac.assemble(last_M[l]);
        const SparseMatrix& J = jac.matrix();
        row.matvec_s.push_back(time_matvec(J, 10, l + 1 == nl ? 0.5 : 0.1));
        row.nonzeros = static_cast<long>(J.nonZeros());
        row.matvec_bytes = traffic::csr_bytes(J.rows(), J.cols(), J.nonZeros(), false);
        if (first) {
            row.level = static_cast<int>(l);
            row.unknowns = L.n_unknowns();
            row.contact_nodes = L.n_contact_nodes();
            row.newton_per_step = per_step;
            row.krylov = krylov;
            row.traffic = lt[l].account;
            row.solves = lt[l].solves;
            row.rss_growth = lt[l].rss_growth;
        }
    }
}

std::string join(const std::vector<int>& v) {
    std::ostringstream os;
    for (size_t i = 0; i < v.size(); ++i)
        os << (i ? ", " : "") << v[i];
    return os.str();
}

std::vector<double> as_doubles(const std::vector<int>& v) {
    return {v.begin(), v.end()};
}

/// "schur on level 0, gmres + mg above" (or "... on every level").
std::string plan_label(const levels::Plan3& p, int finest) {
    std::string s = std::string(levels::to_string(p.level0)) + " on level 0";
    if (finest == 0) return s;
    if (p.upper == p.level0) return std::string(levels::to_string(p.level0)) + " on every level";
    return s + ", " + levels::to_string(p.upper) + " above";
}

/// The per-level JSON object of `row` (medians over the runs).
void json_level(std::ostream& js, const Row3& row, const std::optional<traffic::Stream>& stream) {
    const int newton = row.newton();
    const double per_newton = row.seconds_per_newton();
    const auto n = static_cast<double>(row.unknowns);
    const std::vector<double> its = as_doubles(row.krylov);
    double its_sum = 0;
    for (double i : its)
        its_sum += i;
    js << "{\"level\": " << row.level << ", \"unknowns\": " << row.unknowns
       << ", \"contact_nodes\": " << row.contact_nodes << ", \"nonzeros\": " << row.nonzeros
       << ", \"newton_steps\": " << newton << ", \"newton_steps_per_load_step\": ["
       << join(row.newton_per_step) << "], \"krylov_per_newton\": [" << join(row.krylov)
       << "], \"krylov_per_newton_median\": " << median(its) << ", \"krylov_per_newton_mean\": "
       << (its.empty() ? 0.0 : its_sum / static_cast<double>(its.size()))
       << ", \"krylov_per_newton_max\": "
       << (its.empty() ? 0.0 : *std::max_element(its.begin(), its.end()))
       << ",\n        \"linear_seconds\": " << median(row.linear_s)
       << ", \"level_seconds\": " << median(row.level_s)
       << ", \"seconds_per_newton\": " << per_newton
       << ", \"seconds_per_newton_per_unknown\": " << per_newton / n
       << ", \"matvec_seconds\": " << median(row.matvec_s)
       << ", \"matvec_bytes\": " << whole(row.matvec_bytes)
       << ", \"newton_step_in_matvecs\": " << row.step_in_matvecs();
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
    js << ",\n        \"bandwidth\": {\"newton_solves\": " << row.solves
       << ", \"krylov_seconds\": " << ks << ", \"bytes\": " << whole(a.total_bytes())
       << ", \"bytes_per_newton\": " << a.total_bytes() / steps
       << ", \"bytes_per_newton_per_unknown\": " << a.total_bytes() / steps / n
       << ", \"bytes_per_newton_in_matvecs\": "
       << (row.matvec_bytes > 0 ? a.total_bytes() / steps / row.matvec_bytes : 0.0)
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
    js << "}},\n        \"memory\": {\"solver_rss_growth_bytes\": " << whole(row.rss_growth)
       << ", \"solver_rss_growth_bytes_per_unknown\": " << row.rss_growth / n
       << ", \"jacobian_bytes\": "
       << whole(12.0 * static_cast<double>(row.nonzeros) + 4.0 * (n + 1)) << "}}";
}

/// The JSON object of one series.
void json_series(std::ostream& js, const Series3& s, const std::optional<traffic::Stream>& stream) {
    const Row3& f = s.fine();
    js << "{\"solver\": " << json_string(s.pc) << ", \"finest\": " << s.finest
       << ", \"level0\": " << json_string(levels::to_string(s.plan.level0))
       << ", \"upper\": " << json_string(levels::to_string(s.plan.upper))
       << ", \"plan\": " << json_string(s.plan.why)
       << ", \"converged\": " << (s.converged ? "true" : "false");
    if (!s.converged) js << ", \"failure\": " << json_string(s.failure);
    js << ",\n     \"runs\": " << s.runs << ", \"wall_seconds\": " << median(s.walls)
       << ", \"wall_seconds_runs\": [";
    for (size_t i = 0; i < s.walls.size(); ++i)
        js << (i ? ", " : "") << s.walls[i];
    js << "], \"peak_rss_mib\": " << s.peak_rss_mib
       << ", \"memory_estimate_mib\": " << s.estimate_bytes / kMiB3
       << ", \"hierarchy_rss_growth_bytes\": " << whole(s.hierarchy_rss)
       << ",\n     \"fine_newton_step_seconds\": " << f.seconds_per_newton()
       << ", \"fine_matvec_seconds\": " << median(f.matvec_s)
       << ", \"fine_newton_step_in_matvecs\": " << f.step_in_matvecs() << ",\n     \"levels\": [";
    for (size_t l = 0; l < s.rows.size(); ++l) {
        js << (l ? "," : "") << "\n       ";
        json_level(js, s.rows[l], stream);
    }
    js << "\n     ]}";
}

/// The tables of one series: levels, bandwidth, memory (appended to the three streams).
void text_series(std::ostream& os, std::ostream& bw, std::ostream& mem, const Series3& s,
                 const std::optional<traffic::Stream>& stream) {
    for (const Row3& row : s.rows) {
        const std::vector<double> its = as_doubles(row.krylov);
        const double per_newton = row.seconds_per_newton();
        os << std::setw(8) << s.pc << std::setw(7) << s.finest << std::setw(6) << row.level
           << std::setw(10) << row.unknowns << std::setw(8) << row.contact_nodes << std::setw(7)
           << row.newton() << std::fixed << std::setprecision(1) << std::setw(9) << median(its)
           << std::setprecision(0) << std::setw(6)
           << (its.empty() ? 0.0 : *std::max_element(its.begin(), its.end()))
           << std::setprecision(4) << std::setw(11) << per_newton << std::setprecision(3)
           << std::setw(13) << 1e6 * per_newton / static_cast<double>(row.unknowns) << std::setw(11)
           << 1e3 * median(row.matvec_s) << std::setprecision(1) << std::setw(10)
           << row.step_in_matvecs() << std::defaultfloat << "\n";
        const traffic::Account& a = row.traffic;
        if (row.solves > 0 && a.total_bytes() > 0) {
            using traffic::Kind;
            const double steps = row.solves;
            const double ks = median(row.krylov_s);
            bw << std::setw(8) << s.pc << std::setw(7) << s.finest << std::setw(6) << row.level
               << std::fixed << std::setprecision(2) << std::setw(10)
               << a.total_bytes() / steps / 1e6 << std::setw(9) << a.b(Kind::matvec) / steps / 1e6
               << std::setw(9) << a.b(Kind::smoother) / steps / 1e6 << std::setw(9)
               << a.b(Kind::transfer) / steps / 1e6 << std::setw(9)
               << a.b(Kind::vector) / steps / 1e6 << std::setprecision(0) << std::setw(10)
               << row.bytes_per_newton() / static_cast<double>(row.unknowns) << std::setprecision(1)
               << std::setw(9)
               << (row.matvec_bytes > 0 ? row.bytes_per_newton() / row.matvec_bytes : 0.0)
               << std::setprecision(4) << std::setw(10) << ks / steps << std::setprecision(2)
               << std::setw(8) << gbs(a.total_bytes(), ks) << std::setprecision(0) << std::setw(7)
               << (stream && stream->triad_gbs > 0
                       ? 100 * gbs(a.total_bytes(), ks) / stream->triad_gbs
                       : 0.0)
               << std::defaultfloat << "\n";
        }
        mem << std::setw(8) << s.pc << std::setw(7) << s.finest << std::setw(6) << row.level
            << std::setw(10) << row.unknowns << std::fixed << std::setprecision(1) << std::setw(12)
            << row.rss_growth / kMiB3 << std::setprecision(0) << std::setw(11)
            << row.rss_growth / static_cast<double>(row.unknowns) << std::setprecision(2)
            << std::setw(12)
            << (12.0 * static_cast<double>(row.nonzeros) +
                4.0 * static_cast<double>(row.unknowns + 1)) /
                   kMiB3
            << std::defaultfloat << "\n";
    }
    os << std::setw(8) << s.pc << "  finest " << s.finest << ": " << plan_label(s.plan, s.finest)
       << "; total wall " << std::fixed << std::setprecision(3) << median(s.walls)
       << " s (median of " << s.runs << "), peak RSS " << std::setprecision(0) << s.peak_rss_mib
       << " MiB (estimate " << s.estimate_bytes / kMiB3 << " MiB)" << std::defaultfloat
       << (s.converged ? "" : "  FAILED: " + s.failure) << "\n";
}

/// The scaling criterion of two series (the level below, then the finest).
struct Scaling3 {
    double unknowns_ratio = 0;
    double matvecs_below = 0, matvecs_fine = 0, matvecs_growth = 0;
    double bytes_below = 0, bytes_fine = 0, bytes_growth = 0;
    double step_below = 0, step_fine = 0;
    double time_ratio = 0;
    double krylov_below = 0, krylov_fine = 0; ///< median Krylov iterations per fine Newton step
    bool matvecs_met = false, time_met = false;
};

Scaling3 scaling_of(const Series3& below, const Series3& fine) {
    Scaling3 c;
    const Row3& a = below.fine();
    const Row3& b = fine.fine();
    c.unknowns_ratio = static_cast<double>(b.unknowns) / static_cast<double>(a.unknowns);
    c.matvecs_below = a.step_in_matvecs();
    c.matvecs_fine = b.step_in_matvecs();
    c.matvecs_growth = c.matvecs_below > 0 ? c.matvecs_fine / c.matvecs_below - 1 : 0.0;
    c.bytes_below = a.bytes_per_newton() / static_cast<double>(a.unknowns);
    c.bytes_fine = b.bytes_per_newton() / static_cast<double>(b.unknowns);
    c.bytes_growth = c.bytes_below > 0 ? c.bytes_fine / c.bytes_below - 1 : 0.0;
    c.krylov_below = median(as_doubles(a.krylov));
    c.krylov_fine = median(as_doubles(b.krylov));
    c.step_below = a.seconds_per_newton();
    c.step_fine = b.seconds_per_newton();
    const double wa = median(below.walls), wb = median(fine.walls);
    c.time_ratio = wa > 0 ? wb / wa : 0.0;
    c.matvecs_met = c.matvecs_below > 0 && c.matvecs_growth <= kScalingMatvecGrowth;
    c.time_met = c.time_ratio > 0 && c.time_ratio <= kScalingTimeRatio;
    return c;
}

void json_scaling(std::ostream& js, const Series3& below, const Series3& fine, const Scaling3& c) {
    js << ",\n  \"scaling\": {\"below\": " << below.finest << ", \"finest\": " << fine.finest
       << ", \"runs_each\": " << fine.runs << ", \"order\": \"alternated, the level below first\""
       << ", \"unknowns\": [" << below.fine().unknowns << ", " << fine.fine().unknowns
       << "], \"unknowns_ratio\": " << c.unknowns_ratio
       << ",\n    \"fine_newton_step_in_matvecs\": [" << c.matvecs_below << ", " << c.matvecs_fine
       << "], \"matvecs_growth\": " << c.matvecs_growth
       << ", \"matvecs_growth_bound\": " << kScalingMatvecGrowth
       << ", \"matvecs_met\": " << (c.matvecs_met ? "true" : "false")
       << ",\n    \"wall_seconds\": [" << median(below.walls) << ", " << median(fine.walls)
       << "], \"time_ratio\": " << c.time_ratio << ", \"time_ratio_bound\": " << kScalingTimeRatio
       << ", \"time_met\": " << (c.time_met ? "true" : "false")
       << ",\n    \"fine_krylov_per_newton_median\": [" << c.krylov_below << ", " << c.krylov_fine
       << "], \"fine_newton_step_seconds\": [" << c.step_below << ", " << c.step_fine
       << "], \"fine_bytes_per_newton_per_unknown\": [" << c.bytes_below << ", " << c.bytes_fine
       << "], \"bytes_growth\": ";
    // No counted passes below (an exact solve there): no growth to give.
    if (c.bytes_below > 0)
        js << c.bytes_growth;
    else
        js << "null";
    js << "}";
}

void text_scaling(std::ostream& os, const Series3& below, const Series3& fine, const Scaling3& c) {
    os << "\nscaling, finest " << below.finest << " -> " << fine.finest << " (" << fine.runs
       << " runs each, alternated; medians): " << below.fine().unknowns << " -> "
       << fine.fine().unknowns << " unknowns (x" << std::fixed << std::setprecision(2)
       << c.unknowns_ratio << ")\n"
       << "  fine Newton step in fine mat-vecs: " << std::setprecision(1) << c.matvecs_below
       << " -> " << c.matvecs_fine << ", growth " << std::showpos << 100 * c.matvecs_growth
       << std::noshowpos << " % (bound +" << std::setprecision(0) << 100 * kScalingMatvecGrowth
       << " %): " << (c.matvecs_met ? "met" : "NOT met") << "\n"
       << "  whole-run wall time: " << std::setprecision(3) << median(below.walls) << " -> "
       << median(fine.walls) << " s, ratio " << std::setprecision(2) << c.time_ratio << " (bound "
       << std::setprecision(0) << kScalingTimeRatio
       << "x for 8x the unknowns): " << (c.time_met ? "met" : "NOT met") << "\n"
       << "  beside them: Krylov iterations per fine Newton step (median) " << std::setprecision(1)
       << c.krylov_below << " -> " << c.krylov_fine << "; fine Newton step " << std::setprecision(4)
       << c.step_below << " -> " << c.step_fine
       << " s; counted bytes per fine Newton step per unknown " << std::setprecision(0)
       << c.bytes_below << " -> " << c.bytes_fine;
    if (c.bytes_below > 0)
        os << " (" << std::showpos << std::setprecision(1) << 100 * c.bytes_growth << std::noshowpos
           << " %)";
    else
        os << " (the level below is solved exactly: no counted passes)";
    os << std::defaultfloat << "\n";
}

} // namespace

int bench_square3(const BenchSquareOptions& opt, std::ostream& os) {
    refuse_2d_options(opt);
    MLC_CHECK(opt.repeat >= 1, "bench square: --repeat must be >= 1, found " << opt.repeat);
    MLC_CHECK(!opt.pcs.empty(), "bench square: no --pc given");
    const levels::ElasticProblem3 base = scene::load_scene3(opt.scene);
    MLC_CHECK(!base.contacts.empty(), "bench square: scene '"
                                          << base.name << "' has no contact: a 3D scene without "
                                          << "contact runs with `mlcontact bench elastic "
                                          << opt.scene << "`");
    const int L = opt.levels_from_scene ? base.levels : opt.levels;
    MLC_CHECK(L >= 0 && L <= levels::kMaxLevels3, "bench square: --levels must lie in 0.."
                                                      << levels::kMaxLevels3
                                                      << " for a 3D scene, found " << L);
    if (opt.scaling) {
        MLC_CHECK(L >= 1, "bench square --scaling compares the finest level with the level "
                          "below: --levels must be >= 1, found "
                              << L);
        MLC_CHECK(opt.pcs.size() == 1, "bench square --scaling runs one solver, found "
                                           << opt.pcs.size() << " --pc entries");
    }
    // Every series planned (and a run that cannot fit refused) before anything runs.
    std::vector<Series3> series;
    if (opt.scaling) series.push_back(make_series(base, opt.pcs.front(), L - 1));
    for (const std::string& pc : opt.pcs)
        series.push_back(make_series(base, pc, L));
    const bool timing_was = traffic::timing();
    traffic::set_timing(true);
    struct RestoreTiming {
        bool was;
        ~RestoreTiming() { traffic::set_timing(was); }
    } restore_timing{timing_was};
    if (opt.scaling) {
        // Alternated, the level below first (its first run's peak RSS is its own).
        for (int rep = 0; rep < opt.repeat && series[0].converged && series[1].converged; ++rep) {
            run_once(base, series[0]);
            run_once(base, series[1]);
        }
    } else {
        for (Series3& s : series)
            for (int rep = 0; rep < opt.repeat && s.converged; ++rep)
                run_once(base, s);
    }
    // STREAM after every run (its arrays stay out of the runs' peak RSS).
    const std::optional<traffic::Stream> stream =
        traffic::measure_stream(opt.stream_doubles, opt.stream_repeats);
    int code = 0;
    for (const Series3& s : series)
        if (!s.converged) code = 2;

    const std::filesystem::path out = bench_json_path(opt.out, "", base.name, L);
    AtomicOfstream js = open_json(out);
    js << "{\n  \"scene\": " << json_string(base.name) << ",\n  \"dimension\": 3"
       << ",\n  \"levels\": " << L << ",\n  \"load_steps\": " << base.load_steps
       << ",\n  \"repeat\": " << opt.repeat << ",\n  \"threads\": " << parallel::num_threads()
       << ",\n  \"extrapolate\": true,\n  \"krylov_rel_tol\": "
       << levels::SolveOptions3{}.krylov_rel_tol << ",\n  \"runs\": [";
    for (size_t i = 0; i < series.size(); ++i) {
        js << (i ? "," : "") << "\n    ";
        json_series(js, series[i], stream);
    }
    js << "\n  ]";
    std::optional<Scaling3> scaling;
    if (opt.scaling && series[0].converged && series[1].converged) {
        scaling = scaling_of(series[0], series[1]);
        json_scaling(js, series[0], series[1], *scaling);
    }
    js << ",\n  \"stream\": {\"copy_gbs\": " << stream->copy_gbs
       << ", \"triad_gbs\": " << stream->triad_gbs << ", \"doubles\": " << stream->n
       << ", \"repeats\": " << stream->repeats << ", \"threads\": " << stream->threads << "}";
    js << "\n}\n";

    os << "bench square " << base.name << " (3D): " << (opt.scaling ? "finest " : "levels 0..")
       << (opt.scaling ? std::to_string(L - 1) + " and " + std::to_string(L) + " alternated"
                       : std::to_string(L))
       << ", coarse-to-fine, " << base.load_steps << " load steps, Newton systems as `run` "
       << "solves them, " << parallel::num_threads() << " thread(s), times are medians of "
       << opt.repeat << " run(s)\n";
    for (const Series3& s : series)
        os << "plan (" << s.pc << ", finest " << s.finest << "): " << s.plan.why << "\n";
    os << std::setw(8) << "solver" << std::setw(7) << "finest" << std::setw(6) << "level"
       << std::setw(10) << "unknowns" << std::setw(8) << "contact" << std::setw(7) << "newton"
       << std::setw(9) << "its med" << std::setw(6) << "max" << std::setw(11) << "s/newton"
       << std::setw(13) << "us/newt/unk" << std::setw(11) << "mat-vec ms" << std::setw(10)
       << "mat-vecs"
       << "\n";
    std::ostringstream bw, mem;
    for (const Series3& s : series)
        text_series(os, bw, mem, s, stream);
    os << "(its: Krylov iterations per Newton step; mat-vecs: a Newton step's seconds in the "
          "level's Jacobian mat-vecs)\n";
    os << "\nbandwidth account per Newton step (compulsory bytes of the counted passes, "
          "docs/studies.md#bench-bandwidth)\n"
       << std::setw(8) << "solver" << std::setw(7) << "finest" << std::setw(6) << "level"
       << std::setw(10) << "MB/newt" << std::setw(9) << "matvec" << std::setw(9) << "smooth"
       << std::setw(9) << "transf" << std::setw(9) << "vector" << std::setw(10) << "B/unknown"
       << std::setw(9) << "mat-vecs" << std::setw(10) << "krylov s" << std::setw(8) << "GB/s"
       << std::setw(7) << "%triad"
       << "\n"
       << bw.str();
    os << "STREAM (same binary, " << stream->threads << " thread(s), " << stream->n
       << " doubles per array, best of " << stream->repeats << "): copy " << std::fixed
       << std::setprecision(2) << stream->copy_gbs << " GB/s, triad " << stream->triad_gbs
       << " GB/s" << std::defaultfloat << "\n";
    os << "\nmemory per level: RSS growth while the run built the level's Newton-system solver "
          "and ran its first Newton solve; the assembled Jacobian's CSR\n"
       << std::setw(8) << "solver" << std::setw(7) << "finest" << std::setw(6) << "level"
       << std::setw(10) << "unknowns" << std::setw(12) << "MiB" << std::setw(11) << "B/unknown"
       << std::setw(12) << "J MiB"
       << "\n"
       << mem.str();
    if (scaling) text_scaling(os, series[0], series[1], *scaling);
    os << "wrote " << out.string() << "\n";
    return code;
}

} // namespace mlc::apps

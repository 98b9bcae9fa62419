// SPDX-License-Identifier: MIT
// Stability study over stiff and extreme cases (benchmarks.md, "Stiff and extreme cases").
#include "studies/extremes.hpp"

#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "levels/checks.hpp"
#include "levels/solve.hpp"
#include "scene/scene.hpp"

#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <functional>
#include <iomanip>
#include <map>
#include <sstream>
#include <sys/wait.h>
#include <toml++/toml.h>
#include <unistd.h>
#include <vector>
#if defined(_OPENMP)
#include <omp.h>
#endif

namespace mlc::apps {

namespace {

/// What a case reports back to the parent (key = value lines through a pipe).
using Fields = ExtremesFields;

struct Case {
    std::string name;
    std::string what;
    std::function<Fields(int levels, const levels::LinearSolverSpec& solver)> run;
};

std::string num(double v, int digits = 3) {
    std::ostringstream os;
    os << std::setprecision(digits) << v;
    return os.str();
}

/// mg:smoother=lattice (the default's sweep from level 4 on) on p (its levels set): kept from
/// level 4 on (levels::solve numbers the levels for it), below it (the slender case's level 1)
/// smoother=block, as the default takes there; returns whether the block sweep replaced it.
bool sweep_for(const levels::Problem& p, levels::LinearSolverSpec& solver) {
    if (!solver.pc.lattice_numbering() || p.levels >= levels::kMgDefaultLatticeLevel) return false;
    std::get<solvers::MgOptions>(solver.pc.options).smoother =
        solvers::MultigridParams::Smoother::block;
    solver.numbering.reset();
    return true;
}

/// Solves a problem and summarizes it.
Fields solve_case(levels::Problem p, int levels, levels::LinearSolverSpec solver) {
    p.levels = levels;
    const bool block_sweep = sweep_for(p, solver);
    Fields f;
    if (block_sweep) f["block_sweep"] = std::to_string(levels);
    const double t0 = wall_seconds();
    levels::SolveOptions so;
    so.linear = solver;
    so.exact_fallback = true; // as `mlcontact run` does
    so.r_continuation = true;
    const auto r = levels::solve(p, so);
    f["seconds"] = num(wall_seconds() - t0);
    int newton = 0, krylov = 0, cycling = -1, krylov_systems = 0, fallbacks = 0, continuations = 0;
    for (const auto& ls : r.level_steps)
        for (const auto& st : ls) {
            fallbacks += st.report.fallback_solves;
            continuations += st.report.continuation_factor > 0;
            newton += st.report.iterations;
            krylov += st.report.linear_iterations;
            krylov_systems += static_cast<int>(st.report.linear_iterations_per_newton.size());
            if (st.report.cycling_detected_at >= 0) cycling = st.report.cycling_detected_at;
        }
    f["newton"] = std::to_string(newton);
    f["krylov"] = std::to_string(krylov);
    // Krylov iterations per Krylov-solved Newton system (levels >= 1; level 0 is exact).
    if (krylov_systems > 0)
        f["krylov_per_newton"] = num(static_cast<double>(krylov) / krylov_systems);
    if (cycling >= 0) f["cycling"] = "damped";
    if (fallbacks > 0) f["fallbacks"] = std::to_string(fallbacks);
    if (continuations > 0) f["continuations"] = std::to_string(continuations);
    if (!r.converged) {
        f["status"] = "no conv";
        f["diagnosis"] = r.failure;
        return f;
    }
    double res = 0;
    for (const auto& s : r.steps)
        res = std::max(res, s.residuals.back());
    f["residual"] = num(res);
    const levels::StateChecks c = levels::check_state(p, r);
    f["penetration"] = num(c.penetration);
    f["coulomb"] = num(std::max(c.coulomb_excess, c.slip_equality));
    f["balance"] = num(c.force_balance);
    for (double v : r.u_full)
        if (!std::isfinite(v)) {
            f["status"] = "NaN";
            f["diagnosis"] = "non-finite displacement";
            return f;
        }
    const auto n = r.steps.back().counts;
    f["statuses"] = std::to_string(n.gap) + "/" + std::to_string(n.stick) + "/" +
                    std::to_string(n.slip_forward) + "/" + std::to_string(n.slip_backward);
    f["status"] = "converged";
    return f;
}

levels::Problem square() {
    return scene::load_scene("square");
}

/// The square with one parameter pushed to its extremes: friction, r, Poisson's ratio, loads.
void add_square_parameter_cases(std::vector<Case>& cs) {
    for (double mu : {0.0, 0.01, 1.0, 2.0})
        cs.push_back({"mu=" + num(mu), "square, friction coefficient",
                      [mu](int l, const levels::LinearSolverSpec& solver) {
                          auto p = square();
                          p.contacts[0].mu = mu;
                          return solve_case(p, l, solver);
                      }});
    for (double rf : {1e-4, 1e-2, 10.0, 1e4})
        cs.push_back({"r=" + num(rf) + "E", "square, augmentation parameter",
                      [rf](int l, const levels::LinearSolverSpec& solver) {
                          auto p = square();
                          p.contacts[0].r = rf * p.bodies[0].material.E;
                          return solve_case(p, l, solver);
                      }});
    for (double nu : {0.45, 0.49, 0.4999})
        cs.push_back({"nu=" + num(nu, 6), "square, near-incompressible",
                      [nu](int l, const levels::LinearSolverSpec& solver) {
                          auto p = square();
                          p.bodies[0].material.nu = nu;
                          return solve_case(p, l, solver);
                      }});
    for (double f : {1e-8, 1e-4, 1e3})
        cs.push_back({"load x" + num(f), "square, loads scaled",
                      [f](int l, const levels::LinearSolverSpec& solver) {
                          auto p = square();
                          for (auto& ld : p.loads) {
                              ld.pressure *= f;
                              ld.traction *= f;
                          }
                          return solve_case(p, l, solver);
                      }});
}

/// Extreme loadings and shapes: lift-off, gross slip, a slender strip.
void add_loading_cases(std::vector<Case>& cs) {
    cs.push_back({"lift-off", "square with suction on top: every node opens",
                  [](int l, const levels::LinearSolverSpec& solver) {
                      auto p = square();
                      p.loads[0].pressure = -50.0;
                      p.loads[1].pressure = 0.0;
                      auto f = solve_case(p, l, solver);
                      const std::string& st = f["statuses"];
                      if (f["status"] == "converged" &&
                          (st.size() < 6 || st.compare(st.size() - 6, 6, "/0/0/0") != 0)) {
                          f["status"] = "wrong";
                          f["diagnosis"] = "expected every contact node open";
                      }
                      return f;
                  }});
    cs.push_back({"gross slip", "square, side load 20 x mu P, mu = 0.1, held by the symmetry plane",
                  [](int l, const levels::LinearSolverSpec& solver) {
                      auto p = square();
                      p.contacts[0].mu = 0.1;
                      p.loads[1].pressure = 150.0 * 10;
                      return solve_case(p, l, solver);
                  }});
    cs.push_back({"slender 100:1", "strip 100 x 1 on a plane, pressed and pushed",
                  [](int l, const levels::LinearSolverSpec& solver) {
                      const std::string text = R"(
[scene]
name = "slender"
load_steps = 3
[[body]]
E = 1.0e3
nu = 0.3
mesh = { type = "rectangle", corner = [0.0, 0.0], size = [100.0, 1.0], divisions = [200, 2] }
[[load]]
tag = "top"
pressure = 1.0
[[load]]
tag = "left"
pressure = 5.0
[[support]]
tag = "right"
ux = 0.0
[[contact]]
contactor = "bottom"
mu = 0.3
obstacle = { type = "line", point = [0.0, 0.0], normal = [0.0, 1.0] }
)";
                      return solve_case(scene::parse_scene(text, "extremes:slender"),
                                        std::min(l, 1), solver);
                  }});
}

/// Two bodies of very different stiffness, and the square in two systems of units.
void add_contrast_and_unit_cases(std::vector<Case>& cs) {
    // Two bodies, Young's moduli 1e6 apart, node on facet with friction, the default
    // r = 0.1 x the smaller E (with the larger one, r = 1e5 x the soft modulus, the statuses cycle
    // and Newton fails). Both ways round: a soft block on a stiff base, a stiff block on a soft
    // one.
    for (const bool soft_on_stiff : {true, false})
        cs.push_back(
            {soft_on_stiff ? "contrast 1e6 soft/stiff" : "contrast 1e6 stiff/soft",
             soft_on_stiff ? "two bodies: block E = 1 pressed on a base E = 1e6, side load"
                           : "two bodies: block E = 1e6 pressed on a base E = 1, side load",
             [soft_on_stiff](int l, const levels::LinearSolverSpec& solver) {
                 const double Eb = soft_on_stiff ? 1.0 : 1e6;
                 const double Ebase = soft_on_stiff ? 1e6 : 1.0;
                 std::ostringstream t;
                 t << std::setprecision(17) << R"(
[scene]
name = "contrast"
load_steps = 3
[[body]]
name = "base"
E = )" << Ebase << R"(
nu = 0.3
mesh = { type = "rectangle", corner = [0.0, 0.0], size = [2.0, 1.0], divisions = [8, 4] }
tags = { bottom = "base_bottom", top = "base_top", left = "base_left", right = "base_right" }
[[body]]
name = "block"
E = )" << Eb << R"(
nu = 0.3
mesh = { type = "rectangle", corner = [0.5, 1.0], size = [1.0, 1.0], divisions = [5, 5] }
tags = { bottom = "block_bottom", top = "block_top", left = "block_left", right = "block_right" }
[[support]]
tag = "base_bottom"
ux = 0.0
uy = 0.0
[[support]]
tag = "block_top"
ux = 0.0
uy = -0.01
[[load]]
tag = "block_left"
pressure = )" << 2e-3 * Eb
                   << R"(
[[contact]]
name = "interface"
contactor = "block_bottom"
target = "base_top"
element = "node_on_facet"
mu = 0.3
)";
                 return solve_case(scene::parse_scene(t.str(), "extremes:contrast"), l, solver);
             }});
    cs.push_back({"units N/m/Pa vs N/mm/MPa", "square in SI and in mm units; compare",
                  [](int l, const levels::LinearSolverSpec& solver) {
                      auto mm = square();
                      auto si = square();
                      const double L = 1e-3, P = 1e6; // mm -> m, MPa -> Pa
                      for (auto& v : si.mesh0.vertices)
                          v *= L;
                      si.bodies[0].material.E *= P;
                      for (auto& ld : si.loads)
                          ld.pressure *= P;
                      for (auto& s : si.supports)
                          if (s.point) *s.point *= L;
                      si.contacts[0].r *= P; // r = 0.1 E in both
                      mm.levels = si.levels = l;
                      levels::LinearSolverSpec spec = solver;
                      sweep_for(mm, spec);
                      sweep_for(si, spec);
                      levels::SolveOptions so;
                      so.linear = spec;
                      so.exact_fallback = true;
                      so.r_continuation = true;
                      const auto a = levels::solve(mm, so);
                      const auto b = levels::solve(si, so);
                      Fields f;
                      if (!a.converged || !b.converged) {
                          f["status"] = "no conv";
                          f["diagnosis"] = a.converged ? b.failure : a.failure;
                          return f;
                      }
                      // Displacements scale by L, nodal forces per unit thickness by P L^2 / L
                      // (force per length of thickness: N/mm -> N/m is x1000 = P L).
                      const double du = (b.u_full - L * a.u_full).norm() / (L * a.u_full.norm());
                      double dl = 0, lmax = 0;
                      for (size_t e = 0; e < a.nodes.size(); ++e) {
                          dl = std::max(
                              {dl, std::abs(b.nodes[e].lambda_n - P * L * a.nodes[e].lambda_n),
                               std::abs(b.nodes[e].lambda_t - P * L * a.nodes[e].lambda_t)});
                          lmax = std::max(lmax, std::abs(P * L * a.nodes[e].lambda_n));
                      }
                      f["unit_diff_u"] = num(du);
                      f["unit_diff_lambda"] = num(dl / lmax);
                      int na = 0, nb = 0;
                      for (const auto& st : a.steps)
                          na += st.iterations;
                      for (const auto& st : b.steps)
                          nb += st.iterations;
                      f["newton"] = std::to_string(na) + "|" + std::to_string(nb);
                      f["status"] = du <= 1e-8 && dl / lmax <= 1e-8 ? "converged" : "mismatch";
                      if (f["status"] == "mismatch")
                          f["diagnosis"] = "results differ after unit conversion";
                      return f;
                  }});
}

std::vector<Case> make_cases() {
    std::vector<Case> cs;
    add_square_parameter_cases(cs);
    add_loading_cases(cs);
    add_contrast_and_unit_cases(cs);
    return cs;
}

} // namespace

ExtremesFields run_isolated(const std::function<ExtremesFields()>& run, double seconds) {
    std::fflush(nullptr); // nothing buffered may be written twice by the child
#if defined(_OPENMP)
    // OpenMP's idle threads (CHOLMOD's, when the process factorized before) are not copied into
    // the child, whose first parallel region would wait for them forever: end them first (the
    // next region of this process starts new ones).
    omp_pause_resource_all(omp_pause_hard);
#endif
    int fd[2];
    if (pipe(fd) != 0) return {{"status", "error"}, {"diagnosis", "pipe failed"}};
    const pid_t pid = fork();
    if (pid == 0) {
        close(fd[0]);
        Fields f;
        try {
            f = run();
        } catch (const std::exception& e) {
            f["status"] = "error";
            f["diagnosis"] = e.what();
        }
        std::string out;
        for (const auto& [k, v] : f) {
            std::string vv = v;
            for (char& ch : vv)
                if (ch == '\n') ch = ' ';
            out += k + "=" + vv + "\n";
        }
        ssize_t w = write(fd[1], out.data(), out.size());
        (void)w;
        close(fd[1]);
        _exit(f["status"] == "converged" ? 0 : 2);
    }
    close(fd[1]);
    fcntl(fd[0], F_SETFL, fcntl(fd[0], F_GETFL) | O_NONBLOCK);
    std::string buf;
    char tmp[4096];
    const double t0 = wall_seconds();
    int status = 0;
    bool done = false;
    // Read while waiting, so that a large report cannot block the child.
    while (true) {
        const ssize_t n = read(fd[0], tmp, sizeof(tmp));
        if (n > 0) {
            buf.append(tmp, static_cast<size_t>(n));
            continue;
        }
        const pid_t w = waitpid(pid, &status, WNOHANG);
        if (w == pid) {
            done = true;
            while (true) {
                const ssize_t m = read(fd[0], tmp, sizeof(tmp));
                if (m <= 0) break;
                buf.append(tmp, static_cast<size_t>(m));
            }
            break;
        }
        if (wall_seconds() - t0 > seconds) break;
        usleep(20000);
    }
    close(fd[0]);
    Fields f;
    if (!done) {
        kill(pid, SIGKILL);
        waitpid(pid, &status, 0);
        f["status"] = "timeout";
        f["diagnosis"] = "killed after " + num(seconds) + " s";
        return f;
    }
    std::istringstream in(buf);
    std::string line;
    while (std::getline(in, line)) {
        const auto eq = line.find('=');
        if (eq != std::string::npos) f[line.substr(0, eq)] = line.substr(eq + 1);
    }
    if (WIFSIGNALED(status)) {
        f["status"] = "crash";
        f["diagnosis"] = std::string("signal ") + strsignal(WTERMSIG(status));
    }
    f["exit"] = std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1);
    return f;
}

int study_extremes(const ExtremesOptions& opt, std::ostream& os) {
    MLC_CHECK(opt.levels >= 0 && opt.levels <= 6, "--levels must lie in [0, 6]");
    MLC_CHECK(opt.seconds_per_case > 0, "--seconds must be positive");
    const auto dir = opt.out.empty() ? std::filesystem::path("out/studies/extremes") : opt.out;
    std::filesystem::create_directories(dir);
    // The solvers: the one asked for, or each the default may choose.
    std::vector<levels::SolverPlan> solvers;
    levels::Problem sq = square();
    sq.levels = opt.levels;
    if (opt.linear || opt.krylov || opt.pc || opt.linear_rel_tol) {
        levels::SolverRequest req;
        if (opt.linear) req.linear = mlc::solvers::parse_method(*opt.linear);
        if (opt.krylov) req.krylov = mlc::solvers::parse_krylov(*opt.krylov);
        if (opt.pc) req.pc = mlc::solvers::parse_pc(*opt.pc);
        req.rel_tol = opt.linear_rel_tol;
        solvers.push_back(levels::plan_solver(sq, req));
    } else {
        solvers.push_back(levels::plan_solver(sq, {.linear = mlc::solvers::Method::schur}));
        if (opt.levels >= 1) {
            // What the default takes above its crossover: BiCGStab + mg's V(0,2) cycle (one
            // body) and the same damped (with a two-body pair, as in the contrast cases); from
            // level 4 on both with the lattice sweep, on levels numbered for it.
            const bool lattice = opt.levels >= levels::kMgDefaultLatticeLevel;
            for (const bool two_body : {false, true})
                solvers.push_back(
                    levels::plan_solver(sq, {.krylov = levels::kMgDefaultKrylov,
                                             .pc = levels::default_mg(two_body, lattice)}));
        }
    }
    os << "stability study: square-based cases on levels 0.." << opt.levels << " (coarse-to-fine), "
       << opt.seconds_per_case << " s per case, " << solvers.size() << " Newton-system solver(s)\n";
    AtomicOfstream csv(dir / "extremes.csv");
    csv << "solver,case,description,result,exit,newton,krylov,krylov_per_newton,residual,"
           "penetration,coulomb,balance,seconds,notes\n";
    toml::array jrows;
    bool bad = false;
    for (const auto& solver : solvers) {
        std::ostringstream sname;
        sname << solver.spec;
        os << "\nsolver: " << sname.str() << "\n";
        os << std::left << std::setw(26) << "case" << std::setw(11) << "result" << std::setw(6)
           << "exit" << std::setw(9) << "newton" << std::setw(11) << "residual" << std::setw(12)
           << "penetration" << std::setw(10) << "Coulomb" << std::setw(10) << "balance"
           << std::setw(9) << "seconds" << std::setw(12) << "krylov/newt"
           << "notes\n"
           << std::right << std::flush;
        for (const auto& c : make_cases()) {
            if (!opt.only.empty() && c.name.find(opt.only) == std::string::npos) continue;
            Fields f =
                run_isolated([&] { return c.run(opt.levels, solver.spec); }, opt.seconds_per_case);
            auto get = [&](const std::string& k) { return f.count(k) ? f[k] : std::string("-"); };
            std::string notes = get("diagnosis") == "-" ? "" : get("diagnosis");
            if (f.count("statuses"))
                notes += (notes.empty() ? "" : "; ") + std::string("g/st/s+/s- ") + f["statuses"];
            if (f.count("cycling"))
                notes += (notes.empty() ? "" : "; ") + std::string("status cycling, damped");
            if (f.count("fallbacks"))
                notes += (notes.empty() ? "" : "; ") + f["fallbacks"] +
                         " Newton system(s) solved by the exact fallback";
            if (f.count("continuations"))
                notes += (notes.empty() ? "" : "; ") + f["continuations"] +
                         " level step(s) recovered by r continuation";
            if (f.count("block_sweep"))
                notes += (notes.empty() ? "" : "; ") + std::string("level ") + f["block_sweep"] +
                         ": the block sweep (lattices need level 4)";
            if (f.count("unit_diff_u"))
                notes += "rel. diff u " + f["unit_diff_u"] + ", lambda " + f["unit_diff_lambda"];
            os << std::left << std::setw(26) << c.name << std::setw(11) << get("status")
               << std::setw(6) << get("exit") << std::setw(9) << get("newton") << std::setw(11)
               << get("residual") << std::setw(12) << get("penetration") << std::setw(10)
               << get("coulomb") << std::setw(10) << get("balance") << std::setw(9)
               << get("seconds") << std::setw(12) << get("krylov_per_newton") << notes << std::right
               << "\n"
               << std::flush;
            csv << '"' << sname.str() << "\",\"" << c.name << "\",\"" << c.what << "\","
                << get("status") << "," << get("exit") << "," << get("newton") << ","
                << get("krylov") << "," << get("krylov_per_newton") << "," << get("residual") << ","
                << get("penetration") << "," << get("coulomb") << "," << get("balance") << ","
                << get("seconds") << ",\"" << notes << "\"\n";
            toml::table row;
            row.insert("solver", sname.str());
            row.insert("case", c.name);
            row.insert("description", c.what);
            for (const auto& [k, v] : f)
                row.insert(k, v);
            jrows.push_back(row);
            const std::string st = get("status");
            bad = bad || st == "crash" || st == "timeout" || st == "NaN" || st == "error";
        }
    }
    toml::table root;
    root.insert("levels", static_cast<int64_t>(opt.levels));
    root.insert("cases", jrows);
    AtomicOfstream js(dir / "extremes.json");
    js << toml::json_formatter{root} << "\n";
    os << "\nwrote " << (dir / "extremes.csv").string() << ", extremes.json\n";
    return bad ? 3 : 0;
}

} // namespace mlc::apps

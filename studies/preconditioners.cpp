// SPDX-License-Identifier: MIT
// Preconditioner study (issue: the papers' Krylov solvers and preconditioners).
#include "studies/preconditioners.hpp"

#include "run/preconditioners.hpp"

#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "levels/solve.hpp"
#include "run/plot_script.hpp"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <functional>
#include <iomanip>
#include <sstream>
#include <sys/wait.h>
#include <toml++/toml.h>
#include <unistd.h>

namespace mlc::apps {

namespace {

/// One (level) row of a run.
struct LevelRow {
    int level = 0;
    Index unknowns = 0;
    int newton = 0;
    double krylov_mean = 0, krylov_max = 0;
    double seconds_per_newton = 0, setup_seconds = 0, total_seconds = 0;
};

/// Runs one combination in this process; returns text lines "level ..." or "fail ...".
std::string run_combination(const levels::Problem& base, const PreconditionerStudyOptions& opt,
                            const std::string& krylov, const std::string& pc, double mu, double rf,
                            int finest) {
    levels::Problem p = base;
    p.levels = finest;
    if (opt.load_steps > 0) p.load_steps = opt.load_steps;
    for (auto& c : p.contacts) {
        c.mu = mu;
        c.r = rf * p.min_young_modulus(); // as the scene default r_over_E
    }
    levels::SolveOptions so;
    so.coarse_to_fine = true;
    so.linear = {.method = solvers::Method::krylov,
                 .krylov = solvers::parse_krylov(krylov),
                 .pc = solvers::parse_pc(pc),
                 .rel_tol = opt.rel_tol,
                 .max_iter = opt.max_iter};
    std::ostringstream out;
    out << std::setprecision(6);
    const levels::RunResult r = levels::solve(p, so);
    // Only the finest level's row: each level is its own bounded run (coarse-to-fine from level
    // 0), so a level that fails or runs out of time does not hide the levels below it.
    for (size_t l = static_cast<size_t>(finest); l < r.level_steps.size(); ++l) {
        LevelRow row;
        row.level = static_cast<int>(l);
        row.unknowns = r.levels()[l].n_unknowns();
        // This level's verdict: every load step solved and converged here. A run stops at the
        // first failure (a load step visits levels 0..L in turn), so the levels above the failing
        // one have fewer steps, possibly none.
        int steps_ok = 0;
        for (const auto& st : r.level_steps[l])
            steps_ok += st.report.converged;
        const int steps_run = static_cast<int>(r.level_steps[l].size());
        const int verdict = steps_ok == p.load_steps ? 1
                            : steps_run == 0         ? 2
                            : steps_ok == steps_run  ? 3 // every step it ran converged
                                                     : 0;
        std::vector<int> its;
        double lin_s = 0, setup = 0, total = 0;
        for (const auto& st : r.level_steps[l]) {
            row.newton += st.report.iterations;
            its.insert(its.end(), st.report.linear_iterations_per_newton.begin(),
                       st.report.linear_iterations_per_newton.end());
            lin_s += st.report.linear_seconds;
            setup += st.report.linear_setup_seconds;
            total += st.report.seconds;
        }
        if (!its.empty()) {
            double sum = 0;
            for (int i : its)
                sum += i;
            row.krylov_mean = sum / static_cast<double>(its.size());
            row.krylov_max = *std::max_element(its.begin(), its.end());
            row.seconds_per_newton = lin_s / static_cast<double>(its.size());
        }
        out << "level " << row.level << " " << row.unknowns << " " << row.newton << " "
            << row.krylov_mean << " " << row.krylov_max << " " << row.seconds_per_newton << " "
            << setup << " " << total << " " << verdict << "\n";
    }
    if (!r.converged) {
        std::string f = r.failure;
        std::replace(f.begin(), f.end(), '\n', ' ');
        out << "fail " << f << "\n";
    }
    return out.str();
}

/// Forks, runs, waits with a time bound; returns the child's text or a "fail" line.
std::string run_bounded(const std::function<std::string()>& job, double seconds) {
    std::fflush(nullptr);
    int fd[2];
    if (pipe(fd) != 0) return "fail pipe\n";
    const pid_t pid = fork();
    if (pid == 0) {
        close(fd[0]);
        std::string s;
        try {
            s = job();
        } catch (const std::exception& e) {
            s = std::string("fail ") + e.what() + "\n";
        }
        ssize_t w = write(fd[1], s.data(), s.size());
        (void)w;
        close(fd[1]);
        _exit(0);
    }
    close(fd[1]);
    fcntl(fd[0], F_SETFL, fcntl(fd[0], F_GETFL) | O_NONBLOCK);
    std::string buf;
    char tmp[4096];
    const double t0 = wall_seconds();
    int status = 0;
    for (;;) {
        const ssize_t n = read(fd[0], tmp, sizeof(tmp));
        if (n > 0) {
            buf.append(tmp, static_cast<size_t>(n));
            continue;
        }
        if (waitpid(pid, &status, WNOHANG) == pid) {
            for (ssize_t m; (m = read(fd[0], tmp, sizeof(tmp))) > 0;)
                buf.append(tmp, static_cast<size_t>(m));
            close(fd[0]);
            if (WIFSIGNALED(status))
                buf += std::string("fail crashed: signal ") + strsignal(WTERMSIG(status)) + "\n";
            return buf;
        }
        if (wall_seconds() - t0 > seconds) {
            kill(pid, SIGKILL);
            waitpid(pid, &status, 0);
            close(fd[0]);
            std::ostringstream os;
            os << "fail time bound of " << seconds << " s reached\n";
            return buf + os.str();
        }
        usleep(20000);
    }
}

/// The 1997 paper's square test (mu = 0.1, r = 0.1 E): unknowns and CPU seconds per Newton
/// iteration (their machine), formulation.md §6.
struct PaperPoint {
    const char* pc;
    double unknowns;
    double seconds; ///< < 0: "no conv"
};
constexpr PaperPoint kPaper[] = {{"ebe", 220, 1.8},     {"ebe", 780, 7.6},   {"ebe", 2620, 33.3},
                                 {"ebe", 7980, 164},    {"ebe", 23200, 414}, {"ilu", 220, 0.73},
                                 {"ilu", 780, 4.4},     {"ilu", 2620, 25.6}, {"ilu", 7980, 123},
                                 {"ilu", 23200, 343.5}, {"diag", 220, 1.3},  {"diag", 780, 8.2},
                                 {"diag", 2620, 50},    {"diag", 7980, 425}, {"diag", 23200, -1}};

/// The "level ..." lines of a combination's output (their text after "level "), and in
/// `failure` its "fail ..." line's text.
std::vector<std::string> level_lines(const std::string& text, std::string& failure) {
    std::istringstream in(text);
    std::string line;
    std::vector<std::string> lines;
    while (std::getline(in, line)) {
        if (line.rfind("fail ", 0) == 0)
            failure = line.substr(5);
        else if (line.rfind("level ", 0) == 0)
            lines.push_back(line.substr(6));
    }
    return lines;
}

} // namespace

int study_preconditioners(const levels::Problem& problem, const PreconditionerStudyOptions& opt,
                          std::ostream& os) {
    MLC_CHECK(opt.levels >= 1 && opt.levels <= 6, "--levels must lie in [1, 6]");
    MLC_CHECK(!opt.pcs.empty() && !opt.krylovs.empty() && !opt.mu.empty() && !opt.r_over_E.empty(),
              "empty preconditioner, Krylov, mu or r list");
    check_preconditioner_names(opt.pcs);
    for (double m : opt.mu)
        MLC_CHECK(m >= 0, "--mu values must be >= 0, found " << m);
    for (double r : opt.r_over_E)
        MLC_CHECK(r > 0, "--r values must be > 0, found " << r);
    const auto dir =
        opt.out.empty() ? std::filesystem::path("out/studies") / (problem.name + "_preconditioners")
                        : opt.out;
    std::filesystem::create_directories(dir);
    os << "preconditioner study: scene '" << problem.name << "', levels 1.." << opt.levels
       << " (coarse-to-fine; level 0 exact), Krylov rel_tol " << opt.rel_tol << ", max "
       << opt.max_iter << " iterations per Newton step\n\n";
    os << std::left << std::setw(8) << "krylov" << std::setw(16) << "pc" << std::right
       << std::setw(6) << "mu" << std::setw(8) << "r/E" << std::setw(7) << "level" << std::setw(10)
       << "unknowns" << std::setw(8) << "newton" << std::setw(11) << "its/newton" << std::setw(8)
       << "max" << std::setw(12) << "s/newton" << std::setw(10) << "setup s" << std::setw(10)
       << "total s"
       << "  result\n"
       << std::flush;
    AtomicOfstream csv(dir / "preconditioners.csv");
    csv << "krylov,pc,mu,r_over_E,level,unknowns,newton,krylov_per_newton_mean,krylov_per_newton_"
           "max,"
           "seconds_per_newton,setup_seconds,total_seconds,result\n";
    toml::array jr;
    for (const auto& kr : opt.krylovs)
        for (const auto& pc : opt.pcs)
            for (double mu : opt.mu)
                for (double rf : opt.r_over_E) {
                    // Levels 1..L, each its own run; after a level fails, the finer ones are not
                    // run (they repeat the failing level first). The lattice sweep runs from
                    // level 4 (below it the option is refused: those levels are not run).
                    bool stop = false;
                    const int first = solvers::parse_pc(pc).lattice_numbering()
                                          ? std::min(opt.levels, levels::kMgDefaultLatticeLevel)
                                          : 1;
                    if (first > 1)
                        os << pc << ": levels 1-" << first - 1
                           << " not run (smoother=lattice sweeps levels 4 and finer)\n";
                    for (int finest = first; finest <= opt.levels && !stop; ++finest) {
                        const std::string text = run_bounded(
                            [&] { return run_combination(problem, opt, kr, pc, mu, rf, finest); },
                            opt.seconds_per_run);
                        std::string failure;
                        const std::vector<std::string> lines = level_lines(text, failure);
                        for (size_t k = 0; k < lines.size(); ++k) {
                            std::istringstream ls(lines[k]);
                            LevelRow row;
                            int verdict = 0;
                            ls >> row.level >> row.unknowns >> row.newton >> row.krylov_mean >>
                                row.krylov_max >> row.seconds_per_newton >> row.setup_seconds >>
                                row.total_seconds >> verdict;
                            // converged: every load step on this level; no conv: this level failed;
                            // stopped: the steps it ran converged, but another level failed and the
                            // run stopped; not reached: a level below failed first (nothing
                            // measured).
                            const std::string result = verdict == 1   ? "converged"
                                                       : verdict == 2 ? "not reached"
                                                       : verdict == 3 ? "stopped"
                                                                      : "no conv";
                            os << std::left << std::setw(8) << kr << std::setw(16) << pc
                               << std::right << std::setw(6) << mu << std::setw(8) << rf
                               << std::setw(7) << row.level << std::setw(10) << row.unknowns
                               << std::setw(8) << row.newton << std::setw(11) << std::fixed
                               << std::setprecision(1) << row.krylov_mean << std::setw(8)
                               << std::setprecision(0) << row.krylov_max << std::setw(12)
                               << std::setprecision(4) << row.seconds_per_newton << std::setw(10)
                               << std::setprecision(3) << row.setup_seconds << std::setw(10)
                               << row.total_seconds << std::defaultfloat << "  " << result << "\n";
                            csv << kr << ",\"" << pc << "\"," << mu << "," << rf << "," << row.level
                                << "," << row.unknowns << "," << row.newton << ","
                                << row.krylov_mean << "," << row.krylov_max << ","
                                << row.seconds_per_newton << "," << row.setup_seconds << ","
                                << row.total_seconds << "," << result << "\n";
                            toml::table t;
                            t.insert("krylov", kr);
                            t.insert("pc", pc);
                            t.insert("mu", mu);
                            t.insert("r_over_E", rf);
                            t.insert("level", static_cast<int64_t>(row.level));
                            t.insert("unknowns", static_cast<int64_t>(row.unknowns));
                            t.insert("newton", static_cast<int64_t>(row.newton));
                            t.insert("krylov_per_newton_mean", row.krylov_mean);
                            t.insert("krylov_per_newton_max", row.krylov_max);
                            t.insert("seconds_per_newton", row.seconds_per_newton);
                            t.insert("setup_seconds", row.setup_seconds);
                            t.insert("total_seconds", row.total_seconds);
                            t.insert("result", result);
                            jr.push_back(t);
                        }
                        if (!failure.empty()) {
                            stop = true;
                            os << "        " << kr << " + " << pc << " (mu " << mu << ", r/E " << rf
                               << ", levels 0.." << finest << "): " << failure.substr(0, 300);
                            if (finest < opt.levels)
                                os << "; levels above " << finest << " not run";
                            os << "\n";
                            if (lines.empty()) {
                                csv << kr << ",\"" << pc << "\"," << mu << "," << rf << ","
                                    << finest << ",,,,,,,,\"" << failure.substr(0, 200) << "\"\n";
                                toml::table t;
                                t.insert("krylov", kr);
                                t.insert("pc", pc);
                                t.insert("mu", mu);
                                t.insert("r_over_E", rf);
                                t.insert("level", static_cast<int64_t>(finest));
                                t.insert("result", failure);
                                jr.push_back(t);
                            }
                        }
                        os << std::flush;
                    }
                }
    // The paper's numbers, for the plot and the table.
    AtomicOfstream pp(dir / "paper_1997_square.csv");
    pp << "pc,unknowns,seconds_per_newton\n";
    for (const auto& p : kPaper)
        pp << p.pc << "," << p.unknowns << "," << p.seconds << "\n";
    os << "\n1997 paper, square test (mu = 0.1, r = 0.1 E), CPU s per Newton iteration on their "
          "machine:\n"
          "  unknowns   220    780    2620   7980   23200\n"
          "  EBE        1.8    7.6    33.3   164    414\n"
          "  ILU        0.73   4.4    25.6   123    343.5\n"
          "  DIAG       1.3    8.2    50     425    no conv\n"
          "  (dovetail, mu = 0.3: CGS iterations per Newton step EBE 287 / ILU 268 at 2362 nodes,\n"
          "   EBE 740.4 / ILU 884.2 at 14354 nodes)\n";
    toml::table root;
    root.insert("scene", problem.name);
    root.insert("runs", jr);
    AtomicOfstream js(dir / "preconditioners.json");
    js << toml::json_formatter{root} << "\n";
    csv.close();
    js.close();
    pp.close();
    os << "wrote " << (dir / "preconditioners.csv").string()
       << ", preconditioners.json, paper_1997_square.csv\n";
    if (opt.plot && run_plot_script("plot_preconditioners.py", dir, os))
        os << "wrote " << (dir / "preconditioners.png").string() << "\n";
    return 0;
}

} // namespace mlc::apps

// SPDX-License-Identifier: MIT
// The preconditioner study over process counts: `mlcontact run` launched on
// N = 1, 2, 4, ... processes per preconditioner and level, each run's iterations.csv read back.
#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "core/timer.hpp"
#include "levels/distributed_solve.hpp"
#include "run/plot_script.hpp"
#include "run/preconditioners.hpp"
#include "studies/preconditioners.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <sys/wait.h>
#include <tuple>
#include <unistd.h>

namespace mlc::apps {

namespace {

/// `name` on PATH (an executable file), or empty.
std::string find_on_path(const std::string& name) {
    const char* path = std::getenv("PATH");
    if (!path) return {};
    std::istringstream in(path);
    std::string dir;
    while (std::getline(in, dir, ':')) {
        if (dir.empty()) continue;
        const std::filesystem::path f = std::filesystem::path(dir) / name;
        if (::access(f.c_str(), X_OK) == 0 && std::filesystem::is_regular_file(f)) return f;
    }
    return {};
}

/// The first line `cmd` prints (stdout and stderr), or empty.
std::string first_output_line(const std::string& cmd) {
    FILE* f = ::popen((cmd + " 2>&1").c_str(), "r");
    if (!f) return {};
    char buf[512];
    std::string line;
    if (std::fgets(buf, sizeof buf, f)) line = buf;
    while (std::fgets(buf, sizeof buf, f)) {
    }
    ::pclose(f);
    return line;
}

/// The launcher's words: opt.mpiexec split at spaces, or mpiexec / mpirun from PATH (with
/// --oversubscribe for Open MPI, which otherwise refuses more processes than cores).
std::vector<std::string> launcher(const std::string& given) {
    std::vector<std::string> words;
    if (!given.empty()) {
        std::istringstream in(given);
        for (std::string w; in >> w;)
            words.push_back(w);
        MLC_CHECK(!words.empty(), "--mpiexec is empty");
        return words;
    }
    std::string exe = find_on_path("mpiexec");
    if (exe.empty()) exe = find_on_path("mpirun");
    MLC_CHECK(!exe.empty(),
              "study preconditioners --np-list: a process count above 1 needs an MPI launcher, "
              "and neither mpiexec nor mpirun is on PATH; install Open MPI (Debian "
              "openmpi-bin), give one with --mpiexec PATH, or use --np-list 1");
    words.push_back(exe);
    // Open MPI's launchers say "mpirun (Open MPI) 4.1.4" or "mpiexec (OpenRTE) 4.1.4".
    const std::string v = first_output_line("'" + exe + "' --version");
    if (v.find("Open MPI") != std::string::npos || v.find("OpenRTE") != std::string::npos)
        words.push_back("--oversubscribe");
    return words;
}

/// How a child run ended.
struct ChildEnd {
    int exit_code = -1; ///< when it exited
    int signal = 0;     ///< when a signal ended it
    bool timed_out = false;
    double seconds = 0;
};

/// Runs argv with stdout and stderr into `log`, in its own process group, one thread per process
/// (OMP_NUM_THREADS=1; one process also without an MPI launcher: a singleton); after `seconds` the
/// group gets SIGTERM (mpirun passes it on), then SIGKILL.
ChildEnd run_child(const std::vector<std::string>& argv, const std::filesystem::path& log,
                   double seconds) {
    std::fflush(nullptr);
    const pid_t pid = ::fork();
    MLC_CHECK(pid >= 0, "fork failed: " << std::strerror(errno));
    if (pid == 0) {
        ::setpgid(0, 0);
        // No terminal input: a launcher reading it in a background job would be stopped.
        if (const int in = ::open("/dev/null", O_RDONLY); in >= 0) {
            ::dup2(in, 0);
            ::close(in);
        }
        const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd >= 0) {
            ::dup2(fd, 1);
            ::dup2(fd, 2);
            ::close(fd);
        }
        ::setenv("OMP_NUM_THREADS", "1", 1);
        ::setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
        std::vector<char*> args;
        for (const auto& a : argv)
            args.push_back(const_cast<char*>(a.c_str()));
        args.push_back(nullptr);
        ::execvp(args[0], args.data());
        std::fprintf(stderr, "mlcontact: error: cannot start %s: %s\n", args[0],
                     std::strerror(errno));
        ::_exit(127);
    }
    ::setpgid(pid, pid); // also here: no race with the kill below
    ChildEnd end;
    const double t0 = wall_seconds();
    int status = 0;
    double term_at = -1;
    for (;;) {
        const pid_t w = ::waitpid(pid, &status, WNOHANG);
        if (w == pid) break;
        const double t = wall_seconds() - t0;
        if (t > seconds && term_at < 0) {
            end.timed_out = true;
            ::kill(-pid, SIGTERM);
            term_at = t;
        } else if (term_at >= 0 && t > term_at + 5) {
            ::kill(-pid, SIGKILL);
            ::waitpid(pid, &status, 0);
            break;
        }
        ::usleep(20000);
    }
    end.seconds = wall_seconds() - t0;
    if (WIFEXITED(status)) end.exit_code = WEXITSTATUS(status);
    if (WIFSIGNALED(status)) end.signal = WTERMSIG(status);
    return end;
}

/// The last error line of a run's log ("mlcontact: error...", "error: ..."), or its last line.
std::string failure_reason(const std::filesystem::path& log) {
    std::ifstream in(log);
    std::string line, last, error;
    while (std::getline(in, line)) {
        if (line.empty()) continue;
        last = line;
        if (line.rfind("error: ", 0) == 0 || line.rfind("mlcontact: error", 0) == 0 ||
            line.rfind("mlcontact: numerical breakdown", 0) == 0)
            error = line;
    }
    std::string r = error.empty() ? last : error;
    std::replace(r.begin(), r.end(), '"', '\'');
    return r.substr(0, 300);
}

/// One cell of the table.
struct Cell {
    std::string krylov, pc;
    double mu = 0, rf = 0;
    int level = 0, np = 1;
    std::int64_t unknowns = 0;
    int newton = 0;
    double mean = 0, max = 0;
    bool distributed = false;
    double seconds = 0; ///< the run's wall time (oversubscribed runs: not a timing)
    std::string result; ///< converged, no conv, time bound, failed
    std::string reason;
};

/// Level `level`'s rows of iterations.csv: false when the file is missing or has none.
bool read_level(const std::filesystem::path& file, Cell& c) {
    std::ifstream in(file);
    if (!in) return false;
    std::string line;
    std::getline(in, line);
    MLC_CHECK(line == "level,unknowns,distributed,step,newton,krylov",
              file.string() << ": unexpected header '" << line << "'");
    std::vector<int> its;
    while (std::getline(in, line)) {
        std::istringstream ls(line);
        std::string f[6];
        for (auto& x : f)
            std::getline(ls, x, ',');
        if (std::stoi(f[0]) != c.level) continue;
        c.unknowns = std::stoll(f[1]);
        c.distributed = f[2] == "1";
        its.push_back(std::stoi(f[5]));
    }
    if (its.empty()) return false;
    c.newton = static_cast<int>(its.size());
    double sum = 0;
    for (int i : its)
        sum += i;
    c.mean = sum / static_cast<double>(its.size());
    c.max = *std::max_element(its.begin(), its.end());
    return true;
}

/// A folder name from a run's parameters.
std::string run_name(const Cell& c) {
    std::ostringstream os;
    os << c.krylov << "_" << c.pc << "_mu" << c.mu << "_r" << c.rf << "_L" << c.level << "_np"
       << c.np;
    std::string s = os.str();
    for (char& ch : s)
        if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '.' && ch != '-' && ch != '_')
            ch = '-';
    return s;
}

/// Runs one cell as `mlcontact run` (under the launcher `mpiexec` when c.np > 1) in its folder
/// under dir/runs, reads its iterations and prints its row.
void run_cell(Cell& c, const NpStudyScene& problem, const PreconditionerStudyOptions& opt,
              const std::filesystem::path& dir, const std::filesystem::path& self,
              const std::vector<std::string>& mpiexec, std::ostream& os) {
    const std::string& kr = c.krylov;
    const std::string& pc = c.pc;
    const double mu = c.mu, rf = c.rf;
    const int l = c.level, np = c.np;
    const auto rd = dir / "runs" / run_name(c);
    std::filesystem::remove_all(rd);
    std::filesystem::create_directories(rd);
    std::vector<std::string> argv;
    if (np > 1) {
        argv = mpiexec;
        argv.insert(argv.end(), {"-n", std::to_string(np)});
    }
    std::ostringstream r, m, t;
    r << std::setprecision(17) << rf * problem.young_modulus;
    m << std::setprecision(17) << mu;
    t << std::setprecision(17) << opt.rel_tol;
    argv.insert(argv.end(), {self.string(), "run", opt.scene_arg, "--levels", std::to_string(l),
                             "--krylov", c.krylov, "--pc", c.pc, "--linear-tol", t.str(), "--mu",
                             m.str(), "--r", r.str(), "--quiet", "--out", rd.string()});
    if (opt.load_steps > 0) argv.insert(argv.end(), {"--steps", std::to_string(opt.load_steps)});
    // 2D runs fall back to an exact solve and continue in r by default: the study measures the
    // Krylov solve alone (3D runs have neither).
    if (problem.dimension == 2) argv.insert(argv.end(), {"--no-fallback", "--no-continuation"});
    {
        std::ofstream cmd(rd / "command.txt");
        for (size_t i = 0; i < argv.size(); ++i)
            cmd << (i ? " " : "") << argv[i];
        cmd << "\n";
    }
    const ChildEnd end = run_child(argv, rd / "run.log", opt.seconds_per_run);
    c.seconds = end.seconds;
    const bool read = read_level(rd / "iterations.csv", c);
    if (end.timed_out) {
        std::ostringstream os2;
        os2 << "time bound of " << opt.seconds_per_run << " s reached";
        c.result = "time bound";
        c.reason = os2.str();
    } else if (end.exit_code == 0 && read) {
        c.result = "converged";
    } else if (end.exit_code == 2) {
        c.result = "no conv";
        c.reason = failure_reason(rd / "run.log");
    } else {
        c.result = "failed";
        std::ostringstream os2;
        if (end.signal)
            os2 << "signal " << strsignal(end.signal) << ": ";
        else
            os2 << "exit " << end.exit_code << ": ";
        os2 << failure_reason(rd / "run.log");
        c.reason = os2.str();
    }
    // Keep the small files; the VTU pieces are not needed here.
    for (const auto& e : std::filesystem::directory_iterator(rd)) {
        const auto ext = e.path().extension();
        if (ext == ".vtu" || ext == ".pvtu") std::filesystem::remove(e.path());
    }
    os << std::left << std::setw(10) << kr << std::setw(16) << pc << std::right << std::setw(6)
       << mu << std::setw(8) << rf << std::setw(7) << l << std::setw(5) << np << std::setw(10)
       << c.unknowns << std::setw(8) << c.newton << std::setw(11) << std::fixed
       << std::setprecision(1) << c.mean << std::setw(8) << std::setprecision(0) << c.max
       << std::defaultfloat << std::setprecision(6) << "  " << c.result;
    if (!c.reason.empty()) os << " (" << c.reason << ")";
    os << "\n" << std::flush;
}

/// preconditioners_np.csv and preconditioners_np.json.
void write_cells(const std::filesystem::path& dir, const std::string& scene,
                 const std::vector<int>& nps, double rel_tol, const std::vector<Cell>& cells) {
    AtomicOfstream csv(dir / "preconditioners_np.csv");
    csv << "krylov,pc,mu,r_over_E,level,processes,unknowns,level_distributed,newton,"
           "krylov_per_newton_mean,krylov_per_newton_max,result,reason\n";
    toml::array jr;
    for (const auto& c : cells) {
        csv << c.krylov << ",\"" << c.pc << "\"," << c.mu << "," << c.rf << "," << c.level << ","
            << c.np << "," << c.unknowns << "," << (c.distributed ? 1 : 0) << "," << c.newton << ","
            << std::setprecision(9) << c.mean << "," << c.max << std::setprecision(6) << ","
            << c.result << ",\"" << c.reason << "\"\n";
        toml::table t;
        t.insert("krylov", c.krylov);
        t.insert("pc", c.pc);
        t.insert("mu", c.mu);
        t.insert("r_over_E", c.rf);
        t.insert("level", static_cast<int64_t>(c.level));
        t.insert("processes", static_cast<int64_t>(c.np));
        t.insert("unknowns", static_cast<int64_t>(c.unknowns));
        t.insert("level_distributed", c.distributed);
        t.insert("newton", static_cast<int64_t>(c.newton));
        t.insert("krylov_per_newton_mean", c.mean);
        t.insert("krylov_per_newton_max", c.max);
        t.insert("result", c.result);
        if (!c.reason.empty()) t.insert("reason", c.reason);
        jr.push_back(t);
    }
    toml::table root;
    root.insert("scene", scene);
    toml::array np_arr;
    for (int n : nps)
        np_arr.push_back(static_cast<int64_t>(n));
    root.insert("processes", np_arr);
    root.insert("rel_tol", rel_tol);
    root.insert("runs", jr);
    AtomicOfstream js(dir / "preconditioners_np.json");
    js << toml::json_formatter{root} << "\n";
    csv.close();
    js.close();
}

/// The table by processes: Krylov iterations per Newton step, mean (max), on the finest level.
void print_by_processes(std::ostream& os, const std::vector<int>& nps,
                        const std::vector<Cell>& cells) {
    os << "\nKrylov iterations per Newton step on level l, mean (max), by processes N:\n"
       << std::left << std::setw(10) << "krylov" << std::setw(16) << "pc" << std::right
       << std::setw(6) << "mu" << std::setw(8) << "r/E" << std::setw(7) << "level" << std::setw(10)
       << "unknowns";
    for (int n : nps)
        os << std::setw(16) << ("N=" + std::to_string(n));
    os << "\n";
    std::map<std::tuple<std::string, std::string, double, double, int>, std::map<int, const Cell*>>
        grid;
    std::vector<std::tuple<std::string, std::string, double, double, int>> keys;
    for (const auto& c : cells) {
        const auto k = std::make_tuple(c.krylov, c.pc, c.mu, c.rf, c.level);
        if (!grid.count(k)) keys.push_back(k);
        grid[k][c.np] = &c;
    }
    for (const auto& k : keys) {
        const auto& row = grid[k];
        std::int64_t unknowns = 0;
        for (const auto& [n, c] : row)
            unknowns = std::max(unknowns, c->unknowns);
        os << std::left << std::setw(10) << std::get<0>(k) << std::setw(16) << std::get<1>(k)
           << std::right << std::setw(6) << std::get<2>(k) << std::setw(8) << std::get<3>(k)
           << std::setw(7) << std::get<4>(k) << std::setw(10) << unknowns;
        for (int n : nps) {
            const auto it = row.find(n);
            std::ostringstream v;
            if (it == row.end())
                v << "not run";
            else if (it->second->result != "converged")
                v << it->second->result;
            else
                v << std::fixed << std::setprecision(1) << it->second->mean << " ("
                  << std::setprecision(0) << it->second->max << ")";
            os << std::setw(16) << v.str();
        }
        os << "\n";
    }
}

} // namespace

int study_preconditioners_np(const levels::Problem& problem, const PreconditionerStudyOptions& opt,
                             std::ostream& os) {
    NpStudyScene scene;
    scene.name = problem.name;
    scene.young_modulus = problem.min_young_modulus();
    scene.check = [&problem](const std::string& kr, const std::string& pc, int np) {
        const levels::SolverRequest req{.krylov = solvers::parse_krylov(kr),
                                        .pc = solvers::parse_pc(pc)};
        (void)levels::plan_solver(problem, req, np);
    };
    return study_preconditioners_np(scene, opt, os);
}

int study_preconditioners_np(const NpStudyScene& problem, const PreconditionerStudyOptions& opt,
                             std::ostream& os) {
    MLC_CHECK(opt.levels >= 1 && opt.levels <= 6, "--levels must lie in [1, 6]");
    MLC_CHECK(!opt.np_list.empty(), "--np-list is empty");
    MLC_CHECK(!opt.pcs.empty() && !opt.krylovs.empty() && !opt.mu.empty() && !opt.r_over_E.empty(),
              "empty preconditioner, Krylov, mu or r list");
    MLC_CHECK(opt.max_iter == levels::LinearSolverSpec{}.max_iter,
              "--max-iter has no effect with --np-list: each cell is an `mlcontact run`, whose "
              "Krylov limit is "
                  << levels::LinearSolverSpec{}.max_iter);
    MLC_CHECK(opt.seconds_per_run > 0, "--seconds must be > 0");
    check_preconditioner_names(opt.pcs);
    for (double m : opt.mu)
        MLC_CHECK(m >= 0, "--mu values must be >= 0, found " << m);
    for (double r : opt.r_over_E)
        MLC_CHECK(r > 0, "--r values must be > 0, found " << r);
    std::vector<int> nps = opt.np_list;
    for (int n : nps)
        MLC_CHECK(n >= 1 && n <= 1024, "--np-list values must lie in [1, 1024], found " << n);
    std::sort(nps.begin(), nps.end());
    nps.erase(std::unique(nps.begin(), nps.end()), nps.end());
    std::vector<std::string> mpiexec;
    if (nps.back() > 1 || problem.dimension == 3) {
        // What has no distributed form (or no 3D form) is refused before anything runs (the
        // run's own message).
        for (const auto& kr : opt.krylovs)
            for (const auto& pc : opt.pcs)
                problem.check(kr, pc, nps.back());
        if (nps.back() > 1) mpiexec = launcher(opt.mpiexec);
    }
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe");
    const auto dir = opt.out.empty() ? std::filesystem::path("out/studies") /
                                           (problem.name + "_preconditioners_np")
                                     : opt.out;
    std::filesystem::create_directories(dir / "runs");

    os << "preconditioner study over processes: scene '" << problem.name << "', levels 1.."
       << opt.levels << " (one run per finest level l, coarse-to-fine; level l distributed when "
       << "N > 1), N =";
    for (int n : nps)
        os << " " << n;
    os << ", Krylov rel_tol " << opt.rel_tol << ", max " << opt.max_iter
       << " iterations per Newton step, one thread per process";
    if (!mpiexec.empty()) {
        os << ", launcher '";
        for (size_t i = 0; i < mpiexec.size(); ++i)
            os << (i ? " " : "") << mpiexec[i];
        os << " -n N'";
    }
    os << "\n\n"
       << std::left << std::setw(10) << "krylov" << std::setw(16) << "pc" << std::right
       << std::setw(6) << "mu" << std::setw(8) << "r/E" << std::setw(7) << "level" << std::setw(5)
       << "N" << std::setw(10) << "unknowns" << std::setw(8) << "newton" << std::setw(11)
       << "its/newton" << std::setw(8) << "max"
       << "  result\n"
       << std::flush;

    std::vector<Cell> cells;
    for (const auto& kr : opt.krylovs)
        for (const auto& pc : opt.pcs)
            for (double mu : opt.mu)
                for (double rf : opt.r_over_E)
                    for (int np : nps)
                        for (int l = 1; l <= opt.levels; ++l) {
                            Cell c;
                            c.krylov = kr;
                            c.pc = pc;
                            c.mu = mu;
                            c.rf = rf;
                            c.level = l;
                            c.np = np;
                            run_cell(c, problem, opt, dir, self, mpiexec, os);
                            cells.push_back(c);
                            if (c.result != "converged") {
                                if (l < opt.levels)
                                    os << "        levels above " << l << " not run for " << pc
                                       << " on " << np << " process(es)\n";
                                break;
                            }
                        }

    write_cells(dir, problem.name, nps, opt.rel_tol, cells);

    print_by_processes(os, nps, cells);
    os << "wrote " << (dir / "preconditioners_np.csv").string()
       << ", preconditioners_np.json, runs/\n";
    if (opt.plot && run_plot_script("plot_preconditioners_np.py", dir, os))
        os << "wrote " << (dir / "preconditioners_np.png").string() << "\n";
    return 0;
}

} // namespace mlc::apps

// SPDX-License-Identifier: MIT
// The plotting scripts: where they are, and running one.
#include "run/plot_script.hpp"

#include <dlfcn.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace mlc::apps {

namespace {

// The first share/mlcontact/plots in `from`'s folder or a folder above it.
std::filesystem::path plots_above(const std::filesystem::path& from) {
    std::error_code ec;
    std::filesystem::path dir = std::filesystem::weakly_canonical(from, ec).parent_path();
    for (; !dir.empty(); dir = dir.parent_path()) {
        const std::filesystem::path p = dir / "share" / "mlcontact" / "plots";
        if (std::filesystem::is_directory(p, ec)) return p;
        if (dir == dir.root_path()) break;
    }
    return {};
}

} // namespace

std::filesystem::path plot_script_dir() {
    if (const char* env = std::getenv("MLC_PLOT_DIR"); env && *env) return env;
    Dl_info info{};
    if (::dladdr(reinterpret_cast<void*>(&plot_script_dir), &info) != 0 && info.dli_fname &&
        *info.dli_fname)
        if (auto p = plots_above(info.dli_fname); !p.empty()) return p;
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    return ec ? std::filesystem::path() : plots_above(exe);
}

bool run_plot_script(const std::string& script, const std::filesystem::path& dir, std::ostream& os,
                     const std::string& extra, std::string* cause) {
    const std::filesystem::path plots = plot_script_dir();
    const std::filesystem::path path = plots / script;
    if (plots.empty() || !std::filesystem::exists(path)) {
        const std::string why =
            (plots.empty() ? script + " not found: no share/mlcontact/plots above the program"
                           : path.string() + " not found") +
            " (install the program, or set MLC_PLOT_DIR to the folder of the plot scripts)";
        os << "plot: " << why << "\n";
        if (cause) *cause = why;
        return false;
    }
    // Debian's interpreter has python3-matplotlib; a python3 earlier on PATH may not.
    const std::string py =
        std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
    auto quoted = [](const std::string& s) {
        std::string q = "'";
        for (char c : s)
            q += c == '\'' ? std::string("'\\''") : std::string(1, c);
        return q + "'";
    };
    const std::string cmd = py + " " + quoted(path.string()) + " " + quoted(dir.string()) +
                            (extra.empty() ? "" : " " + extra);
    os << std::flush;
    std::string output;
    int rc = -1;
    if (std::FILE* pipe = ::popen((cmd + " 2>&1").c_str(), "r")) {
        char buf[4096];
        size_t n = 0;
        while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0)
            output.append(buf, n);
        rc = ::pclose(pipe);
    }
    if (rc == 0) {
        os << output;
        return true;
    }
    // The script's last line says what went wrong (a Python exception's type and message).
    std::string last;
    {
        std::istringstream in(output);
        for (std::string line; std::getline(in, line);)
            if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
    }
    const std::string why =
        "'" + cmd + "' failed (" +
        (rc == -1        ? std::string("could not be started")
         : WIFEXITED(rc) ? "exit " + std::to_string(WEXITSTATUS(rc))
                         : "signal " + std::to_string(WTERMSIG(rc))) +
        ")" + (last.empty() ? std::string() : ": " + last.substr(last.find_first_not_of(" \t")));
    os << output << "plot: " << why << "\n";
    if (cause) *cause = why;
    return false;
}

} // namespace mlc::apps

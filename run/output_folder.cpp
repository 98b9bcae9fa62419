// SPDX-License-Identifier: MIT
// The output folder of a run: its lock, the summary.json of a run in progress or stopped.
#include "run/output.hpp"
#include "run/summary_json.hpp"

#include "core/atomic_file.hpp"
#include "core/check.hpp"
#include "core/memory.hpp"
#include "core/parallel.hpp"
#include "levels/checks.hpp"
#include "mesh/io/vtu.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <sys/file.h>
#include <sys/stat.h>
#include <toml++/toml.h>
#include <unistd.h>

namespace mlc::apps {

namespace {

/// A name the driver writes into an output folder (the only names begin_writing removes).
bool driver_file_name(const std::string& n) {
    if (n.empty() || n.find('/') != std::string::npos || n[0] == '.') return false;
    const bool ours_prefix = n.rfind("solution", 0) == 0 || n.rfind("contact", 0) == 0 ||
                             n == "iterations.csv" || n == "summary.json";
    const bool ours_suffix = n.ends_with(".vtu") || n.ends_with(".pvtu") || n.ends_with(".pvd") ||
                             n.ends_with(".csv") || n.ends_with(".png") || n.ends_with(".json");
    return ours_prefix && ours_suffix;
}

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        if (static_cast<unsigned char>(c) < 0x20) {
            out += ' ';
            continue;
        }
        out += c;
    }
    return out + "\"";
}

/// The earlier run's summary.json: whether it says "complete": true, and its "files" (read as
/// write_summary formats it; anything else reads as not complete).
bool read_complete_summary(const std::filesystem::path& file, std::vector<std::string>& files) {
    std::ifstream in(file);
    if (!in) return false;
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string t = ss.str();
    auto value_at = [&](const std::string& key) -> size_t {
        const size_t k = t.find("\"" + key + "\"");
        if (k == std::string::npos) return std::string::npos;
        size_t i = k + key.size() + 2;
        while (i < t.size() && (t[i] == ' ' || t[i] == ':' || t[i] == '\n' || t[i] == '\t'))
            ++i;
        return i;
    };
    const size_t c = value_at("complete");
    if (c == std::string::npos || t.compare(c, 4, "true") != 0) return false;
    const size_t f = value_at("files");
    if (f == std::string::npos || f >= t.size() || t[f] != '[') return false;
    const size_t end = t.find(']', f);
    if (end == std::string::npos) return false;
    for (size_t i = f; i < end; ++i) {
        if (t[i] != '"') continue;
        const size_t q = t.find('"', i + 1);
        if (q == std::string::npos || q > end) break;
        files.push_back(t.substr(i + 1, q - i - 1));
        i = q;
    }
    return true;
}

[[noreturn]] void folder_error(const std::filesystem::path& dir, const std::string& what) {
    throw InvalidInput("the output folder '" + dir.string() + "' " + what);
}

} // namespace

std::string in_progress_summary(const std::string& scene) {
    return "{\n    \"complete\": false,\n    \"scene\": " + json_string(scene) +
           ",\n    \"stopped\": false,\n    \"pid\": " + std::to_string(::getpid()) +
           ",\n    \"note\": \"being written by process " + std::to_string(::getpid()) +
           "; a run that ended without completing this folder leaves it so\"\n}\n";
}

std::string killed_summary(const std::string& scene, int sig, int processes) {
    const char* name = sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : "a signal";
    return "{\n    \"complete\": false,\n    \"scene\": " + json_string(scene) +
           ",\n    \"converged\": false,\n    \"stopped\": true,\n    \"stopped_at\": " +
           json_string(std::string("ended at once by ") + name +
                       (processes > 1
                            ? " under mpirun (" + std::to_string(processes) + " processes)"
                            : std::string()) +
                       "; the other files in this folder may be incomplete or from an earlier "
                       "run") +
           ",\n    \"signal\": " + json_string(name) +
           ",\n    \"processes\": " + std::to_string(processes) + "\n}\n";
}

OutputFolder::OutputFolder(std::filesystem::path dir, bool lock) : dir_(std::move(dir)) {
    std::error_code ec;
    if (std::filesystem::exists(dir_, ec) && !std::filesystem::is_directory(dir_, ec))
        folder_error(dir_, "is not a folder (a file of that name exists); choose another --out");
    created_ = std::filesystem::create_directories(dir_, ec);
    if (ec)
        folder_error(dir_, "cannot be created: " + ec.message() +
                               "; choose a writable folder with --out");
    if (!lock) return;
    const std::filesystem::path lf = dir_ / lock_name;
    for (int attempt = 0;; ++attempt) {
        const int fd = ::open(lf.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
        if (fd < 0)
            folder_error(dir_, std::string("is not writable: cannot create its lock file (") +
                                   std::strerror(errno) + "); choose a writable folder with --out");
        auto read_pid = [&] {
            char buf[32] = {};
            const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
            return n > 0 ? std::strtol(buf, nullptr, 10) : 0L;
        };
        if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
            const int err = errno;
            long pid = 0;
            // The holder writes its id right after locking: give it a moment.
            for (int i = 0; i < 100 && (pid = read_pid()) == 0; ++i)
                ::usleep(10000);
            ::close(fd);
            if (err == EWOULDBLOCK)
                folder_error(dir_,
                             "is in use by another mlcontact run (process " +
                                 (pid > 0 ? std::to_string(pid) : std::string("unknown")) +
                                 ", lock file " + lf.string() +
                                 "); wait for it to end, or choose another folder with --out");
            folder_error(dir_, std::string("cannot be locked (") + std::strerror(err) + ")");
        }
        // Locked; but the file may have been removed (its holder ended) between open and flock:
        // then lock the new one.
        struct stat a {
        }, b{};
        if (::fstat(fd, &a) != 0 || ::stat(lf.c_str(), &b) != 0 || a.st_ino != b.st_ino ||
            a.st_dev != b.st_dev) {
            ::close(fd);
            if (attempt < 100) continue;
            folder_error(dir_, "cannot be locked (its lock file keeps changing)");
        }
        took_over_from_ = read_pid();
        const std::string id = std::to_string(::getpid()) + "\n";
        const bool ok = ::ftruncate(fd, 0) == 0 &&
                        ::pwrite(fd, id.data(), id.size(), 0) == static_cast<ssize_t>(id.size()) &&
                        ::fsync(fd) == 0;
        if (!ok) {
            const int err = errno;
            ::unlink(lf.c_str());
            ::close(fd);
            folder_error(dir_, std::string("is not writable (") + std::strerror(err) +
                                   "); choose another folder with --out");
        }
        lock_fd_ = fd;
        lock_registered_.emplace(lf);
        return;
    }
}

OutputFolder::~OutputFolder() {
    if (lock_fd_ < 0) return;
    lock_registered_.reset();
    ::unlink((dir_ / lock_name).c_str()); // while still holding it (see the constructor)
    ::close(lock_fd_);
    // A run refused or failed before its first file leaves no folder it made (only if empty).
    std::error_code ec;
    if (created_ && !begun_) std::filesystem::remove(dir_, ec);
}

void OutputFolder::begin_writing(const std::string& scene) {
    if (begun_) return;
    begun_ = true;
    std::vector<std::string> earlier;
    if (read_complete_summary(dir_ / "summary.json", earlier))
        for (const auto& n : earlier) {
            std::error_code ec;
            const auto f = dir_ / n;
            if (!driver_file_name(n) || !std::filesystem::is_regular_file(f, ec)) continue;
            if (std::filesystem::remove(f, ec)) removed_.push_back(n);
        }
    const std::string text = in_progress_summary(scene);
    write_file_atomically(dir_ / "summary.json", [&](std::ostream& f) { f << text; });
}

void OutputFolder::add(const std::string& name) {
    if (std::find(files_.begin(), files_.end(), name) == files_.end()) files_.push_back(name);
}

} // namespace mlc::apps

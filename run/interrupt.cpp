// SPDX-License-Identifier: MIT
// The signal handlers of the driver.
#include "run/interrupt.hpp"

#include "core/atomic_file.hpp"
#include "core/stop.hpp"

#include <cerrno>
#include <csignal>
#include <cstring>
#include <ctime>
#include <fcntl.h>
#include <unistd.h>

namespace mlc::apps {

namespace {

std::atomic<int> g_signals{0};
std::atomic<bool> g_exit_at_once{false};
std::atomic<int> g_exit_delay_ms{0};

/// The summary written by a handler that ends the process: file, temporary and the two texts,
/// rendered beforehand. `g_summary_ready` is set only while they are complete.
struct StopSummary {
    std::string file, tmp, sigint_text, sigterm_text;
};
StopSummary g_summary;
std::atomic<bool> g_summary_ready{false};

void write_all(int fd, const char* p, size_t n) {
    while (n > 0) {
        const ssize_t w = ::write(fd, p, n);
        if (w <= 0) return;
        p += w;
        n -= static_cast<size_t>(w);
    }
}

/// Async-signal-safe: open, write, close, rename.
void write_stop_summary(int sig) {
    if (!g_summary_ready.load()) return;
    const std::string& text = sig == SIGINT ? g_summary.sigint_text : g_summary.sigterm_text;
    const int fd = ::open(g_summary.tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) return;
    write_all(fd, text.data(), text.size());
    const bool ok = ::close(fd) == 0;
    if (ok)
        ::rename(g_summary.tmp.c_str(), g_summary.file.c_str());
    else
        ::unlink(g_summary.tmp.c_str());
}

extern "C" void on_stop_signal(int sig) {
    const int n = g_signals.fetch_add(1) + 1;
    mlc::request_stop(sig);
    if (n >= 2 || g_exit_at_once.load()) {
        mlc::remove_registered_temporaries();
        write_stop_summary(sig);
        if (const int ms = g_exit_delay_ms.load(); ms > 0) {
            timespec t{ms / 1000, (ms % 1000) * 1000000L};
            while (::nanosleep(&t, &t) != 0 && errno == EINTR) {
            }
        }
        ::_exit(128 + sig);
    }
}

} // namespace

void install_stop_handlers(bool exit_at_once, int exit_delay_ms) {
    g_exit_at_once.store(exit_at_once);
    g_exit_delay_ms.store(exit_delay_ms);
    struct sigaction sa {};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sigaddset(&sa.sa_mask, SIGINT);
    sigaddset(&sa.sa_mask, SIGTERM);
    sa.sa_flags = SA_RESTART;
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
}

const std::atomic<bool>& stop_flag() {
    return mlc::stop_request_flag();
}

bool stop_requested() {
    return mlc::stop_requested();
}

int stop_signal() {
    return mlc::stop_request_signal();
}

const char* signal_name(int sig) {
    switch (sig) {
    case SIGINT:
        return "SIGINT";
    case SIGTERM:
        return "SIGTERM";
    default:
        return "a signal";
    }
}

void set_stop_summary(const std::filesystem::path& file, std::string sigint_text,
                      std::string sigterm_text) {
    // Not ready while the strings change (the handler reads them only when ready).
    g_summary_ready.store(false);
    if (file.empty()) return;
    g_summary.file = file.string();
    g_summary.tmp = temporary_path(file).string();
    g_summary.sigint_text = std::move(sigint_text);
    g_summary.sigterm_text = std::move(sigterm_text);
    g_summary_ready.store(true);
}

} // namespace mlc::apps

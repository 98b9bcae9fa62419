// SPDX-License-Identifier: MIT
// The process-wide stop request.
#include "core/stop.hpp"

namespace mlc {

namespace {

std::atomic<bool> g_stop{false};
std::atomic<int> g_signal{0};
std::atomic<bool> g_writes_stoppable{false};
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free,
              "a signal handler may only touch lock-free atomics");

} // namespace

void request_stop(int sig) noexcept {
    int none = 0;
    g_signal.compare_exchange_strong(none, sig);
    g_stop.store(true);
}

bool stop_requested() noexcept {
    return g_stop.load(std::memory_order_relaxed);
}

int stop_request_signal() noexcept {
    return g_signal.load();
}

const std::atomic<bool>& stop_request_flag() noexcept {
    return g_stop;
}

void set_writes_stoppable(bool on) noexcept {
    g_writes_stoppable.store(on);
}

bool write_stop_requested() noexcept {
    return g_writes_stoppable.load(std::memory_order_relaxed) && stop_requested();
}

void clear_stop_request() noexcept {
    g_stop.store(false);
    g_signal.store(0);
}

} // namespace mlc

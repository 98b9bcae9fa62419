// SPDX-License-Identifier: MIT
// Process-wide counters of compulsory bytes per kind of pass, and STREAM copy / triad.
#include "core/traffic.hpp"

#include "core/check.hpp"
#include "core/csr.hpp"
#include "core/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <limits>
#include <memory>

namespace mlc::traffic {

namespace {

struct Counters {
    std::array<std::atomic<std::uint64_t>, kKinds> bytes{};
    std::array<std::atomic<std::uint64_t>, kKinds> passes{};
    std::array<std::atomic<std::uint64_t>, kKinds> nanoseconds{};
};

Counters& counters() {
    static Counters c;
    return c;
}

std::atomic<bool> timing_on{false};

} // namespace

std::string_view to_string(Kind k) {
    switch (k) {
    case Kind::matvec:
        return "matvec";
    case Kind::smoother:
        return "smoother";
    case Kind::transfer:
        return "transfer";
    case Kind::coarse:
        return "coarse";
    case Kind::vector:
        return "vector";
    case Kind::structured:
        return "structured";
    }
    return "unknown";
}

double Account::total_bytes() const {
    double t = 0;
    for (double v : bytes)
        t += v;
    return t;
}

double Account::timed_seconds() const {
    double t = 0;
    for (double v : seconds)
        t += v;
    return t;
}

Account Account::operator-(const Account& o) const {
    Account d;
    for (int k = 0; k < kKinds; ++k) {
        d.bytes[k] = bytes[k] - o.bytes[k];
        d.passes[k] = passes[k] - o.passes[k];
        d.seconds[k] = seconds[k] - o.seconds[k];
    }
    return d;
}

Account& Account::operator+=(const Account& o) {
    for (int k = 0; k < kKinds; ++k) {
        bytes[k] += o.bytes[k];
        passes[k] += o.passes[k];
        seconds[k] += o.seconds[k];
    }
    return *this;
}

Account snapshot() {
    Counters& c = counters();
    Account a;
    for (int k = 0; k < kKinds; ++k) {
        a.bytes[k] = static_cast<double>(c.bytes[k].load(std::memory_order_relaxed));
        a.passes[k] = static_cast<double>(c.passes[k].load(std::memory_order_relaxed));
        a.seconds[k] = 1e-9 * static_cast<double>(c.nanoseconds[k].load(std::memory_order_relaxed));
    }
    return a;
}

void add(Kind kind, double bytes, double seconds, int passes) {
    Counters& c = counters();
    const auto k = static_cast<size_t>(kind);
    c.bytes[k].fetch_add(static_cast<std::uint64_t>(bytes), std::memory_order_relaxed);
    c.passes[k].fetch_add(static_cast<std::uint64_t>(passes), std::memory_order_relaxed);
    if (seconds > 0)
        c.nanoseconds[k].fetch_add(static_cast<std::uint64_t>(seconds * 1e9),
                                   std::memory_order_relaxed);
}

void set_timing(bool on) {
    timing_on.store(on, std::memory_order_relaxed);
}

bool timing() {
    return timing_on.load(std::memory_order_relaxed);
}

double csr_bytes(Index rows, Index cols, Index nonzeros, bool add, int value_bytes) {
    const auto n = static_cast<double>(rows), m = static_cast<double>(cols),
               z = static_cast<double>(nonzeros);
    const double v = value_bytes;
    return (v + 4.0) * z + 4.0 * (n + 1) + 8.0 * m + 8.0 * n + (add ? 8.0 * n : 0.0);
}

double sweep_bytes(Index rows, Index nonzeros, Index blocks, Index inverse_entries,
                   int value_bytes) {
    const auto n = static_cast<double>(rows), z = static_cast<double>(nonzeros),
               nb = static_cast<double>(blocks), d = static_cast<double>(inverse_entries);
    const double v = value_bytes;
    return (v + 4.0) * z + 4.0 * (n + 1) + v * d + 8.0 * (2 * nb + 1) + 8.0 * n + 8.0 * n +
           16.0 * n;
}

double sweep_from_zero_bytes(Index rows, Index nonzeros, Index blocks, Index inverse_entries,
                             int value_bytes) {
    const auto n = static_cast<double>(rows), z = static_cast<double>(nonzeros),
               nb = static_cast<double>(blocks), d = static_cast<double>(inverse_entries);
    const double v = value_bytes;
    return (v + 4.0) * z + 8.0 * (n + 1) + v * d + 8.0 * (2 * nb + 1) + 16.0 * n + 8.0 * n +
           16.0 * n + 24.0 * n;
}

Stream measure_stream(std::size_t n, int repeats) {
    MLC_CHECK(n >= 1, "measure_stream: n must be >= 1");
    MLC_CHECK(repeats >= 1, "measure_stream: repeats must be >= 1, found " << repeats);
    // Uninitialized arrays, first touched by the pool's threads (as the kernels' vectors are).
    std::unique_ptr<double[]> a(new double[n]), b(new double[n]), c(new double[n]);
    double* ap = a.get();
    double* bp = b.get();
    double* cp = c.get();
    const std::size_t chunk = static_cast<std::size_t>(kMinRowsPerThread);
    parallel::for_rows(n, chunk, [&](std::size_t i0, std::size_t i1) {
        for (std::size_t i = i0; i < i1; ++i) {
            ap[i] = 1.0;
            bp[i] = 2.0;
            cp[i] = 0.5;
        }
    });
    const double s = 3.0;
    double best_copy = std::numeric_limits<double>::infinity(), best_triad = best_copy;
    for (int r = 0; r < repeats; ++r) {
        auto t0 = std::chrono::steady_clock::now();
        parallel::for_rows(n, chunk, [&](std::size_t i0, std::size_t i1) {
            const double* __restrict src = ap;
            double* __restrict dst = cp;
            for (std::size_t i = i0; i < i1; ++i)
                dst[i] = src[i];
        });
        auto t1 = std::chrono::steady_clock::now();
        parallel::for_rows(n, chunk, [&](std::size_t i0, std::size_t i1) {
            const double* __restrict x = bp;
            const double* __restrict y = cp;
            double* __restrict dst = ap;
            for (std::size_t i = i0; i < i1; ++i)
                dst[i] = x[i] + s * y[i];
        });
        auto t2 = std::chrono::steady_clock::now();
        best_copy = std::min(best_copy, std::chrono::duration<double>(t1 - t0).count());
        best_triad = std::min(best_triad, std::chrono::duration<double>(t2 - t1).count());
    }
    // Keep the results observable (a[0] = 2 + 3 * 1 after the first triad).
    MLC_CHECK(ap[0] == bp[0] + s * cp[0], "measure_stream: wrong triad result");
    Stream st;
    st.n = n;
    st.repeats = repeats;
    st.threads = parallel::num_threads();
    const auto bytes = static_cast<double>(n) * 8.0;
    st.copy_gbs = best_copy > 0 ? 2.0 * bytes / best_copy * 1e-9 : 0.0;
    st.triad_gbs = best_triad > 0 ? 3.0 * bytes / best_triad * 1e-9 : 0.0;
    return st;
}

} // namespace mlc::traffic

// SPDX-License-Identifier: MIT
// The per-process worker pool behind mlc::parallel::for_chunks.
//
// One 64-bit word describes the current loop: its number (epoch, high 32 bits) and how many of
// its chunks are not yet claimed (low 32 bits). A thread claims a chunk with a compare-exchange
// that succeeds only while the epoch is the one it woke for, so a worker that was descheduled
// and wakes after its loop ended (or while the next one runs) claims nothing of a loop it did not
// see start. The loop's function, context and chunk count are written by the caller before it
// publishes the word and are read by a thread only after a successful claim; the caller does not
// return (nor start another loop) before every claimed chunk has been counted done, so they stay
// valid while read.
#include "core/parallel.hpp"
#include "core/check.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <climits>
#include <cstdint>
#include <cstdlib>
#include <dlfcn.h>
#include <exception>
#include <mutex>
#include <sched.h>
#include <stdexcept>
#include <thread>
#include <vector>

namespace mlc::parallel {

namespace {

/// How long an idle thread spins before it sleeps: long enough to stay awake through the Krylov
/// vector operations between two sweeps of a level of millions of unknowns, short enough to give
/// the core back when a V-cycle ends.
constexpr std::chrono::microseconds spin_time{2000};

inline void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    asm volatile("yield" ::: "memory");
#endif
}

/// Spins (with a pause instruction) until done() or spin_time has passed; true if done().
template <class Done> bool spin_until(Done done) {
    const auto start = std::chrono::steady_clock::now();
    for (unsigned i = 1;; ++i) {
        if (done()) return true;
        cpu_relax();
        if (i % 64 == 0 && std::chrono::steady_clock::now() - start > spin_time) return false;
    }
}

constexpr std::uint32_t epoch_of(std::uint64_t word) {
    return std::uint32_t(word >> 32);
}
constexpr std::uint32_t unclaimed_of(std::uint64_t word) {
    return std::uint32_t(word);
}

/// True on pool workers always and on a caller while it runs a loop: loops started there run
/// sequentially.
thread_local bool in_loop = false;

std::atomic<std::size_t> worker_chunks{0};

/// Runs fn on every chunk in order on this thread, with the pool's exception rule.
void run_sequential(std::size_t n_chunks, detail::ChunkFn fn, void* ctx) {
    std::exception_ptr error;
    for (std::size_t c = 0; c < n_chunks; ++c) {
        try {
            fn(ctx, c);
        } catch (...) {
            if (!error) error = std::current_exception();
        }
    }
    if (error) std::rethrow_exception(error);
}

class Pool {
public:
    explicit Pool(int threads) { start(threads); }
    ~Pool() { stop(); }
    Pool(const Pool&) = delete;
    Pool& operator=(const Pool&) = delete;

    /// Held by the thread running a loop or resizing the pool.
    std::mutex busy;

    int threads() const { return threads_.load(std::memory_order_relaxed); }

    /// Caller holds `busy`.
    void resize(int threads) {
        stop();
        start(threads);
    }

    /// Caller holds `busy`; 2 <= n_chunks < 2^32.
    void run(std::size_t n_chunks, detail::ChunkFn fn, void* ctx) {
        fn_ = fn;
        ctx_ = ctx;
        n_ = std::uint32_t(n_chunks);
        error_ = nullptr;
        done_.store(0, std::memory_order_relaxed);
        caller_waiting_.store(false, std::memory_order_relaxed);
        const std::uint32_t epoch = ++epoch_;
        word_.store(std::uint64_t(epoch) << 32 | n_, std::memory_order_seq_cst);
        wake_workers();

        work(epoch, false);

        // Every chunk is claimed; wait for those still running on workers.
        const std::uint32_t n = n_;
        if (!spin_until([&] { return done_.load(std::memory_order_acquire) == n; })) {
            caller_waiting_.store(true, std::memory_order_seq_cst);
            for (;;) {
                const std::uint32_t d = done_.load(std::memory_order_seq_cst);
                if (d == n) break;
                done_.wait(d, std::memory_order_seq_cst);
            }
        }
        if (error_) {
            std::exception_ptr e = std::move(error_);
            error_ = nullptr;
            std::rethrow_exception(e);
        }
    }

    void hold(bool on) {
        hold_.store(on, std::memory_order_seq_cst);
        if (!on) hold_.notify_all();
    }

private:
    void start(int threads) {
        stop_.store(false);
        const std::uint32_t seen = epoch_of(word_.load());
        for (int i = 1; i < threads; ++i)
            workers_.emplace_back([this, seen] { worker(seen); });
        threads_.store(threads);
    }

    void stop() {
        stop_.store(true, std::memory_order_seq_cst);
        wake_workers();
        hold(false);
        for (auto& t : workers_)
            t.join();
        workers_.clear();
    }

    void wake_workers() {
        wake_.fetch_add(1, std::memory_order_seq_cst);
        if (sleepers_.load(std::memory_order_seq_cst) > 0) wake_.notify_all();
    }

    void worker(std::uint32_t seen) {
        in_loop = true;
        for (;;) {
            const std::uint64_t word = wait_for_loop(seen);
            if (stop_.load(std::memory_order_relaxed)) return;
            seen = epoch_of(word);
            work(seen, true);
        }
    }

    /// The word of the first loop after `seen` (or any word once stop_ is set).
    std::uint64_t wait_for_loop(std::uint32_t seen) {
        std::uint64_t word = 0;
        const auto fresh = [&] {
            word = word_.load(std::memory_order_acquire);
            return epoch_of(word) != seen || stop_.load(std::memory_order_relaxed);
        };
        if (spin_until(fresh)) return word;
        for (;;) {
            // Sleep. The caller bumps wake_ after publishing the word and then looks at
            // sleepers_; with sequentially consistent order either it sees this sleeper and
            // notifies, or this thread sees the new word (or the new wake_ value) first.
            sleepers_.fetch_add(1, std::memory_order_seq_cst);
            const std::uint32_t w = wake_.load(std::memory_order_seq_cst);
            word = word_.load(std::memory_order_seq_cst);
            if (epoch_of(word) != seen || stop_.load(std::memory_order_seq_cst)) {
                sleepers_.fetch_sub(1, std::memory_order_relaxed);
                return word;
            }
            wake_.wait(w, std::memory_order_seq_cst);
            sleepers_.fetch_sub(1, std::memory_order_relaxed);
        }
    }

    /// Claims and runs chunks of loop `epoch` until none is left.
    void work(std::uint32_t epoch, bool is_worker) {
        for (;;) {
            if (is_worker) {
                while (hold_.load(std::memory_order_seq_cst))
                    hold_.wait(true);
            }
            std::uint64_t word = word_.load(std::memory_order_acquire);
            do {
                if (epoch_of(word) != epoch || unclaimed_of(word) == 0) return;
            } while (!word_.compare_exchange_weak(word, word - 1, std::memory_order_acq_rel,
                                                  std::memory_order_acquire));
            // Claimed: the loop's data stay valid until this chunk is counted done.
            const std::uint32_t n = n_;
            const std::uint32_t chunk = n - unclaimed_of(word);
            try {
                fn_(ctx_, chunk);
            } catch (...) {
                std::lock_guard lock(error_mutex_);
                if (!error_ || chunk < error_chunk_) {
                    error_ = std::current_exception();
                    error_chunk_ = chunk;
                }
            }
            if (is_worker) worker_chunks.fetch_add(1, std::memory_order_relaxed);
            if (done_.fetch_add(1, std::memory_order_seq_cst) + 1 == n &&
                caller_waiting_.load(std::memory_order_seq_cst))
                done_.notify_one();
        }
    }

    std::vector<std::thread> workers_;
    std::atomic<int> threads_{1};
    std::uint32_t epoch_ = 0; // the caller's count of loops (written under `busy`)

    std::atomic<std::uint64_t> word_{0}; // epoch << 32 | unclaimed chunks
    std::atomic<std::uint32_t> wake_{0}; // futex word the sleeping workers wait on
    std::atomic<int> sleepers_{0};
    std::atomic<bool> stop_{false};
    std::atomic<bool> hold_{false};
    std::atomic<std::uint32_t> done_{0}; // chunks of the current loop finished
    std::atomic<bool> caller_waiting_{false};

    // The current loop, written by the caller before it publishes word_.
    detail::ChunkFn fn_ = nullptr;
    void* ctx_ = nullptr;
    std::uint32_t n_ = 0;
    std::mutex error_mutex_;
    std::exception_ptr error_;
    std::uint32_t error_chunk_ = 0;
};

Pool& pool() {
    static Pool p(default_num_threads());
    return p;
}

// Eigen on one thread from the library's load on (EigenThreadsScope lends it more).
const bool eigen_single_threaded = [] {
    Eigen::setNbThreads(1);
    return true;
}();

} // namespace

EigenThreadsScope::EigenThreadsScope() {
    (void)eigen_single_threaded;
    Eigen::setNbThreads(num_threads());
}

EigenThreadsScope::~EigenThreadsScope() {
    Eigen::setNbThreads(1);
}

int default_num_threads() {
    if (const char* s = std::getenv("OMP_NUM_THREADS")) {
        char* end = nullptr;
        const long n = std::strtol(s, &end, 10);
        if (end != s && n > 0) return int(std::min(n, 1024L));
    }
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof(set), &set) == 0 && CPU_COUNT(&set) > 0) return CPU_COUNT(&set);
    return int(std::max(1u, std::thread::hardware_concurrency()));
}

int num_threads() {
    return pool().threads();
}

namespace {

// A symbol of the process's BLAS, looked up at run time: the executable links CHOLMOD, which
// links libblas.so.3, so the symbol is in the global scope; a module loaded with RTLD_LOCAL (the
// Python extension) finds it through the already loaded library.
void* blas_symbol(const char* name) {
    if (void* f = dlsym(RTLD_DEFAULT, name)) return f;
    if (void* h = dlopen("libblas.so.3", RTLD_NOW | RTLD_NOLOAD)) {
        void* f = dlsym(h, name);
        dlclose(h);
        return f;
    }
    return nullptr;
}

} // namespace

void set_num_threads(int n) {
    MLC_CHECK(n >= 0, "set_num_threads: the number of threads must be >= 0, found " << n);
    if (in_loop) throw std::logic_error("mlc::parallel::set_num_threads called inside a loop");
    Pool& p = pool();
    std::lock_guard lock(p.busy);
    p.resize(n == 0 ? default_num_threads() : n);
}

std::string blas_library() {
    // Once per process (the library does not change; openblas_get_config writes a static buffer).
    static const std::string name = [] {
        void* dgemm = blas_symbol("dgemm_");
        if (!dgemm) return std::string("none");
        std::string out = "unknown";
        Dl_info info{};
        if (dladdr(dgemm, &info) != 0 && info.dli_fname) {
            char resolved[PATH_MAX];
            out = realpath(info.dli_fname, resolved) ? resolved : info.dli_fname;
        }
        using Config = char* (*)();
        if (auto f = reinterpret_cast<Config>(blas_symbol("openblas_get_config")))
            if (const char* c = f()) out += std::string(" (") + c + ")";
        return out;
    }();
    return name;
}

RowChunks row_chunks(std::size_t n, std::size_t min_rows_per_chunk) {
    RowChunks rc;
    rc.n = n;
    const std::size_t spread = (n + RowChunks::max_chunks - 1) / RowChunks::max_chunks;
    rc.size = std::max({min_rows_per_chunk, spread, std::size_t(1)});
    rc.count = (n + rc.size - 1) / rc.size;
    return rc;
}

namespace detail {

void run(std::size_t n_chunks, ChunkFn fn, void* ctx) {
    if (n_chunks == 0) return;
    if (n_chunks >= (std::size_t(1) << 32))
        throw std::length_error("mlc::parallel::for_chunks: at most 2^32 - 1 chunks");
    if (n_chunks == 1 || in_loop) return run_sequential(n_chunks, fn, ctx);
    Pool& p = pool();
    std::unique_lock lock(p.busy, std::try_to_lock);
    in_loop = true;
    struct Reset {
        ~Reset() { in_loop = false; }
    } reset;
    if (!lock.owns_lock() || p.threads() == 1) return run_sequential(n_chunks, fn, ctx);
    p.run(n_chunks, fn, ctx);
}

} // namespace detail

namespace testing {
void hold_workers() {
    pool().hold(true);
}
void release_workers() {
    pool().hold(false);
}
std::size_t chunks_run_by_workers() {
    return worker_chunks.load();
}
} // namespace testing

} // namespace mlc::parallel

// SPDX-License-Identifier: MIT
// mlc::parallel: every chunk once, rows covered exactly, results independent of the thread count,
// exceptions, nesting, many tiny loops, and a caller that does not wait for absent workers.
#include "core/parallel.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace par = mlc::parallel;

namespace {

/// Each test sets its own thread count; restore the default afterwards.
class Parallel : public ::testing::Test {
protected:
    void TearDown() override {
        par::testing::release_workers();
        par::set_num_threads(0);
    }
};

/// Holds the workers for the lifetime of the object.
struct HeldWorkers {
    HeldWorkers() { par::testing::hold_workers(); }
    ~HeldWorkers() { par::testing::release_workers(); }
};

/// Waits (up to ten seconds, for a loaded machine) until pred() holds.
template <class Pred> bool eventually(Pred pred) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (!pred()) {
        if (std::chrono::steady_clock::now() > end) return false;
        std::this_thread::yield();
    }
    return true;
}

} // namespace

TEST_F(Parallel, EveryChunkRunsExactlyOnce) {
    for (int threads : {1, 2, 4}) {
        par::set_num_threads(threads);
        EXPECT_EQ(par::num_threads(), threads);
        for (std::size_t n : {0, 1, 2, 3, 7, 100, 1000, 10000}) {
            std::vector<std::atomic<int>> calls(n);
            par::for_chunks(n, [&](std::size_t c) { calls[c].fetch_add(1); });
            for (std::size_t c = 0; c < n; ++c)
                ASSERT_EQ(calls[c].load(), 1) << "threads " << threads << " n " << n << " c " << c;
        }
    }
}

TEST_F(Parallel, ForRowsCoversTheRangeExactlyOnce) {
    par::set_num_threads(2);
    for (std::size_t n : {0, 1, 5, 255, 256, 257, 1000, 12345, 2000001}) {
        for (std::size_t min_rows : {0, 1, 64, 1000, 100000}) {
            const par::RowChunks rc = par::row_chunks(n, min_rows);
            EXPECT_LE(rc.count, par::RowChunks::max_chunks);
            EXPECT_GE(rc.size, std::max<std::size_t>(min_rows, 1));
            EXPECT_EQ(rc.count == 0, n == 0);
            std::vector<std::atomic<int>> calls(n);
            std::atomic<std::size_t> n_calls{0};
            par::for_rows(n, min_rows, [&](std::size_t begin, std::size_t end) {
                EXPECT_LT(begin, end);
                EXPECT_LE(end, n);
                for (std::size_t i = begin; i < end; ++i)
                    calls[i].fetch_add(1);
                n_calls.fetch_add(1);
            });
            EXPECT_EQ(n_calls.load(), rc.count);
            for (std::size_t i = 0; i < n; ++i)
                ASSERT_EQ(calls[i].load(), 1)
                    << "n " << n << " min_rows " << min_rows << " i " << i;
        }
    }
}

TEST_F(Parallel, ResultsBitIdenticalForOneTwoFourThreads) {
    // An element-wise kernel and a reduction with one partial per chunk, added in chunk order.
    const std::size_t n = 300000;
    std::vector<double> x(n);
    for (std::size_t i = 0; i < n; ++i)
        x[i] = std::sin(double(i)) * std::pow(10.0, double(i % 13));
    const auto compute = [&](std::vector<double>& y) {
        y.assign(n, 0.0);
        const par::RowChunks rc = par::row_chunks(n, 1000);
        std::vector<double> partial(rc.count, 0.0);
        par::for_chunks(rc.count, [&](std::size_t c) {
            double s = 0.0;
            for (std::size_t i = rc.begin(c); i < rc.end(c); ++i) {
                y[i] = 0.5 * x[i] + (i > 0 ? x[i - 1] : 0.0) / 3.0;
                s += y[i] * x[i];
            }
            partial[c] = s;
        });
        double sum = 0.0;
        for (double p : partial)
            sum += p;
        return sum;
    };
    std::vector<double> y1, y;
    par::set_num_threads(1);
    const double sum1 = compute(y1);
    for (int threads : {2, 4}) {
        par::set_num_threads(threads);
        for (int repeat = 0; repeat < 5; ++repeat) {
            const double sum = compute(y);
            EXPECT_EQ(std::memcmp(&sum, &sum1, sizeof sum), 0) << "threads " << threads;
            EXPECT_EQ(std::memcmp(y.data(), y1.data(), n * sizeof(double)), 0);
        }
    }
}

TEST_F(Parallel, ExceptionOfTheLowestThrowingChunkPropagatesAfterAllChunksRan) {
    for (int threads : {1, 2, 4}) {
        par::set_num_threads(threads);
        const std::size_t n = 64;
        std::vector<std::atomic<int>> calls(n);
        try {
            par::for_chunks(n, [&](std::size_t c) {
                calls[c].fetch_add(1);
                if (c == 41 || c == 17 || c == 60) throw std::runtime_error(std::to_string(c));
            });
            ADD_FAILURE() << "no exception, threads " << threads;
        } catch (const std::runtime_error& e) {
            EXPECT_EQ(std::string(e.what()), "17") << "threads " << threads;
        }
        for (std::size_t c = 0; c < n; ++c)
            EXPECT_EQ(calls[c].load(), 1);
        // The pool still works afterwards.
        std::atomic<int> sum{0};
        par::for_chunks(10, [&](std::size_t c) { sum += int(c); });
        EXPECT_EQ(sum.load(), 45);
    }
    EXPECT_THROW(par::for_chunks(1, [](std::size_t) { throw std::logic_error("one"); }),
                 std::logic_error);
}

TEST_F(Parallel, NestedCallsRunSequentiallyOnTheChunksThread) {
    par::set_num_threads(2);
    const std::size_t outer = 8, inner = 16;
    std::vector<std::atomic<int>> calls(outer * inner);
    std::atomic<int> foreign{0};
    par::for_chunks(outer, [&](std::size_t o) {
        const auto me = std::this_thread::get_id();
        par::for_rows(inner, 1, [&](std::size_t begin, std::size_t end) {
            if (std::this_thread::get_id() != me) foreign.fetch_add(1);
            for (std::size_t i = begin; i < end; ++i)
                calls[o * inner + i].fetch_add(1);
        });
        EXPECT_THROW(par::set_num_threads(3), std::logic_error);
    });
    EXPECT_EQ(foreign.load(), 0);
    for (auto& c : calls)
        EXPECT_EQ(c.load(), 1);
    EXPECT_EQ(par::num_threads(), 2);
}

TEST_F(Parallel, ManyTinySuccessiveLoopsComplete) {
    // 100k loops of 2..5 chunks: a lost wake-up or a stale worker claiming a later loop's chunk
    // would hang or miscount here.
    for (int threads : {2, 4}) {
        par::set_num_threads(threads);
        std::uint64_t expected = 0;
        std::atomic<std::uint64_t> sum{0};
        for (int k = 0; k < 100000; ++k) {
            const std::size_t n = 2 + std::size_t(k % 4);
            par::for_chunks(n, [&](std::size_t c) { sum.fetch_add(c + 1); });
            expected += n * (n + 1) / 2;
        }
        EXPECT_EQ(sum.load(), expected) << "threads " << threads;
    }
}

TEST_F(Parallel, WorkersTakePart) {
    // Two chunks that each wait until both have started: only two threads can run them.
    par::set_num_threads(2);
    std::atomic<int> started{0};
    std::thread::id ids[2];
    std::atomic<bool> both{true};
    par::for_chunks(2, [&](std::size_t c) {
        ids[c] = std::this_thread::get_id();
        started.fetch_add(1);
        if (!eventually([&] { return started.load() == 2; })) both = false;
    });
    EXPECT_TRUE(both.load()) << "the second chunk did not start while the first was running";
    EXPECT_NE(ids[0], ids[1]);
}

TEST_F(Parallel, CallerDoesNotWaitForWorkersThatClaimNothing) {
    // Held workers behave like descheduled ones: they wake for the loop but claim nothing. The
    // loop completes all the same, every chunk run by the caller.
    for (int threads : {2, 4}) {
        par::set_num_threads(threads);
        const std::size_t before = par::testing::chunks_run_by_workers();
        const auto caller = std::this_thread::get_id();
        const std::size_t n = 100;
        std::vector<std::atomic<int>> calls(n);
        std::atomic<int> on_caller{0};
        {
            HeldWorkers held;
            for (int loop = 0; loop < 10; ++loop)
                par::for_chunks(n, [&](std::size_t c) {
                    calls[c].fetch_add(1);
                    if (std::this_thread::get_id() == caller) on_caller.fetch_add(1);
                });
        }
        EXPECT_EQ(on_caller.load(), int(10 * n));
        EXPECT_EQ(par::testing::chunks_run_by_workers(), before);
        for (auto& c : calls)
            EXPECT_EQ(c.load(), 10);

        // Released, the workers find those loops gone and join the next ones.
        std::vector<std::atomic<int>> next(n);
        par::for_chunks(n, [&](std::size_t c) { next[c].fetch_add(1); });
        for (auto& c : next)
            EXPECT_EQ(c.load(), 1);
        for (auto& c : calls)
            EXPECT_EQ(c.load(), 10);
        EXPECT_TRUE(eventually([&] {
            std::atomic<int> dummy{0};
            par::for_chunks(64, [&](std::size_t) {
                std::this_thread::sleep_for(std::chrono::microseconds(100));
                dummy.fetch_add(1);
            });
            return par::testing::chunks_run_by_workers() > before;
        }));
    }
}

TEST_F(Parallel, ConcurrentCallersFromTwoThreads) {
    // A loop started while another thread runs one runs sequentially; both stay correct.
    par::set_num_threads(2);
    const auto loops = [](std::uint64_t& total) {
        std::atomic<std::uint64_t> sum{0};
        for (int k = 0; k < 20000; ++k)
            par::for_chunks(8, [&](std::size_t c) { sum.fetch_add(c); });
        total = sum.load();
    };
    std::uint64_t a = 0, b = 0;
    std::thread other([&] { loops(b); });
    loops(a);
    other.join();
    EXPECT_EQ(a, 20000u * 28u);
    EXPECT_EQ(b, 20000u * 28u);
}

TEST_F(Parallel, DefaultThreadCountFromOmpNumThreadsElseAffinity) {
    const char* old = std::getenv("OMP_NUM_THREADS");
    const std::string saved = old ? old : "";
    setenv("OMP_NUM_THREADS", "3,2", 1);
    EXPECT_EQ(par::default_num_threads(), 3);
    par::set_num_threads(0);
    EXPECT_EQ(par::num_threads(), 3);
    setenv("OMP_NUM_THREADS", "0", 1);
    EXPECT_GE(par::default_num_threads(), 1);
    unsetenv("OMP_NUM_THREADS");
    const int affinity = par::default_num_threads();
    EXPECT_GE(affinity, 1);
    EXPECT_LE(affinity, int(std::thread::hardware_concurrency()));
    if (old) setenv("OMP_NUM_THREADS", saved.c_str(), 1);
    EXPECT_THROW(par::set_num_threads(-1), std::invalid_argument);
}

TEST_F(Parallel, FirstFlaggedIsTheSerialScansIndexWhateverTheThreads) {
    // Flags in chunks 1 and 3 of 5: the chunk-1 index is returned with one thread or two (each
    // chunk reports its own first flag, and the lowest chunk wins); none flagged gives n.
    const std::size_t n = 5 * 1000;
    std::vector<char> flag(n, 0);
    flag[3 * 1000 + 7] = 1;
    flag[1000 + 500] = 1;
    flag[1000 + 900] = 1;
    auto scan = [&](std::size_t b, std::size_t e) {
        for (std::size_t k = b; k < e; ++k)
            if (flag[k]) return k;
        return e;
    };
    for (int threads : {1, 2}) {
        par::set_num_threads(threads);
        EXPECT_EQ(par::row_chunks(n, 1000).count, 5u);
        EXPECT_EQ(par::first_flagged(n, 1000, scan), 1500u) << threads;
    }
    par::set_num_threads(0);
    std::fill(flag.begin(), flag.end(), 0);
    EXPECT_EQ(par::first_flagged(n, 1000, scan), n);
    EXPECT_EQ(par::first_flagged(0, 1000, scan), 0u);
}

// SPDX-License-Identifier: MIT
/// @file Parallel loops that survive a shared machine: a persistent per-process pool of worker
/// threads, chunks claimed dynamically, and a caller that returns as soon as every chunk is done.
///
/// Why not `#pragma omp parallel for schedule(static)`: a static schedule hands each thread a
/// fixed share, and the region ends in a barrier. When another process occupies a core, the
/// descheduled thread's share (and the barrier) waits for its next time slice, milliseconds later,
/// and a V-cycle has hundreds of regions. Here:
///  - chunks are CLAIMED with an atomic counter, by the calling thread and the workers alike;
///  - completion is a count of finished chunks: the caller never waits for a worker that has not
///    claimed anything (a descheduled worker simply does not take part);
///  - idle workers spin briefly (2 ms, with a pause instruction) and then sleep on
///    a futex, so an idle machine gets low latency and a loaded one loses no core to spinning.
///
/// Determinism: which chunks exist depends only on the arguments (never on the number of threads
/// or on the load), and fn(chunk) must do the same work whichever thread runs it. Kernels written
/// as chunk functions then give bit-identical results for any thread count; a reduction keeps one
/// partial per chunk (row_chunks() says how many) and adds the partials in chunk order.
///
/// Calls from inside a chunk (nested) run sequentially on the calling thread, and so does a call
/// made while another thread of the process is in a parallel loop. Thread-safe.
#pragma once

#include <cstddef>
#include <string>
#include <type_traits>
#include <utility>

namespace mlc::parallel {

/// Threads taking part in a parallel loop, the caller included (>= 1).
int num_threads();

/// Sets the number of threads (caller included); 0 restores the default. Stops and restarts the
/// workers; must not be called from inside a chunk.
void set_num_threads(int n);

/// The BLAS library the process calls (the file behind `libblas.so.3`, which Debian's alternatives
/// choose), and OpenBLAS's configuration when it is OpenBLAS ("SINGLE_THREADED" for the serial
/// one); "none" when no BLAS is loaded. Computed once per process. The reference BLAS (Debian's
/// libblas3) makes `schur`'s set-up slower than OpenBLAS (libopenblas0-serial, which
/// scripts/deps.sh installs); a threaded OpenBLAS starts its threads when the library loads,
/// and they spin against this pool (docs/guide/install.md#install-dependencies). The report notes both; summary.json
/// names the library.
std::string blas_library();

/// The default: OMP_NUM_THREADS if set to a positive number (its first entry), else the number of
/// cores this process may run on (sched_getaffinity).
int default_num_threads();

/// Eigen's own threads. Eigen parallelizes its dense products and its row-major sparse-dense
/// products with OpenMP when built with it, and after each such region OpenMP's threads spin,
/// against this pool's workers, for the cores both need: on two cores a small dense product per
/// Newton iteration made a 3D schur run seven times slower. So Eigen runs on one thread in every
/// process that links this library (set when the library loads), and a scope that makes a large
/// product, where the threads pay (a schur set-up's S = X^T X), lends Eigen this pool's thread
/// count for its duration. Not to be nested or used from several threads at once.
class EigenThreadsScope {
public:
    EigenThreadsScope();
    ~EigenThreadsScope();
    EigenThreadsScope(const EigenThreadsScope&) = delete;
    EigenThreadsScope& operator=(const EigenThreadsScope&) = delete;
};

namespace detail {
using ChunkFn = void (*)(void* ctx, std::size_t chunk);
void run(std::size_t n_chunks, ChunkFn fn, void* ctx);
} // namespace detail

/// Calls fn(chunk) exactly once for every chunk in [0, n_chunks), on any thread (the caller
/// included), in any order, and returns when all calls have returned. If calls throw, every chunk
/// is still run and the exception of the lowest-numbered throwing chunk is rethrown.
/// n_chunks must be below 2^32.
template <class Fn> void for_chunks(std::size_t n_chunks, Fn&& fn) {
    using F = std::remove_reference_t<Fn>;
    detail::run(
        n_chunks, [](void* ctx, std::size_t c) { (*static_cast<F*>(ctx))(c); },
        const_cast<void*>(static_cast<const void*>(&fn)));
}

/// Splitting of the rows [0, n) into `count` consecutive chunks of `size` rows (the last one may be
/// shorter), size >= min_rows_per_chunk and count <= max_chunks. Depends only on n and
/// min_rows_per_chunk, never on the number of threads.
struct RowChunks {
    static constexpr std::size_t max_chunks = 256;
    std::size_t n = 0;
    std::size_t size = 1; ///< rows per chunk (the last chunk may have fewer)
    std::size_t count = 0;
    std::size_t begin(std::size_t chunk) const { return chunk * size; }
    std::size_t end(std::size_t chunk) const { return chunk + 1 == count ? n : (chunk + 1) * size; }
};
RowChunks row_chunks(std::size_t n, std::size_t min_rows_per_chunk);

/// Calls fn(begin, end) on the chunks of row_chunks(n, min_rows_per_chunk), in parallel; together
/// they cover [0, n) exactly once.
template <class Fn> void for_rows(std::size_t n, std::size_t min_rows_per_chunk, Fn&& fn) {
    const RowChunks rc = row_chunks(n, min_rows_per_chunk);
    for_chunks(rc.count, [&](std::size_t c) { fn(rc.begin(c), rc.end(c)); });
}

/// The smallest index in [0, n) that `scan` flags, or n when none is: scan(begin, end) runs on
/// the chunks of row_chunks(n, min_rows_per_chunk) over the threads and returns the first index
/// of [begin, end) it flags, or end. The lowest flagged chunk's index is returned: the one a
/// serial scan finds, whatever the threads. For checks over large arrays that name the first
/// offending entry.
template <class Fn>
std::size_t first_flagged(std::size_t n, std::size_t min_rows_per_chunk, Fn&& scan) {
    const RowChunks rc = row_chunks(n, min_rows_per_chunk);
    std::size_t first[RowChunks::max_chunks];
    for_chunks(rc.count, [&](std::size_t c) { first[c] = scan(rc.begin(c), rc.end(c)); });
    for (std::size_t c = 0; c < rc.count; ++c)
        if (first[c] < rc.end(c)) return first[c];
    return n;
}

/// Test hooks.
namespace testing {
/// While held, workers claim no chunk (as if descheduled): a worker that wakes for a loop waits
/// until release before it looks at the loop again. Loops still complete, run by their callers.
void hold_workers();
void release_workers();
/// Chunks run by worker threads (not by callers) since the start of the process.
std::size_t chunks_run_by_workers();
} // namespace testing

} // namespace mlc::parallel

// SPDX-License-Identifier: MIT
/// @file The memory-traffic account of the solve phase: how many compulsory bytes each kind of
/// pass moves (process-wide counters the kernels add to once per call, never per element), their
/// time, and a STREAM measurement (copy and triad) on the same thread pool, so that `bench
/// square` can put achieved bandwidth beside what the machine streams.
///
/// Compulsory bytes of a pass: every array the pass reads or writes counted once, at its size
/// (8 bytes a double, 4 an int index, sizeof(Index) = 8 a block offset); nothing for cache reuse
/// or for the gathers x[col] beyond x read once, nothing for write-allocate. As counted by the
/// kernels:
///
/// - CSR mat-vec y = A x (or y += A x) of an n x m matrix with nnz stored entries
///   (`csr_multiply`, `MatrixOperator::apply`): `csr_bytes(n, m, nnz, add)` =
///   12 nnz (values and column indices) + 4 (n + 1) (row offsets) + 8 m (x) + 8 n (y written),
///   + 8 n more with `add` (y read). Kind `matvec`, or `transfer` for the multigrid's
///   restriction R r and prolongation z += T e.
/// - One block Gauss–Seidel half-sweep of smoothers::BlockSOR (n rows, nnz entries, nb diagonal
///   blocks whose inverses hold d doubles): `sweep_bytes(n, nnz, nb, d)` =
///   12 nnz + 4 (n + 1) (the matrix) + 8 d (block inverses) + 8 (2 nb + 1) (block starts and
///   inverse offsets) + 8 n (two int bounds per row) + 8 n (b read) + 16 n (x read and written).
///   The multigrid's first forward sweep from zero that also returns the residual
///   (`forward_from_zero`) is two passes: `sweep_from_zero_bytes(n, nnz, nb, d)` =
///   12 nnz + 8 (n + 1) + 8 d + 8 (2 nb + 1) + 16 n (row bounds, both passes) + 8 n (b) + 16 n
///   (x written, then read) + 24 n (residual written, then read and written). Kind `smoother`.
/// - Krylov vector operations (solvers/krylov.cpp): `vector_bytes(n, k)` = 8 n k for a statement
///   touching k vectors of length n (an axpy y += a x: k = 3; a dot product: 2; a norm: 1).
///   Kind `vector`; not timed per statement (their time is what the solve spends outside the
///   timed kinds).
/// - Single precision (`value_bytes` = 4 below: matrix values and block inverses stored as float,
///   vectors still double): each 12 nnz becomes 8 nnz and each 8 d becomes 4 d.
/// - The multigrid's coarse solve (level 0, sparse LU): timed, its bytes not counted (0), kind
///   `coarse`.
/// - The structured passes of `mg:smoother=lattice` (smoothers::LatticeGS: a half-sweep, and the
///   product `multiply` that replaces the Krylov mat-vec): the rows of the blocks swept by rows
///   (12 bytes an entry, their inverses and offsets), the visit entries, the semi-deep points'
///   neighbour lists and the vectors (b read and x read and written: 24 n; x read and y written:
///   16 n); the stencils (one per macro triangle) count nothing. Kind `structured`: these passes
///   read no assembled matrix for most rows, so their GB/s is not a measure of how well a matrix
///   streams (bench square's `matrix` figure leaves them out; their cost is read in time).
///
/// Counters are process-wide relaxed atomics, incremented by the calling thread once per call
/// (a parallel kernel counts once, on the thread that called it). Timing (two steady-clock reads
/// per call) is off unless `set_timing(true)`; the byte and pass counts are always kept.
/// Passes of other preconditioners (ILU, CF, SORCF, EBE, hypre's) are not counted.
#pragma once

#include "core/types.hpp"

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace mlc::traffic {

/// What a pass does.
enum class Kind { matvec, smoother, transfer, coarse, vector, structured };
inline constexpr int kKinds = 6;

/// "matvec", "smoother", "transfer", "coarse", "vector", "structured".
std::string_view to_string(Kind k);

/// The counters at one moment (cumulative since the start of the process); differences of two
/// snapshots give what happened in between.
struct Account {
    std::array<double, kKinds> bytes{};   ///< compulsory bytes
    std::array<double, kKinds> passes{};  ///< calls (passes over the data)
    std::array<double, kKinds> seconds{}; ///< wall time of the timed kinds while timing was on
    double& b(Kind k) { return bytes[static_cast<size_t>(k)]; }
    double b(Kind k) const { return bytes[static_cast<size_t>(k)]; }
    double p(Kind k) const { return passes[static_cast<size_t>(k)]; }
    double s(Kind k) const { return seconds[static_cast<size_t>(k)]; }
    double total_bytes() const;
    /// Seconds of every timed kind together.
    double timed_seconds() const;
    Account operator-(const Account& o) const;
    Account& operator+=(const Account& o);
};

/// The counters now.
Account snapshot();

/// Adds one call of `kind`: `bytes`, `passes` passes, `seconds` of wall time.
void add(Kind kind, double bytes, double seconds = 0.0, int passes = 1);

/// Turns per-call timing on or off (process-wide; off by default).
void set_timing(bool on);
bool timing();

/// Counts one call of `kind` moving `bytes` and, while timing is on, its wall time from
/// construction to destruction.
class Pass {
public:
    Pass(Kind kind, double bytes, int passes = 1)
        : kind_(kind), bytes_(bytes), passes_(passes), timed_(timing()) {
        if (timed_) t0_ = std::chrono::steady_clock::now();
    }
    ~Pass() {
        double s = 0.0;
        if (timed_)
            s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
        add(kind_, bytes_, s, passes_);
    }
    Pass(const Pass&) = delete;
    Pass& operator=(const Pass&) = delete;

private:
    Kind kind_;
    double bytes_;
    int passes_;
    bool timed_;
    std::chrono::steady_clock::time_point t0_{};
};

/// Closed forms of the file comment. `value_bytes` is the size of one stored matrix value and
/// one block-inverse entry: 8 (double, the default) or 4 (float: the multigrid's single-precision
/// data, `mg:precision=single`); indices, offsets and vectors keep their sizes.
double csr_bytes(Index rows, Index cols, Index nonzeros, bool add, int value_bytes = 8);
double sweep_bytes(Index rows, Index nonzeros, Index blocks, Index inverse_entries,
                   int value_bytes = 8);
double sweep_from_zero_bytes(Index rows, Index nonzeros, Index blocks, Index inverse_entries,
                             int value_bytes = 8);
inline double vector_bytes(Index n, int vectors) {
    return 8.0 * static_cast<double>(n) * vectors;
}
/// Counts a Krylov vector statement touching `vectors` vectors of length n (not timed).
inline void vectors(Index n, int vectors) {
    add(Kind::vector, vector_bytes(n, vectors));
}

/// STREAM (McCalpin) on core/parallel's pool with its current threads: best of `repeats` timings
/// of copy a = b (16 n bytes) and triad a = b + s c (24 n bytes) on arrays of n doubles.
struct Stream {
    double copy_gbs = 0.0;  ///< 1e9 bytes per second
    double triad_gbs = 0.0; ///< 1e9 bytes per second
    std::size_t n = 0;      ///< doubles per array
    int threads = 0;        ///< core/parallel's threads during the measurement
    int repeats = 0;
};

/// Measures STREAM copy and triad (see Stream). n >= 1, repeats >= 1. The default size, 2^25
/// doubles (256 MiB per array, 768 MiB in all), is far beyond any cache.
Stream measure_stream(std::size_t n = std::size_t(1) << 25, int repeats = 5);

} // namespace mlc::traffic

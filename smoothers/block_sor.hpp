// SPDX-License-Identifier: MIT
/// @file Point and block SOR / SSOR (Gauss–Seidel with relaxation) preconditioner and smoother,
/// with variable block sizes so that 2x2 vertex and 4x4 vertex+multiplier blocks are handled.
#pragma once

#include "core/linear_operator.hpp"

#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace mlc::smoothers {

/// Order in which the blocks are visited by one sweep.
enum class Sweep {
    forward,  ///< blocks 0, 1, ..., C = D/omega + L
    backward, ///< blocks last, ..., 0, C = D/omega + U
    symmetric ///< forward then backward (SSOR),
              ///< C = omega/(2-omega) (D/omega + L) D^{-1} (D/omega + U)
};

/// "forward", "backward" or "symmetric".
std::string_view to_string(Sweep s);
/// Streams `to_string(s)`.
std::ostream& operator<<(std::ostream& os, Sweep s);

/// Parameters of `BlockSOR`.
struct BlockSORParams {
    /// Relaxation factor omega in (0, 2). Default 1: plain (block) Gauss–Seidel, a safe smoother;
    /// the 1995 paper tunes omega (about 1.2 to 1.5) for SORCF.
    double omega = 1.0;
    /// Sweep direction. Default forward: cheapest; `symmetric` gives SSOR.
    Sweep sweep = Sweep::forward;
    /// Sweeps per `apply`/`smooth`, >= 1 (a symmetric sweep counts as one). Default 1.
    int n_sweeps = 1;
    /// Size of uniform diagonal blocks (rows 0..b-1, b..2b-1, ...; the last block may be
    /// shorter), >= 1; used only when `block_starts` is empty. Default 1: point SOR. Use 2 for
    /// the vertex blocks (u_x, u_y) of a problem without contact.
    Index block_size = 1;
    /// First row of every diagonal block, strictly increasing, starting at 0; a block ends where
    /// the next starts (the last at n). A trailing entry equal to n is allowed. Default empty:
    /// uniform blocks of `block_size`. Pass the vertex starts of the contact dof map so that a
    /// contact vertex with its multipliers forms one 4x4 (3x3 frictionless) block.
    std::vector<Index> block_starts = {};
    /// A diagonal block is singular when a pivot of its partial-pivoting LU satisfies
    /// |u_kk| <= singular_tol * max |block entry|, in [0, 1). Default 1e-14: exact zeros and
    /// round-off remnants only.
    double singular_tol = 1e-14;

    /// Throws mlc::InvalidInput naming the first field out of range (block_starts is checked
    /// against the matrix size in `BlockSOR::setup`).
    void validate() const;
};

/// Prints every field of `p` on one line (block_starts as a count and the largest block).
std::ostream& operator<<(std::ostream& os, const BlockSORParams& p);

/// Block starts 0, b, 2b, ... for n rows in blocks of size b (the last block may be shorter).
std::vector<Index> uniform_block_starts(Index n, Index block_size);

/// Block SOR / SSOR: A = L + D + U with D the block diagonal and L, U the strict block lower and
/// upper parts. One forward sweep on A x = b is
///   x_I <- x_I + omega D_I^{-1} (b_I - sum_J A_IJ x_J)   for I = 0, 1, ...
/// (x_J already updated for J < I), i.e. x <- x + (D/omega + L)^{-1} (b - A x). A backward sweep
/// visits the blocks in reverse, C = D/omega + U; a symmetric sweep does both, which gives
///   C_SSOR = omega/(2 - omega) (D/omega + L) D^{-1} (D/omega + U),
///   C_SSOR^{-1} = omega (2 - omega) (D + omega U)^{-1} D (D + omega L)^{-1}.
///
/// Each D_I is inverted once in `setup` by dense LU with partial pivoting, so zero scalar
/// diagonals inside a block (contact multipliers in stick or slip-normal rows) are fine as long
/// as the block is nonsingular. A singular block (for point blocks: a zero or missing diagonal)
/// throws mlc::InvalidInput from `setup` naming the block and its rows: the blocking does not
/// suit A, so group each contact node's multipliers with its vertex.
///
/// `setup` stores a reference to A: A must outlive this object (or the next `setup`).
/// `apply`, `apply_transpose` and `smooth` do not allocate once sizes are set; they use mutable
/// work vectors, so one object must not be used from two threads at once. r and z (b and x)
/// must be distinct objects.
class BlockSOR final : public Smoother {
public:
    /// Validates `params`.
    explicit BlockSOR(BlockSORParams params = {});

    /// Checks A and the blocking, inverts the diagonal blocks. Allocates.
    void setup(const SparseMatrix& A) override;
    /// z = C^{-1} r: n_sweeps sweeps from z = 0 (the first one skips the zero part of z).
    void apply(const Vector& r, Vector& z) const override;
    /// z = C^{-T} r, the exact transpose of `apply` (half-sweeps on A^T in reverse order).
    void apply_transpose(const Vector& r, Vector& z) const override;
    /// n_sweeps sweeps on A x = b, x updated in place.
    void smooth(const Vector& b, Vector& x) const override;
    /// "sor(omega=W)", "ssor(omega=W)", "backward-sor(omega=W)", with ",sweeps=N" when N > 1,
    /// ",block=B" for uniform blocks B > 1 and ",blocks=var" for given block starts.
    std::string name() const override;

    /// Number of diagonal blocks after the last `setup`.
    Index n_blocks() const { return static_cast<Index>(starts_.size()) - 1; }
    /// Largest block size after the last `setup`.
    Index max_block_size() const { return max_block_; }
    /// The parameters in effect.
    const BlockSORParams& params() const { return params_; }

private:
    void half_sweep(const Vector& b, Vector& x, bool forward, bool from_zero) const;
    void solve_lower_transpose(Vector& w) const; // (D/omega + L)^T t = w, t -> w
    void solve_upper_transpose(Vector& w) const; // (D/omega + U)^T t = w, t -> w

    BlockSORParams params_;
    const SparseMatrix* A_ = nullptr;
    std::vector<Index> starts_; // block starts followed by n
    std::vector<Index> offset_; // offset of block I's inverse in dinv_
    std::vector<double> dinv_;  // row-major inverses of the diagonal blocks
    Index max_block_ = 0;
    mutable Vector work_; // one block's residual
    mutable Vector res_;  // n-vector for apply_transpose
};

} // namespace mlc::smoothers

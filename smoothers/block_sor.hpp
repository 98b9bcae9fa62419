// SPDX-License-Identifier: MIT
/// @file Point and block SOR / SSOR (Gauss–Seidel with relaxation) preconditioner and smoother,
/// with variable block sizes so that 2x2 vertex and 4x4 vertex+multiplier blocks are handled, and
/// threaded "hybrid" parts: the one block Gauss–Seidel of the code base (`--pc sor/ssor` and the
/// multigrid smoother of solvers/mg).
#pragma once

#include "core/csr.hpp"
#include "core/first_touch.hpp"
#include "core/linear_operator.hpp"

#include <Eigen/Dense>

#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace mlc::smoothers {

/// Parts of the hybrid block Gauss–Seidel when BlockSORParams::parts is 0 (the multigrid's
/// smoother): two, as many as the cores of the machines this was tuned on. Fixed, so that the
/// smoother is the same linear map with one thread, two, or a loaded core.
inline constexpr int kHybridParts = 2;

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

/// The arithmetic of a sweep. Both compute the same map in exact arithmetic; they differ in the
/// last bits, and each reproduces the results of one of the two smoothers merged here.
enum class Kernel {
    /// Row residuals b_i - sum_j a_ij x_j subtracted one entry at a time in storage order; block
    /// inverses by partial-pivoting LU, the correction scaled by omega after the block solve.
    /// The default: the arithmetic of `--pc sor/ssor` (their published counts stay identical).
    in_order,
    /// Row residuals by core's `row_dot` (four accumulators); 2x2 blocks inverted in closed
    /// form, larger ones by full-pivoting LU, omega folded into the inverses. About twice as
    /// fast on the sweeps; the arithmetic of the multigrid smoother.
    unrolled
};

/// "in_order" or "unrolled".
std::string_view to_string(Kernel k);

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
    /// Pivot threshold in [0, 1) of the block inversions: the fast paths take a block whose
    /// pivots exceed singular_tol times its largest entry (in_order: partial-pivoting LU; unrolled:
    /// |det| against the 2x2 products, full-pivoting LU threshold), other blocks are equilibrated
    /// and singular when a full-pivoting LU pivot of the scaled block is below singular_tol times
    /// its largest (see `BlockSOR`). Default 1e-14: exact zeros and round-off remnants only.
    double singular_tol = 1e-14;
    /// Number of parts (hybrid Gauss–Seidel, see `BlockSOR`), >= 0: 0 takes kHybridParts; at
    /// most one part per kMinRowsPerThread rows is used (small matrices stay sequential). The
    /// parts never depend on the number of threads or on the load (core/parallel runs them on
    /// whichever threads are free), so neither changes an iteration count. Default 1: plain
    /// sequential (block) Gauss–Seidel, the exact SOR map, which `apply_transpose` needs.
    int parts = 1;
    /// Arithmetic of the sweeps. Default in_order (see `Kernel`).
    Kernel kernel = Kernel::in_order;
    /// Precision of the stored smoother data. float64 (default): the sweeps read A's own values
    /// and double block inverses. float32: a float copy of A's values (rounded at every `setup`
    /// and `update_values`; A's pattern is shared, so it costs 4 bytes per nonzero beside A) and
    /// the block inverses (computed in double, then rounded) are what the sweeps read, with x, b
    /// and the residual still double and every product summed in double; the traffic account
    /// counts 4-byte values. About a third fewer bytes per sweep; `apply_transpose` refuses it.
    Precision precision = Precision::float64;

    /// Throws mlc::InvalidInput naming the first field out of range (block_starts is checked
    /// against the matrix size in `BlockSOR::setup`).
    void validate() const;
};

/// Row-major view of one block's inverse.
using BlockInverseMap =
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;

/// D^{-1} of a diagonal block that a fast path rejected: equilibrated full-pivoting LU with the
/// relative pivot threshold `singular_tol` (see BlockSOR). Block b (rows s0 ..) names it in the
/// messages: a zero row or column throws mlc::InvalidInput, a singular block SolverBreakdown.
void robust_block_inverse(const Eigen::MatrixXd& D, Index b, Index s0, double singular_tol,
                          BlockInverseMap inv);

/// omega D^{-1} as the unrolled kernel forms it: 2x2 in closed form, larger blocks by
/// full-pivoting LU, robust_block_inverse for the blocks those reject.
void invert_block_unrolled(const Eigen::MatrixXd& D, Index b, Index s0, double omega, double tol,
                           BlockInverseMap inv);

/// Prints every field of `p` on one line (block_starts as a count and the largest block).
std::ostream& operator<<(std::ostream& os, const BlockSORParams& p);

/// Parts of a hybrid sweep: `requested` (0: kHybridParts), at most one per kMinRowsPerThread
/// rows and one per block, at least one (BlockSOR's and LatticeGS's cut).
Index hybrid_part_count(int requested, Index rows, Index blocks);

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
/// Each D_I is inverted once in `setup` (and again in `update_values`) by dense LU, so zero
/// scalar diagonals inside a block (contact multipliers in stick or slip-normal rows) are fine as
/// long as the block is nonsingular. The kernel's fast path (see `Kernel`) tests its pivots
/// against singular_tol times the block's largest entry or pivot; a block it rejects is not
/// necessarily singular: a vertex + multiplier block mixes rows of size E with multiplier rows of
/// size 1 and 1/r, so with a large r ([[K, 0], [0, -I/r]]) or nu near 1/2 (K of size 1e8 next to
/// entries 1) its pivots span more than 1/singular_tol. Such a block is equilibrated (rows and
/// columns scaled by powers of two until their largest entries are within a factor 2 of 1) and
/// inverted by full-pivoting LU with the threshold singular_tol relative to the scaled block's
/// largest pivot. Only then:
/// - a zero row or column inside a block (for point blocks: a zero or missing diagonal) throws
///   mlc::InvalidInput naming the block and its rows: the blocking does not suit A, so group
///   each contact node's multipliers with its vertex;
/// - a block that is singular even equilibrated throws mlc::SolverBreakdown with the block's
///   entries (the Jacobian is singular at that node).
/// Blocks that pass the fast path are inverted exactly as before the fallback existed.
///
/// Parts (hybrid Gauss–Seidel, as in hypre's threaded relaxation): with `parts` != 1 the blocks
/// are cut at setup into P contiguous runs of about equal nonzeros, one per OpenMP thread. Each
/// part sweeps its own blocks in order with the newest values of its own unknowns, and reads the
/// unknowns of the other parts as they were when the sweep began (Jacobi across the cuts). So
/// every sweep is the same linear map whatever the threads do, and with P = 1 it is plain block
/// Gauss–Seidel. With the unknowns numbered along a space-filling curve the parts are compact
/// pieces of the domain and only their few interface rows differ from a sequential sweep.
///
/// `setup` stores a reference to A: A must outlive this object (or the next `setup` /
/// `update_values`). `update_values` re-inverts the blocks; the parts and the positions of the
/// diagonal blocks are derived anew only when A's pattern differs from the last one's
/// (core's SparsityPattern). `apply`, `apply_transpose`, `smooth`, `sweep` and
/// `forward_from_zero` do not allocate once sizes are set; they use mutable work vectors, so one
/// object must not be used from two threads at once. r and z (b and x) must be distinct objects.
/// Every half-sweep counts one smoother pass of traffic::sweep_bytes, `forward_from_zero` two
/// passes of traffic::sweep_from_zero_bytes together (core/traffic.hpp).
class BlockSOR final : public Smoother {
public:
    /// Validates `params`.
    explicit BlockSOR(BlockSORParams params = {});

    /// Checks A and the blocking, splits the parts, inverts the diagonal blocks. Allocates.
    void setup(const SparseMatrix& A) override;
    /// New values of A: re-inverts the blocks (parts and diagonal positions kept when the
    /// pattern is the last one's; a different size means a full `setup`).
    void update_values(const SparseMatrix& A) override;
    /// z = C^{-1} r: n_sweeps sweeps from z = 0 (the first one skips the zero part of z).
    void apply(const Vector& r, Vector& z) const override;
    /// z = C^{-T} r, the exact transpose of `apply` (half-sweeps on A^T in reverse order).
    /// Needs one part (throws mlc::InvalidInput otherwise).
    void apply_transpose(const Vector& r, Vector& z) const override;
    /// n_sweeps sweeps on A x = b, x updated in place.
    void smooth(const Vector& b, Vector& x) const override;
    /// One sweep on A x = b in the given direction (symmetric: forward then backward), in place,
    /// whatever `params().sweep` and `params().n_sweeps` say.
    void sweep(const Vector& b, Vector& x, Sweep direction) const;
    /// x = one forward sweep from x = 0, and res = b - A x, in one pass over A (the lower part
    /// during the sweep, the block-diagonal and upper part after it). x and res are resized.
    void forward_from_zero(const Vector& b, Vector& x, Vector& res) const;
    /// "sor(omega=W)", "ssor(omega=W)", "backward-sor(omega=W)", with ",sweeps=N" when N > 1,
    /// ",block=B" for uniform blocks B > 1, ",blocks=var" for given block starts, ",parts=P"
    /// when P != 1, ",unrolled" for that kernel and ",single" for float32 data.
    std::string name() const override;

    /// Number of diagonal blocks after the last `setup`.
    Index n_blocks() const { return static_cast<Index>(starts_.size()) - 1; }
    /// Largest block size after the last `setup`.
    Index max_block_size() const { return max_block_; }
    /// Number of parts of the last setup.
    int parts() const { return static_cast<int>(part_block_.size()) - 1; }
    /// First row of every part, then the number of rows.
    std::vector<Index> part_rows() const;
    /// The parameters in effect.
    const BlockSORParams& params() const { return params_; }
    /// float32: A's values rounded to float, in A's storage order (empty for float64); valid
    /// until the next `setup` / `update_values`.
    const float* values32() const { return values32_.data(); }

private:
    void derive_structure(); // parts and diagonal positions, from *A_'s pattern
    using InverseMap =
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;
    void invert_blocks();
    // Blocks [b_begin, b_end) of invert_blocks (one chunk of the threads' loop).
    void invert_block_range(Index b_begin, Index b_end, const int* ao, const int* ai,
                            const double* av, double omega, double tol);
    static constexpr size_t kInvertBlocksPerChunk = 4096;
    // float32: values32_ from A's values and dinv32_ from dinv_ (then released).
    void round_data();
    // D^{-1} of a block the kernel's fast path rejected (equilibrated full-pivot LU); throws.
    void robust_inverse(const Eigen::MatrixXd& D, Index b, Index s0, InverseMap inv) const;
    // One half-sweep; `count`: one smoother pass of traffic::sweep_bytes (core/traffic.hpp).
    void half_sweep(const Vector& b, Vector& x, bool forward, bool from_zero,
                    bool count = true) const;
    // One part's sweep (blocks [b0, b1)), other parts' unknowns read from snap_; `av` and
    // `dinv` are A's values and the block inverses in the stored precision.
    template <class Value>
    void sweep_part(const Value* av, const Value* dinv, const double* bp, double* xp, Index b0,
                    Index b1, bool forward, bool from_zero, double* t) const;
    template <class Value>
    void forward_from_zero_unrolled(const Value* val, const Value* dinv, const double* bp,
                                    double* xp, double* rp) const;
    // Entries of the stored block inverses and their bytes per value, for the traffic account.
    Index inverse_entries() const { return offset_.empty() ? 0 : offset_.back(); }
    int value_size() const { return value_bytes(params_.precision); }
    void solve_lower_transpose(Vector& w) const; // (D/omega + L)^T t = w, t -> w
    void solve_upper_transpose(Vector& w) const; // (D/omega + U)^T t = w, t -> w

    BlockSORParams params_;
    const SparseMatrix* A_ = nullptr;
    SparsityPattern pattern_;   // of A at the last derive_structure
    std::vector<Index> starts_; // block starts followed by n
    std::vector<Index> offset_; // offset of block I's inverse in dinv_
    // Row-major inverses (times omega for `unrolled`); float64 only. Uninitialised on resize:
    // invert_blocks writes every entry, over the threads.
    parallel::UninitializedVector<double> dinv_;
    parallel::UninitializedVector<float> values32_, dinv32_; // float32: A's values, inverses
    double post_ = 1.0; // factor of the block correction: omega or 1 (unrolled)
    Index max_block_ = 0;
    std::vector<int> diag_begin_;          // per row: first stored entry in or right of its block
    std::vector<int> own_begin_, own_end_; // per row: its entries with columns in its own part
    std::vector<char> twin_;        // per block: a 2x2 block whose rows have the same columns
    std::vector<Index> part_block_; // first block of each part, then the block count
    std::vector<int> interface_;    // columns read across a cut (copied into snap_)
    mutable Vector snap_;           // other parts' unknowns at the start of a sweep
    mutable Vector work_;           // one block's residual per part
    mutable Vector res_;            // n-vector for apply_transpose
};

} // namespace mlc::smoothers

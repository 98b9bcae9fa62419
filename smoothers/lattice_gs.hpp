// SPDX-License-Identifier: MIT
/// @file Vertex-block Gauss–Seidel with structured kernels on the macro triangles' interiors
/// (mg:smoother=lattice): the multigrid smoother of a uniformly refined level.
///
/// On a level refined `depth` times from level 0, the vertices inside each level-0 ("macro")
/// triangle form a triangular lattice (mesh/lattice.hpp) on which every element has the same
/// stiffness, so each vertex whose six neighbours are inside the macro has the same 2x2-block
/// stencil. The assembled sweep (BlockSOR) reads 14 column indices and 28 values per such vertex
/// and gathers x through them. When the level's unknowns are numbered macro by macro, each
/// interior row by row (levels::Problem::Numbering::lattice), a vertex's neighbours sit at fixed
/// offsets from it, and the stencil and its inverted centre block are read once per macro:
///  - "deep" points: interior lattice points whose six neighbours are interior too, in the same
///    threaded part, and whose rows hold exactly the macro's stencil (to stencil_tol of its
///    largest entry), by the stencil, in runs along each lattice row (the point visited just
///    before entering last: x_new = c - G x_behind, see deep_run);
///  - "semi-deep" points: the other interior points whose seven column pairs are plain 2x2 blocks
///    of their part and whose rows hold the stencil (the points next to a macro edge, or next to
///    a cut), by the stencil through a list of their neighbours' rows;
///  - every other block (the macro edges and corners, contact vertices with their multipliers,
///    fixed components, macros not numbered as a lattice) by its own rows, as BlockSOR does.
/// The blocks are visited in a given order (LatticeRows::visit: the multigrid gives each macro's
/// interior in serpentine rows, levels::lattice_rows; the Hilbert order reproduces BlockSOR's)
/// and cut into threaded parts as BlockSOR cuts them (runs of that order of about equal
/// nonzeros, Jacobi across the cuts), so the sweep is block Gauss–Seidel of the matrix in that
/// order, its stencil rows summed differently (round-off). `multiply` is the matrix's product by
/// the same data.
///
/// `update_values` re-reads the row-swept rows, re-inverts their blocks and checks the deep and
/// semi-deep rows against their stencils (a full setup when one no longer matches). Every
/// half-sweep counts one smoother pass (core/traffic).
#pragma once

#include "core/csr.hpp"
#include "core/first_touch.hpp"
#include "core/linear_operator.hpp"
#include "smoothers/block_sor.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace mlc::smoothers {

namespace lattice {
struct Layout; // what the phases of LatticeGS's setup hand on (lattice_gs_setup.cpp)
} // namespace lattice

/// The rows of the interior lattice points of every macro triangle, and the visiting order.
struct LatticeRows {
    /// Subdivisions per macro edge (2^depth); below 6 there are no deep points.
    int n = 0;
    /// first_row[m * (n-1)(n-2)/2 + p]: the first of the two rows of the vertex at interior point
    /// p of macro m (mesh::MacroLattice's numbering), or -1 when that vertex is not a plain 2x2
    /// vertex block (a fixed component, contact multipliers). A macro whose points are not
    /// rows first_row[m * np] + 2p (a lattice numbering) is swept by rows.
    std::vector<Index> first_row;
    /// The first row of every block in the order the sweep visits them (a permutation of the
    /// blocks); empty: row order.
    std::vector<Index> visit;

    /// Interior points of one macro, (n-1)(n-2)/2 (mesh::MacroLattice::interior_points; this
    /// folder does not depend on mesh/).
    static long interior_points(int n) {
        return n < 3 ? 0 : static_cast<long>(n - 1) * (n - 2) / 2;
    }
    /// Index of interior point (i, j) in its macro's row-by-row numbering
    /// (mesh::MacroLattice::point_index).
    static long point_index(int n, int i, int j) {
        return static_cast<long>(j - 1) * (2 * n - 2 - j) / 2 + (i - 1);
    }
    /// Macros: first_row.size() / interior_points(n) (0 without interior points).
    long macros() const {
        const long np = interior_points(n);
        return np == 0 ? 0 : static_cast<long>(first_row.size()) / np;
    }
    /// The first row of macro m's interior when its points are rows first_row[m np] + 2p (a
    /// lattice numbering of the macro), else -1.
    Index lattice_base(long m) const {
        const long np = interior_points(n);
        const Index* f = first_row.data() + m * np;
        if (np == 0 || f[0] < 0) return -1;
        for (long p = 1; p < np; ++p)
            if (f[p] != f[0] + 2 * p) return -1;
        return f[0];
    }
};

/// Parameters of `LatticeGS`.
struct LatticeGSParams {
    double omega = 1.0; ///< relaxation, in (0, 2), folded into the block inverses
    /// Threaded parts, >= 0 (0: kHybridParts), at most one per kMinRowsPerThread rows, as
    /// BlockSORParams::parts.
    int parts = 0;
    double singular_tol = 1e-14; ///< pivot threshold of the block inversions (BlockSORParams)
    /// A deep row matches its macro's stencil when every entry is within stencil_tol times the
    /// stencil's largest entry (rounding of the element stiffness of congruent triangles).
    double stencil_tol = 1e-12;
};

/// The vertex-block Gauss–Seidel smoother with structured kernels on the macro triangles'
/// interiors (mg:smoother=lattice); see the file comment.
class LatticeGS {
public:
    /// block_starts: the vertex blocks (first row of each, as BlockSORParams::block_starts).
    LatticeGS(std::vector<Index> block_starts, LatticeRows lattice, LatticeGSParams params = {});

    /// Parts, stencils, deep points, rows and block inverses from A (square, compressed CSR).
    void setup(const SparseMatrix& A);
    /// New values of A with the same pattern (a different pattern or size: setup).
    void update_values(const SparseMatrix& A);
    /// `count` sweeps on A x = b in the given direction (forward or backward), x updated.
    void smooth(const Vector& b, Vector& x, Sweep direction, int count) const;
    /// x = one forward sweep from zero, res = b - A x.
    void forward_from_zero(const Vector& b, Vector& x, Vector& res) const;

    /// y = A x for the matrix of the last setup or update_values: deep and semi-deep rows by
    /// their macro's stencil (equal to A's rows to stencil_tol), every other row by its
    /// entries; rows over the parts' threads. Counts one mat-vec pass (core/traffic) with the bytes
    /// it reads.
    void multiply(const Vector& x, Vector& y) const;

    /// Interior lattice points swept by their macro's stencil after the last setup.
    Index deep_points() const { return n_deep_; }
    /// Interior lattice points next to a macro edge (or a part's cut) whose rows hold the
    /// macro's stencil: swept by it, their neighbours through a list of rows.
    Index semi_deep_points() const { return static_cast<Index>(semi_macro_.size()); }
    /// Rows of the matrix.
    Index rows() const { return n_; }
    /// Parts of the last setup.
    int parts() const { return static_cast<int>(part_visit_.size()) - 1; }
    /// The first rows of the blocks of a part in forward sweep order.
    std::vector<Index> sweep_order_blocks(int part) const;
    /// "lattice-gs(omega=W,parts=P)".
    std::string name() const;

private:
    // The setup, in phases (lattice_gs_setup.cpp).
    void derive(const SparseMatrix& A);
    void derive_blocks(lattice::Layout& lay) const;
    void derive_parts(const SparseMatrix& A, lattice::Layout& lay) const;
    void derive_points(const SparseMatrix& A, lattice::Layout& lay);
    void number_visits(const lattice::Layout& lay);
    void group_items();
    void derive_swept_rows(const SparseMatrix& A, const lattice::Layout& lay);
    void load_rows(const SparseMatrix& A); // values of the row-swept blocks and their inverses
    bool deep_rows_match(const SparseMatrix& A) const;
    bool same_pattern(const SparseMatrix& A) const;
    template <bool Forward> void sweep_part(int p, const double* b, double* x) const;
    // The row step (+2 or -2) of the deep run of visit entries [i0, i1) (+2 for one point).
    long run_step(int i0, int i1) const;
    void half_sweep(const double* b, double* x, bool forward) const;

    std::vector<Index> block_starts_in_;
    LatticeRows lattice_;
    LatticeGSParams params_;
    Index n_ = 0;
    const SparseMatrix* A_ = nullptr;
    std::vector<int> outer_; // A's row pointers at the last setup
    Index nnz_ = 0;
    // Per macro (kStencil doubles): 7 slots x 2x2 (row-major), omega D^-1, G_east, G_west, then
    // the same ten blocks packed for two-lane arithmetic.
    std::vector<double> stencils_;
    // The visit: per part a run of entries; entry i is a deep point (code >= 0: macro * 4096 +
    // its row's length, the neighbour offsets) at first row visit_row_[i], a semi-deep point
    // (code kSemi + its index into semi_*), or a row-swept block (code = -1 - its index into
    // cb_*).
    std::vector<int> part_visit_;
    std::vector<int> visit_row_, visit_code_;
    // The visit cut into items (item k: entries item_begin_[k] to item_begin_[k + 1]), those of
    // part p from part_item_[p]: a run of deep points along one lattice row (swept by deep_run),
    // a run of semi-deep points, or a run of row-swept blocks.
    std::vector<int> item_begin_, part_item_;
    Index n_deep_ = 0;
    // Deep points: first row, macro, and their neighbours' slots in A's column order, to check
    // them at update_values.
    std::vector<int> deep_row_, deep_len_, deep_macro_;
    std::vector<std::uint8_t> deep_slots_; // 7 per deep point
    // Semi-deep points (visit code kSemi + index): interior points whose rows hold their macro's
    // stencil, some neighbours on the macro's edges: macro, the neighbours' first rows by slot
    // (7 per point, slot 0 the point's own), and the slot of each column pair of its rows.
    std::vector<int> semi_macro_, semi_nbr_;
    std::vector<std::uint8_t> semi_slots_;
    // Row-swept blocks: first row, size, block index, their rows (entries of the own part
    // first, then those read across a cut), twin flag and inverse.
    std::vector<int> cb_row_, cb_size_, cb_block_, cb_crow_;
    std::vector<char> cb_twin_;
    std::vector<Index> cb_inv_;
    std::vector<int> crow_ptr_, crow_own_end_;
    std::vector<int> ccol_, csrc_;
    parallel::UninitializedVector<double> cval_, cinv_;
    std::vector<int> interface_; // columns read across the cuts
    mutable Vector snap_;
};

/// A LatticeGS's matrix as a LinearOperator (LatticeGS::multiply): the Krylov product of a level
/// whose multigrid smoother is mg:smoother=lattice. The smoother must outlive it.
class LatticeOperator final : public LinearOperator {
public:
    explicit LatticeOperator(const LatticeGS& gs) : gs_(gs) {}
    Index rows() const override { return gs_.rows(); }
    Index cols() const override { return gs_.rows(); }
    void apply(const Vector& x, Vector& y) const override { gs_.multiply(x, y); }

private:
    const LatticeGS& gs_;
};

} // namespace mlc::smoothers
